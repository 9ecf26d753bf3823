#!/usr/bin/env bash
# Measures how Slurm runs, signals, requeues and loses a job's processes on the test cluster,
# and how LCM crosses its nodes; prints what each experiment saw (times in seconds from the
# experiment's start; a probe's "alive" lines are shown as the first and last of each run).
# README.md's facts come from it.
#
#   tests/cluster/facts.sh [EXPERIMENT...]      all by default, in this order:
#     env cpus exits srun_signals orphan scancel requeue timelimit timelimit_steps selfrequeue
#     lost_nokill lost bcast lcm
#
# Root only. It brings a 3-node cluster up and down, or uses the one in $CLUSTER_DIR if one is up
# there. timelimit, timelimit_steps and selfrequeue take about 90 s each, the lost ones about
# 60 s each; all of them about 15 minutes.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
source "$here/cluster.sh"

experiments=(env cpus exits srun_signals orphan scancel requeue timelimit timelimit_steps selfrequeue
  lost_nokill lost bcast lcm)
case "${1:-}" in -h | --help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;; esac
[ $# -eq 0 ] || experiments=("$@")

if [ -n "${CLUSTER_DIR:-}" ] && [ -e "$CLUSTER_DIR/cluster.env" ]; then
  source "$CLUSTER_DIR/cluster.env"
else
  cluster_up 3
fi
FACTS=$CLUSTER_SHARED/facts
mkdir -p "$FACTS"
cp "$here/facts/lib.sh" "$here/facts/probe.pl" "$here/facts/job.sh" "$FACTS/"
cd "$FACTS"

note() { echo "$EPOCHREALTIME host: $*" >> "$FACTS/$name.log"; }
# Submits job.sh EXPERIMENT ARGS with SBATCH_OPTIONS; the job id in $id.
submit() {  # submit "SBATCH_OPTIONS" EXPERIMENT [ARGS]
  local opts=$1
  shift
  # shellcheck disable=SC2086
  id=$(FACTS=$FACTS FACTS_LOG=$name cluster_submit --output="$FACTS/$name-%j.out" $opts "$FACTS/job.sh" "$@")
  note "submitted job $id: sbatch $opts job.sh $*"
}
ready() {  # ready [RESTART]: waits until the job's probes are up
  cluster_until 60 "job $id's probes" grep -q " ready (job $id, restart ${1:-0})$" "$FACTS/$name.log"
}
finish() {  # finish [SECONDS]: waits for the job's end, then shows the log and the job's end
  local state
  state=$(cluster_wait_job "$id" "${1:-60}") || state="still $(cluster_job "$id" JobState)"
  note "job $id ended: $state, $(cluster_exec ctl scontrol show job -o "$id" | grep -o 'Restarts=[0-9]*\|ExitCode=[0-9:]*' | tr '\n' ' ')"
}
show() {
  echo "== $name"
  sort -s -n -k1,1 "$FACTS/$name.log" | awk '
    { if (!t0) t0 = $1; rest = substr($0, index($0, " ") + 1) }
    / alive$/ { k = $2; if (seen[k]++) { last[k] = sprintf("%+8.3f %s", $1 - t0, rest); next } }
    { for (k in last) { print last[k]; delete last[k] } printf "%+8.3f %s\n", $1 - t0, rest }
    END { for (k in last) print last[k] }'
  [ -z "$id" ] || [ ! -s "$FACTS/$name-$id.out" ] || sed "s/^/   job $id's output: /" "$FACTS/$name-$id.out"
}
watch_node() {  # watch_node NODE SECONDS: logs the node's state changes
  local end=$((SECONDS + $2)) st last=""
  while [ $SECONDS -lt $end ]; do
    st=$(cluster_node_state "$1")
    [ "$st" = "$last" ] || note "sinfo: $1 $st; job $id $(cluster_job "$id" JobState)"
    last=$st
    sleep 0.3
  done
}
lcm_events() {  # lcm_events FILE: the number of events on PROBE in an LCM log file
  perl -e 'local $/; open(my $f, "<", shift) or do { print "0\n"; exit }; binmode $f; my $b = <$f>;
    my $n = 0; while (length($b) >= 28) { my (undef, undef, undef, $c, $d) = unpack("N Q> Q> N N", $b);
    $n++ if substr($b, 28, $c) eq "PROBE"; $b = substr($b, 28 + $c + $d); } print "$n\n"' "$1"
}

for name in "${experiments[@]}"; do
  rm -f "$FACTS/$name".* "$FACTS/$name"-*.out
  id=""
  case "$name" in
    env)
      submit "--nodes=2" env; finish
      # How long a job takes to start, and with --export=ALL,VAR=VALUE.
      submit "--nodes=1" cpus; finish
      submit "--nodes=1 --export=ALL,EXTRA=1" cpus; finish ;;
    cpus)
      for opts in "--nodes=2" "--nodes=2 --exclusive" "--nodes=2 --ntasks-per-node=4" "--nodes=2 -c 3" \
        "--nodes=2 -n 5" "--nodes=3 -n 9" "-n 20" "--nodes=2 --mincpus=6"; do
        submit "$opts" cpus "$opts"; finish
      done ;;
    exits) submit "--nodes=2" exits; finish 120 ;;
    srun_signals) submit "--nodes=2" srun_signals exit; finish 200 ;;
    orphan) submit "--nodes=2" orphan; finish 60 ;;
    scancel)
      for how in "scancel" "scancel --signal=TERM" "scancel --batch --signal=TERM" "scancel --full --signal=TERM"; do
        for mode in "stay 0" "exit 2"; do
          # shellcheck disable=SC2086
          submit "--nodes=2" probes $mode; ready
          note "$how $id (probes: $mode)"
          # shellcheck disable=SC2086
          cluster_exec ctl $how "$id"
          cluster_wait_job "$id" 15 > /dev/null || { note "$how: the job runs on; scancel $id"; cluster_exec ctl scancel "$id"; }
          finish 30
        done
      done ;;
    requeue)
      for out in "" "--open-mode=append"; do
        submit "--nodes=2 $out" probes exit 2; ready
        note "scontrol requeue $id"
        cluster_exec ctl scontrol requeue "$id"
        ready 1
        note "job $id: $(cluster_exec ctl scontrol show job -o "$id" | grep -o 'JobState=[A-Z]*\|Restarts=[0-9]*\|SubmitTime=[^ ]*\|EligibleTime=[^ ]*\|StartTime=[^ ]*' | tr '\n' ' ')"
        cluster_exec ctl scancel "$id"
        finish 30
        note "its output file (sbatch ${out:-without --open-mode}) has the lines of incarnations: $(sed -n 's/.*output, incarnation //p' "$FACTS/$name-$id.out" | tr '\n' ' ')"
      done ;;
    timelimit | timelimit_steps)
      # A minute's limit; a warning signal 20 s before it, to the batch script or to the steps.
      if [ "$name" = timelimit ]; then submit "--nodes=2 --time=1 --signal=B:USR1@20" probes exit 2
      else submit "--nodes=2 --time=1 --signal=USR1@20" probes exit 2; fi
      finish 150 ;;
    selfrequeue)
      # The batch script requeues its own job when warned of the time limit.
      submit "--nodes=2 --time=1 --signal=B:USR1@20 --open-mode=append" probes exit 2 requeue
      ready
      cluster_until 150 "the job's second run" grep -q " ready (job $id, restart 1)$" "$FACTS/$name.log"
      note "job $id: $(cluster_exec ctl scontrol show job -o "$id" | grep -o 'JobState=[A-Z]*\|Restarts=[0-9]*\|TimeLimit=[^ ]*\|StartTime=[^ ]*\|EndTime=[^ ]*' | tr '\n' ' ')"
      cluster_exec ctl scancel "$id"
      finish 30 ;;
    lost_nokill | lost)
      opts="--nodes=3"
      [ "$name" = lost ] || opts="--nodes=3 --no-kill"
      submit "$opts" lost; ready
      note "killing every process of node2"
      cluster_node_kill node2
      note "node2 killed"
      watch_node node2 35
      note "starting node2 again"
      cluster_node_start node2
      watch_node node2 15
      [ "$name" = lost ] || cluster_until 60 "the batch script's last srun" grep -q 'new srun to node3' "$FACTS/$name.log"
      cluster_exec ctl scancel "$id"
      finish 30 ;;
    bcast) submit "--nodes=2" bcast; finish ;;
    lcm)
      url="udpm://239.255.76.67:7667?ttl=1"
      # 100 events of 1 KB on PROBE at 100/s, then 10 on END (lcm-logplayer may drop the last
      # few events of a log).
      perl -e 'open(my $f, ">", shift); binmode $f; my $t = 0; for my $i (1 .. 110) {
        my ($c, $d) = $i <= 100 ? ("PROBE", "message $i " . ("x" x 1000)) : ("END", "end"); $t += 10000;
        print $f pack("N Q> Q> N N", 0xEDA1DA01, $i, $t, length($c), length($d)), $c, $d; }' "$FACTS/probe.lcmlog"
      cluster_bg node1 lcm-logger -q -f --lcm-url="$url&recv_buf_size=4194304" "$FACTS/udpm1.lcmlog"; l1=$cluster_bg_pid
      cluster_bg node3 lcm-logger -q -f --lcm-url="$url&recv_buf_size=4194304" "$FACTS/udpm3.lcmlog"; l3=$cluster_bg_pid
      sleep 1
      cluster_exec node2 lcm-logplayer -s 1 --lcm-url="$url" "$FACTS/probe.lcmlog" > /dev/null
      sleep 1
      kill -INT "$l1" "$l3"; wait
      note "lcm-logplayer on node2 ($url): node1 got $(lcm_events udpm1.lcmlog), node3 got $(lcm_events udpm3.lcmlog) of 100"
      cluster_bg node1 java -cp /usr/share/java/lcm.jar lcm.lcm.TCPService 7700 > /dev/null; hub=$cluster_bg_pid
      t0=$EPOCHREALTIME
      cluster_until 30 "the TCP hub" cluster_exec node2 bash -c "exec 3<> /dev/tcp/$(cluster_addr node1)/7700"
      note "TCPService on node1 accepts connections $(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.1f", b - a }') s after its start"
      for url in "tcpq://$(cluster_addr node1):7700" "tcpq://node1:7700"; do
        rm -f "$FACTS/tcpq3.lcmlog"
        cluster_bg node3 lcm-logger -q -f --lcm-url="$url" "$FACTS/tcpq3.lcmlog"; l3=$cluster_bg_pid
        sleep 1
        cluster_exec node2 lcm-logplayer -s 1 --lcm-url="$url" "$FACTS/probe.lcmlog" > "$FACTS/player.out" 2>&1 || true
        sleep 1
        kill -INT "$l3"; wait "$cluster_bg_job" || true
        note "lcm-logplayer on node2 to $url: lcm-logger on node3 got $(lcm_events tcpq3.lcmlog) of 100; player: $(sort -u "$FACTS/player.out" | grep -v playback | tr '\n' ' ')"
      done
      kill -TERM "$hub"; wait ;;
    *) echo "facts.sh: no experiment '$name' (see --help)" >&2; exit 2 ;;
  esac
  show
done
