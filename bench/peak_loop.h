// The loop that measures an instruction's peak throughput (bench_cnn's peak rows). bench_cnn.cc
// includes it twice, inside two namespaces: once compiled for the build's baseline (256-bit FMA,
// which every CPU of the build runs) and once for AVX-512 with AVX512_BF16 (512-bit FMA,
// vdpbf16ps), which runs only where the CPU has them. It includes nothing itself.

// kChains independent chains acc = step(acc), at least the latency times the pipes of current
// x86 cores (FMA: 4 cycles x 2 pipes; vdpbf16ps: up to 6 x 2), so that only throughput limits
// them, and few enough that the chains and the step's two constants stay in registers (32
// vector registers with AVX-512, 16 without); returns GFLOP/s, `flops_per_lane` per lane and
// step. The steps converge or grow slowly from `start`, without denormals or overflow.
template <int kLanes, class V, class Step>
double ChainGflops(V start, const Step& step, double flops_per_lane, double seconds) {
  constexpr int kChains = sizeof(V) == 64 ? 16 : 12;
  constexpr int64_t kInner = 1 << 14;
  V acc[kChains];
  for (int c = 0; c < kChains; ++c) acc[c] = start;
  int64_t steps = 0;
  const double begin = rl::bench::ClockSeconds();
  double elapsed = 0;
  do {
    // The chains live in registers only between calls: every vector register is lost at a call
    // (ClockSeconds), and a loop around one would keep the chains in memory and measure store
    // forwarding (a load and a store around every instruction) instead of the instruction.
    V live[kChains];
#pragma GCC unroll 16
    for (int c = 0; c < kChains; ++c) live[c] = acc[c];
    for (int64_t i = 0; i < kInner; ++i) {
#pragma GCC unroll 16
      for (int c = 0; c < kChains; ++c) live[c] = step(live[c]);
    }
#pragma GCC unroll 16
    for (int c = 0; c < kChains; ++c) acc[c] = live[c];
    steps += kInner * kChains;
    elapsed = rl::bench::ClockSeconds() - begin;
  } while (elapsed < seconds);
  float sum = 0;
  for (int c = 0; c < kChains; ++c) {
    float lanes[kLanes];
    std::memcpy(lanes, &acc[c], sizeof(lanes));
    for (float v : lanes) sum += v;
  }
  if (sum < -1) std::printf("%g\n", static_cast<double>(sum));  // Keeps the chains.
  return flops_per_lane * kLanes * static_cast<double>(steps) / elapsed / 1e9;
}
