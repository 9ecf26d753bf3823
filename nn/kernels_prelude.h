// Every header the kernels of kernels_*.cc use. Those files include it before they switch the
// compiler to their instruction set, so that the functions these headers define (the standard
// library's, Eigen's) are compiled for the build's baseline only: a copy of one of them compiled
// for AVX-512 could otherwise be the one the linker keeps for the whole program. Not part of
// the public API.
#pragma once

#include <immintrin.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>

#include "nn/gemm.h"
#include "nn/kernels.h"
#include "nn/tensor.h"
