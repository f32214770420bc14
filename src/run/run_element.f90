!> The element solver (src/driver: central difference over element blocks) as a technique of the
!> run skeleton: element_technique_t holds the solver's state of this rank and wraps the
!> driver's phase routines; run_loop drives it.
module run_element
  use base_kinds, only: dp
  use error_report, only: error_t
  use model, only: model_t
  use parallel_partition, only: partition_t, partition_model
  use driver_solver, only: solver_t
  use driver_effects, only: declare_element_effects, effect_user_field
  use driver_setup, only: setup_solver
  use driver_elements, only: element_workspace_t, element_workspace_init
  use driver_loads, only: step_loads_t
  use driver_pressure, only: step_pressures_t
  use driver_output, only: run_output_t, open_run_output, close_run_output, write_frame, write_history, &
       sum_over_ranks
  use driver_checkpoint, only: save_checkpoint, load_checkpoint
  use driver_stop_condition, only: check_stop_condition, report_stop_condition
  use driver_run, only: start_step, proposed_increment, one_increment, strain_energy_scale, print_header, &
       print_summary
  use output_collective, only: stop_agreed_error
  use run_technique, only: technique_t, run_options_t, run_clock_t
  implicit none
  private

  type, public, extends(technique_t) :: element_technique_t
     type(partition_t) :: part
     type(solver_t) :: solver
     type(element_workspace_t) :: ew
     type(step_loads_t) :: loads
     type(step_pressures_t) :: pressures
     type(run_output_t) :: out
   contains
     procedure :: setup, open_outputs, load, header, step_start, stable_increment, increment, frame, history, &
          save, stop_condition, step_end, clock, progress_note, close_outputs, summary
  end type element_technique_t

contains

  subroutine setup(this, m)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer :: i, max_state, max_field

    call partition_model(m, this%comm, this%part)
    call declare_element_effects(m, this%effects)
    call setup_solver(m, this%part, this%solver, this%effects%active(effect_user_field))
    max_state = 1
    max_field = 1
    do i = 1, m%n_materials
       max_state = max(max_state, m%materials(i)%nstatev)
       max_field = max(max_field, m%materials(i)%nfieldv)
    end do
    associate (s => this%solver)
      call element_workspace_init(this%ew, s%part, s%ndim, s%nen, s%ncomp, s%nshr, max_state, max_field)
    end associate
  end subroutine setup

  subroutine open_outputs(this, m, opts)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    type(run_options_t), intent(in) :: opts

    call open_run_output(m, this%solver, this%out, opts%output_base)
    this%out%energy_floor = 1.0e-12_dp * strain_energy_scale(this%solver)
  end subroutine open_outputs

  !> Restart: the checkpoint's state, the field file and history reopened at it, the energy
  !> references of the balance check.
  subroutine load(this, m, opts)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    type(run_options_t), intent(in) :: opts
    type(error_t) :: err
    integer :: first_step, frames, rows

    call load_checkpoint(m, opts%output_base, this%solver, first_step, frames, rows, err)
    if (err%raised) call stop_agreed_error(this%part%comm, err)
    call open_run_output(m, this%solver, this%out, opts%output_base, frames, rows, this%solver%total_time)
    this%out%energy_reference = this%solver%restart_energy_reference
    this%out%energy_peak = this%solver%restart_energy_peak
    this%out%energy_floor = 1.0e-12_dp * strain_energy_scale(this%solver)
  end subroutine load

  subroutine header(this, m, opts)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    type(run_options_t), intent(in) :: opts

    if (this%rank == 0) call print_header(m, this%part, this%effects, opts%output_base)
  end subroutine header

  subroutine step_start(this, m, istep, resumed)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    logical, intent(in) :: resumed

    call start_step(m, istep, resumed, this%solver, this%effects, this%loads, this%pressures, this%out)
  end subroutine step_start

  function stable_increment(this, m, istep) result(dt)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    real(dp) :: dt

    dt = proposed_increment(m, istep, this%solver)
  end function stable_increment

  subroutine increment(this, m, istep, dt, t_new)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    real(dp), intent(in) :: dt, t_new
    real(dp) :: dt_min

    call one_increment(m, this%solver, this%effects, this%ew, this%loads, this%pressures, istep, dt, t_new, dt_min)
  end subroutine increment

  subroutine frame(this, m, istep)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep

    call write_frame(m, this%solver, this%out, istep)
  end subroutine frame

  subroutine history(this, m, istep)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep

    call write_history(m, this%solver, this%out, istep)
  end subroutine history

  subroutine save(this, m, opts)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    type(run_options_t), intent(in) :: opts

    call save_checkpoint(m, opts%output_base, this%solver, this%out)
  end subroutine save

  logical function stop_condition(this, m, istep)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep

    stop_condition = check_stop_condition(m, istep, this%solver)
  end function stop_condition

  !> The step's *STOP CONDITION outcome (flow or arrest), when it has one.
  subroutine step_end(this, m, istep)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep

    call report_stop_condition(m, istep, this%solver)
  end subroutine step_end

  function clock(this) result(c)
    class(element_technique_t), intent(in) :: this
    type(run_clock_t) :: c

    associate (s => this%solver)
      c = run_clock_t(s%step, s%increment, s%step_increment, s%step_time, s%total_time, s%dt)
    end associate
  end function clock

  !> Nothing to add to the progress line.
  function progress_note(this) result(text)
    class(element_technique_t), intent(in) :: this
    character(len=:), allocatable :: text

    text = ''
  end function progress_note

  subroutine close_outputs(this)
    class(element_technique_t), intent(inout) :: this

    call close_run_output(this%out)
  end subroutine close_outputs

  subroutine summary(this, m)
    class(element_technique_t), intent(inout) :: this
    type(model_t), intent(in) :: m

    if (m%n_rigid_surfaces > 0) call sum_over_ranks(this%solver, this%solver%wall_force)
    if (this%rank == 0) call print_summary(m, this%solver)
  end subroutine summary
end module run_element
