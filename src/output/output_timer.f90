!> Wall-time accounting per named phase (an effect, the element loop, output, ...), and the
!> timing report of a run: each phase's time and its share of the run's wall time.
!>
!>   call timer_init(t)                          ! the run's clock starts here
!>   call timer_register(t, 'contact', id_contact)
!>   call timer_start(t, id_contact) ... call timer_stop(t, id_contact)
!>   call timer_report(t, output_unit, comm)     ! collective with comm; rank 0 prints
!>
!> Ids are small integers handed out by name, so the hot loop does no string work. The
!> clock is system_clock with 64-bit counts (nanoseconds on Linux). Shares are relative to
!> the time since timer_init; when phases do not overlap, a last row "other" shows the time
!> spent outside all of them (nested phases are allowed, but then shares add up to more than
!> 100 % and no "other" row is printed). With a communicator, each phase shows the maximum
!> over ranks (the slowest rank sets the pace) and the mean (the gap is load imbalance);
!> shares are those of the mean, so that they add up to 100 %. All ranks must register the
!> same names in the same order.
module output_timer
  use, intrinsic :: iso_fortran_env, only: int64
  use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Allreduce, MPI_IN_PLACE, &
       MPI_DOUBLE_PRECISION, MPI_INTEGER, MPI_MAX, MPI_MIN, MPI_SUM
  use base_kinds, only: dp
  use error_report, only: raise_error
  implicit none
  private

  public :: timer_set_t, timer_init, timer_register, timer_start, timer_stop
  public :: timer_seconds, timer_report, clock_text

  integer, parameter :: name_length = 32

  !> A set of phase timers (components private).
  type :: timer_set_t
     private
     integer :: n = 0
     character(len=name_length), allocatable :: names(:)
     real(dp), allocatable :: seconds(:)
     integer(int64), allocatable :: started(:)
     integer(int64), allocatable :: calls(:)
     logical, allocatable :: running(:)
     integer(int64) :: t0 = 0
  end type timer_set_t

contains

  !> Forget all phases and start the run's clock.
  subroutine timer_init(t)
    type(timer_set_t), intent(out) :: t

    allocate (t%names(16), t%seconds(16), t%started(16), t%calls(16), t%running(16))
    t%n = 0
    t%t0 = clock()
  end subroutine timer_init

  !> The id of phase `name`, registering it on first use.
  subroutine timer_register(t, name, id)
    type(timer_set_t), intent(inout) :: t
    character(len=*), intent(in) :: name
    integer, intent(out) :: id
    character(len=name_length), allocatable :: names(:)
    real(dp), allocatable :: seconds(:)
    integer(int64), allocatable :: started(:), calls(:)
    logical, allocatable :: running(:)
    integer :: m

    if (.not. allocated(t%names)) call timer_init(t)
    do id = 1, t%n
       if (t%names(id) == name) return
    end do
    if (t%n == size(t%names)) then
       m = 2 * size(t%names)
       allocate (names(m), seconds(m), started(m), calls(m), running(m))
       names(:t%n) = t%names(:t%n)
       seconds(:t%n) = t%seconds(:t%n)
       started(:t%n) = t%started(:t%n)
       calls(:t%n) = t%calls(:t%n)
       running(:t%n) = t%running(:t%n)
       call move_alloc(names, t%names)
       call move_alloc(seconds, t%seconds)
       call move_alloc(started, t%started)
       call move_alloc(calls, t%calls)
       call move_alloc(running, t%running)
    end if
    t%n = t%n + 1
    id = t%n
    t%names(id) = name
    t%seconds(id) = 0.0_dp
    t%started(id) = 0
    t%calls(id) = 0
    t%running(id) = .false.
  end subroutine timer_register

  subroutine timer_start(t, id)
    type(timer_set_t), intent(inout) :: t
    integer, intent(in) :: id

    call check_id(t, id, 'timer_start')
    if (t%running(id)) call raise_error('timer_start', 0, 'phase "' // trim(t%names(id)) // &
         '" is already running')
    t%running(id) = .true.
    t%started(id) = clock()
  end subroutine timer_start

  subroutine timer_stop(t, id)
    type(timer_set_t), intent(inout) :: t
    integer, intent(in) :: id
    integer(int64) :: now

    now = clock()
    call check_id(t, id, 'timer_stop')
    if (.not. t%running(id)) call raise_error('timer_stop', 0, 'phase "' // &
         trim(t%names(id)) // '" is not running')
    t%running(id) = .false.
    t%seconds(id) = t%seconds(id) + seconds_between(t%started(id), now)
    t%calls(id) = t%calls(id) + 1
  end subroutine timer_stop

  !> Accumulated seconds of a phase on this rank (a running phase counts up to now).
  real(dp) function timer_seconds(t, id)
    type(timer_set_t), intent(in) :: t
    integer, intent(in) :: id

    call check_id(t, id, 'timer_seconds')
    timer_seconds = t%seconds(id)
    if (t%running(id)) timer_seconds = timer_seconds + seconds_between(t%started(id), clock())
  end function timer_seconds

  !> Print the table on `unit`. With `comm`: collective, times reduced over ranks, rank 0
  !> prints.
  subroutine timer_report(t, unit, comm)
    type(timer_set_t), intent(in) :: t
    integer, intent(in) :: unit
    type(MPI_Comm), intent(in), optional :: comm
    real(dp), allocatable :: tmax(:), tmean(:)
    integer(int64), allocatable :: calls(:)
    real(dp) :: total, other
    integer :: i, rank, nranks, n, nmin

    n = t%n
    allocate (tmax(n + 1), tmean(n + 1), calls(n))
    do i = 1, n
       tmax(i) = timer_seconds(t, i)
       calls(i) = t%calls(i)
    end do
    tmax(n + 1) = seconds_between(t%t0, clock())
    tmean = tmax
    rank = 0
    nranks = 1
    if (present(comm)) then
       call MPI_Comm_rank(comm, rank)
       call MPI_Comm_size(comm, nranks)
       nmin = n
       call MPI_Allreduce(MPI_IN_PLACE, nmin, 1, MPI_INTEGER, MPI_MIN, comm)
       if (nmin /= n) call raise_error('timer_report', 0, 'ranks registered different phases')
       call MPI_Allreduce(MPI_IN_PLACE, tmax, n + 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
       call MPI_Allreduce(MPI_IN_PLACE, tmean, n + 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
       tmean = tmean / nranks
    end if
    if (rank /= 0) return

    ! Shares of the mean rank's time, so that phases and "other" add up to 100 %.
    total = tmean(n + 1)
    if (nranks > 1) then
       write (unit, '(a, i0, a)') 'timing (wall seconds, max and mean over ', nranks, ' ranks):'
       write (unit, '(2x, a, 2a12, a9, a12)') column('phase'), 'max', 'mean', 'share', 'calls'
    else
       write (unit, '(a)') 'timing (wall seconds):'
       write (unit, '(2x, a, a12, a9, a12)') column('phase'), 'time', 'share', 'calls'
    end if
    do i = 1, n
       if (nranks > 1) then
          write (unit, '(2x, a, 2f12.3, f7.1, a2, i12)') t%names(i), tmax(i), tmean(i), &
               share(tmean(i)), ' %', calls(i)
       else
          write (unit, '(2x, a, f12.3, f7.1, a2, i12)') t%names(i), tmean(i), share(tmean(i)), &
               ' %', calls(i)
       end if
    end do
    other = total - sum(tmean(1:n))
    if (other >= 0.0_dp) then
       if (nranks > 1) then
          write (unit, '(2x, a, 12x, f12.3, f7.1, a2)') column('other'), other, share(other), ' %'
       else
          write (unit, '(2x, a, f12.3, f7.1, a2)') column('other'), other, share(other), ' %'
       end if
    end if
    if (nranks > 1) then
       write (unit, '(2x, a, 2f12.3)') column('total'), tmax(n + 1), total
    else
       write (unit, '(2x, a, f12.3)') column('total'), total
    end if

  contains

    pure real(dp) function share(x)
      real(dp), intent(in) :: x

      share = 0.0_dp
      if (total > 0.0_dp) share = 100.0_dp * x / total
    end function share

    !> A left-aligned name column (an `a32` edit would right-align a shorter literal).
    pure function column(text) result(padded)
      character(len=*), intent(in) :: text
      character(len=name_length) :: padded

      padded = text
    end function column

  end subroutine timer_report

  subroutine check_id(t, id, what)
    type(timer_set_t), intent(in) :: t
    integer, intent(in) :: id
    character(len=*), intent(in) :: what

    if (id < 1 .or. id > t%n) call raise_error(what, 0, 'unknown timer id (register it first)')
  end subroutine check_id

  integer(int64) function clock()
    call system_clock(clock)
  end function clock

  real(dp) function seconds_between(from, to)
    integer(int64), intent(in) :: from
    integer(int64), intent(in) :: to
    integer(int64) :: rate

    call system_clock(count_rate=rate)
    seconds_between = real(to - from, dp) / real(rate, dp)
  end function seconds_between

  !> A duration as h:mm:ss (progress lines' ETA).
  function clock_text(seconds) result(text)
    real(dp), intent(in) :: seconds
    character(len=:), allocatable :: text
    character(len=32) :: buf
    integer :: s

    s = nint(min(seconds, 3.6e7_dp))
    write (buf, '(i0,a,i2.2,a,i2.2)') s / 3600, ':', mod(s / 60, 60), ':', mod(s, 60)
    text = trim(buf)
  end function clock_text
end module output_timer
