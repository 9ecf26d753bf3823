#!/usr/bin/env bash
# Actors on another host of a LAN join a run: two network namespaces ("hosts") joined by a veth
# pair, each with a multicast route on its LAN interface. Host A runs the launch script with
# ttl=1 and one actor; host B runs a second actor of the same run. The run must reach its goal,
# the monitor on A must have seen both actors, and B's actor must have used the learner's weights.
source "$(dirname "$0")/lib.sh"
[ "$(id -u)" -eq 0 ] || fail "this test builds network namespaces and needs root"
scratch
a="rl-a-$$" b="rl-b-$$" va="rlva$$" vb="rlvb$$"
teardown() {
  cleanup
  ip netns pids "$b" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
  ip netns pids "$a" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
  ip netns del "$a" 2>/dev/null || true
  ip netns del "$b" 2>/dev/null || true
}
trap teardown EXIT
ip netns add "$a"
ip netns add "$b"
ip link add "$va" type veth peer name "$vb"
ip link set "$va" netns "$a"
ip link set "$vb" netns "$b"
for h in "$a:$va:198.18.0.1" "$b:$vb:198.18.0.2"; do
  IFS=: read -r ns dev addr <<< "$h"
  ip -n "$ns" link set lo up
  ip -n "$ns" addr add "$addr/24" dev "$dev"
  ip -n "$ns" link set "$dev" up
  ip -n "$ns" route add 224.0.0.0/4 dev "$dev"
done

ip netns exec "$a" "$root/scripts/launch.sh" cartpole --no-setup --build-dir "$build_dir" \
  --out "$dir/run" --ttl 1 --port 7667 --actors 1 --num-actors 2 --seed 6 --time-budget 240 \
  > "$dir/launch.log" 2>&1 &
launch_pid=$!
wait_line "$dir/launch.log" "running; logs in" 60
run="$dir/run"
# Host B's copy of the run's key file, owner-only as scp -p would keep it.
install -m 600 "$run/key" "$dir/host-b.key"
ip netns exec "$b" "$bin/actor" --config "$root/configs/cartpole.ini" \
  --run-id "$(run_setting "$run" run-id)" --key-file "$dir/host-b.key" --num-actors 2 --actor-id 1 --seed 6 \
  --lcm-url "$(run_setting "$run" lcm-url)" --lcm-bulk-url "$(run_setting "$run" lcm-bulk-url)" \
  > "$dir/remote-actor.log" 2>&1 &
remote_pid=$!
set +e
wait "$launch_pid"
status=$?
set -e
kill -TERM "$remote_pid" 2>/dev/null || true
wait "$remote_pid" || true
tail -4 "$dir/launch.log"
tail -2 "$dir/remote-actor.log"
[ "$status" -eq 0 ] || fail "the run did not reach its goal (launch exited with $status)"
grep -q "actors 2" "$run/logs/monitor.log" || fail "host A never saw host B's actor"
grep -Eq "actor-1: stopped after [1-9][0-9]* steps.*weights [0-9]+" "$dir/remote-actor.log" ||
  fail "the remote actor did not act with the learner's weights"
expect_no_restarts "$run"
echo "PASS: an actor on another host joined the run"
