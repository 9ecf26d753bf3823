#!/usr/bin/env bash
# The default build runs on a CPU without AVX-512: under qemu-x86_64 -cpu Haswell (AVX2, FMA,
# F16C, BMI; no AVX-512, no AVX512_BF16) the processes start and the network library computes on
# its avx2 path, chosen at run time. Checks:
#  - learner, actor, replay and evaluator --help;
#  - the kernel and layer tests of nn_test, on the path picked for the CPU (avx2: the AVX-512
#    paths are skipped, saying the CPU cannot run them), bf16 products emulated, a network that
#    learns, an update of the Nature network with two threads;
#  - RL_KERNELS=avx512 is refused with the reason, RL_KERNELS=avx2 is taken.
# Skipped (exit 77) where qemu-x86_64 is not installed (Debian: apt-get install qemu-user).
set -euo pipefail
build=${RL_BUILD_DIR:?RL_BUILD_DIR must name the build directory}
if ! command -v qemu-x86_64 > /dev/null; then
  echo "SKIP: qemu-x86_64 is not installed (Debian: apt-get install qemu-user)"
  exit 77
fi
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
haswell() { qemu-x86_64 -cpu Haswell "$@"; }

for process in learner actor replay evaluator; do
  [ -x "$build/bin/$process" ] || fail "$build/bin/$process is not built"
  status=0
  haswell "$build/bin/$process" --help > "$scratch/$process.txt" 2>&1 || status=$?
  [ "$status" -eq 0 ] || fail "$process --help exited with $status on Haswell: $(tail -3 "$scratch/$process.txt")"
  grep -q "Usage" "$scratch/$process.txt" || fail "$process --help printed no usage"
  echo "ok: $process --help on Haswell"
done

tests="$build/tests/nn/nn_test"
[ -x "$tests" ] || fail "$tests is not built"
filter='*GemmTest*:*GemvTest*:*Conv2dKernelTest*:*Bf16*:KernelsTest.*:LinearTest.*'
filter+=':LearningTest.*:*ParallelKernelTest.NetworksGiveTheSameResultsWithThreads*'
status=0
haswell "$tests" --gtest_filter="$filter" > "$scratch/nn_test.txt" 2>&1 || status=$?
tail -5 "$scratch/nn_test.txt"
[ "$status" -eq 0 ] || fail "nn_test failed on Haswell (exit $status): $(grep -m5 -E 'Failure|FAILED' "$scratch/nn_test.txt")"
grep -q "in use: avx2" "$scratch/nn_test.txt" || fail "the automatic path on Haswell is not avx2"
grep -q "this CPU cannot run the avx512 kernels" "$scratch/nn_test.txt" ||
  fail "the avx512 tests were not skipped on Haswell"
grep -q "\[  PASSED  \]" "$scratch/nn_test.txt" || fail "no test passed"
grep -q "OK \] Paths/Bf16GemmTest.MatchesTheReferenceOnEveryLayout/avx2" "$scratch/nn_test.txt" ||
  fail "the emulated bf16 products were not tested"
grep -q "OK \] LearningTest.SmallConvNetLearnsWhichHalfHoldsTheBrightSquare" \
  "$scratch/nn_test.txt" || fail "the learning test did not run"
echo "ok: nn kernel tests on Haswell (avx2 path, bf16 emulated)"

status=0
RL_KERNELS=avx512 haswell "$tests" --gtest_filter='KernelsTest.*' > "$scratch/forced.txt" 2>&1 ||
  status=$?
[ "$status" -ne 0 ] || fail "RL_KERNELS=avx512 was accepted on Haswell"
grep -q "RL_KERNELS=avx512: kernel path 'avx512' needs AVX-512" "$scratch/forced.txt" ||
  fail "RL_KERNELS=avx512 failed without saying why: $(grep -m3 -i error "$scratch/forced.txt")"
RL_KERNELS=avx2 haswell "$tests" --gtest_filter='KernelsTest.*' > "$scratch/avx2.txt" 2>&1 ||
  fail "RL_KERNELS=avx2 failed on Haswell"
echo "ok: RL_KERNELS=avx512 refused on Haswell with its reason, RL_KERNELS=avx2 taken"
echo "PASS"
