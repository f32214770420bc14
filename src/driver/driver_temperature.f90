!> The predefined temperature in time at integration points and particles: *INITIAL CONDITIONS,
!> TYPE=TEMPERATURE and the steps' *TEMPERATURE (model_steps' temperature_t: value × a(t), the
!> last entry naming a node counts). A user's VUMAT receives it as tempOld (start of the
!> increment) and tempNew (end), so the two differ within an increment when an amplitude varies.
!>
!> Elements: the integration point's temperature is the mean of its nodes' temperatures (the
!> centroid value of the bilinear/trilinear interpolation), written as base + Σ_j coef_j a_j(t)
!> with base the initial temperatures of the nodes no entry names; the coefficients are built
!> once per step and block. Particles: model_particle_fields. The element output TEMP
!> (frame_temperatures) is the same mean at the frame's time, for every material; the node
!> output NT (frame_node_temperatures) the node temperatures it averages.
module driver_temperature
  use base_kinds, only: dp
  use model, only: model_t
  use model_time_variation, only: variation_factor
  use driver_solver, only: solver_t, element_block_t
  implicit none
  private

  public :: element_temperatures, frame_temperatures, frame_node_temperatures

contains

  !> temp(1:count) of block `blk` at the given step and total time of the current step.
  subroutine element_temperatures(m, solver, blk, step_time, total_time, temp)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    type(element_block_t), intent(inout) :: blk
    real(dp), intent(in) :: step_time, total_time
    real(dp), intent(out) :: temp(:)
    integer :: j

    if (blk%temp_step /= solver%step) call build_coefficients(m, solver, blk)
    temp = blk%temp_base
    do j = 1, size(blk%temp_coef, 2)
       associate (t => m%steps(solver%step)%temperatures(j))
         temp = temp + blk%temp_coef(:, j) * variation_factor(t%variation, m%amplitudes, step_time, total_time)
       end associate
    end do
  end subroutine element_temperatures

  !> The element output TEMP: temp(n_local_elems) in the solver's element order, the mean of
  !> each element's node temperatures at the solver's current time (the end of the last
  !> increment: what a user's VUMAT received as tempNew). Built from the model at every frame,
  !> so built-in materials (whose blocks keep no temperature) write it too.
  subroutine frame_temperatures(m, solver, temp)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    real(dp), intent(out) :: temp(:)
    real(dp), allocatable :: node_temp(:)
    integer :: e, a

    call frame_node_temperatures(m, solver, node_temp)
    do e = 1, solver%part%n_local_elems
       associate (g => solver%part%elem_global(e))
         temp(e) = 0
         do a = 1, m%mesh%nen
            temp(e) = temp(e) + node_temp(m%mesh%conn(a, g))
         end do
         temp(e) = temp(e) / m%mesh%nen
       end associate
    end do
  end subroutine frame_temperatures

  !> The node output NT: node_temp(n_nodes) of every node of the mesh at the solver's current
  !> time, the last entry of the step naming the node (value × amplitude), else the node's
  !> initial temperature.
  subroutine frame_node_temperatures(m, solver, node_temp)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    real(dp), allocatable, intent(out) :: node_temp(:)
    integer :: j

    call initial_node_temperatures(m, node_temp)
    if (solver%step < 1 .or. solver%step > m%n_steps) return
    if (.not. allocated(m%steps(solver%step)%temperatures)) return
    do j = 1, size(m%steps(solver%step)%temperatures)
       associate (t => m%steps(solver%step)%temperatures(j))
         node_temp(t%nodes) = t%value * variation_factor(t%variation, m%amplitudes, solver%step_time, &
              solver%total_time)
       end associate
    end do
  end subroutine frame_node_temperatures

  !> Every node's *INITIAL CONDITIONS, TYPE=TEMPERATURE value (entries naming a node add up, as
  !> in driver_setup's element means; 0 where none names it).
  subroutine initial_node_temperatures(m, initial)
    type(model_t), intent(in) :: m
    real(dp), allocatable, intent(out) :: initial(:)
    integer :: j, i, node

    allocate(initial(m%mesh%n_nodes))
    initial = 0
    if (.not. allocated(m%initial_fields)) return
    do j = 1, size(m%initial_fields)
       if (m%initial_fields(j)%variable /= 0) cycle
       do i = 1, size(m%initial_fields(j)%nodes)
          node = m%initial_fields(j)%nodes(i)
          initial(node) = initial(node) + m%initial_fields(j)%value
       end do
    end do
  end subroutine initial_node_temperatures

  !> base and coefficients of the block for the current step: node temperatures are the last
  !> entry naming the node (coefficient value/nen), else the node's initial temperature.
  subroutine build_coefficients(m, solver, blk)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    type(element_block_t), intent(inout) :: blk
    integer, allocatable :: entry_of(:)
    real(dp), allocatable :: initial(:)
    integer :: nent, j, e, a, g, node

    nent = 0
    if (allocated(m%steps(solver%step)%temperatures)) nent = size(m%steps(solver%step)%temperatures)
    if (allocated(blk%temp_coef)) deallocate(blk%temp_coef)
    allocate(blk%temp_coef(blk%count, nent))
    blk%temp_coef = 0
    blk%temp_base = blk%temp
    blk%temp_step = solver%step
    if (nent == 0) return
    allocate(entry_of(m%mesh%n_nodes))
    entry_of = 0
    do j = 1, nent
       associate (t => m%steps(solver%step)%temperatures(j))
         entry_of(t%nodes) = j
       end associate
    end do
    call initial_node_temperatures(m, initial)
    do e = 1, blk%count
       g = solver%part%elem_global(blk%first + e - 1)
       do a = 1, m%mesh%nen
          node = m%mesh%conn(a, g)
          j = entry_of(node)
          if (j == 0) cycle
          blk%temp_base(e) = blk%temp_base(e) - initial(node) / m%mesh%nen
          blk%temp_coef(e, j) = blk%temp_coef(e, j) + m%steps(solver%step)%temperatures(j)%value / m%mesh%nen
       end do
    end do
  end subroutine build_coefficients
end module driver_temperature
