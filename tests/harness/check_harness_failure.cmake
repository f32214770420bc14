# cmake -DEXECUTABLE=<test_harness_failure> -DPF_FILE=<its .pf> -DBACKEND=<fallback|pfunit>
#       -P check_harness_failure.cmake
#
# The WILL_FAIL registration of test_harness_failure only proves a non-zero exit, which a crash
# would give too. This script proves the failures are the intended ones: every assertion line
# of the .pf whose message is 'expected failure' is reported as test_harness_failure.pf:<line>,
# a failed assertion ends its test, @after runs after every test, and the run reaches its end.

foreach(var IN ITEMS EXECUTABLE PF_FILE BACKEND)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "check_harness_failure.cmake: -D${var}=... is required")
  endif()
endforeach()

execute_process(COMMAND "${EXECUTABLE}" RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(output "${out}${err}")
get_filename_component(pf_name "${PF_FILE}" NAME)

# Line numbers of the deliberate failures and the number of tests, read from the .pf. Brackets
# and semicolons would upset CMake's list splitting; only line numbers matter here.
file(READ "${PF_FILE}" source)
string(REGEX REPLACE "[][;]" "_" source "${source}")
string(REPLACE "\n" ";" lines "${source}")
set(line_number 0)
set(failure_lines "")
set(n_tests 0)
foreach(line IN LISTS lines)
  math(EXPR line_number "${line_number} + 1")
  if(line MATCHES "^[ \t]*@assert" AND line MATCHES "expected failure")
    list(APPEND failure_lines ${line_number})
  elseif(line MATCHES "^[ \t]*@test")
    math(EXPR n_tests "${n_tests} + 1")
  endif()
endforeach()
list(LENGTH failure_lines n_failures)

set(problems "")
if(NOT status MATCHES "^[0-9]+$")
  list(APPEND problems "the program did not exit normally: ${status}")
elseif(status EQUAL 0)
  list(APPEND problems "exit status 0, but ${n_failures} tests should have failed")
endif()
foreach(line IN LISTS failure_lines)
  string(FIND "${output}" "${pf_name}:${line}" at)
  if(at EQUAL -1)
    list(APPEND problems "no failure reported at ${pf_name}:${line}")
  endif()
endforeach()
string(FIND "${output}" "harness-check: NOT REACHED" at)
if(NOT at EQUAL -1)
  list(APPEND problems "a test went on after its failed assertion")
endif()
string(FIND "${output}" "harness-check: last test ran" at)
if(at EQUAL -1)
  list(APPEND problems "the run stopped before the last test")
endif()
string(REGEX MATCHALL "harness-check: tear_down ran" teardowns "${output}")
list(LENGTH teardowns n_teardowns)
if(NOT n_teardowns EQUAL n_tests)
  list(APPEND problems "@after ran ${n_teardowns} times for ${n_tests} tests")
endif()

# Our own harness also promises its report format.
if(BACKEND STREQUAL "fallback")
  math(EXPR n_passed "${n_tests} - ${n_failures}")
  foreach(text IN ITEMS
      "test_harness_failure: ${n_passed} passed, ${n_failures} failed"
      "PASS test_harness_failure.test_still_runs_after_failures"
      "FAIL test_harness_failure.test_fails_equal_real"
      "1 of 4 elements differ"
      "first at (2,1)"
      "shape mismatch: expected [2], actual [3]"
      "difference: 5.0000000000000000E-001"
      "zero denominator: an expected value is 0"
      "value: Infinity")
    string(FIND "${output}" "${text}" at)
    if(at EQUAL -1)
      list(APPEND problems "missing from the report: ${text}")
    endif()
  endforeach()
endif()

if(problems)
  list(JOIN problems "\n  " problem_text)
  message(FATAL_ERROR "test_harness_failure did not fail as intended:\n  ${problem_text}\n"
                      "--- its output ---\n${output}")
endif()
message(STATUS "test_harness_failure failed as intended: ${n_failures} reported failures, "
               "exit status ${status}")
