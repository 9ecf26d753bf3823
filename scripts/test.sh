#!/usr/bin/env bash
# The whole test suite, as CI runs it (.ci/run). Installs what is missing (scripts/setup.sh),
# builds three trees from the presets of CMakePresets.json and runs, with ctest:
#   1. clang-tidy (.clang-tidy) over the sources that the last commit changed (scripts/tidy.sh),
#   2. the unit tests under ASan+UBSan (preset asan, build-asan/, clang); nn's kernel tests run
#      on every kernel path the CPU can run (tests/nn/kernel_paths.h),
#   3. the multi-process tests labelled "sanitized" on the ASan+UBSan programs,
#   4. the tests that run threads under ThreadSanitizer (preset tsan, build-tsan/),
#   5. the unit tests on the Release build (preset release, build/), in parallel,
#   6. the multi-process integration tests on the Release build, one at a time,
#   7. the fuzz targets (built in build-asan/ as well), each over its corpus and then fuzzing for
#      RL_FUZZ_SECONDS (fuzz/CMakeLists.txt).
# Integration tests run real processes over real LCM, each in its own network namespace when run
# as root (else on its own port). CI=true turns compiler warnings into errors.
#
# Each phase prints its wall time, the CPU time it used and the machine's mean load meanwhile; each
# ctest run writes its tests' times to BUILD/junit-NAME.xml, and the slowest tests are listed at
# the end. The last line is "N passed, N failed" over every test, a failed build or clang-tidy
# counting as one failure. Exit status 0 only when everything passed.
#
# Environment: RL_TIDY_ARGS replaces scripts/tidy.sh's arguments (e.g. --all).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
jobs=$(nproc)
werror=OFF
[ "${CI:-}" = "true" ] && werror=ON


# Phase times: wall (s), CPU of everything the phase ran (user + system, from this shell's
# reaped children), and the mean of the machine's 1-minute load, sampled every 5 s.
ticks=$(getconf CLK_TCK)
load_file=$(mktemp)
(while :; do cut -d' ' -f1 /proc/loadavg; sleep 5; done) >"$load_file" 2>/dev/null &
load_pid=$!
trap 'kill "$load_pid" 2>/dev/null; rm -f "$load_file"' EXIT
children_cpu() { awk -v t="$ticks" '{ printf "%d", ($16 + $17) / t }' "/proc/$$/stat"; }
phase_wall=$SECONDS phase_cpu=$(children_cpu) phase_load=0 phase_name=""
phase_lines=()
phase() {  # phase NAME: ends the phase that ran since the last call and starts NAME
  local cpu samples load
  cpu=$(children_cpu)
  samples=$(wc -l <"$load_file")
  if [ -n "$phase_name" ]; then
    load=$(tail -n +"$((phase_load + 1))" "$load_file" | awk '{ s += $1; n++ } END { printf "%.1f", n ? s / n : 0 }')
    phase_lines+=("$(printf '%-18s %5d s wall %6d s CPU   load %s' "$phase_name" \
      "$((SECONDS - phase_wall))" "$((cpu - phase_cpu))" "$load")")
    echo "test: phase ${phase_lines[-1]}"
  fi
  [ -z "$1" ] || echo "test: === $1"
  phase_name=$1 phase_wall=$SECONDS phase_cpu=$cpu phase_load=$samples
}

status=0
failed_steps=()
step_failed() { failed_steps+=("$1"); status=1; echo "test: FAILED: $1"; }
junits=()
# run_ctest NAME BUILD_DIR ARGS...: ctest with ARGS, per-test times in BUILD_DIR/junit-NAME.xml.
run_ctest() {
  local name=$1 junit="$root/$2/junit-$1.xml"
  shift 2
  rm -f "$junit"
  if ! ctest --no-tests=error --output-junit "$junit" "$@"; then
    status=1
    # A run that failed without a failing test in its XML (no tests found, ctest itself failed).
    grep -q 'failures="[1-9]' "$junit" 2>/dev/null || step_failed "ctest $name"
  fi
  [ ! -f "$junit" ] || junits+=("$junit")
}
build() {  # build PRESET: configure and build a preset's tree
  { cmake --preset "$1" -DRL_WARNINGS_AS_ERRORS="$werror" >/dev/null &&
      cmake --build --preset "$1" -j"$jobs"; } || step_failed "build $1"
}

phase install
scripts/setup.sh --no-build
phase build-release
build release
phase build-asan
build asan
phase build-tsan
build tsan
phase clang-tidy
# shellcheck disable=SC2086  # RL_TIDY_ARGS is a list of arguments
scripts/tidy.sh --build-dir build-asan --jobs "$jobs" ${RL_TIDY_ARGS:---changed} ||
  step_failed clang-tidy

phase asan-unit
run_ctest asan-unit build-asan --preset asan -j"$jobs"
phase asan-processes
run_ctest asan-processes build-asan --preset asan-integration
phase tsan
run_ctest tsan build-tsan --preset tsan -j"$jobs"
phase release-unit
run_ctest release-unit build --preset release-unit -j"$jobs"
phase release-integr
run_ctest release-integration build --preset release-integration
phase fuzz
run_ctest fuzz build-asan --preset asan-fuzz -j"$jobs"
phase ""

echo "test: phases"
printf '  %s\n' "${phase_lines[@]}"
echo "test: total $SECONDS s"
# The slowest tests of every run, from the JUnit files. (No `head` in these pipes: a reader that
# stops early makes a writer with more to say die of SIGPIPE, which pipefail turns into an exit.)
if [ ${#junits[@]} -gt 0 ]; then
  echo "test: slowest tests (s)"
  sed -n 's/.*<testcase name="\([^"]*\)".* time="\([0-9.]*\)".*/\2 \1/p' "${junits[@]}" |
    sort -rn | awk 'NR <= 15 { printf "  %8.1f %s\n", $1, $2 }'
fi
# One closing line: every test of every run, and every failed step as one failure.
total=0 failures=0 skipped=0
attribute() {  # attribute NAME FILE: the testsuite's count NAME (0 when missing)
  local v
  v=$(grep -o "$1=\"[0-9]*\"" "$2" | sed -n 1p | tr -dc '0-9')
  echo "${v:-0}"
}
for junit in ${junits[@]+"${junits[@]}"}; do
  total=$((total + $(attribute tests "$junit")))
  failures=$((failures + $(attribute failures "$junit")))
  skipped=$((skipped + $(attribute skipped "$junit") + $(attribute disabled "$junit")))
done
[ ${#failed_steps[@]} -eq 0 ] || echo "test: failed steps: ${failed_steps[*]}"
[ $((failures + ${#failed_steps[@]})) -eq 0 ] || status=1
echo "$((total - failures - skipped)) passed, $((failures + ${#failed_steps[@]})) failed, $skipped skipped"
exit "$status"
