!> The material point method (src/mpm: MUSL with a PIC/FLIP blend) as a technique of the run
!> skeleton: mpm_technique_t holds the run state of this rank, the particle/grid writer and the
!> history, and wraps the MPM's phase routines; run_loop drives it.
module run_mpm
  use base_kinds, only: dp
  use model, only: model_t
  use mpm_state, only: mpm_state_t
  use mpm_setup, only: mpm_setup_run, mark_wall_nodes
  use mpm_halo, only: whole_grid_shape
  use mpm_musl, only: stable_increment_of => stable_increment
  use mpm_report, only: report_header => header, report_summary => summary, history_columns, measure, &
       write_history, write_frame
  use mpm_output, only: mpm_writer_t, mpm_writer_open, mpm_writer_close, mpm_field_request_t, mpm_field_requests
  use mpm_run, only: mpm_increment, mpm_save, mpm_resume
  use output_history, only: history_t, history_open, history_close
  use run_technique, only: technique_t, run_options_t, run_clock_t
  implicit none
  private

  type, public, extends(technique_t) :: mpm_technique_t
     type(mpm_state_t) :: st
     type(mpm_writer_t) :: wr                      !< particle and grid frames (every rank its blocks)
     type(history_t) :: hist
     character(len=32), allocatable :: columns(:)  !< history columns
     type(mpm_field_request_t) :: fields           !< what a frame holds per particle (SDV, FV, TEMP)
     !> the MDR reference of the last history row (time, mass out)
     real(dp) :: last_row_time = 0, last_row_out = 0
   contains
     procedure :: setup, open_outputs, load, header, step_start, stable_increment, increment, frame, history, &
          save, stop_condition, step_end, clock, progress_note, close_outputs, summary
  end type mpm_technique_t

contains

  subroutine setup(this, m)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m

    this%st%comm = this%comm
    this%st%rank = this%rank
    this%st%nranks = this%nranks
    call mpm_setup_run(m, this%st, this%effects)
    this%fields = mpm_field_requests(m)
    call history_columns(m, this%columns)
  end subroutine setup

  subroutine open_outputs(this, m, opts)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    type(run_options_t), intent(in) :: opts

    if (this%st%dom%on) then
       ! a decomposed grid: the frames show the whole grid (mpm_halo)
       call mpm_writer_open(this%wr, opts%output_base, this%comm, whole_grid_shape(this%st), this%st%nc, this%fields)
    else
       call mpm_writer_open(this%wr, opts%output_base, this%comm, this%st%g, this%st%nc, this%fields)
    end if
    call history_open(this%hist, opts%output_base // '_history.csv', this%columns, this%comm)
    this%last_row_time = 0
    this%last_row_out = 0
  end subroutine open_outputs

  !> Restart: the set-up's particles replaced by the checkpoint's, the outputs reopened at it.
  subroutine load(this, m, opts)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    type(run_options_t), intent(in) :: opts

    call mpm_resume(m, this%st, opts%output_base, this%fields, this%columns, this%wr, this%hist, &
         this%last_row_time, this%last_row_out)
  end subroutine load

  subroutine header(this, m, opts)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    type(run_options_t), intent(in) :: opts

    if (this%rank == 0) call report_header(m, this%st, this%effects, opts%output_base)
  end subroutine header

  !> The step's clock at its start (unless resumed) and the grid nodes of its walls.
  subroutine step_start(this, m, istep, resumed)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    logical, intent(in) :: resumed

    if (.not. resumed) then
       this%st%step = istep
       this%st%step_time = 0
       this%st%step_increment = 0
    end if
    call mark_wall_nodes(m, this%st)
  end subroutine step_start

  !> The stable increment (CFL of the step), or the step's fixed one.
  function stable_increment(this, m, istep) result(dt)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    real(dp) :: dt

    call stable_increment_of(this%st, m%mpm%steps(istep)%cfl, m%mpm%cell)
    dt = this%st%dt_stable
    if (m%steps(istep)%dt_fixed > 0) dt = m%steps(istep)%dt_fixed
  end function stable_increment

  subroutine increment(this, m, istep, dt, t_new)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    real(dp), intent(in) :: dt, t_new

    associate (st => this%st)
      st%dt = dt
      st%particle_steps = st%particle_steps + sum(st%blocks(1:st%nblocks)%count)
      call mpm_increment(m, st, this%effects)
      st%step_time = t_new
      st%total_time = st%total_time + st%dt
      st%increment = st%increment + 1
      st%step_increment = st%step_increment + 1
    end associate
  end subroutine increment

  subroutine frame(this, m, istep)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep

    call write_frame(m, this%st, this%wr, istep, this%st%step_time)
  end subroutine frame

  !> A history row: the particles' sums first (measure, collective).
  subroutine history(this, m, istep)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep

    call measure(this%st)
    call write_history(m, this%st, this%hist, this%last_row_time, this%last_row_out)
  end subroutine history

  subroutine save(this, m, opts)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    type(run_options_t), intent(in) :: opts

    call mpm_save(m, this%st, opts%output_base, this%wr, this%hist, this%last_row_time, this%last_row_out)
  end subroutine save

  !> The MPM has no *STOP CONDITION (the element solver's flow/arrest decision).
  logical function stop_condition(this, m, istep)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep

    stop_condition = .false.
  end function stop_condition

  subroutine step_end(this, m, istep)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
  end subroutine step_end

  function clock(this) result(c)
    class(mpm_technique_t), intent(in) :: this
    type(run_clock_t) :: c

    associate (s => this%st)
      c = run_clock_t(s%step, s%increment, s%step_increment, s%step_time, s%total_time, s%dt)
    end associate
  end function clock

  !> The mass that left through the outflow on rank 0 (its particles; rank 0's share on several ranks).
  function progress_note(this) result(text)
    class(mpm_technique_t), intent(in) :: this
    character(len=:), allocatable :: text
    character(len=40) :: buf

    write (buf, '(a,es11.4)') '  out kg (rank 0) ', this%st%mass_out
    text = trim(buf)
  end function progress_note

  subroutine close_outputs(this)
    class(mpm_technique_t), intent(inout) :: this

    call mpm_writer_close(this%wr)
    call history_close(this%hist)
  end subroutine close_outputs

  subroutine summary(this, m)
    class(mpm_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m

    this%st%loop_seconds = this%loop_seconds
    call report_summary(m, this%st)
  end subroutine summary
end module run_mpm
