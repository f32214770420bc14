!> History CSV: header and rows, numbers read back to 16 digits, and restarts that truncate
!> the rows written after the checkpoint (by time and by row count) before appending; errors
!> (changed columns, too few rows, missing file, bad column name) reach every rank.
!>   usage: test_output_history <output base>
program test_output_history
  use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_COMM_WORLD, MPI_Comm_rank, MPI_Barrier
  use material_kinds, only: dp
  use error_report, only: error_t
  use output_history, only: history_t, history_open, history_row, history_close, history_row_count
  use output_test_support, only: check, check_message, failures_everywhere
  implicit none

  character(len=*), parameter :: columns(4) = [character(len=10) :: 'time', 'ALLKE', 'ALLIE', 'RF2_BOTTOM']
  character(len=512) :: arg
  character(len=:), allocatable :: path
  type(history_t) :: h
  type(error_t) :: err
  integer :: rank, failures, i

  call MPI_Init()
  call MPI_Comm_rank(MPI_COMM_WORLD, rank)
  call get_command_argument(1, arg)
  if (len_trim(arg) == 0) arg = 'output_history'
  path = trim(arg) // '.csv'

  ! The interrupted run: rows at t = 0, 0.1, ..., 0.5.
  call history_open(h, path, columns, MPI_COMM_WORLD, err=err)
  call check(.not. err%raised, 'open')
  do i = 0, 5
     call history_row(h, row(i, 0.0_dp))
  end do
  call check(history_row_count(h) == 6, 'row count on every rank')
  call history_close(h)
  call check_file(6, 6, 'first run')

  ! Restart at t = 0.2: rows after it go, new rows follow.
  call history_open(h, path, columns, MPI_COMM_WORLD, restart_time=2 * 0.1_dp, err=err)
  call check(.not. err%raised, 'restart by time')
  call check(history_row_count(h) == 3, 'restart by time keeps 3 rows (on every rank)')
  do i = 3, 5
     call history_row(h, row(i, 100.0_dp))
  end do
  call history_close(h)
  call check_file(6, 3, 'restart by time')

  ! Restart after row 4 (what a checkpoint records).
  call history_open(h, path, columns, MPI_COMM_WORLD, restart_rows=4, err=err)
  call check(.not. err%raised, 'restart by rows')
  do i = 4, 5
     call history_row(h, row(i, 100.0_dp))
  end do
  call history_close(h)
  call check_file(6, 3, 'restart by rows')

  ! Errors, the same on every rank.
  err = error_t()
  call history_open(h, path, [character(len=10) :: 'time', 'ALLKE'], MPI_COMM_WORLD, &
       restart_rows=1, err=err)
  call check_message(err%raised, err%message, 'header in the file differs', 'changed columns')
  err = error_t()
  call history_open(h, path, columns, MPI_COMM_WORLD, restart_rows=10, err=err)
  call check_message(err%raised, err%message, 'the file holds only 6 rows', 'too few rows')
  call check_file(6, 3, 'file untouched by a failed restart')
  err = error_t()
  call history_open(h, path // '.missing', columns, MPI_COMM_WORLD, restart_rows=1, err=err)
  call check_message(err%raised, err%message, 'does not exist', 'missing file')
  err = error_t()
  call history_open(h, trim(arg) // '_bad.csv', [character(len=10) :: 'time', 'RF,2'], &
       MPI_COMM_WORLD, err=err)
  call check_message(err%raised, err%message, 'has an empty name or one with a comma', 'bad column')

  failures = failures_everywhere()
  if (rank == 0) write (*, '(a, i0)') 'test_output_history: failed checks ', failures
  call MPI_Finalize()
  if (failures > 0) error stop 1

contains

  !> Row i: time 0.1 i and values with many digits (ALLKE shifted by `shift` after a restart).
  function row(i, shift) result(values)
    integer, intent(in) :: i
    real(dp), intent(in) :: shift
    real(dp) :: values(4)

    values = [i * 0.1_dp, shift + 1.5_dp * i + 1.0_dp / 3.0_dp, -i / 7.0_dp, 1.0e-300_dp * i]
  end function row

  !> Rank 0 reads the file: header, n_rows rows, rows >= first_new from the restarted run.
  subroutine check_file(n_rows, first_new, what)
    integer, intent(in) :: n_rows
    integer, intent(in) :: first_new
    character(len=*), intent(in) :: what
    character(len=1024) :: line
    real(dp) :: values(4), expected(4)
    integer :: unit, ios, n

    call MPI_Barrier(MPI_COMM_WORLD)
    if (rank /= 0) return
    open (newunit=unit, file=path, status='old', action='read', iostat=ios)
    call check(ios == 0, what // ': file opens')
    if (ios /= 0) return
    read (unit, '(a)') line
    call check(trim(line) == 'time,ALLKE,ALLIE,RF2_BOTTOM', what // ': header "' // trim(line) // '"')
    n = 0
    do
       read (unit, '(a)', iostat=ios) line
       if (ios /= 0) exit
       call check(index(trim(line), ' ') == 0, what // ': no blanks in "' // trim(line) // '"')
       read (line, *) values
       expected = row(n, merge(100.0_dp, 0.0_dp, n >= first_new))
       call check(all(abs(values - expected) <= 1.0e-15_dp * abs(expected)), &
            what // ': row ' // trim(line))
       n = n + 1
    end do
    close (unit)
    call check(n == n_rows, what // ': number of rows')
  end subroutine check_file

end program test_output_history
