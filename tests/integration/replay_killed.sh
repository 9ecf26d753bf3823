#!/usr/bin/env bash
# SIGKILL of the replay daemon mid-run: the launch script's supervisor restarts it and the run
# still reaches the CartPole goal. Two moments of the kill:
#   replay_killed.sh        after the replay has written a snapshot: the restarted replay starts
#                           from it (its size right after the restart at least the size of the
#                           last snapshot written before the kill)
#   replay_killed.sh early  a few seconds in, before its first snapshot: the restarted replay
#                           starts empty (it knows no actor, so its flow-control messages list none
#                           after messages that listed some), with no actor dropping a
#                           flow-control message ("num_actors mismatch": a message whose arrays
#                           shrank to nothing decoded into the object of the previous one)
# CartPole may reach its goal within the second the replay waits to restart, and the run would
# stop before the restarted replay said how it started; so the learner and the evaluator are held
# (SIGSTOP) from before the kill until the restarted replay is ready, and let go then (SIGCONT).
source "$(dirname "$0")/lib.sh"
isolate "$@"
mode=${1:-snapshot}
case "$mode" in
  snapshot) snapshot_every=1 ;;
  early) snapshot_every=3600 ;;
  *) fail "unknown mode '$mode' (snapshot or early)" ;;
esac
scratch
run="$dir/run"
log="$run/logs/replay.log"
launch cartpole --out "$run" --actors 2 --seed 5 --time-budget 240 \
  --replay-args "--snapshot-every $snapshot_every" > "$dir/launch.log" 2>&1 &
launch_pid=$!
wait_line "$dir/launch.log" "running; logs in" 60
if [ "$mode" = snapshot ]; then
  # Mid-run: a snapshot with transitions in it is on disk.
  wait_line "$log" "^replay: snapshot [0-9]* written to .* (size [1-9]" 60
  saved=$(sed -n 's/^replay: snapshot [0-9]* written to .* (size \([0-9]*\) of.*/\1/p' "$log" | tail -1)
  moment="after a snapshot of size $saved"
else
  # A few seconds in: the replay has stored a thousand transitions or more (so its flow-control
  # messages, 20 a second, have listed the actors for a while), and written no snapshot.
  wait_line "$run/metrics.jsonl" \
    '"role": "replay", "size": [0-9]*, "capacity": [0-9]*, "inserts": [1-9][0-9][0-9][0-9]' 60
  ! grep -q "^replay: snapshot .* written" "$log" || fail "the replay wrote a snapshot before the kill"
  moment="before its first snapshot"
fi
victim=$(awk '$1 == "replay" {p = $2} END {print p}' "$run/pids")
[ -n "$victim" ] || fail "no pid for the replay"
hold_learner_and_evaluator
kill -KILL "$victim"
echo "killed the replay (pid $victim) $moment"
wait_lines "$log" "^replay: ready" 2 30
# shellcheck disable=SC2086
kill -CONT $held
status=0
wait "$launch_pid" || status=$?
tail -4 "$dir/launch.log"
if grep -q "num_actors mismatch" "$run"/logs/actor-*.log; then
  grep -h "num_actors mismatch" "$run"/logs/actor-*.log | head -3 >&2
  fail "actors dropped the restarted replay's flow-control messages"
fi
[ "$status" -eq 0 ] || fail "launch exited with $status after the kill"
grep -q " replay status 137 restart 1$" "$run/restarts" || fail "the replay was not restarted"
if [ "$mode" = early ]; then
  [ "$(grep -c "^replay: no snapshot .* yet; starting empty" "$log")" -eq 2 ] ||
    fail "the replay did not start empty twice (before and after the kill)"
  echo "PASS: the replay was killed before its first snapshot, restarted empty, goal reached"
  exit 0
fi
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
grep -q "^replay: last snapshot written to $run/replay-snapshot.bin" "$log" ||
  fail "no last snapshot at the end of the run"
echo "PASS: the replay was killed after a snapshot of size $saved, restarted from it (size $loaded), goal reached"
