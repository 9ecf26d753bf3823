#!/usr/bin/env bash
# SIGKILL of one actor in the middle of a run: the run goes on and still reaches the goal.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
launch cartpole --out "$dir/run" --actors 4 --seed 2 --time-budget 240 > "$dir/launch.log" 2>&1 &
launch_pid=$!
# Mid-run: the learner has trained (its first checkpoint has been scored).
wait_line "$dir/launch.log" "running; logs in" 60
wait_line "$dir/run/logs/monitor.log" "evaluation: update" 120
victim=$(awk '$1=="actor-1"{print $2}' "$dir/run/pids")
[ -n "$victim" ] || fail "no pid for actor-1"
kill -KILL "$victim"
echo "killed actor-1 (pid $victim)"
set +e
wait "$launch_pid"
status=$?
set -e
tail -8 "$dir/launch.log"
kill -0 "$victim" 2>/dev/null && fail "actor-1 is still alive"
[ "$status" -eq 0 ] || fail "launch exited with $status after an actor was killed"
grep -q "goal of .* reached" "$dir/launch.log" || fail "goal not reported"
echo "PASS: the run reached its goal without actor-1"
