# Assemble the self-contained Abaqus user-subroutine file: every material kernel module in
# dependency order, then vumat and vusdfld, behind one `!DIR$ FREEFORM` line (Intel/Abaqus
# honours it; gfortran needs -ffree-form). Run as:
#   cmake -DOUTPUT=<file> -DSOURCES="<a.f90|b.f90|...>" -P abaqus_single_file.cmake
if(NOT OUTPUT OR NOT SOURCES)
  message(FATAL_ERROR "abaqus_single_file.cmake needs -DOUTPUT and -DSOURCES")
endif()
string(REPLACE "|" ";" SOURCES "${SOURCES}")
set(text "!DIR$ FREEFORM\n")
string(APPEND text "! bulkflow material subroutines for Abaqus/Explicit (VUMAT + VUSDFLD), one file.\n")
string(APPEND text "! Generated from the bulkflow sources; do not edit. Use:\n")
string(APPEND text "!   abaqus job=<job> user=bulkflow_abaqus.f double=both\n")
string(APPEND text "! Material names and props: see umat/README.md of bulkflow.\n")
foreach(src IN LISTS SOURCES)
  file(READ "${src}" body)
  string(REGEX REPLACE "!DIR\\$ FREEFORM\n" "" body "${body}")
  get_filename_component(name "${src}" NAME)
  string(APPEND text "\n! ---- ${name} ----\n${body}")
endforeach()
file(WRITE "${OUTPUT}.tmp" "${text}")
# Only touch the output when it changed, so dependants do not rebuild needlessly.
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUTPUT}.tmp" "${OUTPUT}")
file(REMOVE "${OUTPUT}.tmp")
