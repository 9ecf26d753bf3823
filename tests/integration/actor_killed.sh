#!/usr/bin/env bash
# SIGKILL of one actor in the middle of a run: the run goes on and still reaches the goal.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/launch_lib.sh"
isolate "$@"
scratch
start_cartpole "$dir/launch.log" --actors 4 --seed 2 --time-budget 240
# Mid-run: the learner has trained and saved its first checkpoint. (Not later: CartPole can reach
# its goal at the first evaluation, and a run that has ended has no actor left to kill.)
wait_learner_state "$dir/run"
kill_role actor-1
wait_launch "$dir/launch.log"
kill -0 "$victim" 2>/dev/null && fail "actor-1 is still alive"
[ "$status" -eq 0 ] || fail "launch exited with $status after an actor was killed"
grep -q "goal of .* reached" "$dir/launch.log" || fail "goal not reported"
echo "PASS: the run reached its goal without actor-1"
