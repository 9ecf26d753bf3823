# rl_add_library(name SOURCES ... DEPS ...): a static library rl_<name> with alias rl::<name>.
function(rl_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(rl_${name} STATIC ${ARG_SOURCES})
  add_library(rl::${name} ALIAS rl_${name})
  target_include_directories(rl_${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(rl_${name} PUBLIC ${ARG_DEPS})
  rl_set_warnings(rl_${name})
endfunction()

# rl_add_executable(name SOURCES ... DEPS ...): a program, written to bin/ of the build tree.
function(rl_add_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
  rl_set_warnings(${name})
endfunction()

# rl_add_test(name SOURCES ... DEPS ... [LABELS ...] [NO_UNITY]): a GoogleTest unit test, label
# "unit". With RL_UNITY_TESTS its sources compile in batches of 8 (one translation unit each),
# which parses GoogleTest and Eigen once a batch instead of once a file: a test file's names at
# namespace scope must then differ from those of the other files of its batch: a repeated type or
# variable fails to compile, but a repeated function name of other parameters becomes an overload
# set, where a call may silently take another file's function. NO_UNITY: one translation unit a
# file (for programs whose files define the same names).
function(rl_add_test name)
  cmake_parse_arguments(ARG "NO_UNITY" "" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  if(RL_UNITY_TESTS AND NOT ARG_NO_UNITY)
    set_target_properties(${name} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  endif()
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  rl_set_warnings(${name})
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  gtest_discover_tests(${name} PROPERTIES LABELS "${ARG_LABELS}"
                       ENVIRONMENT "LCM_DEFAULT_URL=memq://" DISCOVERY_TIMEOUT 60)
endfunction()
