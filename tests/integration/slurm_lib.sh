# Helpers of the tests that run CartPole on the Slurm test cluster (sourced after lib.sh).
[ "$(id -u)" -eq 0 ] || fail "this test builds namespaces and runs Slurm's daemons: it needs root"
source "$root/tests/cluster/cluster.sh"

# Brings up 2 nodes of 5 cores (the replay, learner and evaluator and 2 actors on node1) and
# submits CartPole with the documented command, 2 actors on each node; sets job, run (the run
# folder, shared) and out (the job's output). The job's time limit: $slurm_time (sbatch options).
slurm_time=${slurm_time:---time=8}
slurm_cartpole_submit() {  # slurm_cartpole_submit [LAUNCH_OPTIONS...]
  cluster_up 2 --cpus 5
  run=$CLUSTER_SHARED/run
  out=$CLUSTER_SHARED/job.out
  # shellcheck disable=SC2086
  job=$(cd "$root" && RL_BUILD_DIR=$build_dir cluster_submit --nodes=2 --exclusive $slurm_time \
    --output="$out" scripts/slurm.sbatch cartpole --out "$run" --actors-per-node 2 --seed 1 \
    --time-budget 240 "$@")
  echo "job $job submitted: $*"
}

# Waits (120 s at most) until the job's steps are the run's: the replay, learner, evaluator and
# two actors on node1, two actors on node2.
slurm_wait_steps() {
  local want="actor-0 node1,actor-1 node1,actor-2 node2,actor-3 node2,evaluator node1,learner node1,replay node1,"
  local steps="" i
  for ((i = 0; i < 240; i++)); do
    steps=$(cluster_exec ctl squeue -h -s -j "$job" -o '%j %N' | grep -v '^batch\|^extern' | sort | tr '\n' ',' || true)
    [ "$steps" != "$want" ] || break
    sleep 0.5
  done
  [ "$steps" = "$want" ] || { tail -20 "$out" >&2; fail "the job's steps are '$steps', not '$want'"; }
  echo "steps: $steps"
}

# Waits for the job's end (330 s at most): it must complete with its goal reached, the replay
# must have lost no transition (what flow control protects) and no process may have dropped a
# message. Messages lost elsewhere (a weights chunk or a reply in a burst over the nodes' link:
# UDP, and the next version or request makes up for it) are printed with their process. Prints
# the best evaluation mean.
slurm_expect_goal() {
  local state last losses
  state=$(cluster_wait_job "$job" 330) || { tail -30 "$out" >&2; fail "job $job did not end"; }
  tail -12 "$out" >&2
  [ "$state" = COMPLETED ] || fail "job $job ended $state"
  grep -q "^launch: goal of 475 reached" "$out" || fail "the goal was not reached"
  last=$(grep -o 'lost [0-9]*  dropped [0-9]*' "$run/logs/monitor.log" | tail -1)
  echo "monitor: $last" >&2
  [ "${last##* }" = 0 ] || fail "the monitor's last line says: $last"
  # The last count of each process that lost anything, from the run's metrics.
  losses=$(sed -n 's/.*"role": "\([^"]*\)".*"lost": \([0-9]*\),.*/\1 \2/p' "$run/metrics.jsonl" |
    awk '{ n[$1] = $2 } END { for (r in n) if (n[r] > 0) printf "%s lost %d; ", r, n[r] }')
  [ -z "$losses" ] || echo "messages lost over UDP: $losses" >&2
  case "$losses" in *"replay lost"*) fail "the replay lost transitions: $losses" ;; esac
  expect_best_mean "$run" 475 --at-least
}

# hold_learner_and_evaluator (lib.sh), letting them go (SIGCONT) on exit before cluster_up's trap
# (cluster_down, then cleanup).
slurm_hold_learner_and_evaluator() {
  hold_learner_and_evaluator
  trap 'kill -CONT $held 2> /dev/null || true; cluster_down; cleanup' EXIT
}
