#!/usr/bin/env bash
# An actor step killed mid-run on a Slurm cluster is started again on its node: CartPole over
# two nodes (slurm_lib.sh); once the run is going, node2's actor-3 is SIGKILLed; srun returns
# 137, the launcher restarts the step on node2 within its backoff, and the run reaches its goal.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/slurm_lib.sh"
scratch
slurm_cartpole_submit
slurm_wait_steps
wait_line "$run/logs/monitor.log" "actors 4 " 60
# The actor itself, not its srun (in node2's namespaces; its pid as this machine sees it).
pid=$(pgrep -f "^$bin/actor --config $run/config.ini .*--actor-id 3 " | head -1)
[ -n "$pid" ] || fail "no process of actor-3"
kill -KILL "$pid"
echo "killed actor-3 (pid $pid)"
wait_line "$run/restarts" " actor-3 status 137 restart 1$" 30
# Started again as a step on node2.
slurm_wait_steps
best=$(slurm_expect_goal)
grep -q "^launch: actor-3 exited with status 137 after .*; restarting it in 1 s (restart 1 of 5)" "$out" ||
  fail "the launcher did not say that actor-3 died and is restarted"
[ "$(grep -c '^actor-3: ready' "$run/logs/actor-3.log")" -eq 2 ] || fail "actor-3 was not ready twice"
echo "PASS: actor-3's step killed, restarted on node2, goal reached (best $best)"
