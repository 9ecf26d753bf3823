#!/usr/bin/env bash
# The Slurm test cluster works (tests/cluster/cluster.sh): it comes up with slurmctld and three
# slurmd, each in namespaces of its own on a bridge; srun runs a task on every node; an sbatch job
# runs a step on each of its nodes from its batch script and sbcasts an owner-only file to the
# nodes' own /tmp; LCM multicast (ttl=1) from one node reaches the others; LCM's TCP hub on one
# node relays between two others; the cluster goes down leaving no process and no folder behind.
source "$(dirname "$0")/lib.sh"
[ "$(id -u)" -eq 0 ] || fail "this test builds namespaces and runs Slurm's daemons: it needs root"
source "$root/tests/cluster/cluster.sh"

t0=$EPOCHREALTIME
cluster_up 3
t_up=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { print b - a }')
shared=$CLUSTER_SHARED

# srun from the login node: one task on each node.
hosts=$(cluster_exec ctl srun -N3 -n3 hostname | sort | tr '\n' ' ')
[ "$hosts" = "node1 node2 node3 " ] || fail "srun -N3 -n3 hostname ran on: $hosts"

# A batch job: its script runs on the first node and starts a step on each node; the key
# reaches each node's own /tmp by sbcast, owner-only.
cat > "$shared/job.sh" << EOF
#!/bin/bash
echo "batch on \$(hostname), nodes \$SLURM_JOB_NODELIST, cpus \$SLURM_JOB_CPUS_PER_NODE"
umask 077
head -c 32 /dev/urandom > /tmp/run.key
sbcast --force /tmp/run.key /tmp/node.key
for node in node1 node2 node3; do
  srun --overlap --nodes=1 --ntasks=1 --nodelist=\$node \
    bash -c 'echo "step \$SLURM_STEP_ID on \$(hostname): key \$(stat -c %a /tmp/node.key) \$(sha256sum < /tmp/node.key | cut -c1-16)"' &
done
wait
echo "key \$(sha256sum < /tmp/run.key | cut -c1-16)"
EOF
job=$(cluster_sbatch 60 --nodes=3 --exclusive --output="$shared/job.out" "$shared/job.sh") ||
  { cat "$shared/job.out" >&2 || true; fail "the batch job did not complete"; }
cat "$shared/job.out"
grep -q "^batch on node1, nodes node\[1-3\], cpus 8(x3)$" "$shared/job.out" ||
  fail "job $job: the batch script did not run on node1 with 8 CPUs on each of node[1-3]"
key=$(sed -n 's/^key //p' "$shared/job.out")
for node in node1 node2 node3; do
  grep -Eq "^step [0-9]+ on $node: key 600 $key$" "$shared/job.out" ||
    fail "job $job: no step on $node that read the key, owner-only"
  [ -e "$CLUSTER_DIR/nodes/$node/tmp/node.key" ] || fail "the key is not in $node's own /tmp"
done
[ ! -e /tmp/node.key ] || fail "sbcast wrote to the machine's /tmp, not the nodes' own"

# LCM: events of an LCM log file, by channel.
# COUNT events of 1 KB on CHANNEL, 10 ms apart, then 10 events on END 20 ms apart: lcm-logplayer
# relays a log through a queue of its own and exits at the log's end without publishing the
# last few events it read.
lcm_log() {  # lcm_log FILE CHANNEL COUNT
  perl -e 'my ($file, $ch, $n) = @ARGV; open(my $f, ">", $file) or die; binmode $f; my $t = 0;
    for my $i (1 .. $n + 10) { my ($c, $d) = $i <= $n ? ($ch, "$ch $i " . ("x" x 1000)) : ("END", "end");
      $t += $i <= $n ? 10000 : 20000;
      print $f pack("N Q> Q> N N", 0xEDA1DA01, $i, $t, length($c), length($d)), $c, $d; }' "$@"
}
# The numbers (1..100) of the probe messages FILE lacks.
lcm_missing() {  # lcm_missing FILE
  perl -e 'my %seen; if (open(my $f, "<", shift)) { binmode $f; local $/; my $b = <$f>;
    while (length($b) >= 28) { my (undef, undef, undef, $c, $d) = unpack("N Q> Q> N N", $b);
      last if length($b) < 28 + $c + $d; $seen{(split / /, substr($b, 28 + $c, $d))[1]} = 1 if substr($b, 28, $c) eq "PROBE";
      $b = substr($b, 28 + $c + $d); } }
    print join(" ", grep { !$seen{$_} } 1 .. 100), "\n"' "$1"
}
lcm_count() {  # lcm_count FILE CHANNEL: how many events FILE has on CHANNEL
  perl -e 'my ($file, $ch) = @ARGV; my $n = 0; if (open(my $f, "<", $file)) { binmode $f; local $/; my $b = <$f>;
    while (length($b) >= 28) { my (undef, undef, undef, $c, $d) = unpack("N Q> Q> N N", $b);
      last if length($b) < 28 + $c + $d; $n++ if substr($b, 28, $c) eq $ch; $b = substr($b, 28 + $c + $d); } }
    print "$n\n"' "$@"
}
lcm_log "$shared/hello.lcmlog" HELLO 1
lcm_log "$shared/probe.lcmlog" PROBE 100
# Whether LOG has an event on CHANNEL, after NODE played FILE on URL once more.
lcm_heard() {  # lcm_heard NODE URL FILE LOG CHANNEL
  cluster_exec "$1" lcm-logplayer -s 100 --lcm-url="$2" "$3" > /dev/null 2>&1 || true
  [ "$(lcm_count "$4" "$5")" -gt 0 ]
}
# Whether LOG has the 100 probe messages.
lcm_all() { [ "$(lcm_count "$1" PROBE)" -eq 100 ]; }
# Plays the probe log once from NODE on URL once each logger writing a LOG has heard a hello (so
# it is subscribed), then waits until each has the 100 probe messages.
lcm_relay() {  # lcm_relay NODE URL LOG...
  local node=$1 url=$2 log
  shift 2
  for log in "$@"; do
    cluster_until 30 "a hello from $node in $log on $url" lcm_heard "$node" "$url" "$shared/hello.lcmlog" "$log" HELLO ||
      fail "no LCM message from $node reached $log on $url"
  done
  # 100 messages/s: lcm-logger keeps LCM's default queue of 30 messages per subscription.
  cluster_exec "$node" lcm-logplayer --lcm-url="$url" "$shared/probe.lcmlog" > /dev/null
  for log in "$@"; do
    cluster_until 10 "the probe messages in $log" lcm_all "$log" ||
      fail "$log got $(lcm_count "$log" PROBE) of the 100 messages $node sent on $url (it lacks $(lcm_missing "$log"))"
  done
}

# Multicast with ttl=1 from node2 to node1 and node3.
url="udpm://239.255.76.67:7667?ttl=1&recv_buf_size=4194304"
cluster_bg node1 lcm-logger -q -f --lcm-url="$url" "$shared/udpm1.lcmlog"; logger1=$cluster_bg_pid
cluster_bg node3 lcm-logger -q -f --lcm-url="$url" "$shared/udpm3.lcmlog"; logger3=$cluster_bg_pid
lcm_relay node2 "$url" "$shared/udpm1.lcmlog" "$shared/udpm3.lcmlog"
kill -INT "$logger1" "$logger3"
echo "multicast from node2: node1 got $(lcm_count "$shared/udpm1.lcmlog" PROBE), node3 $(lcm_count "$shared/udpm3.lcmlog" PROBE) of 100"

# LCM's TCP hub on node1 relays from node2 to node3 (numeric address: liblcm 1.3.1 resolves
# hostnames in tcpq URLs to 0.0.0.0).
cluster_bg node1 java -cp /usr/share/java/lcm.jar lcm.lcm.TCPService 7700 > "$shared/hub.log" 2>&1
hub_addr=$(cluster_addr node1)
cluster_until 30 "the TCP hub on node1" cluster_exec node2 bash -c "exec 3<> /dev/tcp/$hub_addr/7700" ||
  fail "the TCP hub on node1 did not accept connections"
url=tcpq://$hub_addr:7700
cluster_bg node3 lcm-logger -q -f --lcm-url="$url" "$shared/tcpq3.lcmlog"
lcm_relay node2 "$url" "$shared/tcpq3.lcmlog"
echo "through the TCP hub on node1: node3 got $(lcm_count "$shared/tcpq3.lcmlog" PROBE) of 100 from node2"

# Down: nothing of the cluster may be left.
procs=$(cluster_procs | tr '\n' ' ')
dir=$CLUSTER_DIR
t0=$EPOCHREALTIME
cluster_down
t_down=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { print b - a }')
for pid in $procs; do
  ! cluster_alive "$pid" || fail "process $pid of the cluster outlived it: $(tr '\0' ' ' < "/proc/$pid/cmdline")"
done
[ -n "${CLUSTER_KEEP:-}" ] || [ ! -e "$dir" ] || fail "the cluster's folder $dir is still there"
printf 'PASS: a 3-node Slurm cluster ran steps, sbcast, multicast and the TCP hub (%d processes); up in %.1f s, down in %.1f s\n' \
  "$(echo "$procs" | wc -w)" "$t_up" "$t_down"
