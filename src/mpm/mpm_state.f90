!> The state of a material-point run that the phases share (mpm_setup, mpm_musl,
!> mpm_stress_update, mpm_flow, mpm_report, mpm_run): the grid, the rank's particle blocks, the
!> walls' node lists and mirrors, per-material moduli and VUMAT work sets, the mass and energy
!> bookkeeping, the clock; and the ids of the MPM's effects (declared by mpm_setup into the
!> run's registry, output_effects). Owns the sums over ranks of the run's per-rank values (through src/parallel).
!> Why one type: every phase reads and writes a few of these fields; one argument keeps the
!> phases' interfaces short and the checkpoint's list of what to save in one place.
module mpm_state
  use, intrinsic :: iso_fortran_env, only: int64
  use mpi_f08, only: MPI_Comm
  use base_kinds, only: dp
  use mpm_grid, only: grid_t
  use mpm_particles, only: particle_block_t
  use mpm_walls, only: wall_nodes_t
  use mpm_mirror, only: mirror_plane_t
  use mpm_domain, only: domain_t
  use material_door, only: vumat_work_t
  use output_effects, only: first_technique_effect
  use parallel_comm, only: comm_sum, comm_max
  implicit none
  private

  ! The MPM's effect ids in the run's effects registry (output_effects; output and checkpoint
  ! are the run skeleton's). A new effect: an id here and its declare line in mpm_setup.
  integer, parameter, public :: fx_p2g = first_technique_effect, fx_grid = fx_p2g + 1, fx_g2p = fx_p2g + 2, &
       fx_kinematics = fx_p2g + 3, fx_material = fx_p2g + 4, fx_user_field = fx_p2g + 5, fx_gravity = fx_p2g + 6, &
       fx_damping = fx_p2g + 7, fx_walls = fx_p2g + 8, fx_outflow = fx_p2g + 9, fx_inflow = fx_p2g + 10, &
       fx_side_friction = fx_p2g + 11, fx_exchange = fx_p2g + 12, fx_migration = fx_p2g + 13, &
       fx_nonlocal = fx_p2g + 14, fx_dilation = fx_p2g + 15

  !> Work sets for partial blocks a rank keeps (mpm_state_t%work): more than the partial blocks
  !> a rank usually holds at once (1-8 in the ch. 4 discharge); a work set is at most
  !> particle_block_size rows (about 0.1 MB in 2D).
  integer, parameter, public :: partial_work_sets = 16

  !> Everything the run keeps. Per-rank partial values (sum over ranks when reported) are
  !> marked "rank"; the rest is the same on every rank.
  type, public :: mpm_state_t
     type(MPI_Comm) :: comm
     integer :: rank = 0, nranks = 1
     integer :: nd = 0, nc = 0, nshr = 0, nsup = 0
     type(grid_t) :: g
     integer :: nblocks = 0
     type(particle_block_t), allocatable :: blocks(:)
     type(wall_nodes_t), allocatable :: wall_nodes(:)
     !> per wall: a symmetry plane on a node plane is done by mirroring the grid (mpm_mirror)
     type(mirror_plane_t), allocatable :: mirror(:)
     logical, allocatable :: mirrored(:)
     !> the spatial decomposition of the grid (mpm_domain; %on false: the replicated grid)
     type(domain_t) :: dom
     !> 3D uGIMP: (8, nn) the grid's node values as packed 4-lane records for the vectorised
     !> transfer kernels (mpm_transfer, "packed node records"): in turn the P2G sums, v_new and
     !> v_old for the G2P, the remapped momentum, and (first 4 nn values) the remapped velocity
     !> for the stress update's gradient gather. Scratch of the increment (musl_transfer fills
     !> it), not state: not checkpointed.
     real(dp), allocatable :: gpack(:, :)
     real(dp), allocatable :: modulus(:)             !< per material: λ + 2G (packaging call)
     logical, allocatable :: needs_kinematics(:)     !< per material: user VUMAT reads F, U
     !> VUMAT work sets: work(1) serves full blocks (particle_block_size rows), work(2:) the
     !> partial blocks, each set taking a block's count of rows (its `rows`, 0: not made yet).
     !> Why exactly nb rows: every (1:nb, ...) section the door passes is the whole, contiguous
     !> array (no pack/unpack copies) and the new stress and state are swapped in, not copied.
     !> Why several: a rank holds several partial blocks of different counts; a set that has a
     !> block's count serves it as it is, another takes the count without allocating
     !> (vumat_work_rows: its views re-pointed; docs/scaling.md).
     type(vumat_work_t) :: work(1 + partial_work_sets)
     integer :: work_replace = 1                      !< the partial set a miss re-makes when all are made
     integer :: work_statev = 1, work_fieldv = 1     !< columns of the work sets (largest of the materials)
     integer :: next_number = 0
     ! mass bookkeeping (exact: particle masses never change)
     real(dp) :: mass_initial = 0, mass_in = 0, mass_out = 0   !< mass_out: rank
     integer :: n_initial = 0, n_in = 0, n_out = 0, n_guarded = 0  !< n_out, n_guarded: rank
     !> particle-increments whose J was held at MAX DILATION since this run (or its restart)
     !> began (rank; not checkpointed: a count for the summary, not state)
     integer(int64) :: n_dilation_held = 0
     real(dp) :: mass_cutoff = 0
     ! energies (global sums; 2D per unit thickness)
     real(dp) :: e_kinetic = 0, e_internal = 0, w_external = 0, e_walls = 0, e_damping = 0
     real(dp) :: e_out = 0, e_in = 0                 !< w_external, e_out: rank (e_kinetic, e_internal: global after measure)
     real(dp), allocatable :: wall_force(:, :)       !< (3, n_walls) force of the material on each wall
     !> Impulse of the material on each wall since the last history row, and the time it took.
     !> The history reports impulse / time: the force of one increment, m Δv/Δt at the wall
     !> nodes, also removes the normal velocity the nodes brought into the increment, so it
     !> scales with 1/Δt; a short final increment made it 2-3.5 times too large.
     real(dp), allocatable :: wall_impulse(:, :)
     real(dp), allocatable :: wall_force_row(:, :)   !< the last history row's (mean) wall forces
     real(dp) :: impulse_time = 0
     logical, allocatable :: on_wall(:)              !< grid nodes of the walls active in this step
     real(dp), allocatable :: side_capacity(:)       !< (nn) front/back wall friction capacity (mpm_side_friction)
     !> force of the material on the front and back walls together in the last increment (mpm_side_friction)
     real(dp) :: side_force(3) = 0
     real(dp), allocatable :: side_impulse(:, :)     !< (2, nn) its impulse on each node's own material
     !> (3, model%n_rigid_surfaces) displacement of each rigid surface's reference node (t_n+1
     !> once the walls of the increment are done) and its velocity over the increment
     real(dp), allocatable :: rigid_u(:, :), rigid_v(:, :)
     ! time
     integer :: step = 0, increment = 0
     integer :: step_increment = 0                   !< increments of the running step
     integer(int64) :: particle_steps = 0           !< Σ over increments of the particle count
     real(dp) :: loop_seconds = 0                    !< wall time of the time loop
     real(dp) :: total_time = 0, step_time = 0, dt = 0, dt_stable = 0
     real(dp) :: gravity(3) = 0
  end type mpm_state_t

  public :: sum_over_ranks, max_over_ranks, det_f

contains

  !> x ← Σ over the ranks (in place; nothing to do on one rank). Collective.
  subroutine sum_over_ranks(st, x)
    type(mpm_state_t), intent(in) :: st
    real(dp), contiguous, intent(inout) :: x(:)
    if (st%nranks > 1) call comm_sum(st%comm, x)
  end subroutine sum_over_ranks

  !> x ← max over the ranks (in place). Collective.
  subroutine max_over_ranks(st, x)
    type(mpm_state_t), intent(in) :: st
    real(dp), contiguous, intent(inout) :: x(:)
    if (st%nranks > 1) call comm_max(st%comm, x)
  end subroutine max_over_ranks

  !> det F of particle p (P2G's volume and the stable increment's density use the one formula).
  pure real(dp) function det_f(f, p, nd)
    real(dp), intent(in) :: f(:, :, :)   !< a block's F, (count, nd, nd)
    integer, intent(in) :: p, nd
    if (nd == 2) then
       det_f = f(p, 1, 1) * f(p, 2, 2) - f(p, 1, 2) * f(p, 2, 1)
    else
       det_f = f(p, 1, 1) * (f(p, 2, 2) * f(p, 3, 3) - f(p, 2, 3) * f(p, 3, 2)) &
            - f(p, 1, 2) * (f(p, 2, 1) * f(p, 3, 3) - f(p, 2, 3) * f(p, 3, 1)) &
            + f(p, 1, 3) * (f(p, 2, 1) * f(p, 3, 2) - f(p, 2, 2) * f(p, 3, 1))
    end if
  end function det_f
end module mpm_state
