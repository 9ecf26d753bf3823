# Sanitizer flags for the whole build (every target, the tests and fuzz targets included).
#   RL_SANITIZE  AddressSanitizer + UndefinedBehaviorSanitizer (GCC or clang)
#   RL_FUZZ      the same, plus libFuzzer's coverage instrumentation (clang only); fuzz/ links
#                libFuzzer's main into its targets, while the other programs of the build (tests,
#                processes) run as they are: the sanitizer runtime provides the coverage hooks
#   RL_TSAN      ThreadSanitizer (GCC or clang; alone: it cannot share a process with ASan)
# Every finding aborts the program (-fno-sanitize-recover=all), so a test fails on it.
if(RL_TSAN AND (RL_SANITIZE OR RL_FUZZ))
  message(FATAL_ERROR "RL_TSAN cannot be combined with RL_SANITIZE or RL_FUZZ (one runtime each)")
endif()
if(RL_FUZZ AND NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "RL_FUZZ needs clang: cmake --preset fuzz (or CC=clang-14 CXX=clang++-14)")
endif()

set(rl_sanitizers "")
if(RL_SANITIZE OR RL_FUZZ)
  set(rl_sanitizers address,undefined)
elseif(RL_TSAN)
  set(rl_sanitizers thread)
endif()
if(rl_sanitizers)
  add_compile_options(-fsanitize=${rl_sanitizers} -fno-sanitize-recover=all
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=${rl_sanitizers})
  # The instrumentation keeps clang from vectorizing some loops marked `omp simd` (a hint for
  # speed, evaluator/tsne.cc), which it reports as -Wpass-failed: not a fault of the code.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    add_compile_options(-Wno-pass-failed)
  endif()
endif()
if(RL_FUZZ)
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()
