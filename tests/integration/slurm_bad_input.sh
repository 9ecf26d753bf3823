#!/usr/bin/env bash
# Bad input to scripts/slurm.sbatch gets a clear error before anything starts, on a real Slurm
# cluster (tests/cluster/cluster.sh): an unknown preset, a --transport other than udpm or tcp,
# no srun on the PATH, and a job with fewer cores than the first node's processes need. Each job
# fails with the launcher's one line and leaves no run folder behind.
source "$(dirname "$0")/lib.sh"
[ "$(id -u)" -eq 0 ] || fail "this test builds namespaces and runs Slurm's daemons: it needs root"
source "$root/tests/cluster/cluster.sh"
scratch
cluster_up 2 --cpus 4
shared=$CLUSTER_SHARED
# A PATH with bash and nothing of Slurm's.
mkdir -p "$shared/noslurm"
ln -s "$(command -v bash)" "$shared/noslurm/bash"

# submit NAME [env VAR=VALUE...] -- SBATCH_OPTIONS -- SCRIPT_ARGS: the job's id in jobs[NAME].
declare -A jobs=()
submit() {
  local name=$1 envs=() opts=()
  shift
  while [ "$1" != -- ]; do envs+=("$1"); shift; done
  shift
  while [ "$1" != -- ]; do opts+=("$1"); shift; done
  shift
  jobs[$name]=$(cd "$root" && cluster_exec ctl env RL_BUILD_DIR="$build_dir" ${envs[@]+"${envs[@]}"} \
    /usr/bin/sbatch --parsable "${opts[@]}" --output="$shared/$name.out" scripts/slurm.sbatch "$@")
  jobs[$name]=${jobs[$name]%%;*}
}
submit preset -- --nodes=2 --exclusive -- no_such_preset --out "$shared/run-preset"
submit transport -- --nodes=2 --exclusive -- cartpole --transport udp --out "$shared/run-transport"
submit srun PATH="$shared/noslurm" -- --nodes=2 --exclusive -- cartpole --out "$shared/run-srun"
# The default, one core on each node: the replay, learner and evaluator need 3.
submit cores -- --nodes=2 -- cartpole --out "$shared/run-cores"

expect() {  # expect NAME LINE_REGEX
  local state
  state=$(cluster_wait_job "${jobs[$1]}" 90) || fail "job $1 (${jobs[$1]}) did not end"
  echo "$1: job ${jobs[$1]} $state: $(grep '^launch: ' "$shared/$1.out" || true)"
  [ "$state" = FAILED ] || { cat "$shared/$1.out" >&2; fail "job $1 ended $state, not FAILED"; }
  grep -Eq "$2" "$shared/$1.out" || { cat "$shared/$1.out" >&2; fail "job $1: no line /$2/"; }
  [ ! -e "$shared/run-$1" ] || fail "job $1 left a run folder"
  ! grep -q "^launch: run \|: ready" "$shared/$1.out" || fail "job $1 started something"
}
expect preset "^launch: no preset 'no_such_preset' \(known: .*cartpole.*\)$"
expect transport "^launch: --transport must be udpm \(LCM multicast\) or tcp \(LCM's TCP hub\), not 'udp'$"
expect srun "^launch: --slurm needs Slurm's srun on the PATH"
expect cores "^launch: the job has 1 core on its first node, which needs 3 \(the replay, the learner and the evaluator\) \(ask Slurm for more"
echo "PASS: an unknown preset, a bad --transport, no srun and too few cores refused before anything started"
