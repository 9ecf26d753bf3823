#!/usr/bin/env bash
# The whole pipeline on CarRacing from pixels with TD3 (the car_racing_td3 preset: the TD3
# article's image pipeline with its off-track rule in training, its CNNs, float actions of three
# dimensions over LCM) for a bounded time: frames stored, nothing lost or dropped, and the
# evaluator scoring checkpoints on the unmodified environment (no no-op start, no off-track rule,
# every frame's reward) and new best ones on the article's rules as well. Learning CarRacing takes
# hours; this test checks the plumbing.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
set +e
# Checkpoints every 150 updates and 3 evaluation episodes, so that the evaluator scores a few;
# the learner on one thread, so that the run does not oversubscribe the two cores of CI.
launch car_racing_td3 --out "$dir/run" --seed 1 --goal 100000 --time-budget 150 \
  --learner-args "--checkpoint-every 150 --threads 1" --evaluator-args "--episodes 3 --second-episodes 2 --videos 1" \
  > "$dir/launch.log" 2>&1
status=$?
set -e
tail -6 "$dir/launch.log"
[ "$status" -eq 1 ] || fail "launch exited with $status (expected 1: the budget ran out unsolved)"
grep -q "TD3" "$dir/run/logs/learner.log" || fail "the learner did not run TD3"
expect_clean_pixel_replay "$dir/run"
# The evaluator scored checkpoints, on the env without the training pipeline's changes.
[ -s "$dir/run/eval.jsonl" ] || fail "the evaluator scored no checkpoint"
grep -q 'CarRacing-v3+pixels(skip=5,max-pool=0,crop-bottom=12,crop-left=6,crop-right=6,width=0,height=0,stack=4)' \
  "$dir/run/logs/evaluator.log" "$dir/run/report/index.html" ||
  fail "the evaluator did not name the unmodified env"
if grep -q 'off-track=1' "$dir/run/logs/evaluator.log"; then fail "the evaluator used the off-track rule"; fi
# And its first checkpoint (a new best) on the article's rules too, the second metric.
grep -q '"second_episodes": 2' "$dir/run/eval.jsonl" || fail "no second metric in eval.jsonl"
grep -q "the TD3 article&#39;s rules\|the TD3 article's rules" "$dir/run/report/index.html" ||
  fail "the report does not name the second metric"
expect_no_restarts "$dir/run"
echo "PASS: CarRacing TD3 pipeline ran; $(wc -l < "$dir/run/eval.jsonl") evaluations on the unmodified env"
