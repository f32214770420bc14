# External dependencies, found once at the top level so that every subdirectory sees them.
#
# Results for other CMake files:
#   MPI::MPI_Fortran       MPI (MPI_Fortran_HAVE_F08_MODULE tells whether `use mpi_f08` works)
#   MPIEXEC_EXECUTABLE, MPIEXEC_NUMPROC_FLAG, MPIEXEC_PREFLAGS   for add_test(... mpirun ...)
#   bulkflow::hdf5         parallel HDF5, Fortran API (+ C library, include dir of hdf5.mod, MPI)
#   LAPACK::LAPACK         LAPACK and BLAS
#   Python3_EXECUTABLE     the interpreter the scripts chose (pass -DPython3_EXECUTABLE=...)

find_package(MPI REQUIRED COMPONENTS Fortran)

# Debian installs serial and parallel HDF5 side by side; the output layer writes collectively,
# so only the parallel one will do.
set(HDF5_PREFER_PARALLEL TRUE)
find_package(HDF5 REQUIRED COMPONENTS Fortran)
if(NOT HDF5_IS_PARALLEL)
  message(FATAL_ERROR
    "bulkflow needs HDF5 built with MPI (parallel), but the HDF5 found is serial "
    "(HDF5 ${HDF5_VERSION}, libraries: ${HDF5_Fortran_LIBRARIES}). "
    "On Debian: apt-get install libhdf5-openmpi-dev (scripts/setup.sh does it), "
    "or point -DHDF5_DIR / the h5pfc on PATH at a parallel build.")
endif()
# FindHDF5's hdf5::hdf5_fortran does not carry the C library it depends on, so wrap the full
# link line in a target of our own.
add_library(bulkflow_hdf5 INTERFACE)
add_library(bulkflow::hdf5 ALIAS bulkflow_hdf5)
target_include_directories(bulkflow_hdf5 INTERFACE ${HDF5_Fortran_INCLUDE_DIRS})
target_compile_definitions(bulkflow_hdf5 INTERFACE ${HDF5_Fortran_DEFINITIONS})
target_link_libraries(bulkflow_hdf5 INTERFACE ${HDF5_Fortran_LIBRARIES} MPI::MPI_Fortran)

find_package(LAPACK REQUIRED)

# Python runs the .pf preprocessor at build time and the scene checks at test time. FindPython3
# takes a -DPython3_EXECUTABLE given on the command line as the interpreter to use.
find_package(Python3 REQUIRED COMPONENTS Interpreter)

message(STATUS "bulkflow: MPI ${MPI_Fortran_VERSION}, parallel HDF5 ${HDF5_VERSION}, "
               "Python ${Python3_VERSION} (${Python3_EXECUTABLE})")
