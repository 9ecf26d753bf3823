#!/usr/bin/env bash
# The restart policy and the monitor agree: a process killed again and again is restarted after
# 1, 2, 4, 4, 4, 4 s (doubled up to the backoff's cap and then held there; the cap is
# --max-backoff 4, which shows both in 19 s of waits where the default cap of 10 s takes 35 s),
# and the monitor, whose silence limit the launcher derives from that cap, does not end the run
# while it waits; and a process that ran --reset-restarts-after seconds before it died earns its
# count back (restart 1 again), where a count that never reset would have left it down.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
launch cartpole --out "$dir/run" --actors 1 --seed 3 --goal 1000000 --time-budget 200 \
  --max-restarts 6 --max-backoff 4 --reset-restarts-after 12 > "$dir/launch.log" 2>&1 &
launch_pid=$!
run="$dir/run"
wait_line "$dir/launch.log" "running; logs in" 60

# Kills the evaluator's current start; expects the restart line of restart N, then its next start
# (the K+1-th), ready. Each kill comes after the start before it is ready and has spoken, so that
# each silence the monitor sees is one backoff and one start, as a crash's.
kill_evaluator() {  # kill_evaluator N K
  local victim
  victim=$(awk '$1 == "evaluator" {p = $2} END {print p}' "$run/pids")
  kill -KILL "$victim"
  wait_lines "$run/pids" "^evaluator " $(($2 + 1)) 60  # started again
  [ "$(tail -1 "$run/restarts" | cut -d' ' -f2-)" = "evaluator status 137 restart $1" ] ||
    fail "kill $2: the restart line is $(tail -1 "$run/restarts")"
  echo "$(tail -1 "$run/restarts")"
  # Its log's last line of either kind is a ready line: this start's.
  timeout 60 bash -c 'until grep "^evaluator: ready\|^launch: evaluator" "$0" | tail -1 | grep -q "^evaluator: ready"; do
      sleep 0.05; done' "$run/logs/evaluator.log" || fail "the evaluator was not ready again after kill $2"
  # And heard: its stats go out a few times a second (RL_STATS_EVALUATOR), so a second of running
  # ends the monitor's silence (without it the silences would add up, which no crash does).
  sleep 1
  kill -0 "$launch_pid" 2>/dev/null || fail "the run ended during restart $1: $(tail -3 "$dir/launch.log")"
}
for k in 1 2 3 4 5 6; do kill_evaluator "$k" "$k"; done
grep -q "silent" "$run/logs/monitor.log" && fail "the monitor took a restart for a silent process"
# Alive for longer than --reset-restarts-after: its next death starts a new count. (The limit,
# 12 s, is well above the few seconds from a start to its kill above, which a loaded machine
# stretches: a start that outlived it would have begun a new count too soon.)
sleep 13
kill_evaluator 1 7
echo "(after 13 s of running: its count earned back)"
"$root/scripts/launch.sh" --stop "$run" > "$dir/stop.log" 2>&1 || fail "--stop: $(cat "$dir/stop.log")"
status=0
wait "$launch_pid" || status=$?
[ "$status" -eq 130 ] || fail "the run ended with $status, not by the --stop (130): $(tail -3 "$dir/launch.log")"
# The waits of the seven restarts, in order: doubled up to the cap, held there, and 1 s again
# after the count was earned back.
waits=$(sed -n 's/.*restarting it in \([0-9.]*\) s (restart [0-9]* of 6).*/\1/p' "$dir/launch.log" | xargs)
[ "$waits" = "1 2 4 4 4 4 1" ] || fail "the restarts waited $waits s, not 1 2 4 4 4 4 1"
echo "PASS: 7 restarts, the backoff capped at 4 s, the run never ended by the monitor, the count earned back"
