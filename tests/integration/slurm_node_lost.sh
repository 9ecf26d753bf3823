#!/usr/bin/env bash
# A compute node lost mid-run on a real Slurm cluster: CartPole over two nodes (slurm_lib.sh);
# once the run is going, every process of node2 is killed (its slurmd, its steps' tasks, its
# network). Slurm declares node2 down about 30 s later, node2's actor steps end ("Node failure")
# and the launcher reports the node lost, on its output and in RUN/restarts; the run goes on
# with node1's actors and reaches its goal.
#
# CartPole learns faster than Slurm declares a node down, so the learner and the evaluator are
# held (SIGSTOP) from the loss until the launcher has reported it, and let go then (SIGCONT);
# --max-backoff 60 raises the monitor's silence limit to 95 s to allow for that.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/slurm_lib.sh"
scratch
slurm_cartpole_submit --max-backoff 60
slurm_wait_steps
# Every process ready (a node lost before its actors are ready fails the run's start): the
# monitor, started last, has seen the four actors.
wait_line "$run/logs/monitor.log" "actors 4 " 60
slurm_hold_learner_and_evaluator
t0=$SECONDS
cluster_node_kill node2
echo "node2 killed"
for a in 2 3; do
  wait_line "$out" "^launch: actor-$a exited with status 0: its node node2 is lost" 120
done
echo "node2 reported lost $((SECONDS - t0)) s after it was killed"
# shellcheck disable=SC2086
kill -CONT $held
best=$(slurm_expect_goal)
for a in 2 3; do
  grep -q " actor-$a status 0 lost 0$" "$run/restarts" || fail "RUN/restarts has no line for actor-$a lost"
  grep -q "<td>actor-$a</td><td>0</td><td>node lost</td>" "$run/report/index.html" ||
    fail "the report does not show actor-$a's node lost"
done
grep -q "restarts 2" "$run/logs/monitor.log" || fail "the progress line did not count the lost actors"
grep -q "actors 2 " "$run/logs/monitor.log" || fail "the monitor never saw node1's two actors alone"
! grep -q "^launch: \(replay\|learner\|evaluator\|actor-[01]\) " "$out" || fail "a process of node1 was restarted or stopped"
echo "PASS: node2 lost mid-run, reported after $((SECONDS - t0)) s; goal reached (best $best)"
