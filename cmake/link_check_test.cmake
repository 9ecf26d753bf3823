# The test of cmake/link_check.cmake (ctest: link_check, label unit), in script mode:
#   cmake -DWORK_DIR=DIR -P cmake/link_check_test.cmake
# Configures small projects in WORK_DIR whose targets are interface and imported libraries (no
# compiler needed): one whose graph keeps the rules, which must configure, and two that break
# them, which must fail with the chain that does: a forbidden library reached through two
# targets, an alias and a $<LINK_ONLY:...>, and a library that must link nothing linking one.
if(NOT WORK_DIR)
  message(FATAL_ERROR "link_check_test: give -DWORK_DIR=DIR")
endif()
get_filename_component(check_module ${CMAKE_CURRENT_LIST_DIR}/link_check.cmake ABSOLUTE)

# Writes a project whose targets are declared by `body`, then checked as the project checks its
# own, configures it, and sets result_var to the configure step's exit status and output_var to
# its output.
function(configure_case name body result_var output_var)
  set(dir ${WORK_DIR}/${name})
  file(REMOVE_RECURSE ${dir})
  file(WRITE ${dir}/CMakeLists.txt
       "cmake_minimum_required(VERSION 3.22)\nproject(${name} NONE)\n"
       "include(${check_module})\n"
       "add_library(lcm_external INTERFACE IMPORTED)\n"
       "add_library(OpenSSL::Crypto INTERFACE IMPORTED)\n"
       "add_library(Eigen3::Eigen INTERFACE IMPORTED)\n"
       "${body}\n"
       "rl_check_links(TARGETS rl_base FORBIDDEN \".\")\n"
       "rl_check_links(TARGETS rl_nn FORBIDDEN \"^(lcm_external|rl_bus)$\" \"^OpenSSL::\")\n")
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${dir} -B ${dir}/build
                  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(${result_var} ${result} PARENT_SCOPE)
  set(${output_var} "${out}${err}" PARENT_SCOPE)
endfunction()

# The rules kept: nn links base and Eigen; the bus links OpenSSL, but nn does not link the bus.
configure_case(kept [=[
add_library(rl_base INTERFACE)
add_library(rl::base ALIAS rl_base)
add_library(rl_bus INTERFACE)
target_link_libraries(rl_bus INTERFACE rl::base OpenSSL::Crypto lcm_external)
add_library(rl_nn INTERFACE)
target_link_libraries(rl_nn INTERFACE rl::base Eigen3::Eigen)
]=] result out)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "link_check_test: a graph that keeps the rules was refused:\n${out}")
endif()

# nn reaches the bus through rl_util, by an alias and a $<LINK_ONLY:...>.
configure_case(reached [=[
add_library(rl_base INTERFACE)
add_library(rl_bus INTERFACE)
add_library(rl::bus ALIAS rl_bus)
target_link_libraries(rl_bus INTERFACE rl_base OpenSSL::Crypto)
add_library(rl_util INTERFACE)
set_property(TARGET rl_util PROPERTY INTERFACE_LINK_LIBRARIES "$<LINK_ONLY:rl::bus>")
add_library(rl_nn INTERFACE)
target_link_libraries(rl_nn INTERFACE rl_base rl_util)
]=] result out)
string(REGEX REPLACE "[ \n]+" " " out "${out}")
if(result EQUAL 0)
  message(FATAL_ERROR "link_check_test: nn reaching the bus through another library was not refused")
endif()
if(NOT out MATCHES "rl_nn must not link rl_bus, but does: rl_nn -> rl_util -> rl_bus")
  message(FATAL_ERROR "link_check_test: the refusal does not name the chain:\n${out}")
endif()

# The base, which must link nothing, links a library.
configure_case(base_links [=[
add_library(rl_base INTERFACE)
target_link_libraries(rl_base INTERFACE Eigen3::Eigen)
add_library(rl_nn INTERFACE)
target_link_libraries(rl_nn INTERFACE rl_base)
]=] result out)
string(REGEX REPLACE "[ \n]+" " " out "${out}")
if(result EQUAL 0 OR NOT out MATCHES "rl_base must not link Eigen3::Eigen")
  message(FATAL_ERROR "link_check_test: a base that links a library was not refused:\n${out}")
endif()
message(STATUS "link_check_test: 3 graphs checked as expected")
