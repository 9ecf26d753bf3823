#!/usr/bin/env bash
# Two runs at once on one host never hear each other: each launch picks its own port, and no
# process of either run counts a message of the other (foreign) or loses one. As a control, two
# runs forced onto the same port do hear each other (their processes count foreign messages).
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch

pair() {  # pair NAME [extra launch options]: two concurrent runs; prints their monitors' last lines
  local name=$1
  shift
  launch cartpole --out "$dir/$name-a" --actors 2 --seed 4 --goal 1000000 --time-budget 12 "$@" \
    > "$dir/$name-a.log" 2>&1 &
  local a=$!
  launch cartpole --out "$dir/$name-b" --actors 2 --seed 5 --goal 1000000 --time-budget 12 "$@" \
    > "$dir/$name-b.log" 2>&1 &
  local b=$!
  wait "$a" || true
  wait "$b" || true
}

pair apart
for r in a b; do
  final=$(grep 'steps' "$dir/apart-$r/logs/monitor.log" | tail -1)
  echo "apart-$r: $final"
  echo "$final" | grep -q ' dropped 0$' || fail "run $r dropped messages: $final"
  echo "$final" | grep -q ' lost 0 ' || fail "run $r lost messages: $final"
  echo "$final" | grep -Eq 'steps [1-9]' || fail "run $r made no progress: $final"
done
[ "$(run_setting "$dir/apart-a" lcm-url)" != "$(run_setting "$dir/apart-b" lcm-url)" ] ||
  fail "the two runs got the same URL"

# Control: the same port for both runs makes them hear each other's (foreign) messages.
pair shared --port 23456
foreign=0
for r in a b; do
  final=$(grep 'steps' "$dir/shared-$r/logs/monitor.log" | tail -1)
  echo "shared-$r: $final"
  echo "$final" | grep -Eq ' dropped [1-9]' && foreign=1
done
[ "$foreign" -eq 1 ] || fail "the control runs on one port did not see each other's messages"
for run in apart-a apart-b shared-a shared-b; do expect_no_restarts "$dir/$run"; done
echo "PASS: concurrent runs are isolated by their ports"
