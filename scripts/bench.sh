#!/usr/bin/env bash
# Builds and runs the benchmarks in bench/ and prints one JSON object per line (bench, value,
# unit, min/median/max over repeats). Where the PyTorch peer in ../shared/bench/peer can run
# (Debian's python3 with python3-torch), it measures the same things in the same run, and each
# of our lines gains "peer" (the peer's median) and "ratio" (how many times faster ours is).
#
# Usage: scripts/bench.sh [--no-setup] [--build-dir DIR] [--skip-goal] [--skip-peer]
#                         [--skip-transport]
# Environment: REPEATS (5), SECONDS_PER (1.0, per measurement), GOAL_SEEDS ("1 2 3"),
#              PEER_REPEATS (3), PEER_DQN (1: also time the peer's full CartPole DQN run),
#              CNN_REPEATS (REPEATS) and CNN_SECONDS (SECONDS_PER) for bench_cnn, CNN_THREADS
#              ("1,2": the thread counts of bench_cnn and of the peer's CNN modes), PEER_CNN (1:
#              run the peer's nature, small and latency modes; 0: skip them), KUKA_EPISODES
#              (20: episodes of each policy in kuka_probe), KUKA_PIPELINE_SECONDS (300: length of
#              the kuka_grasp launch that measures the whole pipeline's episodes per hour; 0 or
#              --skip-goal: skip it), CAR_PIPELINE_SECONDS (300: the same for car_racing_td3, whose
#              env steps are agent steps of 5 frames), TD3_SEEDS ("1": seeds of the Pendulum and
#              LunarLanderContinuous runs to their goals), PEER_TD3 (1: run the peer's td3 mode),
#              BENCHES ("env actor learner replay cnn kuka transport": which of our benchmarks
#              run), TRANSPORT_REPEATS (3), TRANSPORT_SECONDS (2), TRANSPORT_LOCAL ("1 4":
#              publisher processes on this host) and TRANSPORT_NODES ("1 3": publisher nodes of
#              the test cluster, root only; "" skips them) for bench/transport.sh,
#              PEER_BF16 (1: also run the peer's update modes with --precision bf16, torch's CPU
#              autocast, for the bf16 rows of ours), RL_BENCH_CLOCK (cpu: our one-thread rates
#              per CPU second, for a shared machine; the peer's stay per wall second).
# Our learner and network rows come in fp32 and bf16 ("precision"); each gains "peer" and
# "ratio" against the peer in the same precision, and "peer_fp32", "ratio_vs_peer_fp32",
# "peer_bf16", "ratio_vs_peer_bf16" against both.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
setup=1 build_dir="$root/build" skip_goal=0 skip_peer=0 skip_transport=0
while [ $# -gt 0 ]; do
  case "$1" in
    --no-setup) setup=0 ;;
    --build-dir) build_dir="$2"; shift ;;
    --skip-goal) skip_goal=1 ;;
    --skip-peer) skip_peer=1 ;;
    --skip-transport) skip_transport=1 ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "bench.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
repeats=${REPEATS:-5}
seconds=${SECONDS_PER:-1.0}
[ "$setup" -eq 0 ] || scripts/setup.sh --build-dir "$build_dir" >&2
bin="$build_dir/bin"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Runs a command in its own network namespace when possible (LCM multicast on lo only).
isolated() {
  if [ "$(id -u)" -eq 0 ] && command -v unshare >/dev/null; then
    unshare -n bash -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' _ "$@"
  else
    "$@"
  fi
}

ours="$work/ours.jsonl"
echo "bench: ours" >&2
benches=" ${BENCHES:-env actor learner replay cnn kuka transport} "
wanted() { [[ "$benches" == *" $1 "* ]]; }
if wanted env; then "$bin/bench_env" "$repeats" "$seconds" >> "$ours"; fi
if wanted actor; then "$bin/bench_actor" "$repeats" "$seconds" >> "$ours"; fi
if wanted learner; then "$bin/bench_learner" "$repeats" "$seconds" >> "$ours"; fi
if wanted replay; then isolated "$bin/bench_replay" "$repeats" "$seconds" >> "$ours"; fi
# Pixel networks (Nature and grasp CNN): updates/s, latency, convolution GFLOP/s, the FMA and
# bf16 peaks; the CarRacing actors' latency.
cnn_threads=${CNN_THREADS:-1,2}
if wanted cnn; then
  "$bin/bench_cnn" "${CNN_REPEATS:-$repeats}" "${CNN_SECONDS:-$seconds}" "$cnn_threads" >> "$ours"
fi
# KUKA grasping (Bullet, OSMesa at 48x48, one llvmpipe thread): rendered frames/s, physics and
# env steps/s and episodes per hour of one actor (per CPU second), oracle and random success.
if wanted kuka; then "$bin/kuka_probe" --json --episodes "${KUKA_EPISODES:-20}" >> "$ours"; fi
# Transports: transitions/s one replay daemon stores and messages lost at the raw limit, udpm and
# LCM's TCP hub, flat and pixel, without and with the key, publishers on this host and on nodes
# of the test cluster (bench/transport.sh; 20 to 30 minutes with the defaults).
if wanted transport && [ "$skip_transport" -eq 0 ]; then
  echo "bench: transport" >&2
  bench/transport.sh --build-dir "$build_dir" --repeats "${TRANSPORT_REPEATS:-3}" \
    --seconds "${TRANSPORT_SECONDS:-2}" --local "${TRANSPORT_LOCAL:-1 4}" \
    --nodes "${TRANSPORT_NODES-1 3}" >> "$ours"
fi

# Time from launch to goal for CartPole, start-up and evaluation included.
if [ "$skip_goal" -eq 0 ]; then
  times=()
  solved=0
  for seed in ${GOAL_SEEDS:-1 2 3}; do
    echo "bench: launch cartpole, seed $seed" >&2
    start=$(date +%s.%N)
    if isolated "$root/scripts/launch.sh" cartpole --no-setup --build-dir "$build_dir" \
        --seed "$seed" --time-budget 300 --out "$work/run-$seed" > "$work/run-$seed.log" 2>&1; then
      solved=$((solved + 1))
    fi
    end=$(date +%s.%N)
    times+=("$(awk -v a="$start" -v b="$end" 'BEGIN{printf "%.3f", b - a}')")
  done
  printf '%s\n' "${times[@]}" | sort -g | awk -v n="${#times[@]}" -v solved="$solved" '
    {v[NR]=$1} END {med = (n % 2) ? v[(n+1)/2] : (v[n/2] + v[n/2+1]) / 2;
      printf "{\"bench\": \"cartpole_time_to_goal\", \"value\": %.2f, \"unit\": \"s\", \"min\": %.2f, \"median\": %.2f, \"max\": %.2f, \"repeats\": %d, \"solved\": %d, \"goal\": 475, \"actors\": 4}\n", med, v[1], med, v[n], n, solved}' >> "$ours"
fi

# LunarLander: wall time and env steps until an evaluation mean of 200 (the "solved" mark).
if [ "$skip_goal" -eq 0 ]; then
  for seed in ${LUNAR_SEEDS:-1}; do
    echo "bench: launch lunar_lander, seed $seed" >&2
    start=$(date +%s.%N)
    ok=0
    isolated "$root/scripts/launch.sh" lunar_lander --no-setup --build-dir "$build_dir" \
      --seed "$seed" --time-budget 900 --out "$work/lunar-$seed" > "$work/lunar-$seed.log" 2>&1 && ok=1
    end=$(date +%s.%N)
    n_actors=$(sed -n 's/^# actors = \([0-9]*\).*/\1/p' "$work/lunar-$seed/config.ini" 2>/dev/null)
    steps=$(awk -F'"env_steps": ' '/"mean": *(2[0-9][0-9]|[3-9][0-9][0-9])/{split($2,a,","); print a[1]; exit}' \
      "$work/lunar-$seed/eval.jsonl" 2>/dev/null)
    echo "{\"bench\": \"lunar_lander_time_to_200\", \"value\": $(awk -v a="$start" -v b="$end" 'BEGIN{printf "%.1f", b - a}'), \"unit\": \"s\", \"seed\": $seed, \"solved\": $ok, \"env_steps\": ${steps:-null}, \"actors\": ${n_actors:-null}}" >> "$ours"
  done
fi

# TD3: wall time and env steps until the goal (Pendulum-v1: -200; LunarLanderContinuous-v3: 200).
if [ "$skip_goal" -eq 0 ]; then
  for preset in pendulum lunar_lander_continuous; do
    case "$preset" in pendulum) budget=300 ;; *) budget=1200 ;; esac
    for seed in ${TD3_SEEDS:-1}; do
      echo "bench: launch $preset, seed $seed" >&2
      start=$(date +%s.%N)
      ok=0
      isolated "$root/scripts/launch.sh" "$preset" --no-setup --build-dir "$build_dir" \
        --seed "$seed" --time-budget "$budget" --out "$work/$preset-$seed" \
        > "$work/$preset-$seed.log" 2>&1 && ok=1
      end=$(date +%s.%N)
      goal=$(sed -n 's/^goal *= *//p' "$work/$preset-$seed/config.ini" 2>/dev/null | tail -1)
      # The env steps of the first evaluation at or above the goal.
      steps=$(awk -v goal="${goal:-0}" '{
          m = $0; sub(/.*"mean": */, "", m); sub(/[,}].*/, "", m)
          s = $0; sub(/.*"env_steps": */, "", s); sub(/[,}].*/, "", s)
          if (m + 0 >= goal + 0) { print s; exit } }' "$work/$preset-$seed/eval.jsonl" 2>/dev/null)
      echo "{\"bench\": \"${preset}_time_to_goal\", \"value\": $(awk -v a="$start" -v b="$end" 'BEGIN{printf "%.1f", b - a}'), \"unit\": \"s\", \"seed\": $seed, \"solved\": $ok, \"goal\": ${goal:-null}, \"env_steps\": ${steps:-null}}" >> "$ours"
    done
  done
fi

# A whole pipeline (actors, replay, learner, evaluator) for SECONDS: episodes per hour and env
# steps/s after the first minute (start-up, replay warm-up), from the monitor's progress lines;
# and the learner's updates/s over the same span, with every process of the run beside it (a
# row of its own, BENCH_NAME with "episodes_per_hour" made "learner_updates_per_s").
# pipeline_rate PRESET SECONDS BENCH_NAME
pipeline_rate() {
  local preset="$1" seconds="$2" name="$3"
  echo "bench: launch $preset for $seconds s" >&2
  isolated "$root/scripts/launch.sh" "$preset" --no-setup --build-dir "$build_dir" --seed 1 \
    --goal 1000000 --time-budget "$seconds" --out "$work/$preset" > "$work/$preset.log" 2>&1 || true
  local n_actors
  n_actors=$(sed -n 's/^# actors = \([0-9]*\).*/\1/p' "$work/$preset/config.ini" 2>/dev/null)
  # Progress lines: "[  499.6s] steps 16,049  episodes 2,221  ...  learner 44 upd/s (9,120)  ...".
  tr -d ',' < "$work/$preset/logs/monitor.log" | awk -v actors="${n_actors:-null}" -v name="$name" '
    /^\[ *[0-9.]+s\] steps [0-9]+ +episodes [0-9]+/ {
      t = $0; sub(/^\[ */, "", t); sub(/s\].*/, "", t)
      match($0, /steps [0-9]+/); s = substr($0, RSTART + 6, RLENGTH - 6)
      match($0, /episodes [0-9]+/); e = substr($0, RSTART + 9, RLENGTH - 9)
      u = match($0, /upd\/s \([0-9]+\)/) ? substr($0, RSTART + 7, RLENGTH - 8) : ""
      if (t + 0 >= 60 && t0 == "") { t0 = t; s0 = s; e0 = e; u0 = u }
      t1 = t; s1 = s; e1 = e; u1 = u
    }
    END {
      if (t0 == "" || t1 - t0 < 10) { print "bench.sh: " name " ran too briefly to measure" > "/dev/stderr"; exit }
      printf "{\"bench\": \"%s\", \"value\": %.0f, \"unit\": \"episodes/h\", \"env_steps_per_s\": %.1f, \"seconds\": %.0f, \"actors\": %s, \"note\": \"whole pipeline on this machine, learner and evaluator included, after the first minute\"}\n", name, (e1 - e0) * 3600 / (t1 - t0), (s1 - s0) / (t1 - t0), t1 - t0, actors
      if (u0 == "" || u1 == "") exit
      learner = name; sub(/episodes_per_hour$/, "learner_updates_per_s", learner)
      printf "{\"bench\": \"%s\", \"value\": %.1f, \"unit\": \"updates/s\", \"updates\": %d, \"seconds\": %.0f, \"actors\": %s, \"note\": \"the learner of a whole pipeline on this machine, with the replay, the actors and the evaluator beside it, after the first minute\"}\n", learner, (u1 - u0) / (t1 - t0), u1 - u0, t1 - t0, actors
    }' >> "$ours"
}

# KUKA grasping (held-out objects in the evaluator) and CarRacing with TD3 from pixels (agent
# steps of 5 frames; training episodes end early off the track).
kuka_seconds=${KUKA_PIPELINE_SECONDS:-300}
if [ "$skip_goal" -eq 0 ] && [ "$kuka_seconds" -gt 90 ]; then
  pipeline_rate kuka_grasp "$kuka_seconds" kuka_pipeline_episodes_per_hour
fi
car_seconds=${CAR_PIPELINE_SECONDS:-300}
if [ "$skip_goal" -eq 0 ] && [ "$car_seconds" -gt 90 ]; then
  pipeline_rate car_racing_td3 "$car_seconds" car_racing_pipeline_episodes_per_hour
fi

# The PyTorch peer, in the same run.
peer_dir="$root/../shared/bench/peer"
py=/usr/bin/python3
peer="$work/peer.jsonl"
: > "$peer"
if [ "$skip_peer" -eq 0 ] && [ -f "$peer_dir/micro.py" ] && "$py" -c 'import torch' 2>/dev/null; then
  for r in $(seq "${PEER_REPEATS:-3}"); do
    echo "bench: peer micro, repeat $r" >&2
    (cd "$peer_dir" && "$py" micro.py --only env,mlp,actor --threads 1 --min-time 2 --tag "r$r") >> "$peer"
  done
  if [ "${PEER_CNN:-1}" = 1 ]; then
    for r in $(seq "${PEER_REPEATS:-3}"); do
      echo "bench: peer micro CNN (nature, small, latency; threads $cnn_threads), repeat $r" >&2
      (cd "$peer_dir" && "$py" micro.py --only nature,small,latency --threads "$cnn_threads" \
        --min-time 2 --tag "cnn-r$r") >> "$peer"
    done
  fi
  if [ "${PEER_TD3:-1}" = 1 ]; then
    for r in $(seq "${PEER_REPEATS:-3}"); do
      echo "bench: peer micro TD3 (td3_mlp, td3_car; one thread), repeat $r" >&2
      (cd "$peer_dir" && "$py" micro.py --only td3 --threads 1 --min-time 2 --tag "td3-r$r") \
        >> "$peer"
    done
  fi
  if [ "${PEER_BF16:-1}" = 1 ]; then
    for r in $(seq "${PEER_REPEATS:-3}"); do
      echo "bench: peer micro bf16 (mlp, td3; one thread), repeat $r" >&2
      (cd "$peer_dir" && "$py" micro.py --only mlp,td3 --threads 1 --min-time 2 --precision bf16 \
        --tag "bf16-r$r") >> "$peer"
      if [ "${PEER_CNN:-1}" = 1 ]; then
        echo "bench: peer micro bf16 CNN (nature, small; threads $cnn_threads), repeat $r" >&2
        (cd "$peer_dir" && "$py" micro.py --only nature,small --threads "$cnn_threads" \
          --min-time 2 --precision bf16 --tag "bf16-cnn-r$r") >> "$peer"
      fi
    done
  fi
  if [ "${PEER_DQN:-1}" = 1 ] && [ "$skip_goal" -eq 0 ]; then
    echo "bench: peer DQN on CartPole (500,000 steps)" >&2
    start=$(date +%s.%N)
    (cd "$peer_dir" && "$py" dqn_peer.py --total-timesteps 500000 --seed 1 --threads 1 \
      --progress-every 0) > "$work/peer_dqn.json" 2>/dev/null || true
    end=$(date +%s.%N)
    echo "{\"bench\": \"peer_dqn_wall\", \"rate\": $(awk -v a="$start" -v b="$end" 'BEGIN{printf "%.3f", b - a}')}" >> "$peer"
  fi
else
  echo "bench: the PyTorch peer cannot run here (no python3-torch); our figures only" >&2
fi

# Join: our line + the peer's median for the same measurement.
"$py" - "$ours" "$peer" <<'PY'
import json, statistics, sys
ours = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
peer = [json.loads(l) for l in open(sys.argv[2]) if l.strip().startswith("{")]
def peer_lines(pred):
    return [p for p in peer if "rate" in p and pred(p)]
def peer_updates(net):
    return lambda o: lambda p: (p["bench"] == "updates" and p.get("net") == net
                                and p.get("batch") == o.get("batch")
                                and p.get("threads") == o.get("threads"))
# Our bench -> (which peer lines, "higher" or "lower" is better[, factor from the peer's unit to
# ours]).
match = {
    "cartpole_env_steps": (lambda o: lambda p: p["bench"] == "env_steps", "higher"),
    "actor_steps": (lambda o: lambda p: p["bench"] == "actor_steps" and p.get("threads") == 1, "higher"),
    "learner_updates_mlp": (lambda o: lambda p: p["bench"] == "updates" and p.get("net") == "mlp"
                            and p.get("batch") == o.get("batch") and p.get("threads") == 1, "higher"),
    "cartpole_time_to_goal": (lambda o: lambda p: p["bench"] == "peer_dqn_wall", "lower"),
    "learner_updates_nature_cnn": (peer_updates("nature_cnn"), "higher"),
    "learner_updates_grasp_cnn": (peer_updates("small_cnn_bn"), "higher"),
    "learner_updates_td3": (lambda o: lambda p: p["bench"] == "updates" and p.get("net") == o.get("net")
                            and p.get("batch") == o.get("batch") and p.get("threads") == 1, "higher"),
    # The peer reports microseconds per call (a mean over calls); ours are milliseconds (median).
    "inference_latency_nature_cnn": (lambda o: lambda p: p["bench"] == "latency"
                                     and p.get("net") == "nature_cnn"
                                     and p.get("threads") == o.get("threads"), "lower", 1e-3),
}
def peak(name):
    values = [o["value"] for o in ours if o["bench"] == name and o.get("threads", 1) == 1]
    return values[0] if values else None
peaks = {"fp32": peak("peak_fp32_gflops"), "bf16": peak("peak_bf16_gflops")}
def peer_median(m, o, precision):
    """The peer's median for our line o in `precision` (the peer's fp32 lines have none)."""
    lines = [l for l in peer_lines(m[0](o)) if l.get("precision", "fp32") == precision]
    if not lines:
        return None, lines
    return statistics.median([l["rate"] for l in lines]) * (m[2] if len(m) > 2 else 1), lines
for o in ours:
    precision = o.get("precision", "fp32")
    if "gflops" in o and peaks.get(precision):
        o["fraction_of_peak"] = round(float(o["gflops"]) / peaks[precision], 3)
        o["peak_used"] = "peak_%s_gflops" % precision
    m = match.get(o["bench"])
    if m:
        for peer_precision in ("fp32", "bf16"):
            p, lines = peer_median(m, o, peer_precision)
            if p is None:
                continue
            ratio = round(o["value"] / p if m[1] == "higher" else p / o["value"], 2)
            o["peer_" + peer_precision] = round(p, 6 if p < 1 else 3)
            o["ratio_vs_peer_" + peer_precision] = ratio
            if peer_precision == precision:
                o["peer"] = o["peer_" + peer_precision]
                o["peer_repeats"] = len(lines)
                if lines[0].get("blas"):
                    o["peer_blas"] = lines[0]["blas"]
                o["ratio"] = ratio
        if "peer" in o:
            if o["bench"] == "cartpole_time_to_goal":
                o["peer_note"] = "wall time of the peer's full 500,000-step CleanRL DQN run"
            if o["bench"].startswith("inference_latency_"):
                o["peer_note"] = "micro.py latency: mean over calls, converted to ms"
    print(json.dumps(o))
PY
