#!/usr/bin/env bash
# SIGKILL of the learner, the replay, the evaluator and an actor at once, mid-run: the launch
# script's supervisors restart each of them, the learner resumes from the state it saved with its
# last checkpoint (its update count carries on from there), weight versions never go back, and
# the run still reaches the CartPole goal. A SIGTERM to the other actor at the same time is its
# clean stop (exit 0): it is left down, not restarted, and the run goes on without it.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/launch_lib.sh"
isolate "$@"
scratch
start_cartpole "$dir/launch.log" --actors 2 --seed 3 --time-budget 240
# Mid-run: the learner has written its state with its first checkpoint.
wait_learner_state "$dir/run"
for role in learner replay evaluator actor-1; do kill_role "$role"; done
kill_role actor-0 TERM
wait_launch "$dir/launch.log"
[ "$status" -eq 0 ] || fail "launch exited with $status after the kills"
for role in learner replay evaluator actor-1; do
  grep -q " $role status 137 restart 1$" "$dir/run/restarts" || fail "$role was not restarted"
done
stopped="actor-0 exited with status 0 while the run goes on; it is not restarted; the run goes on"
grep -q "$stopped without it" "$dir/launch.log" || fail "the launcher did not leave the stopped actor-0 down"
! grep -q " actor-0 " "$dir/run/restarts" || fail "actor-0, stopped by SIGTERM, was restarted"
grep -q "restarts 4" "$dir/run/logs/monitor.log" || fail "the progress line does not count 4 restarts"
grep -q "4 process restarts" "$dir/run/report/index.html" || fail "the report does not list the 4 restarts"
# The learner resumed from its saved state, and counted on from there.
resumed=$(sed -n 's/.*resumed at update \([0-9]*\).*/\1/p' "$dir/run/logs/learner.log" | head -1)
[ -n "$resumed" ] && [ "$resumed" -gt 0 ] || fail "the restarted learner did not resume"
last=$(sed -n 's/^learner: stopped after \([0-9]*\) updates/\1/p' "$dir/run/logs/learner.log" | tail -1)
# It trained on, unless the run ended at the checkpoint it resumed from: the evaluator, killed
# before it had scored that checkpoint, scores it after its restart, and it can reach the goal.
goal_at=$(sed -n 's/^evaluation: update \([0-9]*\),.*goal reached$/\1/p' "$dir/launch.log" | head -1)
trained_on() { [ "${last:-0}" -gt "$resumed" ]; }
ended_at_resume() { [ "${last:-0}" -eq "$resumed" ] && [ "$goal_at" = "$resumed" ]; }
trained_on || ended_at_resume ||
  fail "the resumed learner did not train on (stopped at $last, goal reached at ${goal_at:-none})"
# Weight versions never went back in any actor. A restarted actor holds no weights (version -1)
# until its first weights message: that is no older weights, but its first version after it
# must not be older than what the killed actor had.
awk '/"role": "actor-/ {
    role = $0; sub(/.*"role": "/, "", role); sub(/".*/, "", role)
    v = $0; sub(/.*"weights_version": /, "", v); sub(/[,}].*/, "", v)
    if (v + 0 < 0) next
    if ((role in last) && v + 0 < last[role]) { print role " went from " last[role] " to " v; bad = 1 }
    last[role] = v + 0; n++ }
  END { if (n == 0) { print "no actor row with weights"; bad = 1 } exit bad }' \
  "$dir/run/metrics.jsonl" || fail "a weights version went back"
echo "PASS: 4 processes killed and restarted, one stopped and left down, the learner resumed at update $resumed, goal reached"
