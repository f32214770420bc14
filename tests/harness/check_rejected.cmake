# cmake -DPARSER=<cmd;args> -DPF_FILE=<rejected .pf> -DCOMPILER=<Fortran compiler>
#       -DMODULE_DIR=<dir of the funit module> -DWORK_DIR=<scratch dir> -P check_rejected.cmake
#
# A .pf file under rejected/ holds one assertion that pFUnit 4's interface does not accept
# (its header says which, and the line). This script expands it with the backend's .pf parser,
# compiles the result against that backend's `funit` module and passes only when the compiler
# refuses that line for want of a matching specific procedure: the harness is no more lenient
# than pFUnit. Any other outcome (it compiles, or fails for another reason) is a failure.

foreach(var IN ITEMS PARSER PF_FILE COMPILER MODULE_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "check_rejected.cmake: -D${var}=... is required")
  endif()
endforeach()

get_filename_component(name "${PF_FILE}" NAME_WE)
file(READ "${PF_FILE}" source)
if(NOT source MATCHES "refuse line ([0-9]+)")
  message(FATAL_ERROR "${PF_FILE}: the header must say which line must be refused")
endif()
set(line "${CMAKE_MATCH_1}")
file(STRINGS "${PF_FILE}" pf_lines)
math(EXPR index "${line} - 1")
list(GET pf_lines ${index} construct)
if(NOT construct MATCHES "@assert([A-Za-z]+)")
  message(FATAL_ERROR "${PF_FILE}:${line} is not an assertion")
endif()
string(TOLOWER "assert${CMAKE_MATCH_1}" generic)

file(MAKE_DIRECTORY "${WORK_DIR}")
set(generated "${WORK_DIR}/${name}.F90")
execute_process(COMMAND ${PARSER} "${PF_FILE}" "${generated}"
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${name}: the .pf parser refused the file itself (it must be valid .pf "
                      "syntax; only the call is wrong):\n${out}${err}")
endif()
execute_process(COMMAND "${COMPILER}" -c -I "${MODULE_DIR}" -J "${WORK_DIR}" "${generated}"
                        -o "${WORK_DIR}/${name}.o"
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(output "${out}${err}")
if(status EQUAL 0)
  message(FATAL_ERROR "${name}: compiled, but pFUnit 4 rejects ${construct}")
endif()
if(NOT output MATCHES "no specific subroutine for the generic [^ ]*${generic}[^a-z_]")
  message(FATAL_ERROR "${name}: did not compile, but not for want of a specific '${generic}':\n${output}")
endif()
message(STATUS "${name}: refused as pFUnit refuses it: ${construct}")
