# Runs one scene of the bad-input suite through the checker (cmake -P).
#   -DCHECKER=<program> [-DCHECKER_ARGS=<args separated by blanks>] -DSCENE=<file.inp>
# The scene states its expectation in a comment line:
#   ** expect: <file>.inp:<line>: <message fragment>   -> exit status 2, that text on stderr
#   ** expect: ok                                      -> exit status 0 (control scenes)
#   ** mode: run                                       -> (optional) the scene is run, not checked:
#                                                          for errors only a run can meet (NaN or Inf)
# Every run must be free of backtraces and NaN.
foreach(var CHECKER SCENE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "check_bad_input.cmake: -D${var}=... is required")
  endif()
endforeach()

file(STRINGS "${SCENE}" expect_lines REGEX "^\\*\\* *expect:")
list(LENGTH expect_lines n_expect)
if(NOT n_expect EQUAL 1)
  message(FATAL_ERROR "${SCENE}: needs exactly one '** expect: ...' line, found ${n_expect}")
endif()
string(REGEX REPLACE "^\\*\\* *expect: *" "" expected "${expect_lines}")
# file(STRINGS) returns a list, so a ';' of the message arrives escaped
string(REPLACE "\\;" ";" expected "${expected}")
string(STRIP "${expected}" expected)

separate_arguments(args UNIX_COMMAND "${CHECKER_ARGS}")
file(STRINGS "${SCENE}" mode_lines REGEX "^\\*\\* *mode: *run")
if(mode_lines)
  # the solver itself on the scene: the checker's options without --check, outputs in the
  # working directory
  list(REMOVE_ITEM args "--check")
  list(APPEND args "--quiet")
endif()
execute_process(COMMAND "${CHECKER}" ${args} "${SCENE}"
  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(report "exit status: ${status}\nstdout:\n${out}\nstderr:\n${err}")

foreach(bad "Backtrace" "#0  0x" "NaN" "Infinity" "SIGFPE" "Segmentation" "ERROR STOP" "floating-point exceptions")
  string(FIND "${out}${err}" "${bad}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "${SCENE}: output contains \"${bad}\"\n${report}")
  endif()
endforeach()

if(expected STREQUAL "ok")
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${SCENE}: expected the scene to be accepted\n${report}")
  endif()
  return()
endif()

if(mode_lines)
  # an error of the run has a time instead of a line: '<file>: increment ...'
  if(NOT expected MATCHES "^[^:]+: increment [0-9]+ .+")
    message(FATAL_ERROR "${SCENE}: a run's expectation must read '<file>: increment <n> ...', got '${expected}'")
  endif()
elseif(NOT expected MATCHES "^[^:]+:[0-9]+: .+")
  message(FATAL_ERROR "${SCENE}: the expectation must read '<file>:<line>: <message>', got '${expected}'")
endif()
if(NOT status EQUAL 2)
  message(FATAL_ERROR "${SCENE}: expected exit status 2\n${report}")
endif()
string(FIND "${err}" "${expected}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "${SCENE}: stderr lacks \"${expected}\"\n${report}")
endif()
