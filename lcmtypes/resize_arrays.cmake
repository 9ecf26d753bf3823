# Run after lcm-gen (cmake -P resize_arrays.cmake HEADER...): makes every generated C++ decoder
# size each variable-length array to its length field, also when the length is 0.
#
# lcm-gen 1.3.1 decodes an array of primitives as
#     if(this->n) {
#         this->arr.resize(this->n);
#         ... decode n elements ...
#     }
# so a message whose length is 0 leaves the array as the previous message decoded into the same
# object left it (our bus decodes every message of a subscription into one reused object). The
# resize moves before the `if`; resize keeps the vector's capacity, so a reused object still
# allocates nothing once it has held its largest message. Any such block left unchanged fails the
# build, so that another lcm-gen's output cannot slip through unnoticed.
if(CMAKE_ARGC LESS 4)
  message(FATAL_ERROR "usage: cmake -P resize_arrays.cmake HEADER...")
endif()
math(EXPR last "${CMAKE_ARGC} - 1")
foreach(i RANGE 3 ${last})
  set(header "${CMAKE_ARGV${i}}")
  file(READ "${header}" text)
  set(guarded "( *)if\\(([^)\n]*)\\) {\n *(this->[][A-Za-z0-9_]+)\\.resize\\(([^)\n]*)\\);\n")
  string(REGEX REPLACE "${guarded}" "\\1\\3.resize(\\4);\n\\1if(\\2) {\n" fixed "${text}")
  string(REGEX MATCH "if\\([^)\n]*\\) {\n *this->[^\n]*\\.resize\\(" left "${fixed}")
  if(left)
    message(FATAL_ERROR "${header}: a guarded resize is left after rewriting: ${left}")
  endif()
  if(NOT fixed STREQUAL text)
    file(WRITE "${header}" "${fixed}")
  endif()
endforeach()
