#!/usr/bin/env bash
# Malformed, truncated, foreign-run, invalid, replayed and unauthenticated (no MAC, another key's
# MAC, a bit flipped after signing) messages on every channel are counted and dropped by every
# process, and no process crashes. Usage: bad_messages.sh [PRESET] (default cartpole; the
# pendulum preset makes it a continuous run, where the action fields carry a NaN torque, a torque
# far outside the bounds and one torque too many).
source "$(dirname "$0")/lib.sh"
isolate "$@"
preset=${1:-cartpole}
scratch
# Job control gives the run its own process group, as a terminal would, so that the Ctrl-C below
# reaches every process of the run (without it, bash starts background jobs ignoring SIGINT).
set -m
launch "$preset" --out "$dir/run" --actors 2 --seed 3 --goal 1000000 --time-budget 120 \
  > "$dir/launch.log" 2>&1 &
launch_pid=$!
set +m
wait_line "$dir/launch.log" "running; logs in" 60
run="$dir/run"
env_id=$(sed -n 's/^env = //p' "$run/config.ini" | head -1)
"$bin/inject" --env "$env_id" --run-id "$(run_setting "$run" run-id)" --key-file "$run/key" --lcm-url "$(run_setting "$run" lcm-url)" \
  --lcm-bulk-url "$(run_setting "$run" lcm-bulk-url)" --count 20 --timeout 30 \
  --roles replay,learner,actor,evaluator || fail "the processes did not count every bad message"
# Every process is still alive and still working.
while read -r role pid; do
  kill -0 "$pid" 2>/dev/null || fail "$role (pid $pid) died"
done < "$run/pids"
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
expect_no_restarts "$run"
echo "PASS: every bad message counted and dropped ($preset, $env_id); clean stop"
