#!/usr/bin/env bash
# CartPole over two nodes of a real Slurm cluster (tests/cluster/cluster.sh), submitted with the
# documented command: sbatch --nodes=2 --exclusive scripts/slurm.sbatch cartpole. The replay,
# learner and evaluator run as steps on node1, two actors on each node; the run must reach its
# goal with nothing lost, the monitor must have seen the four actors at once (two of them on
# node2), node2's actors must have acted with the learner's weights, and the key must be
# owner-only in the shared run folder.
#
#   slurm_cartpole.sh [udpm|tcp [LAUNCH_OPTIONS...]]
#     the transport: LCM multicast (default) or LCM's TCP hub; options for the launch after it
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/slurm_lib.sh"
transport=${1:-udpm}
[ $# -eq 0 ] || shift
scratch
t0=$SECONDS
slurm_cartpole_submit --transport "$transport" "$@"
slurm_wait_steps
best=$(slurm_expect_goal)
grep -q "actors 4 " "$run/logs/monitor.log" || fail "the monitor never saw the four actors of both nodes at once"
for a in 2 3; do
  grep -Eq "actor-$a: stopped after [1-9][0-9]* steps.*weights [1-9][0-9]*" "$run/logs/actor-$a.log" ||
    fail "node2's actor-$a did not act with the learner's weights"
done
[ "$(stat -c %a "$run/key")" = 600 ] || fail "the key is not owner-only"
grep -q '<img' "$run/report/index.html" || fail "the report has no learning curve"
expect_no_restarts "$run"
echo "PASS: CartPole over 2 Slurm nodes on $transport: best evaluation mean $best, $((SECONDS - t0)) s"
