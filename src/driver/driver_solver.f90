!> The solver's state on one rank: nodal arrays of the local nodes, element blocks of the
!> local elements, rigid-body motion, energies and time. Built from the model and the
!> partition before the first increment.
!>
!> Element blocks: consecutive local elements (ascending global order, which the deterministic
!> assembly relies on) with the same section, at most `block_size` long. Every per-element array
!> of a block is stored (element, component), so a block's stress is exactly the
!> `(nblock, ncomp)` array a VUMAT receives: no copies on the way in or out.
module driver_solver
  use base_kinds, only: dp
  use model, only: model_t
  use model_mesh, only: element_c3d8r
  use parallel_partition, only: partition_t
  implicit none
  private

  integer, parameter, public :: block_size = 256

  type, public :: element_block_t
     integer :: first = 0, count = 0                  !< local elements first..first+count-1
     integer :: material = 0, section = 0
     integer :: nstatev = 0, nfieldv = 0              !< as the VUMAT sees them (>= 1 for storage)
     integer, allocatable :: elem_number(:)           !< user element numbers (jblock(5:))
     real(dp), allocatable :: volume_ref(:)
     real(dp), allocatable :: bmat_ref(:, :, :)       !< (count, ndim, nen) reference mean gradient
     real(dp), allocatable :: mass(:)                 !< element mass ρ0 V0
     !> CAX4R: (count, 4) share of the element mass at each node (∫ N_I r dA / ∫ r dA);
     !> unallocated for CPE4R and C3D8R (mass/nen at each node)
     real(dp), allocatable :: mass_share(:, :)
     real(dp), allocatable :: bhoop_ref(:, :)         !< CAX4R: (count, 4) hoop row of B̄ on X
     !> R at t_n: C3D8R (count, 3, 3); CPE4R (count, 2, 1), the plane form (cos θ, sin θ) of
     !> R = [c −s; s c] (fem_corotation's rotation_matrix): half the bytes read and written per
     !> element and increment.
     real(dp), allocatable :: rotation(:, :, :)
     real(dp), allocatable :: hourglass(:, :, :)      !< (count, ndim, nmode) stiffness-form state
     real(dp), allocatable :: stress(:, :)            !< corotational Cauchy stress at t_n
     real(dp), allocatable :: state(:, :)             !< (count, nstatev) SDVs at t_n
     real(dp), allocatable :: field(:, :)             !< (count, nfieldv) field variables at t_n
     real(dp), allocatable :: temp(:)                 !< (count) initial temperature (user VUMATs)
     !> The temperature in the step temp_step: temp_base + Σ_j temp_coef(:, j) a_j(t) over the
     !> step's *TEMPERATURE entries (driver_temperature).
     real(dp), allocatable :: temp_base(:), temp_coef(:, :)
     integer :: temp_step = 0
     real(dp), allocatable :: e_int(:), e_inel(:)     !< specific energies (per unit mass)
     real(dp), allocatable :: log_strain(:, :)        !< accumulated corotational strain (LE)
     real(dp), allocatable :: plastic_strain(:, :)    !< corotational plastic strain (PE); (0, ncomp) unless written
     real(dp), allocatable :: sigma_bv(:)             !< bulk-viscosity pressure of the last increment
     !> hourglass forces at t_n: C3D8R (count, 3, 8) nodal; CPE4R (count, 2, 1) the generalised
     !> force of its one mode (fem_cpe4r's cpe4r_hourglass_update)
     real(dp), allocatable :: force_hg(:, :, :)
     real(dp) :: wave_modulus = 0                     !< λ + 2G from the packaging call
     !> Pass F and U (defgradOld/New, stretchOld/New) to the VUMAT. Our own materials never
     !> read them, so blocks of our materials skip computing them (an effect not asked for).
     logical :: vumat_needs_kinematics = .true.
     !> *FIXED MASS SCALING (driver_mass_scaling): factor on each element's inertia, allocated
     !> only once a step scales. The inertia, the stable increment, hourglass and bulk viscosity
     !> see ρ·factor; the VUMAT, gravity and the internal energy keep the physical mass.
     logical :: mass_scaled = .false.
     real(dp), allocatable :: mass_scale(:)
  end type element_block_t

  type, public :: rigid_body_t
     real(dp) :: u(3) = 0, v(3) = 0                   !< reference node displacement, velocity
  end type rigid_body_t

  type, public :: energies_t
     real(dp) :: kinetic = 0, internal = 0, viscous = 0, friction = 0, external = 0, artificial = 0
  end type energies_t

  type, public :: solver_t
     integer :: ndim = 0, nen = 0, ncomp = 0, nshr = 0, nmode = 0
     type(partition_t) :: part
     integer :: n_nodes = 0                           !< local nodes
     real(dp), allocatable :: x0(:, :), u(:, :), v(:, :), a(:, :)   !< (ndim, n_nodes)
     real(dp), allocatable :: mass(:)
     real(dp), allocatable :: f_int(:, :), f_ext(:, :), f_contact(:, :), reaction(:, :)
     logical, allocatable :: fixed(:, :)              !< (ndim, n_nodes) dof prescribed this step
     real(dp), allocatable :: f_ext_old(:, :)          !< f_ext at t_n when gravity changes
     !> v_{n-1/2} of the increment: the constraint impulses (supports, walls) are m (v − v_free),
     !> v_free = v_{n-1/2} + Δt_avg a_n the unconstrained v_{n+1/2}, and their work uses both
     !> (constraint_work forms v_free again from v_old and a: no array of its own). Kept for the
     !> constrained nodes only (nd, size(loads%constrained)), in that list's order.
     real(dp), allocatable :: v_old(:, :)
     integer :: n_blocks = 0
     type(element_block_t), allocatable :: blocks(:)
     type(rigid_body_t), allocatable :: rigid(:)      !< one per rigid surface
     real(dp), allocatable :: wall_force(:, :)        !< (ndim, n_rigid) force on each wall (global)
     ! Energies accumulated by this rank (element and owned-node shares); sums are global.
     real(dp) :: e_viscous = 0, e_artificial = 0, e_friction = 0, e_external = 0
     type(energies_t) :: energies                     !< global values at the last history point
     ! Time
     integer :: step = 0                              !< current step (1-based)
     integer :: increment = 0                         !< increments since the start of the run
     integer :: step_increment = 0
     real(dp) :: total_time = 0, step_time = 0, step_start = 0
     real(dp) :: dt = 0, dt_prev = 0                  !< dt_{n+1/2}, dt_{n-1/2}
     real(dp) :: dt_stable = 0                        !< stable increment at t_n (before scaling)
     integer :: dt_element = 0                        !< user number of the controlling element
     ! Energy check carried through a restart (driver_checkpoint -> driver_run).
     real(dp) :: restart_energy_reference = 0
     real(dp) :: restart_energy_peak = 0
     ! Step stop condition (driver_stop_condition): displacements at the step start, the largest
     ! displacement since then over the condition's node set, the kinetic-energy peak of the
     ! step, the step time since which ALLKE stayed below the arrest fraction (< 0: not below),
     ! the start time and u_max of the current growth window, and the outcome (0 undecided,
     ! 1 FLOW, 2 ARREST). Checkpointed.
     real(dp), allocatable :: u_step_start(:, :)
     real(dp) :: stop_umax = 0, stop_ke = 0, stop_ke_peak = 0, stop_quiet_since = -1
     real(dp) :: stop_window_start = 0, stop_window_umax = 0   !< displacement-growth window
     integer :: stop_outcome = 0
     integer, allocatable :: stop_nodes(:)            !< owned local nodes of the set (cache)
     integer :: stop_nodes_step = 0                   !< step the cache was built for
  end type solver_t

  public :: build_blocks

contains

  !> Split the local elements into blocks of one section and at most block_size elements.
  subroutine build_blocks(m, part, solver)
    type(model_t), intent(in) :: m
    type(partition_t), intent(in) :: part
    type(solver_t), intent(inout) :: solver
    integer :: e, first, n, nblk, sec
    integer, allocatable :: starts(:), counts(:)

    allocate(starts(max(1, part%n_local_elems)), counts(max(1, part%n_local_elems)))
    nblk = 0
    e = 1
    do while (e <= part%n_local_elems)
       first = e
       sec = m%mesh%elem_section(part%elem_global(e))
       n = 1
       do while (first + n <= part%n_local_elems .and. n < block_size)
          if (m%mesh%elem_section(part%elem_global(first + n)) /= sec) exit
          n = n + 1
       end do
       nblk = nblk + 1
       starts(nblk) = first
       counts(nblk) = n
       e = first + n
    end do
    solver%n_blocks = nblk
    allocate(solver%blocks(nblk))
    do e = 1, nblk
       solver%blocks(e)%first = starts(e)
       solver%blocks(e)%count = counts(e)
       solver%blocks(e)%section = m%mesh%elem_section(part%elem_global(starts(e)))
       solver%blocks(e)%material = m%sections(solver%blocks(e)%section)%material
    end do
    solver%ndim = m%mesh%ndim
    solver%nen = m%mesh%nen
    if (m%mesh%element_type /= element_c3d8r) then   ! CPE4R, CAX4R
       solver%ncomp = 4; solver%nshr = 1; solver%nmode = 1
    else
       solver%ncomp = 6; solver%nshr = 3; solver%nmode = 4
    end if
  end subroutine build_blocks
end module driver_solver
