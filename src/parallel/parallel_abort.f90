!> How an error on one rank ends every rank: the stop handlers bulkflow installs when it runs on
!> several ranks (error_report's final stop, the Abaqus host's XPLB_EXIT). Module procedures, not
!> internal ones of the main program: passing an internal procedure needs a stack trampoline, which
!> made the linker mark the executable's stack executable.
module parallel_abort
  use mpi_f08, only: MPI_Abort, MPI_COMM_WORLD
  implicit none
  private

  public :: abort_all, abort_all_status

contains

  subroutine abort_all()
    call MPI_Abort(MPI_COMM_WORLD, 2)
  end subroutine abort_all

  subroutine abort_all_status(status)
    integer, intent(in) :: status
    call MPI_Abort(MPI_COMM_WORLD, status)
  end subroutine abort_all_status
end module parallel_abort
