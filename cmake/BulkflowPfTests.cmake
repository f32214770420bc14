# Unit tests written in pFUnit's .pf syntax, with or without pFUnit.
#
#   bulkflow_add_pf_test(<file.pf> [LINK_LIBRARIES <lib>...] [LABELS <label>...]
#                        [TIMEOUT <seconds>] [WILL_FAIL])
#
# Builds one executable per .pf file, named after the file (test_foo.pf -> bin/test_foo), and
# registers a CTest test of the same name. With pFUnit installed (find_package(PFUNIT)), that is
# add_pfunit_ctest(); otherwise cmake/pf_preprocess.py expands the directives at build time and
# the test links bulkflow_funit (cmake/funit/), our stand-in for pFUnit's `funit` module.
# cmake/README.md lists the .pf subset both understand.

if(NOT BULKFLOW_PFUNIT_FALLBACK)
  find_package(PFUNIT QUIET)
endif()

set(_BULKFLOW_PF_DIR "${CMAKE_CURRENT_LIST_DIR}")

if(PFUNIT_FOUND AND NOT BULKFLOW_PFUNIT_FALLBACK)
  set(BULKFLOW_PF_BACKEND "pfunit")
  message(STATUS "bulkflow: .pf tests use pFUnit ${PFUNIT_VERSION}")
else()
  set(BULKFLOW_PF_BACKEND "fallback")
  message(STATUS "bulkflow: .pf tests use bulkflow's fallback harness (pFUnit not used)")
  # The typed generics (one specific per combination pFUnit 4 accepts) are generated.
  set(_bulkflow_funit_typed "${CMAKE_BINARY_DIR}/funit_generated/funit_assert_typed.f90")
  add_custom_command(
    OUTPUT "${_bulkflow_funit_typed}"
    COMMAND "${Python3_EXECUTABLE}" "${_BULKFLOW_PF_DIR}/funit_generate.py" "${_bulkflow_funit_typed}"
    DEPENDS "${_BULKFLOW_PF_DIR}/funit_generate.py"
    COMMENT "Generating the fallback harness's typed assertions"
    VERBATIM)
  add_library(bulkflow_funit STATIC
    "${_BULKFLOW_PF_DIR}/funit/funit_core.f90"
    "${_BULKFLOW_PF_DIR}/funit/funit_assert_logical.f90"
    "${_BULKFLOW_PF_DIR}/funit/funit_assert_equal.f90"
    "${_BULKFLOW_PF_DIR}/funit/funit_assert_compare.f90"
    "${_bulkflow_funit_typed}"
    "${_BULKFLOW_PF_DIR}/funit/funit.f90"
    "${_BULKFLOW_PF_DIR}/funit/funit_runner.f90")
  # Out of link-time optimisation: inlined into a test, the harness's type dispatch (class(*) ->
  # one branch per kind) made gfortran 12 warn about the branches a given argument never takes
  # (-Wstringop-overread on an int32 array seen through the int64 branch). Speed is not needed here.
  set_target_properties(bulkflow_funit PROPERTIES
    Fortran_MODULE_DIRECTORY "${CMAKE_BINARY_DIR}/mod/funit"
    INTERPROCEDURAL_OPTIMIZATION OFF INTERPROCEDURAL_OPTIMIZATION_RELEASE OFF
    INTERPROCEDURAL_OPTIMIZATION_RELWITHDEBINFO OFF)
  target_include_directories(bulkflow_funit PUBLIC "${CMAKE_BINARY_DIR}/mod/funit")
  bulkflow_require_implicit_none(bulkflow_funit)
endif()

function(bulkflow_add_pf_test pf_file)
  cmake_parse_arguments(PARSE_ARGV 1 arg "WILL_FAIL" "TIMEOUT" "LINK_LIBRARIES;LABELS")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "bulkflow_add_pf_test(${pf_file}): unknown arguments ${arg_UNPARSED_ARGUMENTS}")
  endif()
  get_filename_component(pf "${pf_file}" ABSOLUTE)
  get_filename_component(name "${pf}" NAME_WE)
  if(NOT arg_TIMEOUT)
    set(arg_TIMEOUT 300)
  endif()

  # A label list given quoted ("unit;mpm") reaches us with its ';' escaped: split it again.
  string(REPLACE "\\;" ";" arg_LABELS "${arg_LABELS}")

  if(BULKFLOW_PF_BACKEND STREQUAL "pfunit")
    # add_pfunit_ctest writes the generated .F90 beside an absolute TEST_SOURCES path (it takes
    # such a path to be in the build tree) and into the binary directory for a relative one.
    file(RELATIVE_PATH pf_relative "${CMAKE_CURRENT_SOURCE_DIR}" "${pf}")
    if(pf_relative MATCHES "^\\.\\./")
      message(FATAL_ERROR "bulkflow_add_pf_test(${pf_file}): the .pf file must be in or below ${CMAKE_CURRENT_SOURCE_DIR}")
    endif()
    add_pfunit_ctest(${name} TEST_SOURCES "${pf_relative}" LINK_LIBRARIES ${arg_LINK_LIBRARIES})
    # pFUnit's generated wrappers are not ours to keep warning-free.
    target_compile_options(${name} PRIVATE "$<$<COMPILE_LANGUAGE:Fortran>:-Wno-error>")
  else()
    # .F90: preprocessed by cpp, as pFUnit's output is, so #include / #ifdef in a .pf work.
    set(generated "${CMAKE_CURRENT_BINARY_DIR}/pf_generated/${name}.F90")
    add_custom_command(
      OUTPUT "${generated}"
      COMMAND "${Python3_EXECUTABLE}" "${_BULKFLOW_PF_DIR}/pf_preprocess.py" "${pf}" "${generated}"
      DEPENDS "${pf}" "${_BULKFLOW_PF_DIR}/pf_preprocess.py"
      COMMENT "Preprocessing ${name}.pf"
      VERBATIM)
    add_executable(${name} "${generated}")
    target_link_libraries(${name} PRIVATE bulkflow_funit ${arg_LINK_LIBRARIES})
    bulkflow_require_implicit_none(${name})
    add_test(NAME ${name} COMMAND ${name})
  endif()

  # Each test compiles its own module (module test_foo): keep the .mod files apart.
  set_target_properties(${name} PROPERTIES
    Fortran_MODULE_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}/mod/${name}")
  set_tests_properties(${name} PROPERTIES TIMEOUT ${arg_TIMEOUT})
  if(arg_LABELS)
    set_tests_properties(${name} PROPERTIES LABELS "${arg_LABELS}")
  endif()
  if(arg_WILL_FAIL)
    set_tests_properties(${name} PROPERTIES WILL_FAIL TRUE)
  endif()
endfunction()
