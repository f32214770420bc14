# Run both replays and require byte-identical outputs.
foreach(kind library single)
  if(kind STREQUAL "library")
    set(exe "${LIBRARY_EXE}")
  else()
    set(exe "${SINGLE_EXE}")
  endif()
  execute_process(COMMAND "${exe}" "${WORK_DIR}/replay_${kind}.bin"
                  RESULT_VARIABLE status ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${kind} replay failed (${status}): ${err}")
  endif()
endforeach()
file(SIZE "${WORK_DIR}/replay_library.bin" size)
if(size EQUAL 0)
  message(FATAL_ERROR "replay wrote nothing")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files
                "${WORK_DIR}/replay_library.bin" "${WORK_DIR}/replay_single.bin"
                RESULT_VARIABLE differ)
if(NOT differ EQUAL 0)
  message(FATAL_ERROR "library and single-file VUMAT results differ")
endif()
message(STATUS "identical: ${size} bytes")
