#!/usr/bin/env bash
# A run stopped with a signal (as Ctrl-C stops it) and continued with `launch.sh --resume`: the
# same folder, run id and config; the learner resumes from its saved state and the replay from
# its snapshot; update counts, env steps and the evaluation history carry on; and the resumed run
# reaches the CartPole goal; its progress line starts from the best of the first part.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/launch_lib.sh"
isolate "$@"
scratch
# First part: an unreachable goal, stopped by a signal once an evaluation has been written.
start_cartpole "$dir/first.log" --actors 2 --seed 4 --goal 100000 --time-budget 240
wait_line "$dir/run/eval.jsonl" '"update"' 120
wait_learner_state "$dir/run"
# (and metrics rows 3 s into the run, so that rows of the resumed part that started again at 0
# would be seen going back)
wait_line "$dir/run/metrics.jsonl" '"t": [3-9]\.' 60
kill -TERM "$launch_pid"
wait_launch "$dir/first.log"
[ "$status" -eq 130 ] || fail "the stopped launch exited with $status, not 130"
run_id=$(run_setting "$dir/run" run-id)
evals_before=$(wc -l < "$dir/run/eval.jsonl")
ls "$dir/run/checkpoints" > "$dir/on_disk"
last_update_before=$(sed -n 's/.*"update": \([0-9]*\).*/\1/p' "$dir/run/eval.jsonl" | tail -1)
best_before=$(best_mean "$dir/run/eval.jsonl")
# Second part: resumed, with the preset's goal.
resume_to_goal "$dir/run" "$dir/second.log"
# Its progress lines start from the first part's evaluations: none shows no evaluation or a best
# below the first part's (the resumed evaluator may score its backlog before the first line).
bad=$(grep '^\[ *[0-9.]*s\] steps ' "$dir/second.log" | awk -v b="$best_before" '
  / eval - / { print; exit }
  { if (match($0, /\(best [-0-9.]+\)/)) { v = substr($0, RSTART + 6, RLENGTH - 7) + 0; if (b - v >= 0.11) { print; exit } } }')
[ -z "$bad" ] || fail "a progress line of the resumed run forgot the first part's best $best_before: $bad"
grep -q "run $run_id of 'cartpole'" "$dir/second.log" || fail "the resumed run has another id"
grep -q '^# resumed ' "$dir/run/config.ini" || fail "config.ini does not record the resumption"
resumed=$(sed -n 's/.*resumed at update \([0-9]*\).*/\1/p' "$dir/run/logs/learner.log" | tail -1)
[ -n "$resumed" ] && [ "$resumed" -gt 0 ] || fail "the learner did not resume"
# The history carries on: earlier evaluations kept, later ones at higher updates.
[ "$(wc -l < "$dir/run/eval.jsonl")" -gt "$evals_before" ] || fail "no new evaluation"
head -n "$evals_before" "$dir/run/eval.jsonl" | tail -1 | grep -q "\"update\": $last_update_before," ||
  fail "the earlier evaluations were not kept"
# The replay wrote its last snapshot when it stopped, and the resumed one started from it.
grep -q "^replay: last snapshot written to $dir/run/replay-snapshot.bin (size [1-9]" "$dir/run/logs/replay.log" ||
  fail "the stopped replay wrote no last snapshot"
grep -q "^replay: snapshot $dir/run/replay-snapshot.bin loaded (size [1-9]" "$dir/run/logs/replay.log" ||
  fail "the resumed replay did not load its snapshot"
carries_on "$dir/run/eval.jsonl" "$evals_before" update "$dir/on_disk" || fail "evaluation updates went back"
carries_on "$dir/run/eval.jsonl" "$evals_before" env_steps "$dir/on_disk" || fail "evaluation env steps went back"
# The metrics' time carries on too: the resumed monitor's rows follow the first part's.
grep -q '"t": ' "$dir/run/metrics.jsonl" || fail "no metrics rows"
awk -F'"t": ' '{split($2, a, ","); t = a[1] + 0; if (t < prev) { print "metrics t " t " after " prev; exit 1 } prev = t}' \
  "$dir/run/metrics.jsonl" || fail "the metrics' t went back at the resumption"
expect_no_restarts "$dir/run"
echo "PASS: stopped at update $last_update_before, resumed at $resumed, goal reached"
