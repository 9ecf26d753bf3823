#!/usr/bin/env bash
# Runs the libFuzzer targets of fuzz/ (fuzz/README.md says what each covers).
#
#   scripts/fuzz.sh [options] [TARGET...]   fuzz TARGETs (default: all), each for --time seconds
#   scripts/fuzz.sh --seeds                 rewrite the generated seed corpora in fuzz/corpus/
#                                           (after a change to lcmtypes/*.lcm, a file format or
#                                           configs/*.ini)
#   scripts/fuzz.sh --list                  print the targets
#   scripts/fuzz.sh --build-only            configure (when needed) and build, nothing else
#
# Options:
#   --time SECONDS    fuzzing time per target (default 600), corpus replay included
#   --jobs N          targets fuzzed side by side (default 1; each is one process)
#   --build-dir DIR   the clang build (default build-fuzz; configured here when missing)
#   --no-build        use the binaries in DIR as they are
#   -- ARGS...        passed to libFuzzer (e.g. -- -fork=2 -max_len=4096)
#
# Builds the fuzz targets (only them) unless --no-build, configuring DIR from the preset "fuzz"
# (CMakePresets.json: clang-14, -DRL_FUZZ=ON) when it has no build yet. The preset "asan" builds
# them too, beside the tests (what scripts/test.sh runs: --build-dir build-asan). Each target starts from its committed corpus fuzz/corpus/TARGET/ (only read) and
# its dictionary fuzz/dict/TARGET.dict; new inputs, crash files and the log go to
# DIR/fuzz-runs/TARGET/{corpus,artifacts,log} (the next run starts from both corpora). A
# target's line says how long it ran, its executions and coverage, or what it found and how to
# reproduce it. Exit status 1 when any target found something.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

time_s=600 jobs=1 build_dir=build-fuzz build=1 build_only=0 seeds=0 list=0
targets=() extra=()
usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; }
while [ $# -gt 0 ]; do
  case "$1" in
    --time) time_s="$2"; shift ;;
    --jobs) jobs="$2"; shift ;;
    --build-dir) build_dir="$2"; shift ;;
    --no-build) build=0 ;;
    --build-only) build_only=1 ;;
    --seeds) seeds=1 ;;
    --list) list=1 ;;
    -h|--help) usage; exit 0 ;;
    --) shift; extra=("$@"); break ;;
    -*) echo "fuzz.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    *) targets+=("$1") ;;
  esac
  shift
done
case "$time_s$jobs" in *[!0-9]*) echo "fuzz.sh: --time and --jobs take integers" >&2; exit 2 ;; esac
[ "$jobs" -ge 1 ] || jobs=1

if [ "$build" -eq 1 ]; then
  if [ ! -f "$build_dir/CMakeCache.txt" ]; then
    werror=OFF
    [ "${CI:-}" = "true" ] && werror=ON
    cmake --preset fuzz -B "$build_dir" -DRL_WARNINGS_AS_ERRORS="$werror" >/dev/null
  fi
  cmake --build "$build_dir" --target fuzz -j"$(nproc)"
fi
[ "$build_only" -eq 0 ] || exit 0
bin="$build_dir/bin"
# Sanitizer reports name files and lines when llvm-symbolizer is on the PATH (package llvm-14).
[ -d /usr/lib/llvm-14/bin ] && export PATH="/usr/lib/llvm-14/bin:$PATH"

if [ "$seeds" -eq 1 ]; then
  # Messages, state files, checkpoints: written by the project's own encoders.
  "$bin/fuzz_seeds" fuzz/corpus
  # The bus target reads the messages target's inputs.
  mkdir -p fuzz/corpus/bus
  find fuzz/corpus/bus -type f ! -name 'repro-*' -delete
  find fuzz/corpus/messages -type f ! -name 'repro-*' -exec cp {} fuzz/corpus/bus/ \;
  # Presets as they are, and every env id they name.
  mkdir -p fuzz/corpus/config fuzz/corpus/env_id
  find fuzz/corpus/config fuzz/corpus/env_id -type f ! -name 'repro-*' -delete
  cp configs/*.ini fuzz/corpus/config/
  grep -hE '^\s*(env|eval-env)\s*=' configs/*.ini | sed -E 's/^[^=]*=\s*//; s/\s+$//' | sort -u |
    while IFS= read -r id; do
      printf '%s' "$id" >"fuzz/corpus/env_id/$(printf '%s' "$id" | cksum | cut -d' ' -f1)"
    done
  echo "fuzz.sh: seeds written to fuzz/corpus/"
  exit 0
fi

all=()
for f in "$bin"/fuzz_*; do
  [ -x "$f" ] || continue
  name=${f##*/fuzz_}
  [ "$name" = seeds ] || all+=("$name")
done
if [ "$list" -eq 1 ]; then printf '%s\n' "${all[@]}"; exit 0; fi
[ ${#all[@]} -gt 0 ] || { echo "fuzz.sh: no fuzz targets in $bin (build first)" >&2; exit 2; }
[ ${#targets[@]} -gt 0 ] || targets=("${all[@]}")
for t in "${targets[@]}"; do
  [ -x "$bin/fuzz_$t" ] || { echo "fuzz.sh: no target '$t' (have: ${all[*]})" >&2; exit 2; }
done

# Runs one target; prints its summary line; returns 1 when it found something.
run_one() {
  local t=$1 run="$build_dir/fuzz-runs/$1"
  mkdir -p "$run/corpus" "$run/artifacts"
  touch "$run/start"
  local args=(-max_total_time="$time_s" -timeout=25 -rss_limit_mb=2048 -print_final_stats=1
              -artifact_prefix="$run/artifacts/")
  [ -f "fuzz/dict/$t.dict" ] && args+=(-dict="fuzz/dict/$t.dict")
  local start=$SECONDS rc=0
  "$bin/fuzz_$t" "${args[@]}" "${extra[@]}" "$run/corpus" "fuzz/corpus/$t" >"$run/log" 2>&1 ||
    rc=$?
  local took=$((SECONDS - start))
  local execs cov ft found
  execs=$(grep -Eo 'stat::number_of_executed_units: [0-9]+' "$run/log" | grep -Eo '[0-9]+$' || true)
  cov=$(grep -E '^#[0-9]+.*cov: ' "$run/log" | tail -1 | grep -Eo 'cov: [0-9]+ ft: [0-9]+' || true)
  found=$(find "$run/artifacts" -type f -newer "$run/start" | head -5)
  if [ "$rc" -ne 0 ] || [ -n "$found" ]; then
    echo "fuzz: $t: FOUND A PROBLEM after ${took}s (exit $rc); log $run/log"
    grep -E '^(==[0-9]+==ERROR|SUMMARY|.*runtime error|fuzz_.*: )' "$run/log" | head -5 |
      sed 's/^/  /'
    for f in $found; do echo "  reproduce: $bin/fuzz_$t $f"; done
    return 1
  fi
  echo "fuzz: $t: clean for ${took}s, ${execs:-?} executions, ${cov:-cov ?}"
}

status=0
running=0
for t in "${targets[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || status=1
    running=$((running - 1))
  fi
  run_one "$t" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || status=1
  running=$((running - 1))
done
exit "$status"
