#!/usr/bin/env bash
# A resumed run continues where it stopped; it does not start over. A Pendulum run (TD3, two
# actors, each acting uniformly at random for its first 500 steps) is stopped with a signal once
# both actors are well past their random start, and continued with `launch.sh --resume`. Every
# actor takes up its step count from the replay's snapshot before it acts, so:
#   - each actor's first stats after the resume show at least the steps of its last stats before
#     the stop, and its log says where it continues;
#   - its exploration schedule goes on: sigma 0.1 from its first stats on, never the random
#     start's 1 again;
#   - the progress line's step count carries on from where it was.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
past_start=1200  # steps of each actor before the stop (the random start is 500)

# Steps and exploration of actor-$1 in the metrics rows from line $2 on: "first" or "max" of them.
actor_field() {  # actor_field ACTOR FROM_LINE FIELD first|max
  tail -n +"$2" "$dir/run/metrics.jsonl" | grep "\"role\": \"actor-$1\"" |
    sed -n "s/.*\"$3\": \([-0-9.e+]*\).*/\1/p" |
    awk -v how="$4" 'NR == 1 && how == "first" { print; exit } { if (NR == 1 || $1 > m) m = $1 }
                     END { if (how == "max" && NR > 0) print m }' || true
}
# The step count of the last (or first) progress line with both actors live in a monitor log.
progress_steps() {  # progress_steps LOG last|first
  grep -E '^\[ *[0-9.]+s\] steps .* actors 2' "$1" | { [ "$2" = first ] && head -1 || tail -1; } |
    sed -n 's/.*\] steps \([0-9,]*\) .*/\1/p' | tr -d , || true
}

# First part: an unreachable goal, stopped by a signal once both actors are past their start.
"$root/scripts/launch.sh" pendulum --no-setup --build-dir "$build_dir" --out "$dir/run" \
  --seed 3 --goal 100000 --time-budget 300 > "$dir/first.log" 2>&1 &
launch_pid=$!
wait_line "$dir/first.log" "running; logs in" 60
for _ in $(seq 1200); do
  a0=$(actor_field 0 1 env_steps max) a1=$(actor_field 1 1 env_steps max)
  [ "${a0:-0}" -ge "$past_start" ] && [ "${a1:-0}" -ge "$past_start" ] && break
  kill -0 "$launch_pid" 2>/dev/null || { cat "$dir/first.log"; fail "the first run ended early"; }
  sleep 0.1
done
[ "${a0:-0}" -ge "$past_start" ] && [ "${a1:-0}" -ge "$past_start" ] ||
  fail "the actors did not reach $past_start steps in 120 s (actor-0 ${a0:-none}, actor-1 ${a1:-none})"
kill -TERM "$launch_pid"
status=0
wait "$launch_pid" || status=$?
[ "$status" -eq 130 ] || fail "the stopped launch exited with $status, not 130"
rows_before=$(wc -l < "$dir/run/metrics.jsonl")
cp "$dir/run/logs/monitor.log" "$dir/monitor-first.log"
progress_before=$(progress_steps "$dir/monitor-first.log" last)
for i in 0 1; do
  before[$i]=$(actor_field $i 1 env_steps max)
  echo "actor-$i: ${before[$i]} steps in its last stats before the stop;" \
    "$(grep "^actor-$i: stopped after" "$dir/run/logs/actor-$i.log" | tail -1)"
done
grep -q "^replay: last snapshot written to $dir/run/replay-snapshot.bin" "$dir/run/logs/replay.log" ||
  fail "the stopped replay wrote no last snapshot"

# Second part: resumed until every actor has published stats, then stopped again.
"$root/scripts/launch.sh" --resume "$dir/run" --no-setup --build-dir "$build_dir" --goal 100000 \
  --time-budget 120 > "$dir/second.log" 2>&1 &
launch_pid=$!
wait_line "$dir/second.log" "running; logs in" 60
for _ in $(seq 600); do
  first0=$(actor_field 0 $((rows_before + 1)) env_steps first)
  first1=$(actor_field 1 $((rows_before + 1)) env_steps first)
  [ -n "$first0" ] && [ -n "$first1" ] && [ -n "$(progress_steps "$dir/run/logs/monitor.log" first)" ] &&
    break
  kill -0 "$launch_pid" 2>/dev/null || { cat "$dir/second.log"; fail "the resumed run ended early"; }
  sleep 0.1
done
kill -TERM "$launch_pid"
wait "$launch_pid" || true
grep -q "^replay: snapshot $dir/run/replay-snapshot.bin loaded (size [1-9]" "$dir/run/logs/replay.log" ||
  fail "the resumed replay did not load its snapshot"

for i in 0 1; do
  first=$(actor_field $i $((rows_before + 1)) env_steps first)
  sigma=$(actor_field $i $((rows_before + 1)) exploration first)
  [ -n "$first" ] || fail "no stats of actor-$i after the resume"
  echo "actor-$i: first stats after the resume: $first steps, sigma $sigma"
  [ "$first" -ge "${before[$i]}" ] ||
    fail "actor-$i started over: $first steps after the resume, ${before[$i]} before the stop"
  awk -v s="$sigma" 'BEGIN { exit !(s == 0.1) }' ||
    fail "actor-$i explores with $sigma after the resume (its random start again?), not sigma 0.1"
  # Never the random start again, in any of its stats after the resume.
  tail -n +$((rows_before + 1)) "$dir/run/metrics.jsonl" | grep "\"role\": \"actor-$i\"" |
    grep -q '"exploration": 1,' && fail "actor-$i acted uniformly at random again after the resume"
  took=$(sed -n "s/^actor-$i: continuing at step \([0-9]*\) .*/\1/p" "$dir/run/logs/actor-$i.log" |
    tail -1)
  [ -n "$took" ] && [ "$took" -ge "${before[$i]}" ] && [ "$took" -le "$first" ] ||
    fail "actor-$i's log does not say it continues at a step between ${before[$i]} and $first"
done
progress_after=$(progress_steps "$dir/run/logs/monitor.log" first)
echo "progress line: steps $progress_before before the stop, $progress_after at the resume"
[ -n "$progress_before" ] && [ -n "$progress_after" ] || fail "no progress line with both actors"
[ "$progress_after" -ge "$progress_before" ] ||
  fail "the progress line's step count went back from $progress_before to $progress_after"
echo "PASS: the actors continued at ${first0} and ${first1} steps with sigma 0.1"
