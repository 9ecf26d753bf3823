#!/usr/bin/env bash
# Starts a whole run: the replay daemon, the learner, the evaluator and N actors, talking over
# LCM, with a live progress line. Stops every process when the evaluator's score reaches the goal
# (exit 0) or the time budget runs out (exit 1); Ctrl-C stops the run cleanly (exit 130).
#
# Usage: scripts/launch.sh PRESET [options]
#   PRESET                 a preset in configs/ (cartpole, ...)
#   --out DIR              run folder (default runs/<preset>-<timestamp>)
#   --actors N             actor processes on this host (default: the preset's top-level
#                          "actors = N", else 4)
#   --num-actors N         actors in the whole run, for the Ape-X epsilons (default: --actors)
#   --time-budget SECONDS  stop unsolved after this long (default 600)
#   --goal SCORE           evaluation mean that ends the run (default: the preset's)
#   --seed N               run seed (default 1)
#   --ttl 0|1              LCM multicast TTL: 0 keeps traffic on this host, 1 reaches the LAN
#   --port P               LCM port of the run (P and P+1; default: a free random pair)
#   --run-id ID            run id (default: random)
#   --actor-args "..."     extra options for every actor (also --replay-args, --learner-args,
#                          --evaluator-args)
#   --build-dir DIR        where the binaries are built (default build)
#   --no-setup             do not install or build (use the binaries as they are)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; }
die() { echo "launch: $*" >&2; exit 2; }

[ $# -ge 1 ] || { usage; exit 2; }
case "$1" in -h|--help) usage; exit 0 ;; esac
preset="$1"; shift
config="$root/configs/$preset.ini"
[ -f "$config" ] || die "no preset '$preset' (known: $(ls "$root/configs" | sed 's/\.ini$//' | tr '\n' ' '))"

out="" actors="" num_actors="" time_budget=600 goal="" seed=1 ttl=0 port="" run_id=""
actor_args="" replay_args="" learner_args="" evaluator_args=""
build_dir="$root/build" setup=1
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift ;;
    --actors) actors="$2"; shift ;;
    --num-actors) num_actors="$2"; shift ;;
    --time-budget) time_budget="$2"; shift ;;
    --goal) goal="$2"; shift ;;
    --seed) seed="$2"; shift ;;
    --ttl) ttl="$2"; shift ;;
    --port) port="$2"; shift ;;
    --run-id) run_id="$2"; shift ;;
    --actor-args) actor_args="$2"; shift ;;
    --replay-args) replay_args="$2"; shift ;;
    --learner-args) learner_args="$2"; shift ;;
    --evaluator-args) evaluator_args="$2"; shift ;;
    --build-dir) build_dir="$2"; shift ;;
    --no-setup) setup=0 ;;
    -h|--help) usage; exit 0 ;;
    *) die "unknown option '$1' (see --help)" ;;
  esac
  [ $# -gt 0 ] || die "option needs a value"
  shift
done
# The preset's top-level "actors = N" (before any section), unless given; else 4.
if [ -z "$actors" ]; then
  actors=$(awk -F= '/^\[/{exit} $1~/^ *actors *$/{gsub(/ /,"",$2); print $2}' "$config")
  actors=${actors:-4}
fi
[[ "$actors" =~ ^[0-9]+$ ]] || die "--actors must be a number"
num_actors=${num_actors:-$actors}
[[ "$ttl" == 0 || "$ttl" == 1 ]] || die "--ttl must be 0 or 1"

# The preset's goal ([evaluator] goal = ...), unless given.
if [ -z "$goal" ]; then
  goal=$(awk -F= '/^\[/{s=$0} s=="[evaluator]" && $1~/^ *goal *$/{gsub(/ /,"",$2); print $2}' "$config")
  [ -n "$goal" ] || die "the preset has no [evaluator] goal; pass --goal"
fi

if [ "$setup" -eq 1 ]; then
  "$root/scripts/setup.sh" --build-dir "$build_dir"
fi
bin="$build_dir/bin"
for b in replay learner evaluator actor monitor; do
  [ -x "$bin/$b" ] || die "$bin/$b is missing (build first, or drop --no-setup)"
done

# A free pair of UDP ports: only the port isolates two runs on one host.
port_in_use() {
  local hex
  hex=$(printf '%04X' "$1")
  cat /proc/net/udp /proc/net/udp6 2>/dev/null | awk '{print $2}' | grep -qi ":$hex\$"
}
if [ -z "$port" ]; then
  for _ in $(seq 100); do
    port=$(( 20000 + 2 * (RANDOM % 20000) ))
    port_in_use "$port" || port_in_use $((port + 1)) || break
  done
fi
[ -n "$run_id" ] || run_id=$(( $(od -An -N6 -tu8 /dev/urandom | tr -d ' ') + 1 ))
url="udpm://239.255.76.67:$port?ttl=$ttl&recv_buf_size=4194304"
bulk_url="udpm://239.255.76.67:$((port + 1))?ttl=$ttl&recv_buf_size=4194304"

out=${out:-"$root/runs/$preset-$(date +%Y%m%d-%H%M%S)"}
mkdir -p "$out/logs" "$out/checkpoints" "$out/report"
out=$(cd "$out" && pwd)
{
  echo "# Run of preset '$preset', started $(date -Iseconds)"
  echo "# run-id = $run_id"
  echo "# lcm-url = $url"
  echo "# lcm-bulk-url = $bulk_url"
  echo "# actors = $actors (of $num_actors), seed = $seed, goal = $goal, time budget = $time_budget s"
  [ -z "$actor_args$replay_args$learner_args$evaluator_args" ] ||
    echo "# extra: actor [$actor_args] replay [$replay_args] learner [$learner_args] evaluator [$evaluator_args]"
  echo
  cat "$config"
} > "$out/config.ini"

common=(--config "$out/config.ini" --run-id "$run_id" --lcm-url "$url" --lcm-bulk-url "$bulk_url")
pids=()
roles=()
: > "$out/pids"

start() {  # start ROLE LOG COMMAND...
  local role=$1 log=$2
  shift 2
  "$@" > "$log" 2>&1 &
  pids+=($!)
  roles+=("$role")
  echo "$role $!" >> "$out/pids"
}

stopping=0
stop_all() {
  [ "$stopping" -eq 0 ] || return 0
  stopping=1
  local i
  for i in "${!pids[@]}"; do kill -TERM "${pids[$i]}" 2>/dev/null || true; done
  for _ in $(seq 100); do
    local alive=0
    for i in "${!pids[@]}"; do kill -0 "${pids[$i]}" 2>/dev/null && alive=1; done
    [ "$alive" -eq 0 ] && break
    sleep 0.1
  done
  for i in "${!pids[@]}"; do
    if kill -0 "${pids[$i]}" 2>/dev/null; then
      echo "launch: ${roles[$i]} did not stop; killing it" >&2
      kill -KILL "${pids[$i]}" 2>/dev/null || true
    fi
  done
  wait 2>/dev/null || true
}
trap 'echo; echo "launch: interrupted, stopping the run"; stop_all; exit 130' INT TERM

# Waits until a process's log shows its readiness line (or the process died).
wait_ready() {  # wait_ready ROLE LOG PATTERN
  local role=$1 log=$2 pattern=$3 pid=${pids[-1]}
  for _ in $(seq 600); do
    grep -q "$pattern" "$log" 2>/dev/null && return 0
    if ! kill -0 "$pid" 2>/dev/null; then
      echo "launch: $role exited before it was ready; its log says:" >&2
      tail -5 "$log" >&2
      stop_all
      exit 2
    fi
    sleep 0.05
  done
  echo "launch: $role not ready after 30 s (log: $log)" >&2
  stop_all
  exit 2
}

echo "launch: run $run_id of '$preset' in $out (LCM port $port, ttl $ttl)"
# shellcheck disable=SC2086
start replay "$out/logs/replay.log" "$bin/replay" "${common[@]}" --seed "$seed" $replay_args
wait_ready replay "$out/logs/replay.log" "replay: ready"
# shellcheck disable=SC2086
start learner "$out/logs/learner.log" "$bin/learner" "${common[@]}" --out "$out" --seed "$seed" $learner_args
wait_ready learner "$out/logs/learner.log" "learner: ready"
# shellcheck disable=SC2086
start evaluator "$out/logs/evaluator.log" "$bin/evaluator" "${common[@]}" --out "$out" --goal "$goal" \
  --run-config "$out/config.ini" $evaluator_args
wait_ready evaluator "$out/logs/evaluator.log" "evaluator: ready"
for i in $(seq 0 $((actors - 1))); do
  # shellcheck disable=SC2086
  start "actor-$i" "$out/logs/actor-$i.log" "$bin/actor" "${common[@]}" --actor-id "$i" \
    --num-actors "$num_actors" --seed "$seed" $actor_args
  wait_ready "actor-$i" "$out/logs/actor-$i.log" "actor-$i: ready"
done
echo "launch: $actors actors, replay, learner and evaluator running; logs in $out/logs"
echo "launch: watch it with scripts/spy.sh --run $out"

# The monitor prints the progress line and decides when the run is over. It writes its own pid
# (exec keeps the subshell's) so that the pids file names every process of the run.
{
  echo "monitor $BASHPID" >> "$out/pids"
  exec "$bin/monitor" --lcm-url "$url" --lcm-bulk-url "$bulk_url" --run-id "$run_id" \
    --goal "$goal" --time-budget "$time_budget" --metrics "$out/metrics.jsonl"
} | tee "$out/logs/monitor.log" &
monitor_pid=$!
set +e
wait "$monitor_pid"
set -e
status=$(grep -q 'goal reached' "$out/logs/monitor.log" && echo 0 || echo 1)
stop_all

best=$(awk -F'"mean":' 'NF>1{split($2,a,","); if(a[1]+0>b||n==0){b=a[1]+0}; n++} END{if(n) printf (b > -10 && b < 10 ? "%.2f" : "%.1f") " over %d evaluations", b, n}' "$out/eval.jsonl" 2>/dev/null || true)
echo "launch: run folder $out"
echo "launch: report $out/report/index.html"
[ -z "$best" ] || echo "launch: best evaluation mean $best"
if [ "$status" -eq 0 ]; then
  echo "launch: goal of $goal reached"
else
  echo "launch: goal of $goal not reached"
fi
exit "$status"
