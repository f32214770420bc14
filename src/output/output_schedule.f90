!> When a step writes field frames and history rows: one rule for the element driver and the
!> material-point solver (issue 18; docs/output_format.md "Output schedule").
!>
!> Each *OUTPUT request of the step has its own schedule, as Abaqus/Explicit keeps one per
!> request (Abaqus Analysis User's Guide, "Output to the output database", and the *OUTPUT
!> keyword: NUMBER INTERVAL=n writes at n evenly spaced times of the step, TIME INTERVAL=t at
!> every multiple of t, FREQUENCY=n every n-th increment; each also at the step's end, and the
!> step's initial state is its first frame):
!>   TIME INTERVAL=t     the first increment end at or past each multiple of t in step time
!>   NUMBER INTERVAL=n   the same with t = period/n
!>   FREQUENCY=n         every n-th increment of the step
!>   TIME POINTS=name    the increment ending on a listed step time (the element driver cuts its
!>                       increments onto them; such a request is due at the listed times only,
!>                       not at the step's start and end unless listed)
!>   every other request the step's start (step time 0, increment 0) and its end
!> A frame (row) is written after an increment when at least one request of its kind is due:
!> the union of the requests' times, one frame holding what the step asks for. A step without
!> a history request writes rows at period/200 (the history default of *OUTPUT); a step without
!> a field request writes no frames.
!> "At or past": within 1e-9·max(period, Δt) of the time (the step time is a sum of
!> increments, so a time hit exactly in exact arithmetic may be missed by round-off).
!> A request's next time is only ever advanced by adding its interval, so the schedule of a
!> restarted run is rebuilt from the step time alone (schedule_resume) bit for bit.
module output_schedule
  use base_kinds, only: dp
  use model_steps, only: step_t
  implicit none
  private

  !> History rows of a step without history requests: period / this.
  integer, parameter, public :: default_history_rows = 200

  type, public :: output_schedule_t
     integer :: n = 0                         !< requests
     real(dp) :: period = 0
     real(dp), allocatable :: interval(:)     !< step-time interval of a timed request, else 0
     integer, allocatable :: frequency(:)     !< increments between outputs of a FREQUENCY request, else 0
     real(dp), allocatable :: next(:)         !< next step time of a timed request
     logical, allocatable :: listed(:)        !< a TIME POINTS request (due at its listed times only)
     real(dp), allocatable :: points(:)       !< the listed step times of all TIME POINTS requests
  end type output_schedule_t

  public :: field_schedule, history_schedule, schedule_from_requests, schedule_due, schedule_advance, &
       schedule_resume, schedule_list_times

contains

  !> The schedule of the step's field requests.
  subroutine field_schedule(step, sch)
    type(step_t), intent(in) :: step
    type(output_schedule_t), intent(out) :: sch
    integer :: j

    if (allocated(step%field_outputs)) then
       call schedule_from_requests(step%period, step%field_outputs%time_interval, &
            step%field_outputs%number_interval, step%field_outputs%frequency, sch)
       do j = 1, sch%n   ! TIME POINTS= requests
          if (allocated(step%field_outputs(j)%time_points)) &
               call schedule_list_times(sch, j, step%field_outputs(j)%time_points)
       end do
    else
       call schedule_from_requests(step%period, [real(dp) ::], [integer ::], [integer ::], sch)
    end if
  end subroutine field_schedule

  !> The schedule of the step's history requests; without any, every period/200.
  subroutine history_schedule(step, sch)
    type(step_t), intent(in) :: step
    type(output_schedule_t), intent(out) :: sch
    integer :: j

    if (allocated(step%history_outputs)) then
       if (size(step%history_outputs) > 0) then
          call schedule_from_requests(step%period, step%history_outputs%time_interval, &
               step%history_outputs%number_interval, step%history_outputs%frequency, sch)
          do j = 1, sch%n   ! TIME POINTS= requests
             if (allocated(step%history_outputs(j)%time_points)) &
                  call schedule_list_times(sch, j, step%history_outputs(j)%time_points)
          end do
          return
       end if
    end if
    call schedule_from_requests(step%period, [0.0_dp], [default_history_rows], [0], sch)
  end subroutine history_schedule

  !> Request j writes at the step times `times` only (TIME POINTS=); an empty list changes nothing.
  pure subroutine schedule_list_times(sch, j, times)
    type(output_schedule_t), intent(inout) :: sch
    integer, intent(in) :: j
    real(dp), intent(in) :: times(:)

    if (size(times) == 0) return
    sch%listed(j) = .true.
    sch%points = [sch%points, times]
  end subroutine schedule_list_times

  !> One schedule per request j: TIME INTERVAL time_interval(j) > 0, else NUMBER INTERVAL
  !> number_interval(j) > 0, else FREQUENCY frequency(j) > 0; a request with none of them is
  !> due every increment (FREQUENCY=1).
  subroutine schedule_from_requests(period, time_interval, number_interval, frequency, sch)
    real(dp), intent(in) :: period
    real(dp), intent(in) :: time_interval(:)
    integer, intent(in) :: number_interval(:), frequency(:)
    type(output_schedule_t), intent(out) :: sch
    integer :: j

    sch%n = size(time_interval)
    sch%period = period
    allocate (sch%interval(sch%n), sch%frequency(sch%n), sch%next(sch%n), sch%listed(sch%n), sch%points(0))
    sch%listed = .false.
    do j = 1, sch%n
       sch%interval(j) = 0
       sch%frequency(j) = 0
       if (time_interval(j) > 0) then
          sch%interval(j) = time_interval(j)
       else if (number_interval(j) > 0) then
          sch%interval(j) = period / number_interval(j)
       else
          sch%frequency(j) = max(1, frequency(j))
       end if
       sch%next(j) = sch%interval(j)
    end do
  end subroutine schedule_from_requests

  !> Is an output due after increment `step_increment` of the step (0: the step's start), at
  !> step time `step_time`, the increment having been `dt`?
  pure logical function schedule_due(sch, step_time, step_increment, dt) result(due)
    type(output_schedule_t), intent(in) :: sch
    real(dp), intent(in) :: step_time, dt
    integer, intent(in) :: step_increment
    real(dp) :: t_prev, tol
    logical :: boundary
    integer :: j

    due = .false.
    if (sch%n == 0) return
    boundary = step_increment == 0 .or. step_time >= sch%period * (1 - 1.0e-12_dp)
    do j = 1, sch%n
       if (sch%listed(j)) cycle
       if (boundary) then
          due = .true.
       else if (sch%interval(j) > 0) then
          due = step_time >= sch%next(j) - 1.0e-9_dp * max(sch%period, dt)
       else
          due = mod(step_increment, sch%frequency(j)) == 0
       end if
       if (due) return
    end do
    if (size(sch%points) == 0) return
    ! a listed time in (t_prev, t] (at the step's start: t itself), within 1e-9·period
    tol = 1.0e-9_dp * sch%period
    t_prev = merge(-huge(1.0_dp), step_time - dt, step_increment == 0)
    due = any(sch%points > t_prev + tol .and. sch%points <= step_time + tol)
  end function schedule_due

  !> After an output at step time `step_time`: every timed request's next time past it.
  pure subroutine schedule_advance(sch, step_time)
    type(output_schedule_t), intent(inout) :: sch
    real(dp), intent(in) :: step_time
    integer :: j

    do j = 1, sch%n
       if (.not. sch%interval(j) > 0) cycle
       do while (sch%next(j) <= step_time + 1.0e-9_dp * sch%period)
          sch%next(j) = sch%next(j) + sch%interval(j)
       end do
    end do
  end subroutine schedule_advance

  !> A fresh schedule continued at step time `step_time` (a restart): the same next times as the
  !> run that got there, which advanced them by the same additions.
  pure subroutine schedule_resume(sch, step_time)
    type(output_schedule_t), intent(inout) :: sch
    real(dp), intent(in) :: step_time

    call schedule_advance(sch, step_time)
  end subroutine schedule_resume
end module output_schedule
