#!/usr/bin/env bash
# The pipeline learns LunarLander-v3 (Box2D): within a bounded time, an evaluation over 100
# episodes (epsilon 0.05) beats a mean return of 0 (a random policy scores about -200), and the
# report holds a video of the greedy policy. The full goal of 200 takes longer than CI allows;
# scripts/bench.sh measures it.
source "$(dirname "$0")/lib.sh"
isolate "$@"
scratch
launch_to_goal "$dir/launch.log" lunar_lander --out "$dir/run" --seed 1 --goal 0 --time-budget 300
best=$(expect_best_mean "$dir/run" 0 --at-least)
[ -s "$dir/run/report/best.webm" ] || fail "no video of the greedy policy"
grep -q '<video src="best.webm"' "$dir/run/report/index.html" || fail "the report shows no video"
expect_no_restarts "$dir/run"
echo "PASS: LunarLander learned to a mean of $best"
