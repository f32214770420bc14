!> The technique-neutral contract of a run (issue 18): what the step loop of run_loop needs from
!> a technique — the element solver (run_element) and the material point method (run_mpm) are its
!> two extensions — and the few values the loop and the techniques share (options, clock).
!>
!> The loop owns the steps and increments, the output schedule, the stop conditions, the
!> checkpoint calls, the progress line and the end report; a technique owns its state and its
!> physics. Why an abstract type with deferred procedures (as neko does with its schemes): the
!> two techniques had grown two time loops that drifted apart (output times, restart rules);
!> with one loop a rule is written once and holds for both.
module run_technique
  use mpi_f08, only: MPI_Comm
  use base_kinds, only: dp
  use model, only: model_t
  use output_effects, only: effects_t
  implicit none
  private

  !> What the command line asks of a run (src/app/bulkflow.f90).
  type, public :: run_options_t
     character(len=:), allocatable :: output_base     !< path of the outputs without extension
     logical :: restart = .false.                     !< continue from the checkpoint
     integer :: stop_after = 0                        !< > 0: stop after this increment (tests)
     logical :: progress = .true.
  end type run_options_t

  !> Where a technique is in time: step, increments (in the run and in the running step), step
  !> time, total time and the last increment's Δt. The technique advances it (it keeps these
  !> values in its own state, where its outputs and checkpoints read them); the loop reads it.
  type, public :: run_clock_t
     integer :: step = 0, increment = 0, step_increment = 0
     real(dp) :: step_time = 0, total_time = 0, dt = 0
  end type run_clock_t

  type, abstract, public :: technique_t
     type(MPI_Comm) :: comm
     integer :: rank = 0, nranks = 1
     !> The run's effects registry: the technique declares its own effects in setup, the loop
     !> adds output and checkpoint, times them and prints the table at the end.
     type(effects_t) :: effects
     real(dp) :: loop_seconds = 0      !< wall time of the step loop (set by run_loop before summary)
   contains
     procedure(setup_i), deferred :: setup
     procedure(open_i), deferred :: open_outputs
     procedure(open_i), deferred :: load
     procedure(open_i), deferred :: header
     procedure(step_start_i), deferred :: step_start
     procedure(stable_i), deferred :: stable_increment
     procedure(increment_i), deferred :: increment
     procedure(write_i), deferred :: frame
     procedure(write_i), deferred :: history
     procedure(save_i), deferred :: save
     procedure(condition_i), deferred :: stop_condition
     procedure(write_i), deferred :: step_end
     procedure(clock_i), deferred :: clock
     procedure(note_i), deferred :: progress_note
     procedure(close_i), deferred :: close_outputs
     procedure(summary_i), deferred :: summary
  end type technique_t

  abstract interface
     !> Once before the first increment: partition, the technique's effects (declared into
     !> this%effects, whose clock the loop has started), state (collective).
     subroutine setup_i(this, m)
       import :: technique_t, model_t
       class(technique_t), intent(inout) :: this
       type(model_t), intent(in) :: m
     end subroutine setup_i

     !> open_outputs: a new run's files. load: restart — the state of the checkpoint of
     !> opts%output_base and the files reopened at it (stops on every rank with the reason when it
     !> cannot). header: the run's header on standard output (rank 0).
     subroutine open_i(this, m, opts)
       import :: technique_t, model_t, run_options_t
       class(technique_t), intent(inout) :: this
       type(model_t), intent(in) :: m
       type(run_options_t), intent(in) :: opts
     end subroutine open_i

     !> The step's loads and constraints; unless resumed (a restart continuing the step), the
     !> clock at the step's start (step time 0, step increment 0) and the step's initial state.
     subroutine step_start_i(this, m, istep, resumed)
       import :: technique_t, model_t
       class(technique_t), intent(inout) :: this
       type(model_t), intent(in) :: m
       integer, intent(in) :: istep
       logical, intent(in) :: resumed
     end subroutine step_start_i

     !> The increment the technique would take now (its stable one, scaled, or the step's
     !> fixed one); the loop cuts it at the step's end and at listed output times.
     function stable_i(this, m, istep) result(dt)
       import :: technique_t, model_t, dp
       class(technique_t), intent(inout) :: this
       type(model_t), intent(in) :: m
       integer, intent(in) :: istep
       real(dp) :: dt
     end function stable_i

     !> One increment of Δt that ends at step time t_new; advances the clock.
     subroutine increment_i(this, m, istep, dt, t_new)
       import :: technique_t, model_t, dp
       class(technique_t), intent(inout) :: this
       type(model_t), intent(in) :: m
       integer, intent(in) :: istep
       real(dp), intent(in) :: dt, t_new
     end subroutine increment_i

     !> frame / history: one field frame / history row of the present state (collective).
     !> step_end: the technique's own words at the end of a step that was not stopped.
     subroutine write_i(this, m, istep)
       import :: technique_t, model_t
       class(technique_t), intent(inout) :: this
       type(model_t), intent(in) :: m
       integer, intent(in) :: istep
     end subroutine write_i

     !> A checkpoint of the run into opts%output_base (collective).
     subroutine save_i(this, m, opts)
       import :: technique_t, model_t, run_options_t
       class(technique_t), intent(inout) :: this
       type(model_t), intent(in) :: m
       type(run_options_t), intent(in) :: opts
     end subroutine save_i

     !> Has the step's *STOP CONDITION been decided (collective)?
     logical function condition_i(this, m, istep)
       import :: technique_t, model_t
       class(technique_t), intent(inout) :: this
       type(model_t), intent(in) :: m
       integer, intent(in) :: istep
     end function condition_i

     function clock_i(this) result(c)
       import :: technique_t, run_clock_t
       class(technique_t), intent(in) :: this
       type(run_clock_t) :: c
     end function clock_i

     !> A technique's addition to the progress line ('' for none; rank 0 only).
     function note_i(this) result(text)
       import :: technique_t
       class(technique_t), intent(in) :: this
       character(len=:), allocatable :: text
     end function note_i

     !> Close the output files.
     subroutine close_i(this)
       import :: technique_t
       class(technique_t), intent(inout) :: this
     end subroutine close_i

     !> The technique's lines of the end report (sums over ranks: collective; rank 0 prints),
     !> after the loop's "done" line.
     subroutine summary_i(this, m)
       import :: technique_t, model_t
       class(technique_t), intent(inout) :: this
       type(model_t), intent(in) :: m
     end subroutine summary_i
  end interface
end module run_technique
