#!/usr/bin/env bash
# A real Slurm cluster on this one machine (Debian's slurm-wlm 22.05 and munge), for the
# integration tests and by hand. Root only: it builds namespaces and runs the daemons as root.
#
# Each node is a small machine of its own: a network namespace with its own 198.18.1.x address
# on a bridge (the bridge lives in a namespace of its own), a UTS namespace with its hostname, a
# PID namespace (its init reaps orphans; killing the init kills every process of the node) and a
# mount namespace where /tmp and /dev/shm are the node's own, /etc/hosts names every node and
# /etc/slurm holds the cluster's slurm.conf (Slurm's commands need no SLURM_CONF there). "ctl"
# (198.18.1.1) runs slurmctld and is the login node; node1..nodeN (198.18.1.11..) each run
# `slurmd -N nodeK`. One munged in the root namespace serves every node through its socket.
# All config, state, logs and spool are in the cluster's folder; nothing of the machine's own
# (/etc, its munged, its network, `ip netns`) is touched. The namespaces have no names: they go
# away with their last process, so a cluster whose caller was SIGKILLed leaves only its folder.
#
# Under /tmp only the cluster's folder (with shared/, the "shared filesystem") and the folders
# given with --share are seen by every node; the rest of /tmp is each node's own (sbcast writes
# there). Paths outside /tmp (the source tree, the build) are the same on every node.
#
# By hand (DIR defaults to ${TMPDIR:-/tmp}/rl-cluster; the cluster outlives the command):
#   tests/cluster/cluster.sh up [--nodes N] [--cpus C] [--dir DIR] [--share PATH]...
#   tests/cluster/cluster.sh status [--dir DIR]       sinfo and squeue
#   tests/cluster/cluster.sh exec NODE CMD...         CMD on NODE (CLUSTER_DIR=DIR if not default)
#   tests/cluster/cluster.sh down [--dir DIR]
# e.g. `tests/cluster/cluster.sh exec ctl sbatch --nodes=2 job.sh` with job.sh under DIR/shared.
#
# As a library: `source tests/cluster/cluster.sh` in a test that runs with `set -e` (every wait
# below is bounded; a failure returns non-zero with a message on stderr):
#   cluster_up N [--cpus C] [--dir DIR] [--share PATH]...
#       munged, slurmctld on ctl and slurmd on node1..nodeN (N = 1..9, C CPUs each, 8 by
#       default); returns once every node is idle. Sets CLUSTER_DIR, CLUSTER_SHARED (a shared
#       folder, mode 1777), CLUSTER_NODES ("node1 node2 ..."), CLUSTER_CONF. The cluster dies
#       with the calling shell (call it from the test's main shell, not a subshell), and
#       cluster_down is chained before the caller's EXIT trap.
#   cluster_down             stops every process of the cluster and removes its folder
#                            (kept with CLUSTER_KEEP=1)
#   cluster_procs            the pids of every process of the cluster, the jobs' included
#   cluster_exec NODE CMD... runs CMD on NODE (ctl, nodeK): its network, hostname, PIDs, mounts;
#                            the working directory is kept when the node sees it
#   cluster_bg NODE CMD...   the same in the background: sets cluster_bg_pid (the command's pid,
#                            for signals) and cluster_bg_job (for `wait`)
#   cluster_addr NODE        the node's IP address
#   cluster_submit ARGS...   sbatch ARGS on ctl; prints the job id
#   cluster_wait_job ID SECONDS [STATE_REGEX]
#                            waits until the job's state matches (default: any end state);
#                            prints the state
#   cluster_sbatch SECONDS ARGS...
#                            submits and waits for the end; prints the job id; 0 if COMPLETED
#   cluster_job ID FIELD     a field of `scontrol show job` (JobState, NodeList, Restarts, ...)
#   cluster_node_kill NODE   SIGKILLs every process of a node, its daemon included (a lost node)
#   cluster_node_start NODE  boots a killed node again; its slurmd registers and the node
#                            returns to service by itself (ReturnToService=2)
#   cluster_node_state NODE  its state as sinfo prints it (idle, alloc, mix, down*, ...)
#   cluster_wait_node NODE SECONDS STATE_REGEX

cluster_self=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/$(basename "${BASH_SOURCE[0]}")
cluster_subnet=198.18.1
case ":$PATH:" in *:/usr/sbin:*) ;; *) PATH=$PATH:/usr/sbin:/sbin ;; esac

cluster_fail() { echo "cluster: $*" >&2; return 1; }

# Waits (bounded) until CMD succeeds.
cluster_until() {  # cluster_until SECONDS WHAT CMD...
  local limit=$1 end=$((SECONDS + $1)) what=$2
  shift 2
  until "$@" > /dev/null 2>&1; do
    [ "$SECONDS" -lt "$end" ] || { cluster_fail "$what: not within $limit s"; return 1; }
    sleep 0.05
  done
}

# Seconds since T0 (an $EPOCHREALTIME), to a tenth.
cluster_since() { awk -v a="$1" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.1f", b - a }'; }

# Whether a process is alive (a zombie is not).
cluster_alive() {
  local stat
  read -r stat 2> /dev/null < "/proc/$1/stat" || return 1
  [[ ! "$stat" =~ \)\ Z ]]
}

cluster_addr() {  # cluster_addr NODE
  case "$1" in
    ctl) echo "$cluster_subnet.1" ;;
    node[1-9]) echo "$cluster_subnet.$((10 + ${1#node}))" ;;
    *) cluster_fail "no node '$1' (ctl, node1..node9)" ;;
  esac
}

# Sets cluster_init to the pid of a node's init (pid 1 of its PID namespace) as the root
# namespace sees it: the child of the unshare whose pid is in run/NODE.pid; for "sw", the
# switch's own process. Fails if the node is not running. (Builtins only: it runs often.)
cluster_find_init() {  # cluster_find_init NODE
  local upid=""
  cluster_init=""
  read -r upid 2> /dev/null < "$CLUSTER_DIR/run/$1.pid" || return 1
  if [ "$1" = sw ]; then cluster_alive "$upid" && cluster_init=$upid; return; fi
  read -r cluster_init _ 2> /dev/null < "/proc/$upid/task/$upid/children" || true
  [ -n "$cluster_init" ]
}

# Sets cluster_enter to the nsenter command line that runs a command on NODE: in all of its
# namespaces, in the current working directory if the node sees the same folder there, else /.
cluster_enter_args() {  # cluster_enter_args NODE
  local wd=/ ns=(-n -u -m -p) p
  cluster_find_init "$1" || { cluster_fail "node $1 is not running"; return 1; }
  [ "$1" != sw ] || ns=(-n)
  case "$PWD/" in
    /tmp/*) while read -r p; do case "$PWD/" in "$p"/*) wd=$PWD ;; esac; done < "$CLUSTER_DIR/shared-paths" ;;
    *) wd=$PWD ;;
  esac
  cluster_enter=(nsenter -t "$cluster_init" "${ns[@]}" --wd="$wd" --)
}

cluster_exec() {  # cluster_exec NODE CMD...
  cluster_enter_args "$1" || return 1
  shift
  "${cluster_enter[@]}" "$@"
}

# nsenter forks the command into the node's PID namespace and does not pass signals on: the
# command's own pid is nsenter's child.
cluster_bg() {  # cluster_bg NODE CMD...
  local end=$((SECONDS + 10)) node=$1
  cluster_enter_args "$node" || return 1
  shift
  "${cluster_enter[@]}" "$@" &
  cluster_bg_job=$!
  cluster_bg_pid=""
  while :; do
    # (before its exec, the job is a copy of this shell)
    if [ "$(cat "/proc/$cluster_bg_job/comm" 2> /dev/null || true)" = nsenter ]; then
      cluster_bg_pid=$(cat "/proc/$cluster_bg_job/task/$cluster_bg_job/children" 2> /dev/null || true)
      cluster_bg_pid=${cluster_bg_pid%% *}
      [ -z "$cluster_bg_pid" ] || return 0
    fi
    cluster_alive "$cluster_bg_job" || { cluster_fail "cluster_bg: '$1' ended at once on $node"; return 1; }
    [ "$SECONDS" -lt "$end" ] || { cluster_fail "cluster_bg: '$1' did not start on $node"; return 1; }
    sleep 0.02
  done
}

# Writes slurm.conf, cgroup.conf and the nodes' /etc/hosts into $CLUSTER_DIR/etc.
cluster_write_config() {  # cluster_write_config NODES CPUS
  local n=$1 cpus=$2 d=$CLUSTER_DIR i
  cat > "$d/etc/slurm.conf" << EOF
# A test cluster on one machine, each daemon in namespaces of its own (tests/cluster/cluster.sh).
ClusterName=rltest
SlurmctldHost=ctl($(cluster_addr ctl))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
# The cluster's own munged. cred_expire (default 120 s, at least 5) is also how long a requeued
# job waits before it may start again.
AuthInfo=socket=$d/munge/munge.socket,cred_expire=5
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool/%n
SlurmctldPidFile=$d/run/slurmctld.pid
SlurmdPidFile=$d/run/slurmd-%n.pid
SlurmctldLogFile=$d/log/slurmctld.log
SlurmdLogFile=$d/log/slurmd-%n.log
# cgroup v1 in hybrid mode defeats slurmd's cgroup autodetection: no cgroup plugin in use.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
# Nodes claim CPUs=$cpus whatever the machine has; without this a node with fewer real CPUs
# than configured registers as invalid and is drained.
SlurmdParameters=config_overrides
JobRequeue=1
ReturnToService=2
KillWait=5
SlurmdTimeout=10
MinJobAge=300
# The backfill pass starts requeued jobs once eligible: every second instead of every 30 s.
SchedulerParameters=bf_interval=1
NodeName=DEFAULT CPUs=$cpus RealMemory=1000 State=UNKNOWN
EOF
  for ((i = 1; i <= n; i++)); do
    echo "NodeName=node$i NodeHostname=node$i NodeAddr=$(cluster_addr "node$i")" >> "$d/etc/slurm.conf"
  done
  echo "PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP" >> "$d/etc/slurm.conf"
  echo "CgroupPlugin=cgroup/v1" > "$d/etc/cgroup.conf"
  {
    cat /etc/hosts
    echo "$(cluster_addr ctl) ctl"
    for ((i = 1; i <= n; i++)); do echo "$(cluster_addr "node$i") node$i"; done
  } > "$d/etc/hosts"
}

# Starts a process in the background that dies with this shell when the cluster is tied to it
# (the library), and lives on when not (`cluster.sh up`).
cluster_spawn() {  # cluster_spawn NAME CMD...  (pid in run/NAME.pid)
  local name=$1
  shift
  if [ -n "${cluster_tied:-}" ]; then set -- setpriv --pdeathsig KILL -- "$@"; fi
  "$@" < /dev/null >> "$CLUSTER_DIR/log/$name.init" 2>&1 &
  echo $! > "$CLUSTER_DIR/run/$name.pid"
  disown $!  # still reaped by this shell; no "Killed" line when it ends
}

cluster_node_start() {  # cluster_node_start NODE
  cluster_node_boot "$1" && cluster_node_wire "$1" && cluster_node_booted "$1"
}

# Boots a node: its init starts in new network, UTS, PID and mount namespaces (unshare
# --kill-child takes the node down if unshare dies) and waits for its network
# (cluster_node_wire); then the init sets the node up and starts its daemon
# (cluster_node_booted).
cluster_node_boot() {  # cluster_node_boot NODE
  rm -f "$CLUSTER_DIR/run/$1.net" "$CLUSTER_DIR/run/$1.ready"
  cluster_spawn "$1" unshare --net --uts --pid --mount --fork --mount-proc --kill-child \
    bash "$cluster_self" _init "$1" "$CLUSTER_DIR"
}

# Wires a booting node to the bridge: eth0 with its address, lo, the multicast route.
cluster_node_wire() {  # cluster_node_wire NODE
  local node=$1 sw
  cluster_find_init sw || { cluster_fail "the switch is down"; return 1; }
  sw=$cluster_init
  # The veth end of a node that died goes away with its namespace, a moment later.
  cluster_until 10 "the old port of $node going" eval "! nsenter -t $sw -n ip link show $node" || return 1
  cluster_until 10 "node $node's init" cluster_find_init "$node" || return 1
  cluster_find_init "$node"
  ip link add eth0 netns "$cluster_init" type veth peer name "$node" netns "$sw"
  nsenter -t "$sw" -n ip link set "$node" master br0 up
  nsenter -t "$cluster_init" -n sh -e -c "ip link set lo up
    ip addr add $(cluster_addr "$node")/24 dev eth0
    ip link set eth0 up
    ip route add 224.0.0.0/4 dev eth0"
  touch "$CLUSTER_DIR/run/$node.net"
}

# Waits until a booting node's init has started its daemon.
cluster_node_booted() {  # cluster_node_booted NODE
  local end=$((SECONDS + 20))
  until [ -e "$CLUSTER_DIR/run/$1.ready" ]; do
    cluster_alive "$(cat "$CLUSTER_DIR/run/$1.pid")" && [ "$SECONDS" -lt "$end" ] ||
      { cluster_fail "node $1 did not boot: $(tail -3 "$CLUSTER_DIR/log/$1.init")"; return 1; }
    sleep 0.05
  done
}

# The node's init, pid 1 of its PID namespace: sets the node up, starts its daemon, reaps.
cluster_init() {  # cluster_init NODE DIR
  local node=$1 d=$2 p shared i
  set -e
  hostname "$node"
  for ((i = 0; i < 200; i++)); do [ ! -e "$d/run/$node.net" ] || break; sleep 0.05; done
  [ -e "$d/run/$node.net" ] || { echo "no network within 10 s" >&2; exit 1; }
  # A /tmp of the node's own, with the shared folders bound back in.
  mapfile -t shared < "$d/shared-paths"
  mount --bind /tmp /mnt
  mount --bind "$d/nodes/$node/tmp" /tmp
  for p in "${shared[@]}"; do
    case "$p" in /tmp/*)
      mkdir -p "$p"
      mount --bind "/mnt/${p#/tmp/}" "$p" ;;
    esac
  done
  umount -l /mnt
  mount -t tmpfs -o mode=1777,size=256m tmpfs /dev/shm
  mount --bind "$d/etc/hosts" /etc/hosts
  mkdir -p /etc/slurm
  mount --bind "$d/etc" /etc/slurm
  if [ "$node" = ctl ]; then
    slurmctld -D -i > "$d/log/slurmctld.out" 2>&1 &
  else
    slurmd -D -N "$node" > "$d/log/slurmd-$node.out" 2>&1 &
  fi
  touch "$d/run/$node.ready"
  set +e
  while :; do
    sleep 3600 &
    wait $!
  done
}

cluster_up() {  # cluster_up N [--cpus C] [--dir DIR] [--share PATH]...
  local n=${1:-} cpus=8 dir="" share=() i node p t0=$EPOCHREALTIME
  [ $# -eq 0 ] || shift
  while [ $# -gt 0 ]; do
    case "$1" in
      --cpus) cpus=$2; shift ;;
      --dir) dir=$2; shift ;;
      --share) share+=("$(realpath -m "$2")"); shift ;;
      *) cluster_fail "cluster_up: unknown option '$1'"; return 1 ;;
    esac
    shift
  done
  [[ "$n" =~ ^[1-9]$ ]] || { cluster_fail "cluster_up: 1 to 9 nodes, not '$n'"; return 1; }
  [[ "$cpus" =~ ^[1-9][0-9]*$ ]] || { cluster_fail "cluster_up: --cpus takes a count, not '$cpus'"; return 1; }
  [ "$(id -u)" -eq 0 ] || { cluster_fail "needs root (namespaces, daemons)"; return 1; }
  for p in munged slurmctld slurmd srun sbatch scontrol sinfo nsenter unshare setpriv ip; do
    command -v "$p" > /dev/null ||
      { cluster_fail "'$p' is not installed (scripts/setup.sh installs slurm-wlm and munge)"; return 1; }
  done
  if [ -z "$dir" ]; then
    dir=$(mktemp -d "${TMPDIR:-/tmp}/rl-cluster-XXXXXX")
  else
    [ ! -e "$dir/cluster.env" ] || { cluster_fail "a cluster is up in $dir (down it first)"; return 1; }
    mkdir -p "$dir"
  fi
  CLUSTER_DIR=$(realpath "$dir")
  CLUSTER_SHARED=$CLUSTER_DIR/shared
  CLUSTER_CONF=$CLUSTER_DIR/etc/slurm.conf
  CLUSTER_NODES=$(for ((i = 1; i <= n; i++)); do printf 'node%d ' "$i"; done)
  CLUSTER_NODES=${CLUSTER_NODES% }
  # munged insists that every folder above its socket is searchable by all.
  chmod 755 "$CLUSTER_DIR"
  mkdir -p "$CLUSTER_DIR"/{etc,munge,key,state,spool,log,run,shared}
  chmod 700 "$CLUSTER_DIR/key"
  chmod 1777 "$CLUSTER_SHARED"
  printf '%s\n' "$CLUSTER_DIR" "${share[@]}" > "$CLUSTER_DIR/shared-paths"
  declare -p CLUSTER_DIR CLUSTER_SHARED CLUSTER_CONF CLUSTER_NODES > "$CLUSTER_DIR/cluster.env"
  [ -n "${cluster_detached:-}" ] || { cluster_tied=1; cluster_chain_trap; }
  cluster_write_config "$n" "$cpus"

  dd if=/dev/urandom of="$CLUSTER_DIR/key/munge.key" bs=1024 count=1 status=none
  chmod 400 "$CLUSTER_DIR/key/munge.key"
  cluster_spawn munged munged -F --socket="$CLUSTER_DIR/munge/munge.socket" \
    --key-file="$CLUSTER_DIR/key/munge.key" --pid-file="$CLUSTER_DIR/munge/munged.pid" \
    --seed-file="$CLUSTER_DIR/munge/munged.seed"
  cluster_spawn sw unshare --net -- sleep infinity
  # unshare execs sleep once the namespace is made.
  cluster_until 10 "the switch's namespace" eval "[ \"\$(cat /proc/$(cat "$CLUSTER_DIR/run/sw.pid")/comm)\" = sleep ]" || return 1
  cluster_find_init sw
  nsenter -t "$cluster_init" -n sh -e -c 'ip link add br0 type bridge; ip link set br0 up; ip link set lo up'
  cluster_until 10 "munged's socket" test -S "$CLUSTER_DIR/munge/munge.socket" || return 1
  for node in ctl $CLUSTER_NODES; do
    mkdir -p "$CLUSTER_DIR/nodes/$node/tmp" "$CLUSTER_DIR/spool/$node"
    chmod 1777 "$CLUSTER_DIR/nodes/$node/tmp"
    cluster_node_boot "$node"
  done
  # The nodes are wired at once (the boots stay in this shell: their parent-death signal).
  local wires=()
  for node in ctl $CLUSTER_NODES; do
    cluster_node_wire "$node" &
    wires+=($!)
  done
  for p in "${wires[@]}"; do wait "$p" || return 1; done
  for node in ctl $CLUSTER_NODES; do cluster_node_booted "$node" || return 1; done
  # A slurmd that starts before slurmctld listens registers once it does.
  for node in $CLUSTER_NODES; do
    cluster_wait_node "$node" 30 '^idle$' > /dev/null || return 1
  done
  echo "cluster: up in $(cluster_since "$t0") s: ctl and $CLUSTER_NODES, in $CLUSTER_DIR" >&2
}

# Adds cluster_down to the caller's EXIT trap, before what it does already.
# shellcheck disable=SC2120  # its "$@" is the trap's own words
cluster_chain_trap() {
  local prev=""
  eval "set -- $(trap -p EXIT)"
  [ $# -lt 3 ] || prev=$3
  case "$prev" in *cluster_down*) return 0 ;; esac
  # shellcheck disable=SC2064
  trap "cluster_down; $prev" EXIT
}

# Every process of the cluster: munged, the switch, the nodes' unshare and everything in the
# nodes' PID namespaces (a namespace is known by its inode).
cluster_procs() {
  local name pid inits=() nss
  for name in munged sw ctl $CLUSTER_NODES; do
    read -r pid 2> /dev/null < "$CLUSTER_DIR/run/$name.pid" || continue
    cluster_alive "$pid" || continue
    echo "$pid"
    [ "$name" = munged ] || [ "$name" = sw ] || ! cluster_find_init "$name" ||
      inits+=("/proc/$cluster_init/ns/pid")
  done
  [ ${#inits[@]} -gt 0 ] || return 0
  nss=" $(stat -L -c %i "${inits[@]}" 2> /dev/null | tr '\n' ' ')"
  # (stat fails on the processes that end meanwhile)
  { stat -L -c '%i %n' /proc/[0-9]*/ns/pid 2> /dev/null || true; } |
    awk -v nss="$nss" 'index(nss, " " $1 " ") { split($2, p, "/"); print p[3] }'
}

cluster_down() {
  [ -n "${CLUSTER_DIR:-}" ] && [ -e "$CLUSTER_DIR/cluster.env" ] || return 0
  local name pid procs t0=$EPOCHREALTIME
  procs=$(cluster_procs)
  # munged is stopped by TERM (it saves its seed); a node by SIGKILL of its unshare, whose
  # --kill-child SIGKILLs the init and with it every process of the node's PID namespace.
  for name in $CLUSTER_NODES ctl sw munged; do
    pid=$(cat "$CLUSTER_DIR/run/$name.pid" 2> /dev/null) || continue
    if [ "$name" = munged ]; then kill -TERM "$pid"; else kill -KILL "$pid"; fi 2> /dev/null || true
  done
  local end=$((SECONDS + 10)) left
  while :; do
    left=""
    for pid in $procs; do cluster_alive "$pid" && left+=" $pid"; done
    [ -n "$left" ] && [ "$SECONDS" -lt "$end" ] || break
    sleep 0.05
  done
  if [ -n "$left" ]; then
    echo "cluster: processes$left outlived the cluster: SIGKILL" >&2
    kill -KILL $left 2> /dev/null || true
  fi
  if [ -n "${CLUSTER_KEEP:-}" ]; then
    rm -f "$CLUSTER_DIR/cluster.env"
    echo "cluster: down in $(cluster_since "$t0") s; its folder is kept: $CLUSTER_DIR" >&2
  else
    rm -rf "$CLUSTER_DIR"
    echo "cluster: down in $(cluster_since "$t0") s" >&2
  fi
  CLUSTER_DIR=""
}

cluster_node_kill() {  # cluster_node_kill NODE
  local upid
  upid=$(cat "$CLUSTER_DIR/run/$1.pid") || return 1
  kill -KILL "$upid"
  cluster_until 10 "node $1 dying" eval "! cluster_alive $upid"
}

cluster_node_state() {  # cluster_node_state NODE
  cluster_exec ctl sinfo -h -N -n "$1" -o %t 2> /dev/null | head -1
}

cluster_wait_node() {  # cluster_wait_node NODE SECONDS STATE_REGEX
  local end=$((SECONDS + $2)) state=""
  while :; do
    state=$(cluster_node_state "$1" || true)
    [[ ! "$state" =~ $3 ]] || { echo "$state"; return 0; }
    [ "$SECONDS" -lt "$end" ] || { cluster_fail "node $1 is '$state', not /$3/, after $2 s"; return 1; }
    sleep 0.2
  done
}

cluster_job() {  # cluster_job ID FIELD
  cluster_exec ctl scontrol show job -o "$1" | tr ' ' '\n' | sed -n "s/^$2=//p"
}

cluster_submit() {  # cluster_submit SBATCH_ARGS...
  local out
  out=$(cluster_exec ctl sbatch --parsable "$@") || return 1
  echo "${out%%;*}"
}

cluster_wait_job() {  # cluster_wait_job ID SECONDS [STATE_REGEX]
  local end=$((SECONDS + $2)) state
  local want=${3:-'^(COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE|PREEMPTED)$'}
  while :; do
    state=$(cluster_job "$1" JobState || true)
    [[ ! "$state" =~ $want ]] || { echo "$state"; return 0; }
    [ "$SECONDS" -lt "$end" ] || { cluster_fail "job $1 is '$state', not /$want/, after $2 s"; return 1; }
    sleep 0.2
  done
}

cluster_sbatch() {  # cluster_sbatch SECONDS SBATCH_ARGS...
  local limit=$1 id state
  shift
  id=$(cluster_submit "$@") || return 1
  echo "$id"
  state=$(cluster_wait_job "$id" "$limit") || return 1
  [ "$state" = COMPLETED ] || { cluster_fail "job $id ended $state"; return 1; }
}

# The command line.
cluster_main() {
  local cmd=${1:-} dir=${CLUSTER_DIR:-${TMPDIR:-/tmp}/rl-cluster} n=2 args=()
  [ $# -eq 0 ] || shift
  case "$cmd" in
    _init) cluster_init "$@"; return ;;
    exec)
      [ -e "$dir/cluster.env" ] || { cluster_fail "no cluster in $dir"; return 1; }
      source "$dir/cluster.env"
      cluster_exec "$@"
      return ;;
    up | down | status) ;;
    -h | --help | "") awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$cluster_self"; return 0 ;;
    *) cluster_fail "unknown command '$cmd' (see --help)"; return 2 ;;
  esac
  while [ $# -gt 0 ]; do
    case "$1" in
      --dir) dir=$2; shift ;;
      --nodes) n=$2; shift ;;
      --cpus | --share) args+=("$1" "$2"); shift ;;
      *) cluster_fail "unknown option '$1' (see --help)"; return 2 ;;
    esac
    shift
  done
  case "$cmd" in
    up)
      cluster_detached=1
      trap 'cluster_down' EXIT  # only if it fails half-way
      cluster_up "$n" --dir "$dir" "${args[@]}"
      trap - EXIT
      [ "$dir" = "${TMPDIR:-/tmp}/rl-cluster" ] || echo "export CLUSTER_DIR=$dir" ;;
    down | status)
      [ -e "$dir/cluster.env" ] || { cluster_fail "no cluster in $dir"; return 1; }
      source "$dir/cluster.env"
      if [ "$cmd" = down ]; then
        cluster_down
      else
        cluster_exec ctl sinfo -N -l
        cluster_exec ctl squeue -s
      fi ;;
  esac
}

if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  set -euo pipefail
  cluster_main "$@"
fi
