!> Agreement on errors between the ranks of a communicator.
!>
!> The output routines are collective: when one rank finds a problem (a bad argument, a
!> restart file that does not match) and returned alone, the others would wait forever in the
!> next collective call. So every check ends with `agree_on_error`: all ranks learn whether
!> any rank failed, and all receive the message of the lowest failing rank, so the caller
!> sees the same error everywhere and can stop cleanly.
module output_collective
  use, intrinsic :: iso_fortran_env, only: error_unit
  use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Allreduce, MPI_Bcast, &
       MPI_IN_PLACE, MPI_INTEGER, MPI_CHARACTER, MPI_MIN, MPI_Finalize
  use error_report, only: error_t
  implicit none
  private

  public :: agree_on_error, stop_agreed_error

contains

  !> `failed` and `message` are this rank's; on return `any_failed` is the same on every rank
  !> and, when true, `message` holds the lowest failing rank's message on every rank (and
  !> `file`, when given, that rank's file name: ranks may have files of their own).
  subroutine agree_on_error(comm, failed, message, any_failed, file)
    type(MPI_Comm), intent(in) :: comm
    logical, intent(in) :: failed
    character(len=:), allocatable, intent(inout) :: message
    logical, intent(out) :: any_failed
    character(len=:), allocatable, intent(inout), optional :: file
    integer :: rank, nranks, first

    call MPI_Comm_rank(comm, rank)
    call MPI_Comm_size(comm, nranks)
    first = nranks
    if (failed) first = rank
    call MPI_Allreduce(MPI_IN_PLACE, first, 1, MPI_INTEGER, MPI_MIN, comm)
    any_failed = first < nranks
    if (.not. any_failed) return

    if (rank == first .and. .not. allocated(message)) message = 'unspecified error'
    call broadcast_text(message)
    if (present(file)) then
       if (rank == first .and. .not. allocated(file)) file = ''
       call broadcast_text(file)
    end if

  contains

    subroutine broadcast_text(text)
      character(len=:), allocatable, intent(inout) :: text
      integer :: n

      n = 0
      if (rank == first) n = len(text)
      call MPI_Bcast(n, 1, MPI_INTEGER, first, comm)
      if (rank /= first) then
         if (allocated(text)) deallocate (text)
         allocate (character(len=n) :: text)
      end if
      if (n > 0) call MPI_Bcast(text, n, MPI_CHARACTER, first, comm)
    end subroutine broadcast_text

  end subroutine agree_on_error

  !> End a run on an error every rank of comm knows alike (agreed, or found by all from the
  !> same data, such as a restart that cannot continue): rank 0 says it once, all ranks leave
  !> MPI cleanly, exit status 2 without a backtrace — where an error on one rank alone must
  !> abort them all (error_report's final stop), with MPI's abort banner and every rank's copy.
  subroutine stop_agreed_error(comm, err)
    type(MPI_Comm), intent(in) :: comm
    type(error_t), intent(in) :: err
    integer :: rank

    call MPI_Comm_rank(comm, rank)
    if (rank == 0) then
       if (allocated(err%message)) then
          write (error_unit, '(a)') 'bulkflow: error: ' // err%message
       else
          write (error_unit, '(a)') 'bulkflow: error: unspecified error'
       end if
       flush (error_unit)
    end if
    call MPI_Finalize()
    error stop 2, quiet=.true.
  end subroutine stop_agreed_error

end module output_collective
