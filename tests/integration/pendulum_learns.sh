#!/usr/bin/env bash
# TD3 through the whole pipeline (replay, learner, evaluator, 2 actors with Gaussian noise, float
# actions over LCM) learns Pendulum-v1: a deterministic evaluation over 100 episodes reaches a
# mean above -250 within the time budget.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
launch_to_goal "$dir/launch.log" pendulum --out "$dir/run" --seed 1 --goal -250 --time-budget 300
best=$(expect_best_mean "$dir/run" -250)
grep -q "TD3" "$dir/run/logs/learner.log" || fail "the learner did not run TD3"
grep -q "without noise" "$dir/run/report/index.html" || fail "the report does not say how it scored"
expect_no_restarts "$dir/run"
echo "PASS: TD3 learned Pendulum-v1 with best evaluation mean $best"
