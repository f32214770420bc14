!> The transfer phase of an MPM increment (MUSL with a PIC/FLIP blend; docs/theory/mpm.md §4.1):
!> the stable increment, the step's gravity, stencils, P2G (summed over the ranks), the
!> mirrored symmetry planes, the grid update with local damping, the walls on v^{n+1}, G2P and
!> the MUSL remap (summed over the ranks) with the walls again. What it leaves: particles at
!> x^{n+1} with v^{n+1}, the grid's v_new the remapped velocity the stress update takes its
!> gradient from.
module mpm_musl
  use, intrinsic :: iso_fortran_env, only: int64
  use base_kinds, only: dp
  use error_report, only: raise_error
  use model, only: model_t
  use mpm_scene, only: mpm_step_t
  use model_time_variation, only: variation_factor
  use model_steps, only: bc_velocity
  use mpm_state, only: mpm_state_t, fx_p2g, fx_grid, fx_g2p, fx_walls, fx_exchange, max_over_ranks, det_f
  use mpm_grid, only: grid_sum_length, grid_reset_sums, grid_clear
  use mpm_particles, only: particle_block_t, particle_block_size
  use mpm_shape, only: block_stencil
  use mpm_transfer, only: scatter_p2g, gather_velocity, scatter_momentum, scatter_particles, g2p_particles, &
       scatter_particles_3d_packed, gather_velocity_3d_packed, remap_particles_3d_packed, unpack_momentum, &
       pack_velocities, unpack_grid_sums, scatter_p2g_3d_packed, gather_velocity_3d_packed_pic, stencil_span, &
       clear_records, &
       scatter_momentum_3d_packed
  use mpm_sort, only: sort_due, sort_blocks
  use mpm_walls, only: wall_project, surface_find_nodes, surface_wall_project, surface_guard_block, wall_corner_dissipation
  use mpm_setup, only: mark_wall_nodes
  use mpm_wall_edges, only: any_open_end, open_end_contacts
  use mpm_mirror, only: mirror_fold, mirror_fold_momentum
  use output_effects, only: effects_t
  use mpm_side_friction, only: side_friction_grid, side_friction_work
  use parallel_comm, only: comm_sum
  use mpm_halo, only: halo_sum_p2g, halo_sum_momentum, owned_mass, sum_increment_accounts, local_corners
  implicit none
  private

  public :: stable_increment, block_max_speed, step_gravity, musl_transfer
  public :: stencil, p2g, grid_update, g2p, remap_velocity, rigid_surface_motion, flip_weight

contains

  !> st%dt_stable = cfl·h / max_p(c_p + |v_p|) over all ranks' particles.
  subroutine stable_increment(st, cfl, cell)
    type(mpm_state_t), intent(inout) :: st
    real(dp), intent(in) :: cfl, cell
    real(dp) :: vmax, v1(1)
    integer :: ib

    vmax = 0
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         call block_max_speed(b%count, st%nd, st%modulus(b%material), b%mass, b%vol0, b%f, b%v, vmax)
       end associate
    end do
    v1(1) = vmax
    call max_over_ranks(st, v1)
    st%dt_stable = cfl * cell / max(v1(1), tiny(1.0_dp))
  end subroutine stable_increment

  !> vmax ← max(vmax, c_p + |v_p|) over the particles of a block, in order; c_p from the current
  !> density m/(V0 det F). Explicit-shape dummies, as the other per-block loops (on the block's
  !> allocatable components every access goes through the descriptor).
  pure subroutine block_max_speed(nb, nd, modulus, mass, vol0, f, v, vmax)
    integer, intent(in) :: nb, nd
    real(dp), intent(in) :: modulus, mass(nb), vol0(nb), f(nb, nd, nd), v(nb, nd)
    real(dp), intent(inout) :: vmax
    real(dp) :: speed, rho, detf
    integer :: p

    do p = 1, nb
       detf = det_f(f, p, nd)
       rho = mass(p) / (vol0(p) * detf)
       speed = sqrt(modulus / rho) + norm2(v(p, :))
       vmax = max(vmax, speed)
    end do
  end subroutine block_max_speed

  !> Gravity of the step at the end of the increment (as the element driver takes loads; a
  !> load carried over from an earlier step keeps its value: model_time_variation).
  subroutine step_gravity(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer :: k, s
    real(dp) :: t_new

    s = st%step
    t_new = st%step_time + st%dt
    st%gravity = 0
    if (allocated(m%steps(s)%gravity)) then
       do k = 1, size(m%steps(s)%gravity)
          associate (gl => m%steps(s)%gravity(k))
            st%gravity = st%gravity + gl%magnitude * gl%direction * &
                 variation_factor(gl%variation, m%amplitudes, t_new, st%total_time + st%dt)
          end associate
       end do
    end if
  end subroutine step_gravity

  !> Stencils and P2G, the grid update, the walls, G2P and the MUSL remap of one increment.
  subroutine musl_transfer(m, st, fx)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(effects_t), intent(inout) :: fx
    integer :: ib, k, s, ilo, ihi
    real(dp) :: e_walls0, e_damping0
    real(dp) :: vw(3)   ! a wall's velocity (a rigid surface's; 0 for a fixed wall)
    logical :: packed, sorted

    s = st%step
    e_walls0 = st%e_walls
    e_damping0 = st%e_damping
    ! 3D uGIMP: the P2G, G2P + remap and gradient gather on packed node records (mpm_transfer),
    ! vectorised; the same sums in the same order
    packed = st%nd == 3 .and. st%nsup == 3
    sorted = m%mpm%steps(s)%sort > 0
    call fx%start(fx_p2g)
    call p2g_blocks(m, st, packed, sorted, ilo, ihi)
    call exchange_grid_sums(st, fx, fx_p2g, .true.)
    st%g%mass_own = st%g%mass
    st%wall_force = 0
    do k = 1, size(m%mpm%walls)
       if (.not. (st%mirrored(k) .and. m%mpm%walls(k)%active(s))) cycle
       if (st%dom%on) then
          call mirror_fold(st%mirror(k), st%g, st%dt, st%wall_force(:, k), st%dom%owned)
       else
          call mirror_fold(st%mirror(k), st%g, st%dt, st%wall_force(:, k))
       end if
    end do
    if (st%dom%on) call owned_mass(st)
    call fx%stop(fx_p2g)

    if (fx%active(fx_walls) .and. m%n_rigid_surfaces > 0) call surface_walls_at_new_time(m, st)
    call fx%start(fx_grid)
    call grid_update(st, m%mpm%steps(s)%damping)
    call fx%stop(fx_grid)
    call side_friction_grid(m, st, fx)    ! *MPM SIDE FRICTION (returns at once without it)
    if (fx%active(fx_walls)) then
       call fx%start(fx_walls)
       do k = 1, size(m%mpm%walls)
          if (.not. m%mpm%walls(k)%active(s) .or. st%mirrored(k)) cycle
          associate (w => m%mpm%walls(k))
            if (w%surface > 0) then
               call surface_wall_project(st%wall_nodes(k), st%rigid_v(:, w%surface), w%friction, st%nd, &
                    st%g%mass_own, st%g%active, st%g%v_new, st%dt, st%wall_force(:, k), st%e_walls)
            else
               call wall_project(w, st%wall_nodes(k), st%nd, st%g%mass_own, st%g%active, st%g%v_new, &
                    st%dt, st%wall_force(:, k), st%e_walls)
            end if
          end associate
       end do
       ! friction booked at nodes a later wall moved again (corners): on the velocity they keep
       do k = 1, size(m%mpm%walls)
          if (.not. m%mpm%walls(k)%active(s) .or. st%mirrored(k)) cycle
          vw = 0
          if (m%mpm%walls(k)%surface > 0) vw = st%rigid_v(:, m%mpm%walls(k)%surface)
          call wall_corner_dissipation(st%wall_nodes(k), st%nd, st%g%mass_own, st%g%v_new, vw, st%e_walls)
       end do
       if (st%dom%on) call sum_increment_accounts(st, e_walls0, e_damping0)
       ! the work of the moving walls on the material, −F·v_w Δt (ALLWK; the grid and so the
       ! forces are the same on every rank: counted on rank 0)
       if (st%rank == 0) then
          do k = 1, size(m%mpm%walls)
             associate (w => m%mpm%walls(k))
               if (w%surface > 0 .and. w%active(s)) st%w_external = st%w_external - &
                    st%dt * dot_product(st%wall_force(:, k), st%rigid_v(:, w%surface))
             end associate
          end do
       end if
       st%wall_impulse = st%wall_impulse + st%dt * st%wall_force
       st%impulse_time = st%impulse_time + st%dt
       call fx%stop(fx_walls)
    else if (st%dom%on) then
       call sum_increment_accounts(st, e_walls0, e_damping0)
    end if
    call side_friction_work(m, st, fx)    ! its work on the velocity the walls left

    call fx%start(fx_g2p)
    call g2p_blocks(m, st, packed, sorted, ilo, ihi)
    ! *MPM WALL, OPEN=: the particles at a wall's open end, before the remap is summed
    if (fx%active(fx_walls)) then
       if (any_open_end(m%mpm%walls, s)) call open_end_contacts(m%mpm%walls, st)
    end if
    call exchange_grid_sums(st, fx, fx_g2p, .false.)
    do k = 1, size(m%mpm%walls)
       if (st%mirrored(k) .and. m%mpm%walls(k)%active(s)) call mirror_fold_momentum(st%mirror(k), st%g)
    end do
    call remap_velocity(st)
    call fx%stop(fx_g2p)
    if (fx%active(fx_walls)) then
       call fx%start(fx_walls)
       do k = 1, size(m%mpm%walls)
          if (.not. m%mpm%walls(k)%active(s) .or. st%mirrored(k)) cycle
          associate (w => m%mpm%walls(k))
            if (w%surface > 0) then
               call surface_wall_project(st%wall_nodes(k), st%rigid_v(:, w%surface), w%friction, st%nd, &
                    st%g%mass, st%g%active, st%g%v_new, st%dt)
               ! particles behind it go back onto it here, at their x^n+1 (the fixed walls' guard
               ! follows the stress update, mpm_flow)
               do ib = 1, st%nblocks
                  associate (b => st%blocks(ib))
                    call surface_guard_block(m%rigid_surfaces(w%surface), st%rigid_u(:, w%surface), &
                         st%rigid_v(:, w%surface), w%friction, b%count, st%nd, b%x(1:b%count, :), &
                         b%v(1:b%count, :), st%n_guarded)
                  end associate
               end do
            else
               call wall_project(w, st%wall_nodes(k), st%nd, st%g%mass, st%g%active, st%g%v_new, st%dt)
            end if
          end associate
       end do
       call fx%stop(fx_walls)
    end if
    ! the remapped velocity for the stress update's gradient gather (mpm_stress_update)
    if (packed) call pack_velocities(st%g%nn, ilo, ihi, 4, st%g%v_new, st%g%v_new, st%gpack)
  end subroutine musl_transfer

  !> musl_transfer's P2G over the blocks (stencils, sort, scatter) into st%g's sums. packed (3D
  !> uGIMP): through st%gpack's records, over the span ilo..ihi of nodes the stencils touch
  !> (returned for the G2P; 1, 0 otherwise).
  subroutine p2g_blocks(m, st, packed, sorted, ilo, ihi)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    logical, intent(in) :: packed, sorted
    integer, intent(out) :: ilo, ihi
    integer :: ib, s

    s = st%step
    ilo = 1
    ihi = 0
    if (packed) then
       if (allocated(st%gpack)) then
          if (size(st%gpack, 2) /= st%g%nn) deallocate (st%gpack)
       end if
       if (.not. allocated(st%gpack)) allocate (st%gpack(8, st%g%nn))
    else
       call grid_reset_sums(st%g)
    end if
    ! *MPM CONTROLS, SORT=n: particles in cell order, transfers particle by particle (mpm_sort)
    if (sort_due(m%mpm%steps(s)%sort, st%increment)) &
         call sort_blocks(st%blocks, st%nblocks, st%nd, st%g%lo, st%g%h, st%g%n)
    if (packed) then
       ! every block's stencils first: the span of nodes they touch, the only records cleared,
       ! packed and unpacked in this increment (the nodes beyond get zero sums)
       ilo = huge(ilo)
       ihi = 0
       do ib = 1, st%nblocks
          call stencil(st, st%blocks(ib), m%mpm%shape, m%input_file)
          call stencil_span(st%blocks(ib)%count, st%g%n(1), st%g%n(1) * st%g%n(2), st%blocks(ib)%corner, ilo, ihi)
       end do
       call clear_records(st%g%nn, ilo, ihi, 8, st%gpack)
    end if
    do ib = 1, st%nblocks
       if (.not. packed) call stencil(st, st%blocks(ib), m%mpm%shape, m%input_file)
       if (packed .and. sorted) then
          associate (b => st%blocks(ib))
            call scatter_particles_3d_packed(b%count, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, &
                 b%dw1, b%mass, b%vol0, b%f, b%v, b%stress_global, st%gravity, st%gpack)
          end associate
       else if (sorted) then
          associate (b => st%blocks(ib))
            call scatter_particles(b%count, st%nsup, st%nd, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, &
                 b%w1, b%dw1, b%mass, b%vol0, b%f, b%v, b%stress_global, st%gravity, st%g%mass, st%g%mom, st%g%force)
          end associate
       else
          call p2g(st, st%blocks(ib), packed)
       end if
    end do
    if (packed) call unpack_grid_sums(st%g%nn, ilo, ihi, st%gpack, st%g%mass, st%g%mom, st%g%force)
  end subroutine p2g_blocks

  !> musl_transfer's G2P and MUSL remap over the blocks into st%g%mom (packed: as p2g_blocks).
  subroutine g2p_blocks(m, st, packed, sorted, ilo, ihi)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    logical, intent(in) :: packed, sorted
    integer, intent(in) :: ilo, ihi
    integer :: ib, s
    real(dp) :: alpha

    s = st%step
    alpha = flip_weight(m%mpm%steps(s), st%dt)
    if (packed) then
       ! every block's gather and particle update (v_new, v_old packed), then every block's remap
       ! into the records' first 4 nn values: each node's sum in the particle order of the
       ! block-by-block loop below
       call pack_velocities(st%g%nn, ilo, ihi, 8, st%g%v_new, st%g%v_old, st%gpack)
       do ib = 1, st%nblocks
          associate (b => st%blocks(ib))
            if (sorted) then
               call gather_velocity_3d_packed(b%count, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, &
                    b%w1, st%gpack, b%mass, st%gravity, alpha, st%dt, b%v, b%x, st%w_external)
            else
               call g2p_packed(st, b, alpha)
            end if
          end associate
       end do
       call clear_records(st%g%nn, ilo, ihi, 4, st%gpack)
       do ib = 1, st%nblocks
          associate (b => st%blocks(ib))
            if (sorted) then
               call remap_particles_3d_packed(b%count, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, &
                    b%w1, b%mass, b%v, st%gpack)
            else
               call remap_packed(st, b)
            end if
          end associate
       end do
       call unpack_momentum(st%g%nn, ilo, ihi, st%gpack, st%g%mom)
    else
       call grid_clear(st%nd * st%g%nn, st%g%mom)
       do ib = 1, st%nblocks
          if (sorted) then
             associate (b => st%blocks(ib))
               call g2p_particles(b%count, st%nsup, st%nd, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, &
                    b%w1, st%g%v_new, st%g%v_old, b%mass, st%gravity, alpha, st%dt, b%v, b%x, &
                    st%g%mom, st%w_external)
             end associate
          else
             call g2p(st, st%blocks(ib), alpha)
          end if
       end do
    end if
  end subroutine g2p_blocks

  !> The rigid surfaces at t_n+1: their reference nodes' velocity over the increment and
  !> displacement (rigid_surface_motion), then the nodes of the active rigid-surface walls and
  !> the wall-node marks local damping leaves alone.
  subroutine surface_walls_at_new_time(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer :: k, s

    s = st%step
    call rigid_surface_motion(m, s, st%step_time, st%total_time, st%dt, st%rigid_u, st%rigid_v)
    do k = 1, size(m%mpm%walls)
       associate (w => m%mpm%walls(k))
         if (w%surface == 0 .or. .not. w%active(s)) cycle
         call surface_find_nodes(m%rigid_surfaces(w%surface), st%rigid_u(:, w%surface), st%g, st%wall_nodes(k))
       end associate
    end do
    call mark_wall_nodes(m, st)
  end subroutine surface_walls_at_new_time

  !> Velocity v (over the increment t_n..t_n+1) and displacement u (advanced from t_n to t_n+1)
  !> of every rigid surface's reference node, from the step's *BOUNDARY on it, as the element
  !> driver moves its walls: a velocity condition gives value·A(t_n+½), a displacement condition
  !> the velocity that reaches value·A(t_n+1) at t_n+1; a dof without one does not move (walls
  !> are driven, not free bodies); a surface without a reference node is fixed.
  subroutine rigid_surface_motion(m, s, step_time, total_time, dt, u, v)
    type(model_t), intent(in) :: m
    integer, intent(in) :: s
    real(dp), intent(in) :: step_time, total_time, dt
    real(dp), intent(inout) :: u(:, :), v(:, :)
    integer :: r, ib, dof
    real(dp) :: a_mid, a_new

    v = 0
    if (allocated(m%steps(s)%boundaries)) then
       do ib = 1, size(m%steps(s)%boundaries)
          associate (b => m%steps(s)%boundaries(ib))
            a_mid = variation_factor(b%variation, m%amplitudes, step_time + 0.5_dp * dt, total_time + 0.5_dp * dt)
            a_new = variation_factor(b%variation, m%amplitudes, step_time + dt, total_time + dt)
            do r = 1, m%n_rigid_surfaces
               if (m%rigid_surfaces(r)%ref_node == 0) cycle
               if (.not. any(b%nodes == m%rigid_surfaces(r)%ref_node)) cycle
               do dof = b%first_dof, min(b%last_dof, m%mpm%ndim)
                  if (b%kind == bc_velocity) then
                     v(dof, r) = b%value * a_mid
                  else
                     v(dof, r) = (b%value * a_new - u(dof, r)) / dt
                  end if
               end do
            end do
          end associate
       end do
    end if
    u = u + dt * v
  end subroutine rigid_surface_motion

  !> The grid's sums over the ranks inside a transfer phase (`phase`, paused meanwhile so that the
  !> exchange has a timer of its own): after P2G (all_fields: mass, momentum, force) or after the
  !> remap (momentum), by the halo of the spatial decomposition or by an all-reduce of the
  !> replicated grid. Nothing on one rank. Collective.
  subroutine exchange_grid_sums(st, fx, phase, all_fields)
    type(mpm_state_t), intent(inout) :: st
    type(effects_t), intent(inout) :: fx
    integer, intent(in) :: phase
    logical, intent(in) :: all_fields

    if (st%nranks == 1) return
    call fx%stop(phase)
    call fx%start(fx_exchange)
    if (st%dom%on .and. all_fields) then
       call halo_sum_p2g(st)
    else if (st%dom%on) then
       call halo_sum_momentum(st)
    else
       call reduce_grid(st, all_fields)
    end if
    call fx%stop(fx_exchange)
    call fx%start(phase)
  end subroutine exchange_grid_sums

  !> Sum the grid arrays over ranks: after P2G mass, momentum and force, after the remap momentum.
  subroutine reduce_grid(st, all_fields)
    type(mpm_state_t), intent(inout) :: st
    logical, intent(in) :: all_fields
    real(dp), allocatable :: buf(:)
    integer(int64) :: nn, nv     ! nn (1 + 2 nd) passes 2^31 for large 3D grids

    nn = st%g%nn
    nv = st%nd * nn
    if (all_fields) then
       allocate (buf(grid_sum_length(st%g%nn, st%nd)))
       buf(1:nn) = st%g%mass
       buf(nn + 1:nn + nv) = reshape(st%g%mom, [nv])
       buf(nn + nv + 1:) = reshape(st%g%force, [nv])
       call comm_sum(st%comm, buf)
       st%g%mass = buf(1:nn)
       st%g%mom = reshape(buf(nn + 1:nn + nv), [st%nd, st%g%nn])
       st%g%force = reshape(buf(nn + nv + 1:), [st%nd, st%g%nn])
    else
       call comm_sum(st%comm, st%g%mom)
    end if
  end subroutine reduce_grid

  !> The block's stencils at its particles' positions; a particle outside the grid is an error.
  subroutine stencil(st, b, shape, input_file)
    type(mpm_state_t), intent(in) :: st
    type(particle_block_t), intent(inout) :: b
    integer, intent(in) :: shape               !< mpm_scene's shape_linear / shape_gimp
    character(len=*), intent(in) :: input_file !< for the message
    integer :: outside
    character(len=160) :: text
    character(len=36) :: position

    if (st%dom%on) then
       ! a decomposed grid: the stencil on the whole grid, then its corners on the rank's box
       call block_stencil(b%count, st%nd, st%nsup, shape, st%g%lo, st%g%h, st%dom%n, b%half, b%x, b%corner, &
            b%w1, b%dw1, outside)
       if (outside == 0) call local_corners(st, b)
    else
       call block_stencil(b%count, st%nd, st%nsup, shape, st%g%lo, st%g%h, st%g%n, b%half, b%x, b%corner, &
            b%w1, b%dw1, outside)
    end if
    if (outside /= 0) then
       ! the position apart: a 2D particle has two coordinates, fewer than the edit descriptors
       write (position, '(3es12.4)') b%x(outside, :)
       write (text, '(a,i0,a,a,a,es12.5)') 'particle ', b%number(outside), ' at ', trim(position), &
            ' left the background grid at t = ', st%total_time
       call raise_error(trim(input_file), 0, trim(text) // '; expected a *MPM GRID that covers the flow ' // &
            '(enlarge it, add walls or an *OUTFLOW)')
    end if
  end subroutine stencil

  !> Particle to grid: mass, momentum, internal and gravity forces. The particle factors
  !> (m v, V σ, m g) are formed first in block loops that vectorize; the scatter then does one
  !> multiply-add per value and node.
  !> The factors' work arrays are fixed-size locals of particle_block_size rows' room, seen by
  !> p2g_factors and the scatter as (count, ·) arrays (sequence association): as automatic arrays
  !> of b%count rows gfortran allocated them on the heap per block and increment (issue 19).
  !> packed present and true (3D uGIMP): the sums go to st%gpack's records
  !> (scatter_p2g_3d_packed), the caller unpacks them.
  subroutine p2g(st, b, packed)
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), intent(in) :: b
    logical, intent(in), optional :: packed
    real(dp) :: mv(3 * particle_block_size), vs(6 * particle_block_size), mg(3 * particle_block_size)
    real(dp) :: fac(20 * particle_block_size)
    logical :: into_records

    call p2g_factors(b%count, st%nd, st%nc, b%vol0, b%f, b%stress_global, b%mass, b%v, st%gravity, mv, vs, mg)
    into_records = .false.
    if (present(packed)) into_records = packed
    if (into_records) then
       call scatter_p2g_3d_packed(b%count, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, b%dw1, &
            b%mass, mv, vs, mg, fac, st%gpack)
    else
       call scatter_p2g(b%count, st%nsup, st%nd, st%nc, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, &
            b%w1, b%dw1, b%mass, mv, vs, mg, st%g%mass, st%g%mom, st%g%force)
    end if
  end subroutine p2g

  !> p2g's particle factors m v, V σ (V = V0 det F) and m g of a block.
  pure subroutine p2g_factors(nb, nd, nc, vol0, f, stress, mass, v, gravity, mv, vs, mg)
    integer, intent(in) :: nb, nd, nc
    real(dp), intent(in) :: vol0(nb), f(nb, nd, nd), stress(nb, nc), mass(nb), v(nb, nd), gravity(3)
    real(dp), intent(out) :: mv(nb, nd), vs(nb, nc), mg(nb, nd)
    real(dp) :: vol(particle_block_size)
    integer :: p, k

    ! column by column (particle index innermost): the row-wise form was a quarter of p2g
    do p = 1, nb
       vol(p) = vol0(p) * det_f(f, p, nd)
    end do
    do k = 1, nc
       vs(:, k) = vol(1:nb) * stress(:, k)
    end do
    do k = 1, nd
       mv(:, k) = mass * v(:, k)
       mg(:, k) = mass * gravity(k)
    end do
  end subroutine p2g_factors

  !> v_I^n = p_I/m_I; [local damping f ← f − a|f| sgn v]; v_I^{n+1} = v_I^n + Δt f_I/m_I.
  subroutine grid_update(st, damping)
    type(mpm_state_t), intent(inout) :: st
    real(dp), intent(in) :: damping           !< local damping coefficient a of the step

    call grid_update_nodes(st%g%nn, st%nd, damping, st%dt, st%mass_cutoff, st%g%mass, st%g%mass_own, st%g%mom, &
         st%g%force, st%on_wall, st%g%active, st%g%v_old, st%g%v_new, st%e_damping)
  end subroutine grid_update

  !> grid_update's node loop. Explicit-shape dummies (issue 19): on the grid's allocatable
  !> components the loop went through their descriptors at every access. Inactive nodes get zero
  !> velocities here, in the same pass (no clearing of the two whole arrays first); the active
  !> ones' values and the damping energy's sum (node order) are the arithmetic of before.
  pure subroutine grid_update_nodes(nn, nd, a, dt, cutoff, mass, mass_own, mom, force, on_wall, active, v_old, v_new, &
       e_damping)
    integer, intent(in) :: nn, nd
    real(dp), intent(in) :: a, dt, cutoff, mass(nn), mass_own(nn), mom(nd, nn), force(nd, nn)
    logical, intent(in) :: on_wall(nn)
    logical, intent(out) :: active(nn)
    real(dp), intent(out) :: v_old(nd, nn), v_new(nd, nn)
    real(dp), intent(inout) :: e_damping
    integer :: i, k
    real(dp) :: f, damp

    do i = 1, nn
       active(i) = mass(i) > cutoff
       if (.not. active(i)) then
          ! component by component, not a loop to nd: gcc made that loop two memset calls per
          ! inactive node (issue 19)
          v_old(1, i) = 0
          v_old(2, i) = 0
          v_new(1, i) = 0
          v_new(2, i) = 0
          if (nd == 3) then
             v_old(nd, i) = 0
             v_new(nd, i) = 0
          end if
          cycle
       end if
       do k = 1, nd
          v_old(k, i) = mom(k, i) / mass(i)
          f = force(k, i)
          if (a > 0 .and. abs(v_old(k, i)) > 0 .and. .not. on_wall(i)) then
             ! Cundall's local non-viscous damping: opposes the motion, proportional to |f|
             damp = a * abs(f)
             f = f - sign(damp, v_old(k, i))
             ! the real material's share of the node (image mass folded in: mpm_mirror)
             e_damping = e_damping + damp * abs(v_old(k, i)) * dt * mass_own(i) / mass(i)
          end if
          v_new(k, i) = v_old(k, i) + dt * f / mass(i)
       end do
    end do
  end subroutine grid_update_nodes

  !> Grid to particles: PIC/FLIP blend (alpha: 1 FLIP, 0 PIC) of the velocity, position from the
  !> new grid velocity; then (MUSL) the block's new momentum goes back to the grid (st%g%mom,
  !> zeroed by the caller) while its stencil is at hand.
  subroutine g2p(st, b, alpha)
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), intent(inout) :: b
    real(dp), intent(in) :: alpha
    ! fixed-size work arrays seen as (count, nd) by the kernels (as in p2g: no heap allocation)
    real(dp) :: vpic(3 * particle_block_size), dv(3 * particle_block_size), wk

    call gather_velocity(b%count, st%nsup, st%nd, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, &
         st%g%v_new, st%g%v_old, vpic, dv)
    call g2p_update(b%count, st%nd, alpha, st%dt, st%gravity, b%mass, vpic, dv, b%v, b%x, wk)
    st%w_external = st%w_external + wk
    call scatter_momentum(b%count, st%nsup, st%nd, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, dv, &
         st%g%mom)
  end subroutine g2p

  !> g2p's gather and particle update for 3D uGIMP on st%gpack's velocity records (v_new, v_old);
  !> the remap is remap_packed's, after every block's update (musl_transfer).
  subroutine g2p_packed(st, b, alpha)
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), intent(inout) :: b
    real(dp), intent(in) :: alpha
    real(dp) :: vpic(3 * particle_block_size), dv(3 * particle_block_size), wk

    call gather_velocity_3d_packed_pic(b%count, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, &
         st%gpack, vpic, dv)
    call g2p_update(b%count, st%nd, alpha, st%dt, st%gravity, b%mass, vpic, dv, b%v, b%x, wk)
    st%w_external = st%w_external + wk
  end subroutine g2p_packed

  !> g2p's MUSL remap for 3D uGIMP into st%gpack's momentum records (the first 4 nn values).
  subroutine remap_packed(st, b)
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), intent(in) :: b
    real(dp) :: mv4(4 * particle_block_size)

    call scatter_momentum_3d_packed(b%count, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, b%mass, &
         b%v, mv4, st%gpack)
  end subroutine remap_packed

  !> The FLIP weight α of an increment dt under the step's controls. A fixed α removes the share
  !> 1 − α of the particles' sub-grid velocity (v_p − v_PIC) every increment: a damping rate
  !> (1 − α)/dt that grows as the increment shrinks (a stiffer material, a smaller CFL or cell
  !> damps the flow more: docs/theory/mpm.md §4.3). With PIC TIME=τ the sub-grid part decays
  !> as exp(−t/τ) whatever the increments: α = exp(−dt/τ).
  pure real(dp) function flip_weight(c, dt) result(alpha)
    type(mpm_step_t), intent(in) :: c
    real(dp), intent(in) :: dt

    if (c%pic_time > 0) then
       alpha = exp(-dt / c%pic_time)
    else
       alpha = c%flip
    end if
  end function flip_weight

  !> g2p's particle update: PIC/FLIP velocity, position, the gravity's work wk; dv returns the
  !> particles' momentum m v for the remap.
  pure subroutine g2p_update(nb, nd, alpha, dt, gravity, mass, vpic, dv, v, x, wk)
    integer, intent(in) :: nb, nd
    real(dp), intent(in) :: alpha, dt, gravity(3), mass(nb), vpic(nb, nd)
    real(dp), intent(inout) :: dv(nb, nd), v(nb, nd), x(nb, nd)
    real(dp), intent(out) :: wk
    integer :: p, k

    wk = 0
    do k = 1, nd
       do p = 1, nb
          v(p, k) = alpha * (v(p, k) + dv(p, k)) + (1 - alpha) * vpic(p, k)
          x(p, k) = x(p, k) + dt * vpic(p, k)
          wk = wk + mass(p) * gravity(k) * dt * vpic(p, k)
          ! from here on dv holds the particle momentum for the remap
          dv(p, k) = mass(p) * v(p, k)
       end do
    end do
  end subroutine g2p_update

  !> The remapped velocity v_I = p_I/m_I on the active nodes. Inactive nodes: v_new is still
  !> grid_update's zero (the walls project active nodes only).
  subroutine remap_velocity(st)
    type(mpm_state_t), intent(inout) :: st

    call remap_velocity_nodes(st%g%nn, st%nd, st%g%active, st%g%mass, st%g%mom, st%g%v_new)
  end subroutine remap_velocity

  !> remap_velocity's node loop on explicit-shape dummies (as grid_update_nodes).
  pure subroutine remap_velocity_nodes(nn, nd, active, mass, mom, v_new)
    integer, intent(in) :: nn, nd
    logical, intent(in) :: active(nn)
    real(dp), intent(in) :: mass(nn), mom(nd, nn)
    real(dp), intent(inout) :: v_new(nd, nn)
    integer :: i, k

    do i = 1, nn
       if (.not. active(i)) cycle
       do k = 1, nd
          v_new(k, i) = mom(k, i) / mass(i)
       end do
    end do
  end subroutine remap_velocity_nodes
end module mpm_musl
