#!/usr/bin/env bash
# The pipeline learns Catch from pixels: frames sent once and stacked again by the replay,
# prioritized n-step replay with priorities from the learner, a dueling CNN. Within a bounded
# time an evaluation over 100 episodes (epsilon 0.05) must reach the preset's goal of 0.8 (a
# random paddle scores about -0.5), and nothing may be lost or dropped on the way.
# Usage: catch_learns.sh [PRECISION]: the learner's precision, fp32 or bf16 (default: the
# preset's), so that the learning test passes in both.
source "$(dirname "$0")/lib.sh"
isolate "$@"
precision=${1:-}
learner_args=()
[ -z "$precision" ] || learner_args=(--learner-args "--precision $precision")
scratch
launch_to_goal "$dir/launch.log" catch --out "$dir/run" --seed 1 --time-budget 240 \
  "${learner_args[@]}"
best=$(expect_best_mean "$dir/run" 0.8 --at-least)
# The replay stored pixel frames, applied the learner's priorities, and lost nothing.
expect_clean_pixel_replay "$dir/run"
[ "$(replay_field priorities)" -gt 0 ] || fail "the replay applied no priorities"
[ -s "$dir/run/report/best.webm" ] || fail "no video of the greedy policy"
expect_no_restarts "$dir/run"
if [ -n "$precision" ]; then
  grep -q "precision $precision" "$dir/run/logs/learner.log" ||
    fail "the learner's log does not say precision $precision"
fi
echo "PASS: Catch learned from pixels to a mean of $best${precision:+ in $precision}"
