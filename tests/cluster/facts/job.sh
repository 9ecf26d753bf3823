#!/bin/bash
# The batch script of the facts: job.sh EXPERIMENT [ARGS] (see facts.sh, which submits it).
source "$FACTS/lib.sh"
experiment=$1
shift

# Probe names carry the job and its incarnation: p1.j12r0 is p1 of job 12, first run.
tag=j${SLURM_JOB_ID}r${SLURM_RESTART_COUNT:-0}

case "$experiment" in
  env)  # Where and how the batch script runs.
    r "pid $$, parent: $(ps -o cmd= -p $PPID), cwd $PWD"
    r "network: $(ip -br -4 addr show eth0 | tr -s ' ')"
    env | grep -E '^SLURM' | sort | while read -r l; do r "$l"; done ;;

  cpus)  # SLURM_JOB_CPUS_PER_NODE and the like, for the job's sbatch options (in $@).
    r "$* -> SLURM_JOB_NODELIST=$SLURM_JOB_NODELIST SLURM_JOB_CPUS_PER_NODE=$SLURM_JOB_CPUS_PER_NODE SLURM_CPUS_ON_NODE=$SLURM_CPUS_ON_NODE SLURM_TASKS_PER_NODE=$SLURM_TASKS_PER_NODE" ;;

  exits)  # What srun reports of a task's end: output, exit codes, signals.
    timed "stdout, stderr and exit 3" 20 srun --overlap -N1 -n1 -w node2 bash -c 'echo "to stdout on $(hostname)"; echo "to stderr" >&2; exit 3'
    for sig in KILL TERM INT SEGV ABRT; do
      rm -f "$FACTS/victim"
      bg_step node2 bash -c "echo \$\$ > $FACTS/victim; exec sleep 60"
      until [ -s "$FACTS/victim" ]; do sleep 0.05; done
      srun --overlap -N1 -n1 -w node2 bash -c "kill -$sig \$(cat $FACTS/victim)"
      wait $p; r "task killed by SIG$sig: srun rc=$?"
    done
    timed "no such program" 20 srun --overlap -N1 -n1 -w node2 /nonexistent ;;

  srun_signals)  # Each signal sent to the srun of a probe step (probe mode in $1).
    for sig in TERM INT INTx2 USR1 USR2 HUP QUIT CONT ALRM KILL; do
      bg_step node2 "$FACTS/probe.pl" "$sig" "$log" "$1" 3
      started "$sig"
      sleep 0.3
      r "sending $sig to srun"
      if [ $sig = INTx2 ]; then kill -INT $p; sleep 0.3; kill -INT $p; else kill -$sig $p; fi
      if timeout 8 tail --pid=$p -f /dev/null; then wait $p; r "srun exited, rc=$?"; else r "srun still running 8 s later"; fi
      sleep 1
      steps=$(squeue -h -s -j "$SLURM_JOB_ID" -o %i | grep -v batch | tr '\n' ' ')
      r "the job's steps now: ${steps:-none}"
      [ -z "$steps" ] || scancel --signal=KILL $steps
      kill -KILL $p 2> /dev/null
      wait
    done ;;

  orphan)  # The srun of a step SIGKILLed; then stopping a step cleanly.
    bg_step node2 "$FACTS/probe.pl" orphan "$log" exit 3
    started orphan
    step=$(squeue -h -s -j "$SLURM_JOB_ID" -o %i | grep -v batch)
    kill -KILL $p; wait $p; r "srun of step $step SIGKILLed: rc=$?"
    while squeue -h -s -j "$SLURM_JOB_ID" -o %i | grep -qx "$step"; do sleep 0.1; done
    r "step $step is gone"
    for mode in exit stay; do
      bg_step node2 "$FACTS/probe.pl" "clean-$mode" "$log" "$mode" 1
      started "clean-$mode"
      step=$(squeue -h -s -j "$SLURM_JOB_ID" -o %i | grep -v batch | tail -1)
      scancel --signal=TERM "$step"
      r "scancel --signal=TERM $step: rc=$?"
      if timeout 8 tail --pid=$p -f /dev/null; then wait $p; r "srun exited, rc=$?"; else
        scancel "$step"
        r "srun still running 8 s later; scancel $step: rc=$?"
        timeout 15 tail --pid=$p -f /dev/null; wait $p; r "srun exited, rc=$?"
      fi
    done ;;

  probes)  # Probe steps on node1 and node2 (mode $1, grace $2); the batch script traps signals
    # (with $3 = requeue, it requeues its own job on SIGUSR1).
    for s in TERM INT HUP USR1 USR2 CONT QUIT ALRM; do trap "r got $s" $s; done
    if [ "${3:-}" = requeue ]; then
      trap 'r "got USR1: scontrol requeue $SLURM_JOB_ID"; scontrol requeue "$SLURM_JOB_ID"; r "scontrol requeue: rc=$?"' USR1
    fi
    r "start: job $SLURM_JOB_ID, SLURM_RESTART_COUNT=${SLURM_RESTART_COUNT-unset}, nodes $SLURM_JOB_NODELIST"
    echo "the batch script's output, incarnation ${SLURM_RESTART_COUNT:-0}"
    bg_step node1 "$FACTS/probe.pl" p1.$tag "$log" "$1" "$2"; p1=$p
    bg_step node2 "$FACTS/probe.pl" p2.$tag "$log" "$1" "$2"; p2=$p
    started p1.$tag; started p2.$tag
    ready
    wait_srun $p1; r "srun of p1 rc=$rc"
    wait_srun $p2; r "srun of p2 rc=$rc"
    r "batch script exits" ;;

  lost)  # Probe steps on node1..3; node2 is killed (the host writes "node2 killed" in the log).
    for s in TERM INT HUP USR1 USR2 CONT QUIT ALRM; do trap "r got $s" $s; done
    r "start: SLURM_RESTART_COUNT=${SLURM_RESTART_COUNT-unset}, nodes $SLURM_JOB_NODELIST"
    bg_step node1 "$FACTS/probe.pl" p1.$tag "$log" exit 1; p1=$p
    bg_step node2 "$FACTS/probe.pl" p2.$tag "$log" exit 1; p2=$p
    bg_step node3 "$FACTS/probe.pl" p3.$tag "$log" exit 1; p3=$p
    started p1.$tag; started p2.$tag; started p3.$tag
    ready
    timeout 60 bash -c "until grep -q 'node2 killed' '$log'; do sleep 0.05; done"
    timed "a new srun to node2 just after its loss" 90 srun --overlap -N1 -n1 -w node2 hostname
    wait_srun $p2; r "srun of node2's step: rc=$rc"
    r "job: $(scontrol show job -o "$SLURM_JOB_ID" | grep -o 'JobState=[A-Z]*\| NodeList=[^ ]*' | tr '\n' ' ')"
    timed "a new srun to node2 now" 60 srun --overlap -N1 -n1 -w node2 hostname
    timed "a new srun to node3 now" 60 srun --overlap -N1 -n1 -w node3 hostname
    wait_srun $p1; r "srun of p1 rc=$rc"
    wait_srun $p3; r "srun of p3 rc=$rc" ;;

  bcast)  # sbcast of an owner-only file to node-local /tmp.
    umask 077
    head -c 32 /dev/urandom > /tmp/key.src
    r "source on $host: $(stat -c '%n mode %a owner %U' /tmp/key.src)"
    timed "sbcast /tmp/key.src /tmp/key" 20 sbcast /tmp/key.src /tmp/key
    timed "sbcast again onto the existing file" 20 sbcast /tmp/key.src /tmp/key
    timed "sbcast --force again" 20 sbcast --force /tmp/key.src /tmp/key
    timed "sbcast into a missing folder" 20 sbcast /tmp/key.src /tmp/no/key
    chmod 644 /tmp/key.src
    umask 022
    timed "sbcast of a mode 644 source" 20 sbcast /tmp/key.src /tmp/key644
    srun -N2 -n2 bash -c "echo \"\$EPOCHREALTIME batch@\$(hostname) \$(stat -c '%n mode %a owner %U size %s' /tmp/key /tmp/key644 | tr '\n' ' ')\" >> $log" ;;

  *) r "no experiment '$experiment'"; exit 2 ;;
esac
