!> The one step loop of every scene (issue 18): `run_scene` runs a technique (technique_t: the
!> element solver or the MPM) through the scene's steps, increment by increment, and owns what
!> the two techniques share:
!>   - the increment's length: the technique's stable (or fixed) increment, never past the end of
!>     the step, cut to end exactly on the next TIME POINTS output time;
!>   - the output schedule (output_schedule: one rule for frames and history rows of both);
!>   - the *STOP CONDITION evaluation (every stop_check_stride increments and at the step's end);
!>   - checkpoints (*RESTART, WRITE intervals, --stop-after) and the restart (--restart);
!>   - the progress line, the header's restart line and the end report's first lines;
!>   - the run's effects registry (technique_t%effects, output_effects): its clock, the output and
!>     checkpoint effects after the technique's own, their wall time, the timing table;
!>   - the outputs of a --stop-after stop: one rule for both techniques, below.
!> The order within an increment: the increment, its scheduled frame and row, the checkpoint,
!> the extra row and frame of a --stop-after stop, the progress line, the stop condition. The
!> checkpoint follows the increment's own outputs and precedes a stop's extra ones, so a restart
!> drops those (it keeps the frames and rows the checkpoint counted).
!>
!> The --stop-after rule: the run writes a history row and a field frame of the stopping
!> increment unless the schedule wrote them there already. Why: a user who stops a run early
!> wants its last state, as a *STOP CONDITION stop and the end of every step (Abaqus writes the
!> last increment of a step whatever the output interval) give it; the stop's outputs are
!> made after its checkpoint, so a --restart continues as if there had been no stop.
module run_loop
  use, intrinsic :: iso_fortran_env, only: output_unit
  use mpi_f08, only: MPI_Comm
  use base_kinds, only: dp
  use model, only: model_t
  use output_schedule, only: output_schedule_t, field_schedule, history_schedule, schedule_due, &
       schedule_advance, schedule_resume
  use parallel_comm, only: comm_rank, comm_size
  use output_effects, only: effect_output, effect_checkpoint
  use run_technique, only: technique_t, run_options_t, run_clock_t
  use run_progress, only: progress_t, progress_begin, progress_line, progress_step_done, progress_seconds
  implicit none
  private

  !> A *STOP CONDITION is evaluated every this many increments of its step (and at the step
  !> end): its exact global sum costs about a tenth of an increment of a small 2D model.
  integer, parameter :: stop_check_stride = 10

  public :: run_scene, checkpoint_due, next_time_point, cut_increment

contains

  subroutine run_scene(tech, m, comm, opts)
    class(technique_t), intent(inout) :: tech
    type(model_t), intent(in) :: m
    type(MPI_Comm), intent(in) :: comm
    type(run_options_t), intent(in) :: opts
    type(output_schedule_t) :: field, history
    type(progress_t) :: progress
    type(run_clock_t) :: c
    integer :: istep, first_step
    logical :: resumed, stop_now, condition_met
    real(dp) :: period

    tech%comm = comm
    tech%rank = comm_rank(comm)
    tech%nranks = comm_size(comm)
    call tech%effects%init()
    call tech%setup(m)
    call tech%effects%declare(effect_output, 'output', active=.true.)
    call tech%effects%declare(effect_checkpoint, 'checkpoint', &
         active=any(m%steps(1:m%n_steps)%restart_write) .or. opts%stop_after > 0)
    resumed = opts%restart
    if (resumed) then
       call tech%load(m, opts)
    else
       call tech%open_outputs(m, opts)
    end if
    call tech%header(m, opts)
    c = tech%clock()
    if (resumed .and. tech%rank == 0) then
       write (output_unit, '(a,i0,a,es12.5)') '  restart   from increment ', c%increment, ' at t = ', c%total_time
       flush (output_unit)
    end if
    first_step = 1
    if (resumed) first_step = c%step
    call progress_begin(progress, opts%progress .and. tech%rank == 0, c)

    stop_now = .false.
    condition_met = .false.
    do istep = first_step, m%n_steps
       period = m%steps(istep)%period
       call tech%step_start(m, istep, resumed)
       call field_schedule(m%steps(istep), field)
       call history_schedule(m%steps(istep), history)
       c = tech%clock()
       if (resumed) then
          ! a resumed step continues at the checkpoint's step time and output schedule
          call schedule_resume(field, c%step_time)
          call schedule_resume(history, c%step_time)
       else
          ! the step's first frame and row: its initial state
          call scheduled_outputs(tech, m, istep, c, field, history)
       end if
       resumed = .false.

       do while (c%step_time < period * (1 - 1.0e-12_dp))
          call one_increment(tech, m, istep, c)
          stop_now = opts%stop_after > 0 .and. c%increment >= opts%stop_after
          call increment_end(tech, m, opts, istep, c, field, history, stop_now)
          call progress_line(progress, m, c, tech)
          if (stop_now) exit
          if (m%steps(istep)%stop%active) then
             if (mod(c%step_increment, stop_check_stride) == 0 .or. c%step_time >= period * (1 - 1.0e-12_dp)) then
                if (tech%stop_condition(m, istep)) then
                   ! the last row and frame at the moment of the decision
                   call tech%history(m, istep)
                   call tech%frame(m, istep)
                   condition_met = .true.
                   exit
                end if
             end if
          end if
       end do
       if (.not. stop_now) then
          call progress_step_done(progress, m, c)
          call tech%step_end(m, istep)
       end if
       if (stop_now .or. condition_met) exit
    end do
    tech%loop_seconds = progress_seconds(progress)

    call tech%close_outputs()
    if (tech%rank == 0) then
       if (stop_now) write (output_unit, '(a,i0,a)') 'bulkflow: stopped after increment ', c%increment, &
            ' as asked (--stop-after); continue with --restart'
       write (output_unit, '(a,i0,a,es12.5)') 'bulkflow: done, ', c%increment, ' increments, t = ', c%total_time
    end if
    call tech%summary(m)
    call tech%effects%report(output_unit, comm)
  end subroutine run_scene

  !> The increment: the technique's Δt cut at the step's end and at a listed output time.
  subroutine one_increment(tech, m, istep, c)
    class(technique_t), intent(inout) :: tech
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(run_clock_t), intent(inout) :: c
    real(dp) :: dt, t_new

    dt = tech%stable_increment(m, istep)
    call cut_increment(m, istep, c%step_time, dt, t_new)
    call tech%increment(m, istep, dt, t_new)
    c = tech%clock()
  end subroutine one_increment

  !> Δt no longer than what is left of the step; with TIME POINTS= output, cut to end exactly on
  !> the next listed time. t_new: the step time at the end of the increment.
  subroutine cut_increment(m, istep, step_time, dt, t_new)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    real(dp), intent(in) :: step_time
    real(dp), intent(inout) :: dt
    real(dp), intent(out) :: t_new
    real(dp) :: t_point

    dt = min(dt, m%steps(istep)%period - step_time)
    t_point = next_time_point(m, istep, step_time, 1.0e-9_dp * m%steps(istep)%period)
    t_new = step_time + dt
    if (t_point - step_time <= dt) then
       dt = t_point - step_time
       t_new = t_point
    end if
  end subroutine cut_increment

  !> After an increment: its scheduled frame and row, the checkpoint (due or a --stop-after
  !> stop), and the row and frame of a --stop-after stop that the schedule did not write.
  subroutine increment_end(tech, m, opts, istep, c, field, history, stop_now)
    class(technique_t), intent(inout) :: tech
    type(model_t), intent(in) :: m
    type(run_options_t), intent(in) :: opts
    integer, intent(in) :: istep
    type(run_clock_t), intent(in) :: c
    type(output_schedule_t), intent(inout) :: field, history
    logical, intent(in) :: stop_now
    logical :: frame_due, row_due

    call scheduled_outputs(tech, m, istep, c, field, history, frame_due, row_due)
    if (stop_now .or. checkpoint_due(m, istep, c%step_time, c%dt)) then
       call tech%effects%start(effect_checkpoint)
       call tech%save(m, opts)
       call tech%effects%stop(effect_checkpoint)
    end if
    if (stop_now) then
       call tech%effects%start(effect_output)
       if (.not. row_due) call tech%history(m, istep)
       if (.not. frame_due) call tech%frame(m, istep)
       call tech%effects%stop(effect_output)
    end if
  end subroutine increment_end

  !> The frame and the history row the schedules ask for now (at a step's start too: step
  !> increment 0), timed as output.
  subroutine scheduled_outputs(tech, m, istep, c, field, history, frame_due, row_due)
    class(technique_t), intent(inout) :: tech
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(run_clock_t), intent(in) :: c
    type(output_schedule_t), intent(inout) :: field, history
    logical, intent(out), optional :: frame_due, row_due
    logical :: fdue, rdue

    call tech%effects%start(effect_output)
    fdue = schedule_due(field, c%step_time, c%step_increment, c%dt)
    rdue = schedule_due(history, c%step_time, c%step_increment, c%dt)
    if (fdue) then
       call tech%frame(m, istep)
       call schedule_advance(field, c%step_time)
    end if
    if (rdue) then
       call tech%history(m, istep)
       call schedule_advance(history, c%step_time)
    end if
    call tech%effects%stop(effect_output)
    if (present(frame_due)) frame_due = fdue
    if (present(row_due)) row_due = rdue
  end subroutine scheduled_outputs

  !> Is a checkpoint due after this increment (*RESTART, WRITE of the step)? At every multiple
  !> of the interval the increment reached or crossed; without an interval at the step's end.
  logical function checkpoint_due(m, istep, step_time, dt) result(due)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    real(dp), intent(in) :: step_time, dt
    real(dp) :: interval, before

    due = .false.
    if (.not. m%steps(istep)%restart_write) return
    interval = m%steps(istep)%restart_interval
    if (interval <= 0) then
       due = step_time >= m%steps(istep)%period * (1 - 1.0e-12_dp)
       return
    end if
    before = step_time - dt
    due = floor(step_time / interval + 1.0e-9_dp) > floor(before / interval + 1.0e-9_dp)
  end function checkpoint_due

  !> The first listed time (TIME POINTS=) of any field or history request of the step after
  !> t + tol; huge when there is none.
  real(dp) function next_time_point(m, istep, t, tol)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    real(dp), intent(in) :: t, tol
    integer :: j

    next_time_point = huge(1.0_dp)
    if (allocated(m%steps(istep)%field_outputs)) then
       do j = 1, size(m%steps(istep)%field_outputs)
          call take(m%steps(istep)%field_outputs(j)%time_points)
       end do
    end if
    if (allocated(m%steps(istep)%history_outputs)) then
       do j = 1, size(m%steps(istep)%history_outputs)
          call take(m%steps(istep)%history_outputs(j)%time_points)
       end do
    end if
  contains
    subroutine take(points)
      real(dp), allocatable, intent(in) :: points(:)
      integer :: k

      if (.not. allocated(points)) return
      do k = 1, size(points)
         if (points(k) > t + tol) then
            next_time_point = min(next_time_point, points(k))
            return
         end if
      end do
    end subroutine take
  end function next_time_point
end module run_loop
