#!/usr/bin/env bash
# Recorded traffic played back into the live run it came from changes nothing: a CartPole run
# records its main port (launch.sh --record); with its actors stopped, lcm-logplayer plays a copy
# of the recording back onto the run's port; the replay and the evaluator drop every recorded
# message of their channels as replayed (exactly as many as the file holds), the replay inserts
# nothing, and no lost count moves. Then the run goes on, and launch.sh --stop stops it cleanly.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
command -v lcm-logplayer >/dev/null || fail "lcm-logplayer is missing (liblcm-bin)"
set -m
launch cartpole --out "$dir/run" --actors 2 --seed 4 --goal 1000000 --time-budget 120 --record \
  > "$dir/launch.log" 2>&1 &
launch_pid=$!
set +m
wait_line "$dir/launch.log" "running; logs in" 60
run="$dir/run"
# Traffic of every kind, a checkpoint and its evaluation included, then a copy of what the logger
# has written so far (the live file grows while it plays, with the played messages too).
wait_line "$run/eval.jsonl" '"checkpoint"' 60
cp "$run/lcm-log/main.lcmlog.0" "$dir/recording.lcmlog"
actors=$(awk '$1 ~ /^actor-/ {p[$1] = $2} END {for (a in p) print p[a]}' "$run/pids")
[ -n "$actors" ] || fail "no actor in $run/pids"
# shellcheck disable=SC2086
kill -STOP $actors
"$bin/inject" --replayed-log "$dir/recording.lcmlog" --run-id "$(run_setting "$run" run-id)" \
  --key-file "$run/key" --lcm-url "$(run_setting "$run" lcm-url)" \
  --lcm-bulk-url "$(run_setting "$run" lcm-bulk-url)" --timeout 60 > "$dir/inject.log" 2>&1 &
inject_pid=$!
wait_line "$dir/inject.log" "ready for playback" 60
lcm-logplayer --speed=2 --lcm-url="$(run_setting "$run" lcm-url)" "$dir/recording.lcmlog" \
  > "$dir/player.log" 2>&1 || fail "lcm-logplayer failed: $(tail -3 "$dir/player.log")"
set +e
wait "$inject_pid"
inject_status=$?
set -e
cat "$dir/inject.log"
# shellcheck disable=SC2086
kill -CONT $actors
[ "$inject_status" -eq 0 ] || fail "replayed traffic was not all dropped, or it changed the run"
grep -q "dropped a replayed message" "$run/logs/replay.log" || fail "the replay logged no replayed drop"
while read -r role pid; do
  kill -0 "$pid" 2>/dev/null || fail "$role (pid $pid) died"
done < <(awk '{p[$1] = $2} END {for (r in p) print r, p[r]}' "$run/pids")
# Stopped from outside, as a run in the background or in another terminal is.
"$root/scripts/launch.sh" --stop "$run" > "$dir/stop.log" 2>&1 || fail "launch.sh --stop: $(cat "$dir/stop.log")"
grep -q "^launch: stopped" "$dir/stop.log" || fail "launch.sh --stop did not wait for the stop"
while read -r role pid; do
  kill -0 "$pid" 2>/dev/null && fail "$role (pid $pid) was still running when --stop returned"
done < "$run/pids"
set +e
wait "$launch_pid"
status=$?
set -e
[ "$status" -eq 130 ] || fail "launch exited with $status after --stop, expected 130"
set +e
"$root/scripts/launch.sh" --stop "$run" > "$dir/stop2.log" 2>&1
status=$?
set -e
[ "$status" -eq 1 ] && grep -q "is not going" "$dir/stop2.log" ||
  fail "a second --stop did not say the run is not going (status $status): $(cat "$dir/stop2.log")"
expect_no_restarts "$run"
echo "PASS: a recording played back into its run was dropped as replayed and changed nothing"
