#include "nn/kernels.h"

#include <cpuid.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "nn/precision.h"

namespace rl::nn {
namespace internal {
namespace {

// What the paths need from the CPU and the operating system.
struct Cpu {
  bool avx2 = false;         // AVX, AVX2, FMA, F16C, BMI1, BMI2, and the OS saves ymm state
  bool avx512 = false;       // AVX-512 F, BW, DQ, VL, CD, and the OS saves zmm and mask state
  bool avx512_bf16 = false;  // AVX512_BF16 on top of avx512
  bool amx_bf16 = false;     // AMX-TILE and AMX-BF16, and the OS supports tile state
};

bool Bit(unsigned reg, int bit) { return ((reg >> bit) & 1U) != 0; }

Cpu DetectCpu() {
  Cpu cpu;
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  if (__get_cpuid(1, &eax, &ebx, &ecx, &edx) == 0) return cpu;
  const bool fma = Bit(ecx, 12), osxsave = Bit(ecx, 27), avx = Bit(ecx, 28), f16c = Bit(ecx, 29);
  if (!osxsave || !avx) return cpu;
  // XCR0: which register states the OS saves and restores (XGETBV, allowed since OSXSAVE).
  unsigned xcr0_lo = 0, xcr0_hi = 0;
  __asm__ volatile("xgetbv" : "=a"(xcr0_lo), "=d"(xcr0_hi) : "c"(0));
  const bool os_ymm = (xcr0_lo & 0x6U) == 0x6U;                // SSE and AVX state
  const bool os_zmm = (xcr0_lo & 0xE6U) == 0xE6U;              // and opmask, ZMM_Hi256, Hi16_ZMM
  const bool os_tiles = Bit(xcr0_lo, 17) && Bit(xcr0_lo, 18);  // XTILECFG and XTILEDATA
  static_cast<void>(xcr0_hi);
  if (__get_cpuid_max(0, nullptr) < 7) return cpu;
  __cpuid_count(7, 0, eax, ebx, ecx, edx);
  const unsigned ebx7 = ebx, edx7 = edx;
  const unsigned sub_leaves = eax;
  cpu.avx2 = os_ymm && fma && f16c && Bit(ebx7, 3) && Bit(ebx7, 5) && Bit(ebx7, 8);
  cpu.avx512 = cpu.avx2 && os_zmm && Bit(ebx7, 16) && Bit(ebx7, 17) && Bit(ebx7, 28) &&
               Bit(ebx7, 30) && Bit(ebx7, 31);
  if (sub_leaves >= 1) {
    __cpuid_count(7, 1, eax, ebx, ecx, edx);
    cpu.avx512_bf16 = cpu.avx512 && Bit(eax, 5);
  }
  cpu.amx_bf16 = os_tiles && Bit(edx7, 22) && Bit(edx7, 24);
  return cpu;
}

const Cpu& TheCpu() {
  static const Cpu cpu = DetectCpu();
  return cpu;
}

// The paths, fastest first: their names, what they need and their kernels.
struct Path {
  const char* name;
  bool (*runnable)(const Cpu&);
  const char* needs;
  KernelSet (*make)();
};

const Path kPaths[] = {
    {"avx512_bf16", [](const Cpu& c) { return c.avx512_bf16; },
     "AVX-512 (F, BW, DQ, VL, CD) with AVX512_BF16", &Avx512Bf16Kernels},
    {"avx512", [](const Cpu& c) { return c.avx512; }, "AVX-512 (F, BW, DQ, VL, CD)",
     &Avx512Kernels},
    {"avx2", [](const Cpu& c) { return c.avx2; }, "AVX2, FMA, F16C and BMI (x86-64-v3)",
     &Avx2Kernels},
};

const Path* FindPath(const std::string& name) {
  for (const Path& p : kPaths) {
    if (name == p.name) return &p;
  }
  return nullptr;
}

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

// The path `name` asks for ("auto": the fastest runnable one). Throws std::invalid_argument
// saying why it cannot be used.
const Path& Resolve(const std::string& name) {
  if (name == "auto") {
    for (const Path& p : kPaths) {
      if (p.runnable(TheCpu())) return p;
    }
    // Cannot happen in a process that got this far: the whole build needs x86-64-v3.
    return kPaths[std::size(kPaths) - 1];
  }
  const Path* p = FindPath(name);
  if (p == nullptr) {
    std::vector<std::string> all = KernelPaths();
    throw std::invalid_argument("unknown kernel path '" + name + "' (known: auto, " + Join(all) +
                                ")");
  }
  if (!p->runnable(TheCpu())) {
    throw std::invalid_argument("kernel path '" + name + "' needs " + p->needs +
                                ", which this CPU (or its operating system) does not have; it "
                                "can run: " +
                                Join(RunnableKernelPaths()));
  }
  return *p;
}

// The sets built so far (a KernelSet is built on first use, never freed) and the one in use.
std::mutex g_mutex;
std::atomic<const KernelSet*> g_active{nullptr};

const KernelSet* SetFor(const Path& path) {
  static KernelSet sets[std::size(kPaths)];
  static bool built[std::size(kPaths)] = {};
  const auto i = static_cast<size_t>(&path - kPaths);
  if (!built[i]) {
    sets[i] = path.make();
    built[i] = true;
  }
  return &sets[i];
}

}  // namespace

const KernelSet& Kernels() {
  const KernelSet* set = g_active.load(std::memory_order_acquire);
  if (set != nullptr) return *set;
  std::lock_guard<std::mutex> lock(g_mutex);
  set = g_active.load(std::memory_order_relaxed);
  if (set == nullptr) {
    const char* env = std::getenv("RL_KERNELS");
    const std::string name = env != nullptr && env[0] != '\0' ? env : "auto";
    try {
      set = SetFor(Resolve(name));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(std::string("RL_KERNELS=") + name + ": " + e.what());
    }
    g_active.store(set, std::memory_order_release);
  }
  return *set;
}

}  // namespace internal

const char* PrecisionName(Precision precision) {
  return precision == Precision::kBf16 ? "bf16" : "fp32";
}

Precision ParsePrecision(const std::string& name) {
  if (name == "fp32") return Precision::kFp32;
  if (name == "bf16") return Precision::kBf16;
  throw std::invalid_argument("precision must be fp32 or bf16, not '" + name + "'");
}

std::string KernelPath() { return internal::Kernels().name; }

bool NativeBf16() { return internal::Kernels().gemm_bf16 != nullptr; }

std::vector<std::string> KernelPaths() {
  std::vector<std::string> names;
  for (const internal::Path& p : internal::kPaths) names.emplace_back(p.name);
  return names;
}

std::vector<std::string> RunnableKernelPaths() {
  std::vector<std::string> names;
  for (const internal::Path& p : internal::kPaths) {
    if (p.runnable(internal::TheCpu())) names.emplace_back(p.name);
  }
  return names;
}

void SetKernelPath(const std::string& name) {
  const internal::Path& path = internal::Resolve(name);
  std::lock_guard<std::mutex> lock(internal::g_mutex);
  internal::g_active.store(internal::SetFor(path), std::memory_order_release);
}

std::string CpuFeatureSummary() {
  const internal::Cpu& c = internal::TheCpu();
  std::string s = c.avx2 ? "avx2 fma f16c" : "no avx2";
  if (c.avx512) s += " avx512";
  if (c.avx512_bf16) s += " avx512_bf16";
  s += c.amx_bf16 ? " amx_bf16 (no amx path)" : " (no amx_bf16)";
  return s;
}

}  // namespace rl::nn
