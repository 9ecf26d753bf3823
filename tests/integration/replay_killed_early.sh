#!/usr/bin/env bash
# SIGKILL of the replay daemon a few seconds into a CartPole run, before its first snapshot: the
# launch script's supervisor restarts it, the restarted replay starts empty (it knows no actor, so
# its flow-control messages list none after messages that listed some), and the run still reaches
# the goal, with no actor dropping a flow-control message ("num_actors mismatch": a message whose
# arrays shrank to nothing decoded into the object of the previous one).
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
launch cartpole --out "$dir/run" --actors 2 --seed 5 --time-budget 240 \
  --replay-args "--snapshot-every 3600" > "$dir/launch.log" 2>&1 &
launch_pid=$!
run="$dir/run"
log="$run/logs/replay.log"
wait_line "$dir/launch.log" "running; logs in" 60
# A few seconds in: the replay has stored a thousand transitions or more (so its flow-control
# messages, 20 a second, have listed the actors for a while), and written no snapshot.
wait_line "$run/metrics.jsonl" \
  '"role": "replay", "size": [0-9]*, "capacity": [0-9]*, "inserts": [1-9][0-9][0-9][0-9]' 60
! grep -q "^replay: snapshot .* written" "$log" || fail "the replay wrote a snapshot before the kill"
victim=$(awk '$1 == "replay" {p = $2} END {print p}' "$run/pids")
[ -n "$victim" ] || fail "no pid for the replay"
kill -KILL "$victim"
echo "killed the replay (pid $victim) before its first snapshot"
set +e
wait "$launch_pid"
status=$?
set -e
tail -4 "$dir/launch.log"
if grep -q "num_actors mismatch" "$run"/logs/actor-*.log; then
  grep -h "num_actors mismatch" "$run"/logs/actor-*.log | head -3 >&2
  fail "actors dropped the restarted replay's flow-control messages"
fi
[ "$status" -eq 0 ] || fail "launch exited with $status after the kill"
grep -q " replay status 137 restart 1$" "$run/restarts" || fail "the replay was not restarted"
[ "$(grep -c "^replay: no snapshot .* yet; starting empty" "$log")" -eq 2 ] ||
  fail "the replay did not start empty twice (before and after the kill)"
echo "PASS: the replay was killed before its first snapshot, restarted empty, goal reached"
