#!/usr/bin/env bash
# Malformed, truncated, foreign-run, invalid, replayed and unauthenticated (no MAC, another key's
# MAC, a bit flipped after signing) messages on every channel are counted and dropped by every
# process, no process crashes, and valid traffic still flows on every path afterwards: the replay
# keeps inserting, the learner keeps updating, the actors get weights made after the bad messages
# and the evaluator scores a checkpoint made after them. Ctrl-C then stops the run cleanly. Usage: bad_messages.sh [PRESET] (default cartpole; the
# pendulum preset makes it a continuous run, where the action fields carry a NaN torque, a torque
# far outside the bounds and one torque too many).
source "$(dirname "$0")/lib.sh"
isolate "$@"
preset=${1:-cartpole}
scratch
# Job control gives the run its own process group, as a terminal would, so that the Ctrl-C below
# reaches every process of the run (without it, bash starts background jobs ignoring SIGINT).
set -m
launch "$preset" --out "$dir/run" --actors 2 --seed 3 --goal 1000000 --time-budget 300 \
  > "$dir/launch.log" 2>&1 &
launch_pid=$!
set +m
wait_line "$dir/launch.log" "running; logs in" 60
run="$dir/run"
env_id=$(sed -n 's/^env = //p' "$run/config.ini" | head -1)
"$bin/inject" --env "$env_id" --run-id "$(run_setting "$run" run-id)" --key-file "$run/key" --lcm-url "$(run_setting "$run" lcm-url)" \
  --lcm-bulk-url "$(run_setting "$run" lcm-bulk-url)" \
  --lcm-samples-url "$(run_setting "$run" lcm-samples-url)" --count 20 --timeout 30 \
  --roles replay,learner,actor,evaluator || fail "the processes did not count every bad message"
# Every process is still alive.
while read -r role pid; do
  kill -0 "$pid" 2>/dev/null || fail "$role (pid $pid) died"
done < "$run/pids"
# And still working. The counts are taken once the monitor has written two more learner rows (so
# that no stats of before the injection's end are read as "after"); then, within a bound, the
# replay's inserts and the learner's updates must grow, actor-0 must hold weights of a later update
# and the evaluator must have scored a checkpoint of a later update.
metrics="$run/metrics.jsonl"
rows=$(lines "$metrics" '"role": "learner"')  # a short run may have no learner row yet
wait_lines "$metrics" '"role": "learner"' $((rows + 2)) 30
inserts0=$(last_metric "$run" replay inserts)
updates0=$(last_metric "$run" learner updates)
[ -n "$inserts0" ] && [ -n "$updates0" ] || fail "no replay or learner rows in $metrics"
flow() {
  echo "replay inserts $inserts0 -> $inserts, learner updates $updates0 -> $updates," \
    "actor-0 weights version $weights, last scored checkpoint at update $scored"
}
deadline=$((SECONDS + 150))
while :; do
  inserts=$(last_metric "$run" replay inserts)
  updates=$(last_metric "$run" learner updates)
  weights=$(last_metric "$run" actor-0 weights_version)
  scored=$(last_scored_update "$run")
  if awk -v i0="$inserts0" -v i="$inserts" -v u0="$updates0" -v u="$updates" -v w="$weights" \
       -v s="$scored" 'BEGIN { exit !(i >= i0 + 100 && u >= u0 + 100 && w > u0 && s > u0) }'; then
    break
  fi
  [ "$SECONDS" -lt "$deadline" ] || fail "valid traffic stalled after the bad messages: $(flow)" \
    "(wanted at least 100 more inserts and updates, and weights and a scored checkpoint of an" \
    "update after $updates0)"
  sleep 0.5
done
echo "after the bad messages: $(flow)"
kill -INT -- "-$launch_pid"  # Ctrl-C: SIGINT to the run's process group
set +e
wait "$launch_pid"
status=$?
set -e
[ "$status" -eq 130 ] || fail "launch exited with $status after Ctrl-C, expected 130"
while read -r role pid; do
  kill -0 "$pid" 2>/dev/null && fail "$role (pid $pid) survived the stop"
done < "$run/pids"
grep -q "stopped" "$run/logs/replay.log" "$run/logs/learner.log" || fail "no clean stop"
[ -s "$run/report/index.html" ] || fail "no report after Ctrl-C"
expect_no_sanitizer_reports "$run"
expect_no_restarts "$run"
echo "PASS: every bad message counted and dropped ($preset, $env_id); valid traffic flowed after them; clean stop"
