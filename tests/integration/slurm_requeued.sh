#!/usr/bin/env bash
# A job requeued mid-run resumes its run, and scancel stops it cleanly, on a real Slurm cluster:
# CartPole over two nodes (slurm_lib.sh) with an unreachable goal; once an evaluation and the
# learner's state are written, `scontrol requeue`; the job starts again (same id, restart 1) and
# resumes the run folder: the learner at its update count, the replay from its snapshot, the
# evaluations and best score kept. Once the resumed run has evaluated again, `scancel`: every
# process stops cleanly (the replay's last snapshot, the report), nothing is killed.
#
#   slurm_requeued.sh [scontrol|timelimit]
#     timelimit: no scontrol requeue; the job has a 2-minute limit and is warned 80 s before it
#     (sbatch --time=2 --signal=B:USR1@80), when scripts/slurm.sbatch stops the run and requeues
#     the job itself.
mode=${1:-scontrol}
[ "$mode" != timelimit ] || slurm_time="--time=2 --signal=B:USR1@80"
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/slurm_lib.sh"
scratch
slurm_cartpole_submit --goal 100000 --time-budget 150
slurm_wait_steps
wait_line "$run/eval.jsonl" '"update"' 120
wait_learner_state "$run"
if [ "$mode" = timelimit ]; then
  wait_line "$out" "^slurm.sbatch: the time limit is near: stopping the run to requeue the job" 90
else
  cluster_exec ctl scontrol requeue "$job"
  echo "requeued job $job"
fi
wait_line "$out" "^slurm.sbatch: job $job (restart 1)" 90
wait_line "$out" "^launch: run .* on Slurm job $job: .*, resumed$" 30
evals_before=$(grep -c '"update"' "$run/eval.jsonl")
ls "$run/checkpoints" > "$dir/on_disk"
last_update_before=$(sed -n 's/.*"update": \([0-9]*\).*/\1/p' "$run/eval.jsonl" | head -n "$evals_before" | tail -1)
best_before=$(best_mean "$run/eval.jsonl")
slurm_wait_steps
# A new evaluation of the resumed run, then scancel.
wait_lines "$run/eval.jsonl" '"update"' $((evals_before + 1)) 120
cluster_exec ctl scancel "$job"
state=$(cluster_wait_job "$job" 60) || fail "job $job did not end after scancel"
grep -v '^\[' "$out" | tail -20
[ "$state" = CANCELLED ] || fail "job $job ended $state after scancel"
[ "$(cluster_job "$job" Restarts)" = 1 ] || fail "job $job was not requeued once"
# The learner resumed at (or past) the update of the last evaluation before the requeue.
resumed=$(sed -n 's/.*resumed at update \([0-9]*\).*/\1/p' "$run/logs/learner.log" | tail -1)
[ -n "$resumed" ] && [ "$resumed" -ge "$last_update_before" ] ||
  fail "the learner resumed at update '${resumed}', before $last_update_before"
# The replay wrote its last snapshot at each stop and the resumed one started from it.
[ "$(grep -c "^replay: last snapshot written to $run/replay-snapshot.bin (size [1-9]" "$run/logs/replay.log")" -eq 2 ] ||
  fail "the replay did not write its last snapshot at both stops"
size=$(sed -n "s|^replay: snapshot $run/replay-snapshot.bin loaded (size \([0-9]*\).*|\1|p" "$run/logs/replay.log")
[ -n "$size" ] && [ "$size" -gt 0 ] || fail "the resumed replay did not load its snapshot"
# The evaluations carry on: the earlier ones kept, the best of them still the floor.
head -n "$evals_before" "$run/eval.jsonl" | tail -1 | grep -q "\"update\": $last_update_before," ||
  fail "the earlier evaluations were not kept"
carries_on "$run/eval.jsonl" "$evals_before" update "$dir/on_disk" || fail "evaluation updates went back"
best=$(best_mean "$run/eval.jsonl")
awk -v a="$best" -v b="$best_before" 'BEGIN { exit !(a >= b) }' || fail "the best score went from $best_before to $best"
grep -q '<img' "$run/report/index.html" || fail "the report has no learning curve"
! grep -q "did not stop; killing it" "$out" || fail "a process had to be killed"
[ "$(grep -c '^launch: interrupted, stopping the run' "$out")" -eq 2 ] || fail "the launcher did not stop the run twice"
echo "PASS ($mode): requeued at update $last_update_before (best $best_before), resumed at $resumed from a replay of $size, best $best; scancel stopped it cleanly"
