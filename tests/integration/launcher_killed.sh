#!/usr/bin/env bash
# The launcher itself SIGKILLed mid-run: none of its processes lives on (each gets SIGTERM from
# the kernel as its parent dies, and stops cleanly: the replay writes its last snapshot, the
# learner its state); `launch.sh --stop` then says the run is not going, and `launch.sh --resume`
# continues the run to the CartPole goal.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
# launch.sh execs the launcher: $! is the launcher's pid.
"$root/scripts/launch.sh" cartpole --no-setup --build-dir "$build_dir" --out "$dir/run" \
  --actors 2 --seed 4 --goal 100000 --time-budget 240 > "$dir/first.log" 2>&1 &
launcher=$!
disown "$launcher"  # (no job notice when it is killed)
wait_line "$dir/first.log" "running; logs in" 60
wait_learner_state "$dir/run"
kill -KILL "$launcher"
echo "killed the launcher (pid $launcher)"
expect_all_ended "$dir/run" 15
expect_resumable_after_launcher_death "$dir/run"
echo "PASS: nothing outlived the killed launcher; the run resumed and reached its goal"
