!> Set-up of a material-point run: the state's sizes, grid, per-material moduli and VUMAT work
!> sets, the particles of the *PARTICLES regions (made by mpm_lattice) and their split over the
!> ranks, the walls' node lists and mirrors, and the effects the scene asks for. Also the
!> step's wall-node marks (`mark_wall_nodes`).
module mpm_setup
  use base_kinds, only: dp
  use error_report, only: raise_error
  use material_props, only: model_from_name, model_unknown
  use model, only: model_t
  use mpm_scene, only: decomposition_spatial
  use mpm_migrate, only: decompose_start, decompose_boxes
  use mpm_lattice, only: lattice_tally_t, tally_region, tally_close, generate_region
  use mpm_halo, only: domain_regrid
  use mpm_state, only: mpm_state_t, fx_p2g, fx_grid, fx_g2p, fx_kinematics, fx_material, &
       fx_user_field, fx_gravity, fx_damping, fx_walls, fx_outflow, fx_inflow, fx_side_friction, &
       fx_exchange, fx_migration, fx_nonlocal, fx_dilation
  use output_effects, only: effects_t
  use mpm_grid, only: grid_init
  use mpm_particles, only: particle_block_size
  use mpm_shape, only: stencil_nodes_per_direction
  use mpm_walls, only: wall_find_nodes
  use mpm_wall_edges, only: open_end_support
  use mpm_mirror, only: mirror_plane_setup
  use mpm_stress_update, only: material_work_init
  use material_door, only: checked_packaging_modulus
  implicit none
  private

  public :: mpm_setup_run, setup_state, setup_walls, mark_wall_nodes

contains

  !> The whole set-up of a run: state, walls, particles (this rank's share), effects.
  subroutine mpm_setup_run(m, st, fx)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(effects_t), intent(inout) :: fx
    type(lattice_tally_t) :: tally
    integer :: k, s
    logical :: spatial

    spatial = st%nranks > 1 .and. m%mpm%decomposition == decomposition_spatial
    ! spatial: the whole grid's geometry only; its node arrays are the held box's (domain_regrid)
    call setup_state(m, st, grid_nodes=.not. spatial)
    associate (mpm => m%mpm)
      allocate (st%wall_nodes(size(mpm%walls)), st%wall_force(3, size(mpm%walls)))
      allocate (st%wall_impulse(3, size(mpm%walls)), st%wall_force_row(3, size(mpm%walls)))
      st%wall_force = 0
      st%wall_impulse = 0
      st%wall_force_row = 0
      allocate (st%mirror(size(mpm%walls)), st%mirrored(size(mpm%walls)))
      allocate (st%rigid_u(3, m%n_rigid_surfaces), st%rigid_v(3, m%n_rigid_surfaces))
      st%rigid_u = 0
      st%rigid_v = 0
      call setup_walls(m, st)
      allocate (st%blocks(16))
      st%nblocks = 0
      if (spatial) then
         ! the boxes from the whole set's counts per cell, then only this rank's particles
         ! (mpm_lattice: the same numbers, totals and blocks as if all were made)
         call decompose_start(st, m%mpm%rebalance)
         do k = 1, size(mpm%regions)
            call tally_region(m, st, mpm%regions(k), tally)
         end do
         call tally_close(tally)
         if (tally%particles == 0) call no_particles()
         call decompose_boxes(st, tally%counts)
         deallocate (tally%counts)
         do k = 1, size(mpm%regions)
            call generate_region(m, st, mpm%regions(k), owner_only=.true.)
         end do
         st%mass_initial = tally%mass
         st%mass_cutoff = 1.0e-9_dp * tally%largest_mass
         st%n_initial = tally%particles
         call domain_regrid(st)
         call setup_walls(m, st)
      else
         do k = 1, size(mpm%regions)
            call generate_region(m, st, mpm%regions(k))
         end do
         if (st%nblocks == 0) call no_particles()
         st%mass_initial = 0
         do k = 1, st%nblocks
            st%mass_initial = st%mass_initial + sum(st%blocks(k)%mass)
         end do
         st%mass_cutoff = 1.0e-9_dp * maxval([(maxval(st%blocks(k)%mass), k = 1, st%nblocks)])
         st%n_initial = sum(st%blocks(1:st%nblocks)%count)
      end if
      ! replicated grid: every rank made all blocks (same order); each keeps every nranks-th one
      if (st%nranks > 1 .and. .not. spatial) then
         s = 0
         do k = 1, st%nblocks
            if (mod(k - 1, st%nranks) /= st%rank) cycle
            s = s + 1
            if (s /= k) st%blocks(s) = st%blocks(k)
         end do
         st%nblocks = s
      end if
    end associate
    ! The average needs every neighbour within LENGTH on the rank: neither decomposition keeps
    ! them there (the replicated one deals blocks out, the spatial one would need a particle
    ! halo of width LENGTH). Refused rather than averaged over a rank's share.
    if (m%mpm%nonlocal%on .and. st%nranks > 1) call raise_error(trim(m%mpm%nonlocal%source), 0, &
         '*NONLOCAL is not supported with ' // trim(rank_text(st%nranks)) // ' ranks (the neighbours of a ' // &
         'particle may be on another rank); expected a run on 1 rank')
    call setup_effects(m, st%nranks, fx)
  contains
    subroutine no_particles()
      call raise_error(trim(m%input_file), 0, 'the *PARTICLES regions hold no ' // &
           'particle centre; expected regions at least one particle spacing (CELL/PPC) wide')
    end subroutine no_particles
  end subroutine mpm_setup_run

  pure function rank_text(n) result(t)
    integer, intent(in) :: n
    character(len=12) :: t
    write (t, '(i0)') n
  end function rank_text

  !> The walls' node lists and the mirrored symmetry planes on the rank's grid (again after a
  !> spatial decomposition changed the grid: mpm_domain).
  subroutine setup_walls(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer :: k

    do k = 1, size(m%mpm%walls)
       if (m%mpm%walls(k)%surface > 0) then
          ! a rigid-surface wall finds its nodes every increment (it may move: mpm_musl)
          if (allocated(st%wall_nodes(k)%nodes)) deallocate (st%wall_nodes(k)%nodes, st%wall_nodes(k)%normal)
          allocate (st%wall_nodes(k)%nodes(0), st%wall_nodes(k)%normal(3, 0))
          st%mirrored(k) = .false.
          cycle
       end if
       call wall_find_nodes(m%mpm%walls(k), st%g, st%wall_nodes(k), open_end_support(st%g%h, st%nsup))
       call mirror_plane_setup(m%mpm%walls(k), st%g, st%mirror(k), st%mirrored(k))
       ! a mirrored plane is no wall to the grid: its nodes and images are damped as the full
       ! model's would be (the fold leaves them symmetric)
       if (st%mirrored(k)) st%wall_nodes(k)%nodes = [integer ::]
    end do
  end subroutine setup_walls

  !> Sizes (dimension, stress components, stencil), the grid, the materials' moduli and the
  !> full-block VUMAT work set; no particles yet.
  subroutine setup_state(m, st, grid_nodes)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    logical, intent(in) :: grid_nodes   !< allocate the whole grid's node arrays (mpm_grid grid_init)
    integer :: k, nsv, nfv

    st%nd = m%mpm%ndim
    if (st%nd == 2) then
       st%nc = 4
       st%nshr = 1
    else
       st%nc = 6
       st%nshr = 3
    end if
    st%nsup = stencil_nodes_per_direction(m%mpm%shape)
    call grid_init(st%g, st%nd, m%mpm%lo, m%mpm%hi, m%mpm%cell, nodes=grid_nodes)
    allocate (st%modulus(m%n_materials), st%needs_kinematics(m%n_materials))
    nsv = 1
    nfv = 1
    do k = 1, m%n_materials
       st%modulus(k) = checked_packaging_modulus(m%materials(k), st%nc, st%nshr, m%input_file)
       st%needs_kinematics(k) = m%materials(k)%user_code .or. &
            model_from_name(m%materials(k)%vumat_name) == model_unknown
       nsv = max(nsv, m%materials(k)%nstatev)
       nfv = max(nfv, m%materials(k)%nfieldv)
    end do
    st%work_statev = nsv
    st%work_fieldv = nfv
    call material_work_init(st, st%work(1), particle_block_size)
  end subroutine setup_state

  !> The MPM's effects, declared into the run's registry: active when the scene asks for them.
  !> Gravity and damping act inside the P2G/grid loops, VUSDFLD inside the material call: listed,
  !> not timed apart. On more than one rank the grid's sums over the ranks (all-reduce of the
  !> replicated grid, or the halo sums of the spatial one) and the particles' migration are timed
  !> as effects of their own: the scaling model (docs/scaling.md) needs them apart from the
  !> particle work.
  subroutine setup_effects(m, nranks, fx)
    type(model_t), intent(in) :: m
    integer, intent(in) :: nranks
    type(effects_t), intent(inout) :: fx
    logical :: inflow, damping, gravity, side, dilation
    integer :: s

    inflow = .false.
    damping = .false.
    gravity = .false.
    side = .false.
    dilation = .false.
    do s = 1, m%n_steps
       inflow = inflow .or. m%mpm%steps(s)%inflow%on
       damping = damping .or. m%mpm%steps(s)%damping > 0
       if (allocated(m%steps(s)%gravity)) gravity = gravity .or. size(m%steps(s)%gravity) > 0
       side = side .or. m%mpm%steps(s)%side_friction > 0
       dilation = dilation .or. m%mpm%steps(s)%max_dilation > 0
    end do
    call fx%declare(fx_p2g, 'p2g', active=.true.)
    call fx%declare(fx_grid, 'grid update', active=.true.)
    call fx%declare(fx_g2p, 'g2p', active=.true.)
    call fx%declare(fx_kinematics, 'kinematics', active=.true.)
    call fx%declare(fx_material, 'material', active=.true.)
    call fx%declare(fx_user_field, 'user field', active=any(m%materials(1:m%n_materials)%user_field), timed=.false.)
    call fx%declare(fx_gravity, 'gravity', active=gravity, timed=.false.)
    call fx%declare(fx_damping, 'damping', active=damping, timed=.false.)
    call fx%declare(fx_walls, 'walls', active=size(m%mpm%walls) > 0)
    call fx%declare(fx_outflow, 'outflow', active=m%mpm%outflow)
    call fx%declare(fx_inflow, 'inflow', active=inflow)
    call fx%declare(fx_side_friction, 'side friction', active=side)
    call fx%declare(fx_exchange, 'grid exchange', active=nranks > 1)
    call fx%declare(fx_migration, 'migration', active=nranks > 1 .and. m%mpm%decomposition == decomposition_spatial)
    call fx%declare(fx_nonlocal, 'nonlocal', active=m%mpm%nonlocal%on)
    call fx%declare(fx_dilation, 'max dilation', active=dilation, timed=.false.)
  end subroutine setup_effects

  !> The nodes the active walls of the step constrain: local damping leaves them alone, so that
  !> it does not change the reactions (the wall forces) of a body at rest.
  subroutine mark_wall_nodes(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer :: k

    if (allocated(st%on_wall)) then
       ! a re-partitioned grid (mpm_domain) has another number of nodes
       if (size(st%on_wall) /= st%g%nn) deallocate (st%on_wall)
    end if
    if (.not. allocated(st%on_wall)) allocate (st%on_wall(st%g%nn))
    st%on_wall = .false.
    do k = 1, size(m%mpm%walls)
       if (.not. m%mpm%walls(k)%active(st%step)) cycle
       st%on_wall(st%wall_nodes(k)%nodes) = .true.
       if (allocated(st%wall_nodes(k)%undamped)) st%on_wall(st%wall_nodes(k)%undamped) = .true.
    end do
  end subroutine mark_wall_nodes
end module mpm_setup
