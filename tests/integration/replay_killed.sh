#!/usr/bin/env bash
# SIGKILL of the replay daemon mid-run, after it has written a snapshot: the launch script's
# supervisor restarts it, the restarted replay starts from its snapshot (its size right after the
# restart at least the size of the last snapshot written before the kill), and the run still
# reaches the CartPole goal.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
launch cartpole --out "$dir/run" --actors 2 --seed 5 --time-budget 240 \
  --replay-args "--snapshot-every 1" > "$dir/launch.log" 2>&1 &
launch_pid=$!
log="$dir/run/logs/replay.log"
wait_line "$dir/launch.log" "running; logs in" 60
# Mid-run: a snapshot with transitions in it is on disk.
wait_line "$log" "^replay: snapshot [0-9]* written to .* (size [1-9]" 60
saved=$(sed -n 's/^replay: snapshot [0-9]* written to .* (size \([0-9]*\) of.*/\1/p' "$log" | tail -1)
victim=$(awk '$1 == "replay" {p = $2} END {print p}' "$dir/run/pids")
[ -n "$victim" ] || fail "no pid for the replay"
kill -KILL "$victim"
echo "killed the replay (pid $victim) after a snapshot of size $saved"
set +e
wait "$launch_pid"
status=$?
set -e
tail -4 "$dir/launch.log"
[ "$status" -eq 0 ] || fail "launch exited with $status after the kill"
grep -q " replay status 137 restart 1$" "$dir/run/restarts" || fail "the replay was not restarted"
# The restarted replay loaded the snapshot: the first replay found none, the second one loaded it.
grep -q "^replay: no snapshot .* yet; starting empty" "$log" || fail "the first replay found a snapshot"
loaded_line=$(grep "^replay: snapshot .* loaded (" "$log" | head -1)
[ -n "$loaded_line" ] || fail "the restarted replay did not load its snapshot"
echo "$loaded_line"
loaded=$(echo "$loaded_line" | sed -n 's/.* loaded (size \([0-9]*\) of.*/\1/p')
inserts=$(echo "$loaded_line" | sed -n 's/.*, inserts \([0-9]*\),.*/\1/p')
[ "${loaded:-0}" -ge "$saved" ] || fail "the restarted replay holds $loaded transitions, the snapshot had $saved"
[ "${inserts:-0}" -ge "$saved" ] || fail "the restarted replay's insert count ($inserts) did not carry on"
# And it wrote snapshots of its own, the last one when the run stopped.
grep -q "^replay: last snapshot written to $dir/run/replay-snapshot.bin" "$log" ||
  fail "no last snapshot at the end of the run"
echo "PASS: the replay was killed after a snapshot of size $saved, restarted from it (size $loaded), goal reached"
