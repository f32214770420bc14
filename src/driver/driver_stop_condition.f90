!> *STOP CONDITION (ours): end a run early once the outcome of a step is clear, for the
!> flow/no-flow decision after an outlet opens (thesis §6.2: either the material stops within a
!> fraction of an element or it keeps deforming).
!>
!> After every increment of a step with a condition:
!>   u_max = max over the node set of |u − u(step start)|     (history column UMAX_<NSET>)
!>   FLOW   when u_max > DISPLACEMENT;
!>   ARREST when, from MIN TIME on and with u_max still ≤ DISPLACEMENT, either
!>          ALLKE ≤ KINETIC FRACTION × (peak ALLKE of the step) has held for HOLD step time, or
!>          u_max grew by at most GROWTH × DISPLACEMENT over a window of HOLD step time
!>          (consecutive windows from MIN TIME). The second rule is needed because a model that
!>          was already vibrating elastically when the step began (e.g. the material arched
!>          away from the plate while it slid) never falls to a fraction of its step peak:
!>          bulk viscosity damps the low modes only slowly.
!> The run then ends (exit status 0 for both outcomes) with one human line and one
!> machine-readable line `bulkflow: stop condition: result=FLOW|ARREST|UNDECIDED key=value ...`
!> (UNDECIDED: the step ended first). Both quantities are global values reduced so that the
!> decision and the increment it is taken at are the same on any number of ranks: the maximum is
!> exact, and ALLKE here is summed with global_sum_exact (the history column's ALLKE uses the
!> ordinary sum and may differ from it in the last bits).
module driver_stop_condition
  use, intrinsic :: iso_fortran_env, only: output_unit
  use base_kinds, only: dp
  use model, only: model_t
  use parallel_partition, only: local_node_index
  use parallel_assembly, only: global_max, global_sum_exact
  use driver_solver, only: solver_t
  implicit none
  private

  integer, parameter, public :: stop_undecided = 0, stop_flow = 1, stop_arrest = 2

  public :: stop_step_start, check_stop_condition, report_stop_condition
  public :: count_stop_columns, add_stop_columns, stop_column_values

contains

  !> At the start of every step: reference displacements and a fresh decision state.
  subroutine stop_step_start(solver)
    type(solver_t), intent(inout) :: solver

    if (allocated(solver%u_step_start)) deallocate(solver%u_step_start)
    allocate(solver%u_step_start, source=solver%u)
    solver%stop_umax = 0
    solver%stop_ke = 0
    solver%stop_ke_peak = 0
    solver%stop_quiet_since = -1
    solver%stop_window_start = -1
    solver%stop_window_umax = 0
    solver%stop_outcome = stop_undecided
  end subroutine stop_step_start

  !> Update u_max and ALLKE after an increment of step istep and decide; .true. when the run
  !> should stop now (FLOW or ARREST). Collective: every rank calls it.
  logical function check_stop_condition(m, istep, solver) result(stop_now)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(solver_t), intent(inout) :: solver
    real(dp), allocatable :: ke(:)
    real(dp) :: umax, total
    integer :: k, i

    stop_now = .false.
    associate (sc => m%steps(istep)%stop)
      if (.not. sc%active) return
      if (solver%stop_nodes_step /= istep) call build_node_cache(m, istep, solver)
      if (.not. allocated(solver%u_step_start)) allocate(solver%u_step_start, source=solver%u)
      umax = 0
      do k = 1, size(solver%stop_nodes)
         i = solver%stop_nodes(k)
         umax = max(umax, norm2(solver%u(:, i) - solver%u_step_start(:, i)))
      end do
      call global_max(solver%part, umax)
      ! ALLKE as in the history (½ m v_{n+½}·v_{n+3/2}), one term per owned node, summed exactly.
      allocate(ke(solver%n_nodes))
      do i = 1, solver%n_nodes
         ke(i) = 0
         if (solver%part%node_owned(i)) ke(i) = 0.5_dp * solver%mass(i) * &
              sum(solver%v(:, i) * (solver%v(:, i) + solver%dt * solver%a(:, i)))
      end do
      call global_sum_exact(solver%part, ke, total)
      solver%stop_umax = max(solver%stop_umax, umax)
      solver%stop_ke = total
      solver%stop_ke_peak = max(solver%stop_ke_peak, total)
      if (solver%stop_umax > sc%displacement) then
         solver%stop_outcome = stop_flow
      else if (solver%step_time >= sc%min_time) then
         ! Rule 1: ALLKE low relative to its step peak, continuously for HOLD.
         if (solver%stop_ke_peak > 0 .and. total <= sc%ke_fraction * solver%stop_ke_peak) then
            if (solver%stop_quiet_since < 0) solver%stop_quiet_since = solver%step_time
            if (solver%step_time - solver%stop_quiet_since >= sc%hold) solver%stop_outcome = stop_arrest
         else
            solver%stop_quiet_since = -1
         end if
         ! Rule 2: u_max (nearly) stopped growing over a window of HOLD.
         if (solver%stop_window_start < 0) then
            solver%stop_window_start = solver%step_time
            solver%stop_window_umax = solver%stop_umax
         else if (solver%step_time - solver%stop_window_start >= sc%hold) then
            if (sc%growth > 0 .and. solver%stop_umax - solver%stop_window_umax <= sc%growth * sc%displacement) then
               solver%stop_outcome = stop_arrest     ! the window stays as evidence for the report
            else
               solver%stop_window_start = solver%step_time
               solver%stop_window_umax = solver%stop_umax
            end if
         end if
      end if
      stop_now = solver%stop_outcome /= stop_undecided
    end associate
  end function check_stop_condition

  !> The decision and its evidence on rank 0: a sentence and a machine-readable line.
  subroutine report_stop_condition(m, istep, solver)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(solver_t), intent(in) :: solver
    character(len=9) :: result
    character(len=:), allocatable :: why

    if (solver%part%rank /= 0 .or. .not. m%steps(istep)%stop%active) return
    associate (sc => m%steps(istep)%stop)
      select case (solver%stop_outcome)
      case (stop_flow)
         result = 'FLOW'
         why = 'the largest displacement since the step start exceeds the limit'
      case (stop_arrest)
         result = 'ARREST'
         why = 'ALLKE stayed below the fraction of its step peak, or the displacement stopped growing, ' // &
              'for the hold time, the displacement below the limit'
      case default
         result = 'UNDECIDED'
         why = 'the step ended before FLOW or ARREST was clear'
      end select
      write (output_unit, '(a)') 'bulkflow: stop condition ' // trim(result) // ' in step ' // &
           trim(m%steps(istep)%name) // ': ' // why
      write (output_unit, '(a,i0,a,es14.7,a,es14.7,9(a,es12.5),a)') &
           'bulkflow: stop condition: result=' // trim(result) // ' step=', istep, ' step_time=', &
           solver%step_time, ' total_time=', solver%total_time, ' umax=', solver%stop_umax, ' limit=', &
           sc%displacement, ' allke=', solver%stop_ke, ' ke_peak=', solver%stop_ke_peak, ' ke_fraction=', &
           sc%ke_fraction, ' hold=', sc%hold, ' window_growth=', solver%stop_umax - solver%stop_window_umax, &
           ' growth_limit=', sc%growth * sc%displacement, ' min_time=', sc%min_time, &
           ' nset=' // trim(m%nsets(sc%nset)%name)
      flush (output_unit)
    end associate
  end subroutine report_stop_condition

  !> History columns UMAX_<NSET>, one per distinct node set of the scene's stop conditions.
  integer function count_stop_columns(m) result(n)
    type(model_t), intent(in) :: m
    integer :: i

    n = 0
    do i = 1, m%n_steps
       if (m%steps(i)%stop%active) n = n + 1
    end do
  end function count_stop_columns

  subroutine add_stop_columns(m, columns, n)
    type(model_t), intent(in) :: m
    character(len=*), intent(inout) :: columns(:)
    integer, intent(inout) :: n
    integer :: i
    character(len=len(columns)) :: name

    do i = 1, m%n_steps
       if (.not. m%steps(i)%stop%active) cycle
       name = 'UMAX_' // trim(m%nsets(m%steps(i)%stop%nset)%name)
       if (any(columns(1:n) == name)) cycle
       n = n + 1
       columns(n) = name
    end do
  end subroutine add_stop_columns

  !> Fill the UMAX column of step istep's condition (other UMAX columns stay as the caller set them).
  subroutine stop_column_values(m, istep, solver, columns, row)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(solver_t), intent(in) :: solver
    character(len=*), intent(in) :: columns(:)
    real(dp), intent(inout) :: row(:)
    integer :: col

    if (.not. m%steps(istep)%stop%active) return
    do col = 1, size(columns)
       if (columns(col) == 'UMAX_' // trim(m%nsets(m%steps(istep)%stop%nset)%name)) row(col) = solver%stop_umax
    end do
  end subroutine stop_column_values

  !> The owned local nodes of the condition's set (each node counted on one rank).
  subroutine build_node_cache(m, istep, solver)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(solver_t), intent(inout) :: solver
    integer :: k, li, n
    integer, allocatable :: tmp(:)

    associate (members => m%nsets(m%steps(istep)%stop%nset)%members)
      allocate(tmp(size(members)))
      n = 0
      do k = 1, size(members)
         li = local_node_index(solver%part, members(k))
         if (li == 0) cycle
         if (.not. solver%part%node_owned(li)) cycle
         n = n + 1
         tmp(n) = li
      end do
    end associate
    solver%stop_nodes = tmp(1:n)
    solver%stop_nodes_step = istep
  end subroutine build_node_cache
end module driver_stop_condition
