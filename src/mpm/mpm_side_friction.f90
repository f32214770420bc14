!> Front and back wall friction of a quasi-2D bin in a plane-strain MPM scene
!> (`*MPM SIDE FRICTION, GAP=t, FRICTION=μw`; docs/theory/side_friction.md): the two walls a gap
!> t apart press on each particle with the compressive part of its out-of-plane stress,
!> p = max(−σ_zz, 0), and hold at most the Coulomb force 2 μw p V/t (both walls, V the particle's
!> current volume). Owns the capacity scatter, the node-wise stick/slip update and its work.
!>
!> Why on the grid node, after the force update: Coulomb friction is set-valued at rest (any
!> force up to the capacity). The velocity the friction must oppose is the one the increment
!> would give, with gravity and the stresses in; only the grid node knows it (its trial velocity
!> v* = v^n + Δt f/m). Reducing v* along itself by min(|v*|, Δt C/m) is the exact stick/slip
!> predictor of an explicit step (the walls' node rule, mpm_walls): a node whose capacity covers
!> the force that would move it stays at rest — the static (Janssen) state is a fixed point,
!> reached without chatter — and a sliding node gets the full capacity against its motion. A
!> particle-side force opposing v_p would be zero at rest (a resting column would creep down) or
!> flip sign from one increment to the next. The capacity itself is scattered with the shape
!> functions, as gravity's m g is (S·f_side), so it is consistent with the mass it acts on.
module mpm_side_friction
  use base_kinds, only: dp
  use model, only: model_t
  use mpm_state, only: mpm_state_t, fx_side_friction, sum_over_ranks, det_f
  use output_effects, only: effects_t
  implicit none
  private

  public :: side_friction_grid, side_friction_work, side_capacity_block, side_friction_node

contains

  !> The step's side friction on the grid velocities v_new (after the force update, before the
  !> walls): capacities from all blocks (their stencils of this increment), summed over the ranks
  !> and folded across mirrored symmetry planes, then the stick/slip update of every active node;
  !> the impulse on each node's own material is kept for the work (side_friction_work) and summed
  !> into the force on the walls (SIDEF).
  subroutine side_friction_grid(m, st, fx)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(effects_t), intent(inout) :: fx
    integer :: ib, i, k, s, stuck
    real(dp) :: mu, gap, v_trial(2)

    if (.not. fx%active(fx_side_friction)) return
    s = st%step
    mu = m%mpm%steps(s)%side_friction
    gap = m%mpm%steps(s)%side_gap
    st%side_force = 0
    if (mu <= 0) return
    call fx%start(fx_side_friction)
    if (.not. allocated(st%side_capacity)) allocate (st%side_capacity(st%g%nn), source=0.0_dp)
    st%side_capacity = 0
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         call scatter_block(st, b%count, mu, gap, b%vol0, b%f, b%stress_global, b%corner, b%w1, st%side_capacity)
       end associate
    end do
    call sum_over_ranks(st, st%side_capacity)
    do k = 1, size(m%mpm%walls)
       if (.not. (st%mirrored(k) .and. m%mpm%walls(k)%active(s))) cycle
       associate (mp => st%mirror(k))
         ! a front node and its image share the folded mass: they share the capacity too
         st%side_capacity(mp%front) = st%side_capacity(mp%front) + st%side_capacity(mp%back)
         st%side_capacity(mp%back) = st%side_capacity(mp%front)
       end associate
    end do
    if (.not. allocated(st%side_impulse)) allocate (st%side_impulse(2, st%g%nn), source=0.0_dp)
    do i = 1, st%g%nn
       st%side_impulse(:, i) = 0
       if (.not. st%g%active(i)) cycle
       v_trial = st%g%v_new(:, i)
       call side_friction_node(st%nd, st%g%mass(i), st%side_capacity(i), st%dt, st%g%v_new(:, i), stuck)
       ! the impulse on the node's own material (as the walls' WALLF, weighted by the own mass)
       st%side_impulse(:, i) = st%g%mass_own(i) * (st%g%v_new(:, i) - v_trial)
       st%side_force(1:2) = st%side_force(1:2) - st%side_impulse(:, i) / st%dt
    end do
    call fx%stop(fx_side_friction)
  end subroutine side_friction_grid

  !> The friction's work, after the walls: −Σ_I J_I·v_I^n+1, the impulse times the velocity the
  !> node keeps once the walls have projected it, into ALLFD. Why after the walls: a node on the
  !> floor is slid against by the friction and held by the floor; it does not slip, and a column
  !> resting on the floor must not dissipate. Away from walls this is the friction force times
  !> the slip the node keeps, m_own·drop·|v^n+1| ≥ 0, zero at stick.
  subroutine side_friction_work(m, st, fx)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(effects_t), intent(inout) :: fx
    integer :: i
    real(dp) :: work

    if (.not. fx%active(fx_side_friction)) return
    if (m%mpm%steps(st%step)%side_friction <= 0) return
    call fx%start(fx_side_friction)
    work = 0
    do i = 1, st%g%nn
       if (st%g%active(i)) work = work - dot_product(st%side_impulse(:, i), st%g%v_new(:, i))
    end do
    st%e_walls = st%e_walls + work
    call fx%stop(fx_side_friction)
  end subroutine side_friction_work

  !> The block's capacities C_p = 2 μw max(−σ_zz, 0) V_p/t scattered to the grid, C_I += S_Ip C_p
  !> (2D: the scene reader refuses the keyword in 3D).
  subroutine scatter_block(st, nb, mu, gap, vol0, f, stress, corner, w1, cap)
    type(mpm_state_t), intent(in) :: st
    integer, intent(in) :: nb
    real(dp), intent(in) :: mu, gap, vol0(:), f(:, :, :), stress(:, :), w1(:, :, :)
    integer, intent(in) :: corner(:)
    real(dp), intent(inout) :: cap(:)
    real(dp) :: vol(nb), cp(nb)
    integer :: p, a, c, off, nx

    do p = 1, nb
       vol(p) = vol0(p) * det_f(f, p, 2)
    end do
    call side_capacity_block(nb, mu, gap, vol, stress(1:nb, 3), cp)
    nx = st%g%n(1)
    do c = 1, st%nsup
       do a = 1, st%nsup
          off = (a - 1) + nx * (c - 1)
          do p = 1, nb
             cap(corner(p) + off) = cap(corner(p) + off) + w1(p, a, 1) * w1(p, c, 2) * cp(p)
          end do
       end do
    end do
  end subroutine scatter_block

  !> Friction capacity of each particle: the largest force the two walls can hold,
  !> 2 μw max(−σ_zz, 0) V/t (a particle in out-of-plane tension does not touch them).
  pure subroutine side_capacity_block(nb, mu, gap, vol, szz, cap)
    integer, intent(in) :: nb
    real(dp), intent(in) :: mu, gap, vol(nb), szz(nb)
    real(dp), intent(out) :: cap(nb)
    integer :: p

    do p = 1, nb
       cap(p) = 2 * mu * max(-szz(p), 0.0_dp) * vol(p) / gap
    end do
  end subroutine side_capacity_block

  !> Stick/slip update of one node: the trial velocity v (in: v*, out: v^n+1 before the walls)
  !> loses min(|v*|, Δt C/m) along itself. stuck = 1 when it stops (the capacity covers the force
  !> that would move it), 0 when it slides with the full capacity against its motion.
  pure subroutine side_friction_node(nd, mass, capacity, dt, v, stuck)
    integer, intent(in) :: nd
    real(dp), intent(in) :: mass, capacity, dt
    real(dp), intent(inout) :: v(nd)
    integer, intent(out) :: stuck
    real(dp) :: speed, drop

    speed = norm2(v)
    drop = dt * capacity / mass
    if (drop >= speed) then
       v = 0
       stuck = 1
       return
    end if
    stuck = 0
    v = ((speed - drop) / speed) * v
  end subroutine side_friction_node
end module mpm_side_friction
