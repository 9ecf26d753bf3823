#!/usr/bin/env bash
# The launcher's terminal closes mid-run: the launcher runs in a pseudo-terminal of its own (as
# the session's leader, as in a terminal window), and the terminal's other end closes (the window
# closed, an ssh connection dropped), which hangs it up: the kernel sends SIGHUP to the session
# leader. The launcher must stop the run in order (every process stops cleanly: the replay writes
# its last snapshot, the learner its state) and none may live on; then `launch.sh --stop` says
# the run is not going, and `launch.sh --resume` continues it to the CartPole goal.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
command -v script >/dev/null || fail "script (util-linux) is missing"
cmd="exec '$root/scripts/launch.sh' cartpole --no-setup --build-dir '$build_dir' --out '$dir/run'"
cmd="$cmd --actors 2 --seed 5 --goal 100000 --time-budget 240"
# script(1) holds the terminal's other end and copies what the launcher writes to first.log.
SHELL=/bin/sh script -qfec "$cmd" /dev/null > "$dir/first.log" 2>&1 &
terminal=$!
disown "$terminal"  # (no job notice when it is killed)
wait_line "$dir/first.log" "running; logs in" 60
wait_learner_state "$dir/run"
read -r launcher _ < "$dir/run/launch.pid"
kill -KILL "$terminal"  # the terminal's other end closes
echo "closed the launcher's terminal (launcher pid $launcher)"
echo "launcher $launcher" >> "$dir/run/pids"  # (a line of its own, for the wait below)
expect_all_ended "$dir/run" 20
expect_resumable_after_launcher_death "$dir/run"
echo "PASS: the hang-up stopped the run cleanly; it resumed and reached its goal"
