#!/usr/bin/env bash
# The launcher itself SIGKILLed mid-run: none of its processes lives on (each gets SIGTERM from
# the kernel as its parent dies, and stops cleanly: the replay writes its last snapshot, the
# learner its state); `launch.sh --stop` then says the run is not going, and `launch.sh --resume`
# continues the run to the CartPole goal.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/launch_lib.sh"
isolate "$@"
scratch
start_cartpole "$dir/first.log" --actors 2 --seed 4 --goal 100000 --time-budget 240
disown "$launch_pid"  # (no job notice when it is killed)
wait_learner_state "$dir/run"
kill -KILL "$launch_pid"
echo "killed the launcher (pid $launch_pid)"
expect_all_ended "$dir/run" 15
expect_resumable_after_launcher_death "$dir/run"
echo "PASS: nothing outlived the killed launcher; the run resumed and reached its goal"
