#!/usr/bin/env bash
# The transport benchmark: how many transitions per second one replay daemon stores, and how
# many messages are lost, when actors publish as fast as its flow control allows, over LCM
# multicast (udpm) and over LCM's TCP hub (tcpq://, lcm.lcm.TCPService), flat (CartPole-size,
# batches of 32) and pixel (84x84x4, frames sent once, batches of 32: about 230 KB) transitions,
# without and with the run's key (AES-256-GMAC on every message). Real processes over real LCM:
# build/bin/replay, the hubs, and bench_transport publishers (bench/bench_transport.cc). The
# replay runs without a samples-per-insert ratio, so its flow control holds nobody back; each
# publisher then publishes
#   raw      back to back: the raw limit, and what it loses (udpm only: on tcp a publisher that
#            does not bound what it has on the way stalls the hub, see the loop at the end)
#   window   with at most a fixed number of transitions published and not yet stored (512 flat
#            or 16 pixel batches' worth, see window_for), as a ratio's credit share bounds an
#            actor's: what the replay takes in with nothing lost
#
# Placements:
#   local P   the replay and P publishers on this host (in a network namespace of their own on
#             lo when run as root)
#   nodes K   the test cluster's network namespaces (tests/cluster/cluster.sh; root only): the
#             replay (and the hubs) on node1, one publisher on each of K other nodes, over the
#             cluster's bridge
#
# Prints one JSON line per (kind, transport, key, flow, placement): "bench"
# transport_ingest_KIND, "value" the median over repeats of the transitions/s the replay stored
# (from the first publication to the last transition stored), min/median/max; the share of
# transitions lost and the messages lost (the replay's sequence gaps), median and max; and the
# replay's (and the hub's) CPU time per stored transition, less what they use idle, with its
# inverse: what one core of this machine takes in whatever else runs on it.
#
# Usage: bench/transport.sh [--build-dir DIR] [--repeats N] [--seconds S] [--kinds "flat pixel"]
#          [--transports "udpm tcp"] [--keys "none gmac"] [--flows "raw window"]
#          [--local "1 4"] [--nodes "1 3"]
#   --local ""/--nodes "" leave a placement out; --nodes needs root and the test cluster's
#   packages (scripts/setup.sh installs slurm-wlm and munge). Defaults: 3 repeats of 2 s; with
#   --local 1 it took 27 minutes on a loaded 2-core machine, the defaults take longer.
# Every process of one measurement shares this machine's cores: on a machine shared with other
# work the transitions/s are noisy (the CPU per transition much less), and "nodes" measures the
# link and the processes, not more cores.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=$root/build repeats=3 seconds=2 kinds="flat pixel" transports="udpm tcp"
keys="none gmac" flows="raw window" local_counts="1 4" node_counts="1 3" inner=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir=$2; shift ;;
    --repeats) repeats=$2; shift ;;
    --seconds) seconds=$2; shift ;;
    --kinds) kinds=$2; shift ;;
    --transports) transports=$2; shift ;;
    --keys) keys=$2; shift ;;
    --flows) flows=$2; shift ;;
    --local) local_counts=$2; shift ;;
    --nodes) node_counts=$2; shift ;;
    --inner) inner=1 ;;  # (this script inside its own network namespace)
    -h | --help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "transport.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
bin=$build_dir/bin
for p in replay bench_transport; do
  [ -x "$bin/$p" ] || { echo "transport.sh: $bin/$p is missing (build it first)" >&2; exit 2; }
done
if [[ " $transports " == *" tcp "* ]] && ! [ -f /usr/share/java/lcm.jar ]; then
  echo "transport.sh: no /usr/share/java/lcm.jar (Debian's liblcm-java): tcp left out" >&2
  transports=${transports//tcp/}
fi
args=(--build-dir "$build_dir" --repeats "$repeats" --seconds "$seconds" --kinds "$kinds"
  --transports "$transports" --keys "$keys" --flows "$flows")

# The local placements in a network namespace of their own (multicast on lo only), then the
# cluster's: each part in the main shell of its own process, since a cluster is tied to its shell.
if [ "$inner" -eq 0 ]; then
  if [ -n "${local_counts// /}" ]; then
    if [ "$(id -u)" -eq 0 ] && command -v unshare > /dev/null; then
      unshare -n bash -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' _ \
        bash "$0" "${args[@]}" --local "$local_counts" --nodes "" --inner
    else
      bash "$0" "${args[@]}" --local "$local_counts" --nodes "" --inner
    fi
  fi
  if [ -n "${node_counts// /}" ]; then
    if [ "$(id -u)" -ne 0 ]; then
      echo "transport.sh: the node placements need root (network namespaces): left out" >&2
    else
      bash "$0" "${args[@]}" --local "" --nodes "$node_counts" --inner
    fi
  fi
  exit 0
fi

work=$(mktemp -d)
pids=() bg_jobs=()
cleanup() {
  local p
  for p in "${pids[@]}"; do kill -TERM "$p" 2> /dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
on_cluster=0
if [ -n "${node_counts// /}" ]; then
  max=0
  for k in $node_counts; do [ "$k" -le "$max" ] || max=$k; done
  source "$root/tests/cluster/cluster.sh"
  cluster_up $((max + 1)) > /dev/null
  trap 'cleanup; cluster_down 2> /dev/null' EXIT
  on_cluster=1
  rm -rf "$work"
  work=$(mktemp -d "$CLUSTER_SHARED/transport-XXXXXX")  # seen by every node
fi
head -c 32 /dev/urandom > "$work/key"
chmod 600 "$work/key"

# Runs CMD... on HOST (local, or a cluster node) in the background, its output into FILE; sets
# bg_pid (for signals) and bg_job (for wait).
start_on() {  # start_on HOST FILE CMD...
  local host=$1 file=$2
  shift 2
  if [ "$host" = local ]; then
    "$@" > "$file" 2>&1 &
    bg_pid=$! bg_job=$!
  else
    cluster_bg "$host" "$@" > "$file" 2>&1
    bg_pid=$cluster_bg_pid bg_job=$cluster_bg_job
  fi
  pids+=("$bg_pid")
  bg_jobs+=("$bg_job")
}

# Waits (bounded) until FILE has a line matching REGEX.
wait_line() {  # wait_line SECONDS FILE REGEX WHAT
  local end=$((SECONDS + $1))
  until grep -q "$3" "$2" 2> /dev/null; do
    [ "$SECONDS" -lt "$end" ] || { echo "transport.sh: $4 not within $1 s:" >&2; tail -5 "$2" >&2; exit 1; }
    sleep 0.05
  done
}

# CPU time (user and system, clock ticks) a process has used; 0 for none. (Builtins only: the
# trace below calls it ten times a second.)
cpu_ticks() {  # cpu_ticks [PID]
  local stat f
  if [ -z "${1:-}" ] || ! read -r stat 2> /dev/null < "/proc/$1/stat"; then echo 0; return; fi
  read -r -a f <<< "${stat##*) }"  # the fields after the command's name, from the state (3) on
  echo $((f[11] + f[12]))
}
# Appends "TIME REPLAY_TICKS HUB_TICKS" to FILE every 0.1 s while the replay runs.
cpu_trace() {  # cpu_trace FILE
  while kill -0 "$replay_pid" 2> /dev/null; do
    echo "$EPOCHREALTIME $(cpu_ticks "$replay_pid") $(cpu_ticks "$hub_pid")"
    sleep 0.1
  done >> "$1"
}
tick_us=$((1000000 / $(getconf CLK_TCK)))
# "REPLAY_TICKS HUB_TICKS SECONDS" since the counts and time given (replay_pid, hub_pid).
cpu_line() {  # cpu_line REPLAY_TICKS0 HUB_TICKS0 EPOCHREALTIME0
  echo "$(($(cpu_ticks "$replay_pid") - $1)) $(($(cpu_ticks "$hub_pid") - $2))" \
    "$(awk -v a="$3" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.3f", b - a }')"
}

port=17700
# One configuration: the replay (and the hubs) on SERVER, publishers on HOSTS; prints its JSON line.
measure() {  # measure PLACEMENT SERVER TRANSPORT KIND KEY WINDOW HOSTS...
  local placement=$1 server=$2 transport=$3 kind=$4 key=$5 window=$6 addr url bulk r i
  shift 6
  local hosts=("$@") n=$#
  port=$((port + 2))
  if [ "$server" = local ]; then addr=127.0.0.1; else addr=$(cluster_addr "$server"); fi
  local ttl=1
  [ "$server" != local ] || ttl=0
  local dir="$work/$placement-$transport-$kind-$key-$window"
  mkdir -p "$dir"
  local started=("${pids[@]}") started_jobs=("${bg_jobs[@]}")
  hub_pid=""
  if [ "$transport" = tcp ]; then
    for p in $((port + 1)) "$port"; do
      start_on "$server" "$dir/hub-$p.log" java -cp /usr/share/java/lcm.jar lcm.lcm.TCPService "$p"
    done
    hub_pid=$bg_pid  # the main port's, which carries the transitions
    url=tcpq://$addr:$port bulk=tcpq://$addr:$((port + 1))
    for p in "$port" $((port + 1)); do
      local end=$((SECONDS + 30))
      until (if [ "$server" = local ]; then exec 3<> "/dev/tcp/$addr/$p"; else
        cluster_exec "$server" bash -c "exec 3<> /dev/tcp/$addr/$p"; fi) 2> /dev/null; do
        [ "$SECONDS" -lt "$end" ] || { echo "transport.sh: the hub on port $p did not start" >&2; exit 1; }
        sleep 0.2
      done
    done
  else
    url="udpm://239.255.76.67:$port?ttl=$ttl&recv_buf_size=4194304"
    bulk="udpm://239.255.76.67:$((port + 1))?ttl=$ttl&recv_buf_size=4194304"
  fi
  local common=(--run-id 7 --lcm-url "$url" --lcm-bulk-url "$bulk")
  [ "$key" = none ] || common+=(--key-file "$work/key")
  local capacity=1000000 first=0
  # Pixel tables take their frame ring's pages (174 MB) as they first fill it: a first repeat,
  # not counted, fills it.
  [ "$kind" = flat ] || capacity=20000 first=-1
  start_on "$server" "$dir/replay.log" "$bin/replay" "${common[@]}" --capacity "$capacity" \
    --samples-per-insert 0 --flow-hz 500 --stats-hz 20 --max-actors 1024
  local replay_pid=$bg_pid
  wait_line 60 "$dir/replay.log" "replay: ready" "the replay's start"
  local jobs
  local cpu0 hub0 t0
  : > "$dir/cpu"
  cpu_trace "$dir/cpu-trace" &
  local trace_job=$!
  for ((r = first; r < repeats; r++)); do
    cpu0=$(cpu_ticks "$replay_pid") hub0=$(cpu_ticks "$hub_pid") t0=$EPOCHREALTIME
    local at
    at=$(awk -v t="$EPOCHREALTIME" 'BEGIN { printf "%.3f", t + 3 }')
    jobs=()
    for ((i = 0; i < n; i++)); do
      start_on "${hosts[i]}" "$dir/pub-$r-$i.json" timeout $((${seconds%.*} + 90)) \
        "$bin/bench_transport" "${common[@]}" --kind "$kind" --actor-id $(((r + 1) * n + i)) \
        --actors "$n" --seconds "$seconds" --start-at "$at" --settle 3 --window "$window"
      jobs+=("$bg_job")
    done
    for i in "${!jobs[@]}"; do
      wait "${jobs[i]}" || { echo "transport.sh: publisher $i failed:" >&2; cat "$dir/pub-$r-$i.json" >&2; exit 1; }
    done
    [ "$r" -lt 0 ] || cpu_line "$cpu0" "$hub0" "$t0" >> "$dir/cpu"
  done
  # The CPU the replay and the hub use idle (flow and stats messages, timeouts), per second, once
  # the measurements are over (a replay's start and its first inserts cost more): the last line
  # of cpu, taken out of each measurement's.
  cpu0=$(cpu_ticks "$replay_pid") hub0=$(cpu_ticks "$hub_pid") t0=$EPOCHREALTIME
  sleep 2
  cpu_line "$cpu0" "$hub0" "$t0" >> "$dir/cpu"
  kill -TERM "$replay_pid"
  wait "$trace_job" || true
  for p in "${pids[@]}"; do
    [[ " ${started[*]} " == *" $p "* ]] || kill -TERM "$p" 2> /dev/null || true
  done
  for p in "${bg_jobs[@]}"; do
    [[ " ${started_jobs[*]} " == *" $p "* ]] || wait "$p" 2> /dev/null || true
  done
  pids=("${started[@]}") bg_jobs=("${started_jobs[@]}")
  python3 - "$dir" "$repeats" "$placement" "$transport" "$kind" "$key" "$n" "$tick_us" "$window" << 'PY'
import glob, json, statistics, sys
d, repeats, placement, transport, kind, key, n, tick_us, window = sys.argv[1:]
# The CPU microseconds the replay and the hub use idle per second (the last line of cpu), and
# their CPU microseconds from a repeat's first publication to its last transition stored (the
# trace, interpolated), less that.
lines = [[float(x) for x in l.split()] for l in open(f"{d}/cpu")]
idle = [t * int(tick_us) / lines[-1][2] for t in lines[-1][:2]]
trace = [[float(x) for x in l.split()] for l in open(f"{d}/cpu-trace") if len(l.split()) == 3]
def cpu_at(t, i):
    """Process i's (0 replay, 1 hub) CPU microseconds at wall time t."""
    for a, b in zip(trace, trace[1:]):
        if a[0] <= t <= b[0]:
            return int(tick_us) * (a[1 + i] + (b[1 + i] - a[1 + i]) * (t - a[0]) / max(b[0] - a[0], 1e-9))
    return int(tick_us) * (trace[0][1 + i] if t < trace[0][0] else trace[-1][1 + i])
def cpu_between(t0, t1):
    return [max(0.0, cpu_at(t1, i) - cpu_at(t0, i) - idle[i] * (t1 - t0)) for i in (0, 1)]
def summary(v):
    v = sorted(v)
    return v[0], statistics.median(v), v[-1]
rates, lost_pct, lost_msgs, mb, paused, replay_us, hub_us = [], [], [], [], [], [], []
for r in range(int(repeats)):
    pubs = [json.loads(l) for f in sorted(glob.glob(f"{d}/pub-{r}-*.json"))
            for l in open(f) if l.startswith("{")]
    published = sum(p["published"] for p in pubs)
    stored = sum(p["stored"] for p in pubs)
    # (A publisher that saw nothing stored reports the time of no growth: 0.)
    span = max(1e-3, max(p["last_stored"] for p in pubs) - min(p["start"] for p in pubs))
    rates.append(stored / span)
    mb.append(sum(p["bytes"] * p["stored"] / max(p["published"], 1) for p in pubs) / span / 1e6)
    lost_pct.append(100.0 * (published - stored) / published)
    # Every publisher reads the replay's one count: the largest growth seen covers them all.
    lost_msgs.append(max(p["replay_lost"] for p in pubs))
    paused.append(max(p["paused_s"] for p in pubs))
    # CPU time per transition stored: what one core of this machine can take in, whatever the
    # load beside it (its inverse).
    used = cpu_between(min(p["start"] for p in pubs), max(p["last_stored"] for p in pubs))
    replay_us.append(used[0] / max(stored, 1))
    hub_us.append(used[1] / max(stored, 1))
lo, med, hi = summary(rates)
print(json.dumps({
    "bench": f"transport_ingest_{kind}", "value": round(med), "unit": "transitions/s",
    "min": round(lo), "median": round(med), "max": round(hi), "repeats": int(repeats),
    "transport": transport, "mac": "none" if key == "none" else "AES-256-GMAC",
    "placement": placement, "publishers": int(n),
    "flow": "window" if int(window) else "raw", "window_per_publisher": int(window), "mb_per_s_median": round(summary(mb)[1], 1),
    "lost_percent_median": round(summary(lost_pct)[1], 3), "lost_percent_max": round(max(lost_pct), 3),
    "messages_lost_median": summary(lost_msgs)[1], "messages_lost_max": max(lost_msgs),
    "flow_paused_s_max": round(max(paused), 3),
    "replay_cpu_us_per_transition": round(summary(replay_us)[1], 3),
    "replay_core_transitions_per_s": round(1e6 / summary(replay_us)[1]) if summary(replay_us)[1] else None,
    **({"hub_cpu_us_per_transition": round(summary(hub_us)[1], 3)} if transport == "tcp" else {}),
    "note": "every process on this machine's cores"}))
PY
}

# Transitions on the way per publisher in the "window" runs: 512 flat batches (1 MB), 16 pixel
# ones (3.7 MB), within the replay's 8 MiB receive buffer; with the replay's 500 flow messages
# a second, they let one publisher reach 8 M and 256 k transitions/s.
window_for() { if [ "$1" = flat ]; then echo 16384; else echo 512; fi; }
for kind in $kinds; do
  for transport in $transports; do
    for key in $keys; do
      for flow in $flows; do
        window=0
        [ "$flow" = raw ] || window=$(window_for "$kind")
        # tcpq's publish blocks while the hub's socket is full, and the hub relays each message
        # to its subscribers in the thread that read it: a publisher that does not bound what it
        # has on the way stalls the hub and, through it, the replay's own flow messages.
        if [ "$flow" = raw ] && [ "$transport" = tcp ]; then continue; fi
        for p in $local_counts; do
          hosts=()
          for ((i = 0; i < p; i++)); do hosts+=(local); done
          echo "transport.sh: local, $p publisher(s), $transport, $kind, key $key, $flow" >&2
          measure "local-$p" local "$transport" "$kind" "$key" "$window" "${hosts[@]}"
        done
        if [ "$on_cluster" -eq 1 ]; then
          for k in $node_counts; do
            hosts=()
            for ((i = 2; i <= k + 1; i++)); do hosts+=("node$i"); done
            echo "transport.sh: $k node(s), $transport, $kind, key $key, $flow" >&2
            measure "nodes-$k" node1 "$transport" "$kind" "$key" "$window" "${hosts[@]}"
          done
        fi
      done
    done
  done
done
