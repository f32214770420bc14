# Fortran compiler flags. Included from the top level before any target exists, so
# add_compile_options() reaches every Fortran target of the project (C sources are untouched).
#
# Why these flags:
#   -ffp-contract=off   no fused multiply-add: results must not depend on what got inlined, the
#                       single-file Abaqus build must match our library bit for bit, and Abaqus
#                       itself compiles user subroutines without FMA.
#   -ffree-line-length-none   generated test sources and long VUMAT argument lists.
#   Debug               catch bad indices, NaN production and uninitialised reads early:
#                       -finit-real=snan turns a read of an unset real into an FP trap.
#
# -fimplicit-none is NOT global: Abaqus user code includes vaba_param.inc, whose
# `implicit double precision (a-h,o-z)` relies on the default i-n integer rule, which
# -fimplicit-none removes (gfortran then rejects `nblock`). Targets that are pure modern
# Fortran opt in with bulkflow_require_implicit_none(<target>...).

if(NOT CMAKE_Fortran_COMPILER_ID STREQUAL "GNU")
  message(WARNING "bulkflow's flags are written for gfortran; ${CMAKE_Fortran_COMPILER_ID} "
                  "builds use CMake's defaults only.")
  function(bulkflow_require_implicit_none)
  endfunction()
  return()
endif()

#   -nostdinc           keeps gfortran from pre-including glibc's math-vector-fortran.h, which
#                       declares pow, exp, cos, ... SIMD-callable: vectorised loops then call
#                       libmvec's variants, which differ from scalar libm in the last bits and
#                       between SSE and AVX2 (C3D8R's hourglass |V|^(2/3): an AVX2 and a baseline
#                       build drifted apart, and a point's result depended on its lane in the
#                       block). Our include files come by -I; the compiler's own intrinsic
#                       modules (ieee_arithmetic, ...) by -fintrinsic-modules-path, which
#                       -nostdinc would otherwise drop.
set(_bf_fortran_all -Wall -Wextra -ffree-line-length-none -ffp-contract=off)
execute_process(COMMAND ${CMAKE_Fortran_COMPILER} -print-file-name=finclude
                OUTPUT_VARIABLE _bf_finclude OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(IS_DIRECTORY "${_bf_finclude}")
  list(APPEND _bf_fortran_all -nostdinc -fintrinsic-modules-path=${_bf_finclude})
else()
  message(STATUS "bulkflow: no finclude directory from ${CMAKE_Fortran_COMPILER}: glibc's SIMD math "
                 "declarations stay in (results may differ in the last bits between instruction sets)")
endif()

# Instruction set of optimised builds. The hot loops run over blocks of points (the VUMAT nblock
# layout) and vectorise; AVX2 (x86-64-v3: every x86 server CPU since about 2015) holds four
# doubles where baseline x86-64 holds two: 1.2x CPE4R and 1.4x C3D8R Mohr-Coulomb element-steps/s
# (scripts/bench_solver.py part 4 runs both builds). Results do not change: -ffp-contract=off keeps
# FMA out and nothing reassociates, so an x86-64-v3 build and a baseline build agree bit for bit
# (checked by the benchmark on its scenes). BULKFLOW_ARCH=auto takes x86-64-v3 when the compiler
# accepts it and this machine runs it, else the compiler's default; give any -march value
# instead (e.g. x86-64 for a binary that must run on older nodes of a cluster), or "default".
set(BULKFLOW_ARCH "auto" CACHE STRING "-march of optimised builds: auto, default, or a -march value")
if(BULKFLOW_NATIVE)
  set(_bf_march native)
elseif(BULKFLOW_ARCH STREQUAL "auto")
  include(CheckFortranSourceRuns)
  set(CMAKE_REQUIRED_FLAGS -march=x86-64-v3)
  check_fortran_source_runs("program p\n  real(8) :: x(8) = 1\n  if (sum(x * 2) /= 16) stop 1\nend program p"
                            BULKFLOW_HOST_RUNS_X86_64_V3 SRC_EXT F90)
  unset(CMAKE_REQUIRED_FLAGS)
  if(BULKFLOW_HOST_RUNS_X86_64_V3)
    set(_bf_march x86-64-v3)
  endif()
elseif(NOT BULKFLOW_ARCH STREQUAL "default" AND NOT BULKFLOW_ARCH STREQUAL "")
  set(_bf_march ${BULKFLOW_ARCH})
endif()
if(BULKFLOW_WERROR)
  list(APPEND _bf_fortran_all -Werror)
endif()
set(_bf_fortran_release -O3 -funroll-loops)
if(_bf_march)
  list(APPEND _bf_fortran_release -march=${_bf_march})
endif()
set(_bf_fortran_debug
  -O0 -g -fbacktrace -fcheck=all -ffpe-trap=invalid,zero,overflow
  -finit-real=snan -finit-integer=-99999999)

# Quoted, so each list stays inside its generator expression; the ";" between flags splits them
# into separate arguments once the expression is evaluated.
add_compile_options(
  "$<$<COMPILE_LANGUAGE:Fortran>:${_bf_fortran_all}>"
  "$<$<AND:$<COMPILE_LANGUAGE:Fortran>,$<CONFIG:Release,RelWithDebInfo>>:${_bf_fortran_release}>"
  "$<$<AND:$<COMPILE_LANGUAGE:Fortran>,$<CONFIG:Debug>>:${_bf_fortran_debug}>")

# bulkflow_require_implicit_none(<target>...): reject any implicitly typed name in the target's
# Fortran sources, as if every scope said `implicit none`.
function(bulkflow_require_implicit_none)
  foreach(target IN LISTS ARGN)
    target_compile_options(${target} PRIVATE "$<$<COMPILE_LANGUAGE:Fortran>:-fimplicit-none>")
  endforeach()
endfunction()

# Link-time optimisation in optimised builds: the material kernels live in one module per
# concept and are called per material point, so without LTO nothing is inlined across modules
# (measured: +25 % plane-strain Mohr-Coulomb updates/s). Results do not change (no FMA).
option(BULKFLOW_LTO "Link-time optimisation (inlining across modules) in Release builds" ON)
if(BULKFLOW_LTO)
  include(CheckIPOSupported)
  check_ipo_supported(RESULT _bf_ipo_ok OUTPUT _bf_ipo_msg LANGUAGES Fortran)
  if(_bf_ipo_ok)
    set(CMAKE_INTERPROCEDURAL_OPTIMIZATION_RELEASE ON)
    set(CMAKE_INTERPROCEDURAL_OPTIMIZATION_RELWITHDEBINFO ON)
  else()
    message(STATUS "bulkflow: link-time optimisation not available: ${_bf_ipo_msg}")
  endif()
endif()

if(NOT _bf_march)
  set(_bf_march "compiler default")
endif()
message(STATUS "bulkflow: build type ${CMAKE_BUILD_TYPE}, optimised builds -march=${_bf_march}, "
               "werror=${BULKFLOW_WERROR}")
