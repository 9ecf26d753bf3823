#!/usr/bin/env bash
# CartPole over two nodes of a real Slurm cluster (tests/cluster/cluster.sh), submitted with the
# documented command: sbatch --nodes=2 --exclusive scripts/slurm.sbatch cartpole. The replay,
# learner and evaluator run as steps on node1, two actors on each node; the run must reach its
# goal with nothing lost, the monitor must have seen the four actors at once (two of them on
# node2), node2's actors must have acted with the learner's weights, and the key must be
# owner-only in the shared run folder.
#
#   slurm_cartpole.sh [udpm|tcp]      the transport: LCM multicast (default) or LCM's TCP hub
source "$(dirname "$0")/lib.sh"
[ "$(id -u)" -eq 0 ] || fail "this test builds namespaces and runs Slurm's daemons: it needs root"
source "$root/tests/cluster/cluster.sh"
transport=${1:-udpm}
scratch
# 5 cores a node: the replay, learner and evaluator, and 2 actors, on node1.
cluster_up 2 --cpus 5
run=$CLUSTER_SHARED/run
out=$CLUSTER_SHARED/job.out
t0=$SECONDS
job=$(cd "$root" && RL_BUILD_DIR=$build_dir cluster_submit --nodes=2 --exclusive --time=8 \
  --output="$out" scripts/slurm.sbatch cartpole --out "$run" --actors-per-node 2 --seed 1 \
  --time-budget 240 --transport "$transport")
echo "job $job submitted ($transport)"
# While it runs: Slurm runs the replay, learner, evaluator and two actors as steps on node1 and
# two actors as steps on node2.
want="actor-0 node1,actor-1 node1,actor-2 node2,actor-3 node2,evaluator node1,learner node1,replay node1,"
job_steps() { cluster_exec ctl squeue -h -s -j "$job" -o '%j %N' | grep -v '^batch\|^extern' | sort | tr '\n' ','; }
steps=""
for ((i = 0; i < 240; i++)); do
  steps=$(job_steps || true)
  [ "$steps" != "$want" ] || break
  sleep 0.5
done
[ "$steps" = "$want" ] || { tail -20 "$out" >&2; fail "the job's steps are '$steps', not '$want'"; }
echo "steps: $steps"
state=$(cluster_wait_job "$job" 330) || { tail -30 "$out" >&2; fail "job $job did not end"; }
wall=$((SECONDS - t0))
tail -12 "$out"
[ "$state" = COMPLETED ] || fail "job $job ended $state"
grep -q "^launch: goal of 475 reached" "$out" || fail "the goal was not reached"
best=$(expect_best_mean "$run" 475 --at-least)
grep -q "actors 4 " "$run/logs/monitor.log" || fail "the monitor never saw the four actors of both nodes at once"
for a in 2 3; do
  grep -Eq "actor-$a: stopped after [1-9][0-9]* steps.*weights [1-9][0-9]*" "$run/logs/actor-$a.log" ||
    fail "node2's actor-$a did not act with the learner's weights"
done
last=$(grep -o 'lost [0-9]*  dropped [0-9]*' "$run/logs/monitor.log" | tail -1)
[ "$last" = "lost 0  dropped 0" ] || fail "the monitor's last line says: $last"
[ "$(stat -c %a "$run/key")" = 600 ] || fail "the key is not owner-only"
grep -q '<img' "$run/report/index.html" || fail "the report has no learning curve"
expect_no_restarts "$run"
echo "PASS: CartPole over 2 Slurm nodes on $transport: best evaluation mean $best, job $wall s"
