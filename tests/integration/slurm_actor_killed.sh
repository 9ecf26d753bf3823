#!/usr/bin/env bash
# An actor step killed mid-run on a Slurm cluster is started again on its node: CartPole over
# two nodes (slurm_lib.sh); once the run is going, node2's actor-3 is SIGKILLed; srun returns
# 137, the launcher restarts the step on node2 within its backoff, and the run reaches its goal.
#
# CartPole may learn faster than a step restarts, so the learner and the evaluator are held
# (SIGSTOP) from before the kill until actor-3 is ready again on node2, and let go then
# (SIGCONT).
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/slurm_lib.sh"
scratch
slurm_cartpole_submit
slurm_wait_steps
slurm_hold_learner_and_evaluator
# Past its start (a process that dies within 3 s of its start failed at its start): its first
# progress line comes 5 s after it.
wait_line "$run/logs/actor-3.log" "^actor-3: steps " 60
# The actor itself, not its srun (in node2's namespaces; its pid as this machine sees it).
pid=$(pgrep -f "^$bin/actor --config $run/config.ini .*--actor-id 3 " | head -1)
[ -n "$pid" ] || fail "no process of actor-3"
kill -KILL "$pid"
echo "killed actor-3 (pid $pid)"
wait_line "$run/restarts" " actor-3 status 137 restart 1$" 30
# Started again as a step on node2, and ready.
slurm_wait_steps
wait_lines "$run/logs/actor-3.log" "^actor-3: ready" 2 30
# shellcheck disable=SC2086
kill -CONT $held
best=$(slurm_expect_goal)
grep -q "^launch: actor-3 exited with status 137 after .*; restarting it in 1 s (restart 1 of 5)" "$out" ||
  fail "the launcher did not say that actor-3 died and is restarted"
echo "PASS: actor-3's step killed, restarted on node2, goal reached (best $best)"
