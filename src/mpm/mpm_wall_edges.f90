!> The open ends of walls (*MPM WALL, OPEN=START|END|BOTH in 2D, OPEN=XLOW ... ZHIGH, a face of
!> the wall's box, in 3D; docs/theory/mpm.md §4.4, "Open wall ends"). A wall's grid condition acts on nodes, and a node's shape function reaches a cell
!> and a half (uGIMP) past it: the floor node next to an outlet's edge holds the sand above the
!> opening too, and the outlet discharges as if it were narrower by about a cell at each edge (a
!> first-order error in h, docs/accuracy.md). At an open end the wall leaves the nodes whose
!> support reaches past the end free (mpm_walls' wall_find_nodes) and holds the particles over
!> it instead: after G2P, a particle over the wall near the end whose domain touches the wall
!> loses its velocity into the wall by the nodes' Coulomb rule, and the momentum it loses leaves
!> the MUSL-remapped grid momentum through the particle's own stencil, so the strain rate the
!> stress update gathers sees the held particle. Its displacement, Δt Σ S v_I over the free
!> nodes, gets the same rule (and gravity's work on it the same correction): without that the
!> first row sank by a free node's step every increment, the guard (mpm_flow) put it back, and
!> gravity's work on the undone descent drifted ETOTAL by 10 % of ALLIE in a 3 s bin discharge.
module mpm_wall_edges
  use base_kinds, only: dp
  use mpm_scene, only: mpm_wall_t
  use mpm_walls, only: wall_distance, wall_contains, wall_slide_velocity, near_open_end, wall_rows_behind
  use mpm_particles, only: particle_block_t, particle_block_size
  use mpm_state, only: mpm_state_t, sum_over_ranks
  implicit none
  private

  public :: open_end_support, any_open_end, open_end_contacts, block_open_end_contact

contains

  !> How far a node's shape function reaches [m]: a cell for linear shapes, a cell and the
  !> largest uGIMP half-length (h/2, one particle per cell) for uGIMP.
  pure real(dp) function open_end_support(h, nsup)
    real(dp), intent(in) :: h
    integer, intent(in) :: nsup
    open_end_support = merge(1.5_dp, 1.0_dp, nsup == 3) * h
  end function open_end_support

  !> Does an active wall of step s have an open end?
  pure logical function any_open_end(walls, s)
    type(mpm_wall_t), intent(in) :: walls(:)
    integer, intent(in) :: s
    integer :: k
    any_open_end = .false.
    do k = 1, size(walls)
       if (walls(k)%active(s) .and. (walls(k)%open_start .or. walls(k)%open_end)) any_open_end = .true.
    end do
  end function any_open_end

  !> Every active wall's open ends on every block of the rank, after G2P and before the remapped
  !> momentum is summed over the ranks; the reactions (summed over the ranks) go into the walls'
  !> force and impulse, the friction work into ALLFD.
  subroutine open_end_contacts(walls, st)
    type(mpm_wall_t), intent(in) :: walls(:)
    type(mpm_state_t), intent(inout) :: st
    integer :: k, ib, nw
    real(dp) :: support
    real(dp), allocatable :: acc(:)

    nw = size(walls)
    allocate (acc(3 * nw + 1))
    acc = 0
    support = open_end_support(st%g%h, st%nsup)
    do k = 1, nw
       if (.not. walls(k)%active(st%step)) cycle
       if (.not. (walls(k)%open_start .or. walls(k)%open_end)) cycle
       do ib = 1, st%nblocks
          call block_open_end_contact(walls(k), st%g%n, support, st%dt, st%gravity, st%g%v_new, &
               st%blocks(ib), st%g%mom, acc(3 * k - 2:3 * k), acc(3 * nw + 1), st%w_external)
       end do
    end do
    call sum_over_ranks(st, acc)
    st%wall_force = st%wall_force + reshape(acc(1:3 * nw), [3, nw])
    st%wall_impulse = st%wall_impulse + st%dt * reshape(acc(1:3 * nw), [3, nw])
    st%e_walls = st%e_walls + acc(3 * nw + 1)
  end subroutine open_end_contacts

  !> One block (2D or 3D: the columns of its x) against one wall: the particles over it within
  !> 2·support of an open end (their stencil holds a node the wall left free) and closer to it
  !> than twice their half-length (the first row on it) lose their approaching velocity
  !> (wall_slide_velocity); m Δv leaves gmom(:, nodes) through the stencil (corner, w1 of this
  !> increment; n: grid nodes per axis), −m Δv/Δt is the reaction added to force, m (|v_t| −
  !> |v_t,new|) |v_t,new| the friction work added to dissipated (the nodes' booking, mpm_walls'
  !> wall_project). The displacement G2P gave it, Δt s with s = Σ S v_new (grid v_new(:, nodes)),
  !> becomes Δt slide(s), and gravity's work m g·Δt s booked on it in wk the same.
  subroutine block_open_end_contact(w, n, support, dt, gravity, v_new, b, gmom, force, dissipated, wk)
    type(mpm_wall_t), intent(in) :: w
    integer, intent(in) :: n(3)
    real(dp), intent(in) :: support, dt, gravity(3), v_new(:, :)
    type(particle_block_t), intent(inout) :: b
    real(dp), intent(inout) :: gmom(:, :), force(3), dissipated, wk
    integer :: p, i, nd, row, nrows, rows(particle_block_size), nodes(27), ns
    real(dp) :: x(3), xs(3), v(3), vnew(3), dv(3), normal(3), t_old, t_new, weights(27), sv(3), ds(3), dist
    real(dp) :: d(particle_block_size)

    nd = size(b%x, 2)
    normal = w%normal
    ! A vectorised pre-filter first (the scalar scan of every particle was 2 % of a bin
    ! increment's CPU samples): the rows a hair wider than the first row's band, then the exact
    ! tests on those, so the rows held are the same.
    call wall_rows_behind(w, b%count, nd, b%x, 2 * b%half * (1 + 1.0e-6_dp), d, nrows, rows)
    do row = 1, nrows
       p = rows(row)
       x = 0
       x(1:nd) = b%x(p, :)
       dist = wall_distance(w, x)
       if (.not. dist < 2 * b%half) cycle
       ! 3D: where the particle is over the plane (its foot on it), since the box bounds the
       ! plane and the nodes behind it, not the space in front; 2D: the segment's projection
       xs = x
       if (nd == 3) xs = x - dist * normal
       if (.not. wall_contains(w, nd, xs, 0.0_dp)) cycle
       if (.not. near_open_end(w, xs, 2 * support)) cycle
       call particle_stencil(b, p, n, nodes, weights, ns)
       sv = 0
       do i = 1, ns
          sv(1:nd) = sv(1:nd) + weights(i) * v_new(1:nd, nodes(i))
       end do
       ds = 0
       ds(1:nd) = wall_slide_velocity(w, nd, sv(1:nd)) - sv(1:nd)
       b%x(p, :) = b%x(p, :) + dt * ds(1:nd)
       wk = wk + b%mass(p) * dt * dot_product(gravity, ds)
       v = 0
       v(1:nd) = b%v(p, :)
       vnew = 0
       vnew(1:nd) = wall_slide_velocity(w, nd, v(1:nd))
       dv = vnew - v
       if (dot_product(dv, dv) <= 0) cycle
       b%v(p, :) = vnew(1:nd)
       force = force - b%mass(p) * dv / dt
       t_old = norm2(v - dot_product(v, normal) * normal)
       t_new = norm2(vnew - dot_product(vnew, normal) * normal)
       dissipated = dissipated + b%mass(p) * (t_old - t_new) * t_new
       do i = 1, ns
          gmom(1:nd, nodes(i)) = gmom(1:nd, nodes(i)) + weights(i) * b%mass(p) * dv(1:nd)
       end do
    end do
  end subroutine block_open_end_contact

  !> Particle p's stencil nodes and weights S (the product of its 1D weights), in the order
  !> i fastest, then j, then k (3D); n: grid nodes per axis. At most 3 nodes per axis (uGIMP).
  pure subroutine particle_stencil(b, p, n, nodes, weights, ns)
    type(particle_block_t), intent(in) :: b
    integer, intent(in) :: p, n(3)
    integer, intent(out) :: nodes(27), ns
    real(dp), intent(out) :: weights(27)
    integer :: i, j, k, nsup, nd

    nsup = size(b%w1, 2)
    nd = size(b%x, 2)
    ns = 0
    do k = 1, merge(nsup, 1, nd == 3)
       do j = 1, nsup
          do i = 1, nsup
             ns = ns + 1
             nodes(ns) = b%corner(p) + (i - 1) + n(1) * (j - 1) + n(1) * n(2) * (k - 1)
             weights(ns) = b%w1(p, i, 1) * b%w1(p, j, 2)
             if (nd == 3) weights(ns) = weights(ns) * b%w1(p, k, 3)
          end do
       end do
    end do
  end subroutine particle_stencil
end module mpm_wall_edges
