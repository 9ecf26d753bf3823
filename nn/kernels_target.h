// RL_NN_TARGET_BEGIN("isa,...") ... RL_NN_TARGET_END: every function defined in between is
// compiled for those instruction sets, whatever the build's baseline (GCC's target pragma,
// clang's attribute pragma; only instruction sets, so that the functions of headers included
// before, which keep the baseline, can still be inlined into them). Used by the kernels_*.cc
// files. Not part of the public API.
#pragma once

#define RL_NN_PRAGMA(...) _Pragma(#__VA_ARGS__)
#if defined(__clang__)
#define RL_NN_TARGET_BEGIN(isa) \
  RL_NN_PRAGMA(clang attribute push(__attribute__((target(isa))), apply_to = function))
#define RL_NN_TARGET_END RL_NN_PRAGMA(clang attribute pop)
#else
#define RL_NN_TARGET_BEGIN(isa) RL_NN_PRAGMA(GCC push_options) RL_NN_PRAGMA(GCC target(isa))
#define RL_NN_TARGET_END RL_NN_PRAGMA(GCC pop_options)
#endif
