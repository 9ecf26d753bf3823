#!/usr/bin/env bash
# The whole pipeline (replay, learner, evaluator, 4 actors) solves CartPole-v1: an evaluation
# over 100 greedy episodes (epsilon 0.05) reaches a mean of at least 475.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
launch_to_goal "$dir/launch.log" cartpole --out "$dir/run" --actors 4 --seed 1 --time-budget 240
best=$(expect_best_mean "$dir/run" 475 --at-least)
grep -q '<img' "$dir/run/report/index.html" || fail "the report has no learning curve"
ls "$dir/run/checkpoints"/ckpt-*.bin >/dev/null || fail "no checkpoints"
for role in replay learner evaluator actor-0; do
  [ -s "$dir/run/logs/$role.log" ] || fail "no log of $role"
done
expect_no_restarts "$dir/run"
echo "PASS: solved with best evaluation mean $best"
