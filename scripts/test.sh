#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite with ctest:
#   1. the unit tests under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/),
#   2. every test, unit and multi-process integration, on the Release build (build/),
#   3. the fuzz targets (fuzz/, clang + libFuzzer, build-fuzz/), each over its corpus and then
#      fuzzing for a few seconds.
# Integration tests run real processes over real LCM, each in its own network namespace when
# run as root (else on its own port). CI=true turns compiler warnings into errors.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
jobs=$(nproc)

scripts/setup.sh --build-dir build

werror=OFF
[ "${CI:-}" = "true" ] && werror=ON
echo "test: building the sanitizer configuration (ASan+UBSan) in build-asan/"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRL_SANITIZE=ON -DRL_BUILD_BENCH=OFF \
  -DRL_SKIP="tools;integration" -DRL_WARNINGS_AS_ERRORS="$werror" >/dev/null
cmake --build build-asan -j"$jobs"
echo "test: building the fuzz targets (clang, libFuzzer, ASan+UBSan) in build-fuzz/"
scripts/fuzz.sh --build-only --build-dir build-fuzz

status=0
echo "test: unit tests under ASan+UBSan"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan -L unit --output-on-failure -j"$jobs" | tee build-asan/ctest.log ||
  status=1
echo "test: all tests on the Release build"
ctest --test-dir build --output-on-failure | tee build/ctest.log || status=1
echo "test: fuzz targets (corpus, then a short fuzzing run each)"
ctest --test-dir build-fuzz -L fuzz --output-on-failure -j"$jobs" | tee build-fuzz/ctest.log ||
  status=1

# One closing line for the three runs.
passed=0 failed=0
for log in build-asan/ctest.log build/ctest.log build-fuzz/ctest.log; do
  total=$(grep -Eo 'tests failed out of [0-9]+' "$log" | grep -Eo '[0-9]+' | tail -1 || echo 0)
  fail=$(grep -Eo '[0-9]+ tests failed out of' "$log" | grep -Eo '^[0-9]+' | tail -1 || echo 0)
  passed=$((passed + ${total:-0} - ${fail:-0}))
  failed=$((failed + ${fail:-0}))
done
[ "$failed" -eq 0 ] || status=1
echo "$passed passed, $failed failed"
exit "$status"
