#!/usr/bin/env bash
# Starts a whole run: the replay daemon, the learner, the evaluator and N actors, talking over
# LCM, with a live progress line. Stops every process when the evaluator's score reaches the goal
# (exit 0) or the time budget runs out (exit 1); Ctrl-C stops the run cleanly (exit 130).
#
# Every process runs under a supervisor: one that exits while the run goes on (a crash, a kill)
# is started again after 1, 2, 4, ... 30 s, at most --max-restarts times (one that fails with an
# error status within 3 s of its start is not: that is a startup error, and the run stops with
# its log; one killed by a signal always is). The learner always starts with --resume, so a
# restarted learner continues from the state it saved with its last checkpoint; the replay always
# starts with --snapshot RUN/replay-snapshot.bin, which it writes every 60 s (--snapshot-every)
# and when it stops, so a restarted replay continues from its last snapshot. Restarts are lines
# of RUN/restarts, in the process's log and on the progress line.
#
# Usage: scripts/launch.sh PRESET [options]
#        scripts/launch.sh --resume RUN_DIR [options]
#        scripts/launch.sh --stop RUN_DIR
#   PRESET                 a preset in configs/ (cartpole, ...)
#   --resume RUN_DIR       continue a stopped or crashed run in its folder: its copy of the
#                          preset, run id and seed; the learner from its saved state, the
#                          replay from its snapshot, the evaluator's history and the metrics
#                          kept (options as below, except --out, --seed and --run-id)
#   --stop RUN_DIR         stop the run going in RUN_DIR as Ctrl-C would (for a run started in
#                          the background or in another terminal); waits until it has stopped
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
#   --record               record the run's main-port LCM traffic (stats, transitions,
#                          evaluations, ...) with lcm-logger into RUN/lcm-log/: main.lcmlog.0 is
#                          the newest file, older ones main.lcmlog.1 ... main.lcmlog.7
#   --record-mb MB         size cap of the recording, in 8 files (default 256): past it the
#                          oldest file goes
#   --max-restarts N       restarts of each process before it is left down (default 5)
#   --build-dir DIR        where the binaries are built (default build)
#   --no-setup             do not install or build (use the binaries as they are)
set -euo pipefail
# The whole script is one block, so that bash reads all of it before running any: a run of hours
# is not broken by an edit of this file while it goes.
{
root=$(cd "$(dirname "$0")/.." && pwd)

usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; }
die() { echo "launch: $*" >&2; exit 2; }

[ $# -ge 1 ] || { usage; exit 2; }
case "$1" in -h|--help) usage; exit 0 ;; esac

# A run's launch script: "PID START" in RUN/launch.pid, START being the process's start time
# (field 22 of /proc/PID/stat), so that a pid since reused by another process is not taken for it.
# Nothing for a process that has ended (gone, or a zombie).
launch_start() { awk '$3 != "Z" { print $22 }' "/proc/$1/stat" 2>/dev/null || true; }
if [ "$1" = "--stop" ]; then
  [ $# -eq 2 ] || die "--stop takes a run folder and nothing else"
  dir=$(cd "$2" 2>/dev/null && pwd) || die "no run folder '$2'"
  [ -f "$dir/config.ini" ] || die "$dir has no config.ini: not a run folder"
  read -r pid start 2>/dev/null < "$dir/launch.pid" || true
  if [[ ! "${pid:-}" =~ ^[0-9]+$ ]] || [ "$(launch_start "$pid")" != "${start:-}" ]; then
    echo "launch: the run in $dir is not going"
    exit 1
  fi
  echo "launch: stopping the run in $dir (launch.sh, pid $pid)"
  kill -TERM "$pid" 2>/dev/null || true
  # Its processes get 10 s to stop before they are killed, and its recorder a few more.
  for _ in $(seq 600); do
    [ "$(launch_start "$pid")" = "$start" ] || { echo "launch: stopped"; exit 0; }
    sleep 0.1
  done
  die "the run in $dir has not stopped after 60 s (pid $pid)"
fi
out="" actors="" num_actors="" time_budget=600 goal="" seed=1 ttl=0 port="" run_id=""
resume=""
if [ "$1" = "--resume" ]; then
  [ $# -ge 2 ] || die "--resume needs a run folder"
  resume=$(cd "$2" 2>/dev/null && pwd) || die "no run folder '$2'"
  shift 2
  [ -f "$resume/config.ini" ] || die "$resume has no config.ini: not a run folder"
  # The run's own copy of the preset (its first lines: preset name, run id, seed).
  preset=$(sed -n "s/^# Run of preset '\(.*\)', started.*/\1/p" "$resume/config.ini" | head -1)
  run_id=$(sed -n 's/^# run-id = //p' "$resume/config.ini" | head -1)
  seed=$(sed -n 's/^# actors = .*seed = \([0-9]*\),.*/\1/p' "$resume/config.ini" | head -1)
  [ -n "$preset" ] && [ -n "$run_id" ] && [ -n "$seed" ] ||
    die "$resume/config.ini lacks the launch script's header (preset, run id, seed)"
  # Its actor counts too, unless given.
  actors=$(sed -n 's/^# actors = \([0-9]*\) (of \([0-9]*\)).*/\1/p' "$resume/config.ini" | head -1)
  num_actors=$(sed -n 's/^# actors = \([0-9]*\) (of \([0-9]*\)).*/\2/p' "$resume/config.ini" | head -1)
  config="$resume/config.ini"
  out="$resume"
else
  preset="$1"; shift
  config="$root/configs/$preset.ini"
  [ -f "$config" ] || die "no preset '$preset' (known: $(ls "$root/configs" | sed 's/\.ini$//' | tr '\n' ' '))"
fi
max_restarts=5
actor_args="" replay_args="" learner_args="" evaluator_args=""
build_dir="$root/build" setup=1 record=0 record_mb=256
while [ $# -gt 0 ]; do
  case "$1" in
    --out) [ -z "$resume" ] || die "--out cannot change a resumed run's folder"; out="$2"; shift ;;
    --actors) actors="$2"; shift ;;
    --num-actors) num_actors="$2"; shift ;;
    --time-budget) time_budget="$2"; shift ;;
    --goal) goal="$2"; shift ;;
    --seed) [ -z "$resume" ] || die "--seed cannot change a resumed run's seed"; seed="$2"; shift ;;
    --ttl) ttl="$2"; shift ;;
    --port) port="$2"; shift ;;
    --run-id) [ -z "$resume" ] || die "--run-id cannot change a resumed run's id"; run_id="$2"; shift ;;
    --max-restarts) max_restarts="$2"; shift ;;
    --actor-args) actor_args="$2"; shift ;;
    --replay-args) replay_args="$2"; shift ;;
    --learner-args) learner_args="$2"; shift ;;
    --evaluator-args) evaluator_args="$2"; shift ;;
    --build-dir) build_dir="$2"; shift ;;
    --no-setup) setup=0 ;;
    --record) record=1 ;;
    --record-mb) record_mb="$2"; shift ;;
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
[[ "$max_restarts" =~ ^[0-9]+$ ]] || die "--max-restarts must be a whole number"
[[ "$record_mb" =~ ^[0-9]+$ && "$record_mb" -ge 8 ]] || die "--record-mb must be a whole number of at least 8"

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
if [ "$record" -eq 1 ]; then
  command -v lcm-logger >/dev/null || die "--record needs lcm-logger (Debian's liblcm-bin: scripts/setup.sh)"
fi

# A free pair of UDP ports: only the port isolates two runs on one host.
port_in_use() {
  local hex
  hex=$(printf '%04X' "$1")
  cat /proc/net/udp /proc/net/udp6 2>/dev/null | awk '{print $2}' | grep -qi ":$hex\$"
}
if [ -n "$resume" ] && [ -z "$port" ]; then
  # The resumed run keeps its port, so that its config.ini and scripts/spy.sh stay right.
  port=$(sed -n 's/^# lcm-url = udpm:\/\/[0-9.]*:\([0-9]*\).*/\1/p' "$config" | head -1)
  if port_in_use "${port:-0}" || port_in_use $((${port:-0} + 1)); then
    die "the run's LCM port $port is in use: is the run still going? (or pass --port)"
  fi
fi
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
if [ -n "$resume" ]; then
  echo "# resumed $(date -Iseconds): actors = $actors, time budget = $time_budget s" >> "$out/config.ini"
else {
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
fi

# The run's secret key: every message carries a MAC made with it (common/message_auth.h). Only
# the owner may read it; processes on other hosts get a copy of the file (README: "Actors on
# other hosts"), never the key on a command line. A resumed run keeps its key.
if [ ! -s "$out/key" ]; then
  (umask 077 && head -c 32 /dev/urandom > "$out/key.tmp" && mv "$out/key.tmp" "$out/key") ||
    die "cannot write the run's key file $out/key"
fi
common=(--config "$out/config.ini" --run-id "$run_id" --key-file "$out/key" --lcm-url "$url"
  --lcm-bulk-url "$bulk_url")
pids=()
roles=()
: > "$out/pids"
echo "$$ $(launch_start $$)" > "$out/launch.pid"

[ -n "$resume" ] || : > "$out/restarts"
touch "$out/restarts"

# Runs COMMAND under a supervisor (see the top of this file) in the background. The pids file
# gets a line "ROLE PID" for the process each time it starts (the last one is current).
start() {  # start ROLE LOG COMMAND...
  local role=$1 log=$2
  shift 2
  [ -n "$resume" ] || : > "$log"
  supervise "$role" "$log" "$@" &
  pids+=($!)
  roles+=("$role")
}

supervise() {  # supervise ROLE LOG COMMAND... (in a background subshell)
  local role=$1 log=$2 child=0 stop=0 restarts=0 delay=1 code started
  shift 2
  # Stopping (the run's end, or Ctrl-C to the process group) ends the process, not the
  # supervisor, which waits for it: nothing is left unreaped.
  trap 'stop=1; [ "$child" -eq 0 ] || kill -TERM "$child" 2>/dev/null || true' TERM INT
  while :; do
    started=$SECONDS
    "$@" >> "$log" 2>&1 &
    child=$!
    echo "$role $child" >> "$out/pids"
    code=0
    wait "$child" || code=$?
    # A signal to the supervisor ends `wait` early: wait for the process itself to end.
    while kill -0 "$child" 2>/dev/null; do code=0; wait "$child" || code=$?; done
    [ "$stop" -eq 0 ] && [ "$code" -ne 0 ] || exit 0
    if [ "$code" -le 128 ] && [ $((SECONDS - started)) -lt 3 ]; then
      echo "launch: $role failed within 3 s of its start (status $code); not restarting it" >> "$log"
      exit "$code"
    fi
    if [ "$restarts" -ge "$max_restarts" ]; then
      echo "launch: $role exited with status $code; its $max_restarts restarts are spent" | tee -a "$log" >&2
      exit "$code"
    fi
    restarts=$((restarts + 1))
    echo "$(date -Iseconds) $role status $code restart $restarts" >> "$out/restarts"
    echo "launch: $role exited with status $code; restarting it in $delay s ($restarts of $max_restarts)" |
      tee -a "$log" >&2
    sleep "$delay" & wait $! || true
    [ "$stop" -eq 0 ] || exit 0
    delay=$((delay * 2 > 30 ? 30 : delay * 2))
  done
}

# Stops the --record logger once every other process has stopped: with nothing published any
# more, it has caught up when its files stop growing (it flushes every 100 ms; bounded at 3 s).
# SIGTERM makes it close its file; what it has read but not yet written would be lost.
recorder_sup=""
stop_recorder() {
  [ -n "$recorder_sup" ] || return 0
  local size last=-1 same=0
  for _ in $(seq 30); do
    size=$(stat -c %s "$out"/lcm-log/main.lcmlog.* 2>/dev/null | awk '{s += $1} END {print s + 0}')
    if [ "$size" -eq "$last" ]; then
      same=$((same + 1))
      [ "$same" -lt 2 ] || break
    else
      same=0
    fi
    last=$size
    sleep 0.1
  done
  kill -TERM "$recorder_sup" 2>/dev/null || true
  for _ in $(seq 50); do
    kill -0 "$recorder_sup" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$recorder_sup" 2>/dev/null; then
    echo "launch: recorder did not stop; killing it" >&2
    kill -KILL "$recorder_sup" 2>/dev/null || true
  fi
  recorder_sup=""
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
  stop_recorder
  # The processes themselves, should a supervisor have been killed before its process ended.
  local pid
  for pid in $(awk '{print $2}' "$out/pids" 2>/dev/null); do kill -KILL "$pid" 2>/dev/null || true; done
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
if [ "$record" -eq 1 ]; then
  # Rotating files of record_mb/8 MB each: main.lcmlog.0 is written, the older ones are renamed
  # up to main.lcmlog.7, and the oldest is deleted (a resumed run's recording moves up too).
  # (Debian's 1.3.1 refuses the short form -l.) Quiet: no line a second in its log.
  mkdir -p "$out/lcm-log"
  start recorder "$out/logs/recorder.log" lcm-logger --quiet --lcm-url="$url" --rotate=8 \
    --split-mb="$((record_mb / 8))" "$out/lcm-log/main.lcmlog"
  # Ready when the logger has its file open. It stops after the others (stop_recorder): kept
  # out of pids[], which stop_all stops at once.
  recorder_sup=${pids[-1]}
  unset 'pids[-1]' 'roles[-1]'
  recording() {  # whether the current lcm-logger has main.lcmlog.0 open
    local fd logger
    logger=$(awk '$1 == "recorder" {p = $2} END {print p}' "$out/pids")
    for fd in /proc/"${logger:-0}"/fd/*; do
      case "$(readlink "$fd" 2>/dev/null)" in */lcm-log/main.lcmlog.0) return 0 ;; esac
    done
    return 1
  }
  for _ in $(seq 200); do
    recording && break
    kill -0 "$recorder_sup" 2>/dev/null || die "lcm-logger exited at its start: $(tail -3 "$out/logs/recorder.log")"
    sleep 0.05
  done
  recording || { stop_recorder; die "lcm-logger did not open its file in 10 s (log: $out/logs/recorder.log)"; }
fi
# shellcheck disable=SC2086
start replay "$out/logs/replay.log" "$bin/replay" "${common[@]}" --seed "$seed" \
  --snapshot "$out/replay-snapshot.bin" $replay_args
wait_ready replay "$out/logs/replay.log" "replay: ready"
# shellcheck disable=SC2086
start learner "$out/logs/learner.log" "$bin/learner" "${common[@]}" --out "$out" --seed "$seed" \
  --resume $learner_args
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
if [ "$record" -eq 1 ]; then
  echo "launch: recording the main port into $out/lcm-log/ (replay: see README, Recording a run)"
fi

# The monitor prints the progress line and decides when the run is over. It writes its own pid
# (exec keeps the subshell's) so that the pids file names every process of the run.
{
  echo "monitor $BASHPID" >> "$out/pids"
  exec "$bin/monitor" --lcm-url "$url" --lcm-bulk-url "$bulk_url" --run-id "$run_id" \
    --key-file "$out/key" --goal "$goal" --time-budget "$time_budget" --metrics "$out/metrics.jsonl" \
    --restarts "$out/restarts"
} | tee "$out/logs/monitor.log" &
monitor_pid=$!
set +e
wait "$monitor_pid"
set -e
status=$(grep -q 'goal reached' "$out/logs/monitor.log" && echo 0 || echo 1)
stop_all

# The best mean, rounded down as the report shows it (common/text_format.h: 899.96 is "899.9").
best=$(awk -F'"mean":' '
  NF > 1 { split($2, a, ","); if (a[1] + 0 > b || n == 0) b = a[1] + 0; n++ }
  END {
    if (!n) exit
    s = (b > -10 && b < 10) ? 100 : 10
    v = b * s + 1e-6; f = int(v); if (f > v) f -= 1
    printf (s == 100 ? "%.2f" : "%.1f") " over %d evaluations", f / s, n
  }' "$out/eval.jsonl" 2>/dev/null || true)
echo "launch: run folder $out"
echo "launch: report $out/report/index.html"
if [ "$record" -eq 1 ]; then
  echo "launch: LCM recording $out/lcm-log/ ($(du -sh "$out/lcm-log" 2>/dev/null | cut -f1))"
fi
[ -z "$best" ] || echo "launch: best evaluation mean $best"
if [ "$status" -eq 0 ]; then
  echo "launch: goal of $goal reached"
else
  echo "launch: goal of $goal not reached"
fi
exit "$status"
}
