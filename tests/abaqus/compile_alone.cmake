# Compile the generated Abaqus file on its own, as a user would before `abaqus job=... user=`.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
if(NOT EXISTS "${SOURCE}")
  message(FATAL_ERROR "generated Abaqus file not found: ${SOURCE}")
endif()
execute_process(
  COMMAND "${COMPILER}" -ffree-form -ffree-line-length-none -fPIC -c "${SOURCE}" -I "${INCLUDE_DIR}"
          -o "${WORK_DIR}/bulkflow_abaqus.o"
  WORKING_DIRECTORY "${WORK_DIR}"
  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "the single Abaqus file does not compile alone:\n${out}${err}")
endif()
message(STATUS "compiled alone: ${SOURCE}")
