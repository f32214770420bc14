!> Timing report: ids by name, accumulation, the table (collective under MPI, printed by
!> rank 0) with a row per phase, "other" and "total".
!>   usage: test_output_timer <output base>
program test_output_timer
  use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_COMM_WORLD, MPI_Comm_rank, MPI_Comm_size
  use material_kinds, only: dp
  use output_timer, only: timer_set_t, timer_init, timer_register, timer_start, timer_stop, &
       timer_seconds, timer_report
  use output_test_support, only: check, failures_everywhere
  implicit none

  type(timer_set_t) :: t
  character(len=512) :: arg
  character(len=256) :: line
  integer :: rank, nranks, failures, id_a, id_b, id_a2, unit, i, ios
  logical :: seen_a, seen_b, seen_other, seen_total
  real(dp) :: x, seconds_a, seconds_b

  call MPI_Init()
  call MPI_Comm_rank(MPI_COMM_WORLD, rank)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks)
  call get_command_argument(1, arg)
  if (len_trim(arg) == 0) arg = 'output_timer'

  call timer_init(t)
  call timer_register(t, 'elements', id_a)
  call timer_register(t, 'contact', id_b)
  call timer_register(t, 'elements', id_a2)
  call check(id_a == id_a2 .and. id_a /= id_b, 'ids by name')
  x = 0.0_dp
  do i = 1, 20
     call timer_start(t, id_a)
     x = x + busy(20000)
     call timer_stop(t, id_a)
  end do
  call timer_start(t, id_b)
  x = x + busy(20000)
  call timer_stop(t, id_b)
  seconds_a = timer_seconds(t, id_a)
  seconds_b = timer_seconds(t, id_b)
  call check(seconds_a > 0.0_dp .and. seconds_b > 0.0_dp, 'phases accumulate time')
  call check(x > 0.0_dp, 'work done')

  unit = -1      ! only rank 0 prints
  if (rank == 0) open (newunit=unit, file=trim(arg) // '.txt', status='replace', action='write')
  call timer_report(t, unit, MPI_COMM_WORLD)
  if (rank == 0) then
     close (unit)
     seen_a = .false.
     seen_b = .false.
     seen_other = .false.
     seen_total = .false.
     open (newunit=unit, file=trim(arg) // '.txt', status='old', action='read')
     do
        read (unit, '(a)', iostat=ios) line
        if (ios /= 0) exit
        write (*, '(a)') trim(line)
        line = adjustl(line)
        if (line(1:8) == 'elements') then
           seen_a = index(line, '%') > 0 .and. index(line, ' 20') > 0
        end if
        if (line(1:7) == 'contact') seen_b = index(line, '%') > 0
        if (line(1:5) == 'other') seen_other = .true.
        if (line(1:5) == 'total') seen_total = .true.
     end do
     close (unit)
     call check(seen_a, 'report row "elements" with share and 20 calls')
     call check(seen_b, 'report row "contact"')
     call check(seen_other .and. seen_total, 'report rows "other" and "total"')
  end if

  failures = failures_everywhere()
  if (rank == 0) write (*, '(a, i0)') 'test_output_timer: failed checks ', failures
  call MPI_Finalize()
  if (failures > 0) error stop 1

contains

  real(dp) function busy(n)
    integer, intent(in) :: n
    integer :: k

    busy = 0.0_dp
    do k = 1, n
       busy = busy + sqrt(real(k, dp))
    end do
  end function busy

end program test_output_timer
