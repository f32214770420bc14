!> Rigid fixed walls on the background grid (docs/theory/mpm.md §4.4): after the grid momentum update
!> (and again after the MUSL remap) the velocity of every grid node on or behind an active wall
!> is projected: a friction wall removes an approaching normal velocity and reduces the
!> tangential one by μ |Δv_n| (Coulomb; stick when that exceeds it); a symmetry wall removes
!> the normal velocity both ways.
!>
!> Which nodes: those with signed distance d = (x_I − p0)·n <= REACH·h (default 0: on the wall or
!> behind it) whose projection falls on the wall (2D: the segment p0..p1; 3D: the optional box). A grid-aligned
!> wall thus acts on its node line exactly as a standard MPM boundary; an inclined wall acts on
!> the staircase of nodes just behind it, with the exact normal (no staircase friction).
!> Particles that end an increment behind a wall (the wall's stencil is one cell wide) are put
!> back onto it: `guard_particles`; the count is reported.
!>
!> Rigid-surface walls (mpm_wall_t%surface > 0: a *SURFACE paired with the particles) are the
!> element contact's geometry (contact_walls' closest point: 2D chains of lines and arcs; in 3D
!> planes, facets and the CYLINDER/REVOLUTION profiles, so a conical hopper's revolved profile is
!> one wall) and may move with their reference node. Their nodes are found again
!> every increment (`surface_find_nodes`: gap <= 0 against the surface at t_n+1, each with the
!> surface's normal there); the projection splits the velocity relative to the wall,
!> v − v_w, so a node ends with at least the wall's normal velocity (`surface_node_velocity`).
module mpm_walls
  use base_kinds, only: dp
  use mpm_scene, only: mpm_wall_t, wall_symmetry
  use mpm_grid, only: grid_t
  use model_surfaces, only: rigid_surface_t
  use contact_walls, only: wall_closest_point
  implicit none
  private

  !> A wall with the grid nodes it constrains (and, for a rigid-surface wall, the surface's unit
  !> normal into the material at each of them, normal(3, size(nodes))).
  type, public :: wall_nodes_t
     integer, allocatable :: nodes(:)
     !> at an open end (OPEN=): the nodes in the stencils of the particles the wall holds there
     !> (the nodes it leaves free and the row above them). Local damping leaves them alone, as it
     !> does the wall's nodes (mpm_setup's mark_wall_nodes): the held particles take the wall's
     !> reaction from them, and damping them held a settled fill 3 % short of its weight.
     integer, allocatable :: undamped(:)
     real(dp), allocatable :: normal(:, :)
     !> This increment's friction record per node (the booking pass only; wall_corner_dissipation):
     !> hit: a friction projection acted; dv(3, :): the tangential velocity friction removed;
     !> v_after(3, :): the node's velocity right after this wall; booked: the dissipation booked.
     logical, allocatable :: hit(:)
     real(dp), allocatable :: dv(:, :), v_after(:, :), booked(:)
  end type wall_nodes_t

  public :: wall_find_nodes, wall_project, wall_contains, near_open_end, wall_distance, wall_slide_velocity, wall_rows_behind
  public :: surface_find_nodes, surface_wall_project, surface_node_velocity, surface_guard_block
  public :: wall_corner_dissipation

  !> A node within this fraction of the cell from a wall is on it. Scene coordinates come with
  !> ~9 digits, and a cell written with 6 (0.0357143 for 0.125/3.5) put the hopper's axis node
  !> line 6e-8 m in front of the symmetry wall: at 1e-9 h those nodes were free, particles
  !> crossed the axis and were stacked on it, and the discharge rate rose by 42 %.
  real(dp), parameter, public :: node_on_wall_tolerance = 1.0e-6_dp

contains

  pure real(dp) function wall_distance(w, x)
    type(mpm_wall_t), intent(in) :: w
    real(dp), intent(in) :: x(3)
    wall_distance = dot_product(x - w%p0, w%normal)
  end function wall_distance

  !> The rows of x(nb, nd) (points of a particle block) less than `level` in front of the wall's
  !> line/plane, i.e. not wall_distance >= level (level 0: behind it; a NaN counts, as in the
  !> caller's test before), ascending: rows(1:nrows).
  !> Why a kernel: the scan of every particle against every active wall, a scalar loop that
  !> built a 3-vector per particle, was 4 % of the instructions of a hopper increment. The
  !> distance is wall_distance's dot product without its leading 0 + (the same value but for
  !> the sign of a zero, so the same decision), so the loop vectorises; the caller recomputes
  !> wall_distance for the rows it gets. d(nb): the caller's work array (an automatic array
  !> here would be a malloc per call).
  pure subroutine wall_rows_behind(w, nb, nd, x, level, d, nrows, rows)
    type(mpm_wall_t), intent(in) :: w
    integer, intent(in) :: nb, nd
    real(dp), intent(in) :: x(nb, nd), level
    real(dp), intent(out) :: d(nb)
    integer, intent(out) :: nrows, rows(nb)
    real(dp) :: a1, a2, a3, n1, n2, n3, t3
    integer :: p

    a1 = w%p0(1)
    a2 = w%p0(2)
    a3 = w%p0(3)
    n1 = w%normal(1)
    n2 = w%normal(2)
    n3 = w%normal(3)
    if (nd == 2) then
       ! the third component of a 2D point is 0 (as the caller's x(3))
       t3 = (0 - a3) * n3
       do p = 1, nb
          d(p) = (x(p, 1) - a1) * n1 + (x(p, 2) - a2) * n2 + t3
       end do
    else
       do p = 1, nb
          d(p) = (x(p, 1) - a1) * n1 + (x(p, 2) - a2) * n2 + (x(p, nd) - a3) * n3
       end do
    end if
    nrows = 0
    do p = 1, nb
       if (.not. d(p) >= level) then
          nrows = nrows + 1
          rows(nrows) = p
       end if
    end do
  end subroutine wall_rows_behind

  !> Where x lies along the wall towards its open ends: 2D, s from p0 along the segment (x's
  !> projection) and the segment's length; 3D (a box face open), s from the box's low face on
  !> the open axis and the box's extent on it (a node's support is a box along the grid axes, so
  !> it reaches past the face when s is less than the support, whatever the wall's inclination).
  pure subroutine along_wall(w, x, s, length)
    type(mpm_wall_t), intent(in) :: w
    real(dp), intent(in) :: x(3)
    real(dp), intent(out) :: s, length
    real(dp) :: t(3)

    if (w%open_axis > 0) then
       s = x(w%open_axis) - w%lo(w%open_axis)
       length = w%hi(w%open_axis) - w%lo(w%open_axis)
       return
    end if
    t = w%p1 - w%p0
    length = norm2(t)
    s = dot_product(x - w%p0, t) / length
  end subroutine along_wall

  !> Is x within `reach` of one of the wall's open ends (OPEN=), along it (along_wall)?
  pure logical function near_open_end(w, x, reach)
    type(mpm_wall_t), intent(in) :: w
    real(dp), intent(in) :: x(3), reach
    real(dp) :: s, length

    near_open_end = .false.
    if (.not. (w%open_start .or. w%open_end)) return
    call along_wall(w, x, s, length)
    near_open_end = (w%open_start .and. s < reach) .or. (w%open_end .and. s > length - reach)
  end function near_open_end

  !> Is the node x in the stencil of a particle the wall holds at an open end (mpm_wall_edges:
  !> within 2·support of the end along the wall, closer to it than a cell)? Along the wall from
  !> −support to 3·support of the end, and at most a support in front of the wall.
  pure logical function in_open_end_stencils(w, x, support, tol)
    type(mpm_wall_t), intent(in) :: w
    real(dp), intent(in) :: x(3), support, tol
    real(dp) :: s, length

    in_open_end_stencils = .false.
    if (.not. (w%open_start .or. w%open_end)) return
    if (wall_distance(w, x) > support + tol) return
    call along_wall(w, x, s, length)
    in_open_end_stencils = (w%open_start .and. s > -support - tol .and. s < 3 * support + tol) .or. &
         (w%open_end .and. s < length + support + tol .and. s > length - 3 * support - tol)
  end function in_open_end_stencils

  !> Does the wall extend over the point x (its projection lies on the segment / in the box)?
  pure logical function wall_contains(w, ndim, x, tol)
    type(mpm_wall_t), intent(in) :: w
    integer, intent(in) :: ndim
    real(dp), intent(in) :: x(3), tol
    real(dp) :: t(3), length, s

    if (ndim == 2) then
       t = w%p1 - w%p0
       length = norm2(t)
       s = dot_product(x - w%p0, t) / length
       wall_contains = s >= -tol .and. s <= length + tol
    else if (w%bounded) then
       wall_contains = all(x >= w%lo - tol) .and. all(x <= w%hi + tol)
    else
       wall_contains = .true.
    end if
  end function wall_contains

  !> support: how far a node's shape function reaches [m]; the nodes within it of an open end
  !> (OPEN=) are left to the particles (mpm_wall_edges), so the wall's grid condition does
  !> not reach past the end into the opening.
  subroutine wall_find_nodes(w, g, wn, support)
    type(mpm_wall_t), intent(in) :: w
    type(grid_t), intent(in) :: g
    type(wall_nodes_t), intent(out) :: wn
    real(dp), intent(in) :: support
    integer :: i, n, nu
    integer, allocatable :: list(:), undamped(:)
    real(dp) :: x(3), tol

    tol = node_on_wall_tolerance * g%h
    allocate (list(g%nn), undamped(g%nn))
    n = 0
    nu = 0
    do i = 1, g%nn
       x = g%position(i)
       if (in_open_end_stencils(w, x, support, tol)) then
          nu = nu + 1
          undamped(nu) = i
       end if
       if (wall_distance(w, x) > w%reach * g%h + tol) cycle
       if (.not. wall_contains(w, g%ndim, x, tol)) cycle
       if (near_open_end(w, x, support - tol)) cycle
       n = n + 1
       list(n) = i
    end do
    allocate (wn%nodes(n), wn%undamped(nu))
    wn%nodes = list(1:n)
    wn%undamped = undamped(1:nu)
  end subroutine wall_find_nodes

  !> Project the velocities v(ndim, nn) of the wall's active nodes; with `force`, add the
  !> force the material exerts on the wall, −Σ m Δv / Δt, and the work friction does on the
  !> slip, Σ m (|v_t| − |v_t,new|) |v_t,new| >= 0 (friction force times the slip the particles
  !> move with, times Δt), into `dissipated`. Not ½ m (|v_t|² − |v_t,new|²): the trial velocity
  !> v_t never was kinetic energy, and a body resting on the wall (stick, v_t,new = 0) would book
  !> ½ m v_t² every increment (ETOTAL rising linearly at rest; tests/stability corner). The
  !> normal velocity a wall removes is the reaction to the stress of a resting body, not a loss.
  !> Without `dissipated` (the projection of the MUSL remapped velocity, which only feeds the
  !> strain rate) a node this wall held in the increment's first projection also loses a normal
  !> velocity *away* from the wall: see held_this_increment.
  subroutine wall_project(w, wn, ndim, mass, active, v, dt, force, dissipated)
    type(mpm_wall_t), intent(in) :: w
    type(wall_nodes_t), intent(inout) :: wn
    integer, intent(in) :: ndim
    real(dp), intent(in) :: mass(:)
    logical, intent(in) :: active(:)
    real(dp), intent(inout) :: v(:, :)
    real(dp), intent(in) :: dt
    real(dp), intent(inout), optional :: force(3)
    real(dp), intent(inout), optional :: dissipated
    integer :: k, i
    real(dp) :: n(3), vi(3), vn, tn, scale, vnew(3)

    tn = 0
    scale = 1

    n = w%normal
    if (present(dissipated)) call friction_record_reset(wn)
    do k = 1, size(wn%nodes)
       i = wn%nodes(k)
       if (.not. active(i)) cycle
       vi = 0
       vi(1:ndim) = v(:, i)
       vn = dot_product(vi, n)
       if (w%kind == wall_symmetry) then
          vnew = vi - vn * n
       else if (vn < 0) then
          call coulomb_slide(w%friction, vi, vn, n, vnew, tn, scale)
       else if (.not. present(dissipated) .and. held_this_increment(wn, k)) then
          vnew = vi - vn * n
       else
          cycle
       end if
       if (present(force)) force = force - mass(i) * (vnew - vi) / dt
       if (present(dissipated) .and. w%kind /= wall_symmetry) then
          wn%booked(k) = mass(i) * tn * tn * scale * (1 - scale)
          dissipated = dissipated + wn%booked(k)
          call friction_record(wn, k, ndim, vi, vn, n, vnew)
       end if
       v(:, i) = vnew(1:ndim)
    end do
  end subroutine wall_project

  !> A velocity after contact with the wall: the normal part into the wall removed and the
  !> tangential part reduced by μ times it (stick when that exceeds it); a symmetry wall removes
  !> the normal part both ways. Unchanged when it leaves a friction wall.
  pure function wall_slide_velocity(w, ndim, v) result(vnew)
    type(mpm_wall_t), intent(in) :: w
    integer, intent(in) :: ndim
    real(dp), intent(in) :: v(ndim)
    real(dp) :: vnew(ndim)
    real(dp) :: vi(3), vn, vo(3), tn, scale

    vi = 0
    vi(1:ndim) = v
    vn = dot_product(vi, w%normal)
    if (w%kind == wall_symmetry) then
       vo = vi - vn * w%normal
    else if (vn < 0) then
       call coulomb_slide(w%friction, vi, vn, w%normal, vo, tn, scale)
    else
       vo = vi
    end if
    vnew = vo(1:ndim)
  end function wall_slide_velocity

  !> Coulomb's law on a velocity vi with normal part vn < 0: vnew = scale · (vi − vn n),
  !> scale = max(0, 1 − μ|vn|/|v_t|); tn = |v_t|.
  pure subroutine coulomb_slide(mu, vi, vn, n, vnew, tn, scale)
    real(dp), intent(in) :: mu, vi(3), vn, n(3)
    real(dp), intent(out) :: vnew(3), tn, scale
    real(dp) :: vt(3)

    vt = vi - vn * n
    tn = norm2(vt)
    scale = 0
    if (tn > 0) scale = max(0.0_dp, 1 - mu * abs(vn) / tn)
    vnew = vt * scale
  end subroutine coulomb_slide

  ! ------------------------------------------------------------------------------------------
  ! Rigid-surface walls (the element contact's geometry; moving with their reference node)
  ! ------------------------------------------------------------------------------------------

  !> The grid nodes on or behind the rigid surface `surf` translated by `offset` (its position
  !> at t_n+1): gap <= node_on_wall_tolerance·h, with the surface's unit normal at each. Every
  !> node with mass (called after P2G, before the grid update decides which are active: the list
  !> also marks the nodes local damping leaves alone); a node without mass is never active. Why
  !> every increment: a moving wall sweeps over node lines; a fixed one gets the same list.
  subroutine surface_find_nodes(surf, offset, g, wn)
    type(rigid_surface_t), intent(in) :: surf
    real(dp), intent(in) :: offset(3)
    type(grid_t), intent(in) :: g
    type(wall_nodes_t), intent(inout) :: wn
    integer :: i, n, nd
    integer, allocatable :: list(:)
    real(dp), allocatable :: nrm(:, :)
    real(dp) :: x(3), gap, normal(3), cp(3), tol

    nd = g%ndim
    tol = node_on_wall_tolerance * g%h
    allocate (list(g%nn), nrm(3, g%nn))
    n = 0
    do i = 1, g%nn
       if (.not. g%mass(i) > 0) cycle
       x = g%position(i)
       normal = 0
       call wall_closest_point(surf, offset(1:nd), x(1:nd), gap, normal(1:nd), cp(1:nd))
       if (gap > tol) cycle
       n = n + 1
       list(n) = i
       nrm(:, n) = normal
    end do
    wn%nodes = list(1:n)
    wn%normal = nrm(:, 1:n)
  end subroutine surface_find_nodes

  !> A velocity v against a wall with unit normal n (into the material) moving with vw: if the
  !> velocity relative to the wall approaches it, its normal part goes and μ times that is taken
  !> from its tangential part (Coulomb: stick when that exceeds it), then the wall's velocity is
  !> added back (hit); otherwise v is unchanged. tn: |relative tangential velocity|, scale: the
  !> fraction of it left (for the friction dissipation); 0 and 1 when nothing happens.
  pure subroutine surface_node_velocity(n, vw, mu, v, vnew, tn, scale, hit)
    real(dp), intent(in) :: n(3), vw(3), mu, v(3)
    real(dp), intent(out) :: vnew(3), tn, scale
    logical, intent(out) :: hit
    real(dp) :: vrel(3), vn, vt(3)

    vrel = v - vw
    vn = dot_product(vrel, n)
    tn = 0
    scale = 1
    hit = vn < 0
    if (.not. hit) then
       vnew = v
       return
    end if
    call coulomb_slide(mu, vrel, vn, n, vt, tn, scale)
    vnew = vw + vt
  end subroutine surface_node_velocity

  !> Project the velocities of a rigid-surface wall's nodes (wn from surface_find_nodes) for a
  !> wall moving with vw, friction mu; with `force`, add the force of the material on the wall,
  !> −Σ m Δv / Δt (the momentum the wall takes from the nodes), and into `dissipated` the work
  !> of friction on the relative slip, m (|v_t| − |v_t,new|) |v_t,new| per node (wall_project's
  !> rule: a node held at rest books nothing).
  subroutine surface_wall_project(wn, vw, mu, ndim, mass, active, v, dt, force, dissipated)
    type(wall_nodes_t), intent(inout) :: wn
    real(dp), intent(in) :: vw(3), mu
    integer, intent(in) :: ndim
    real(dp), intent(in) :: mass(:)
    logical, intent(in) :: active(:)
    real(dp), intent(inout) :: v(:, :)
    real(dp), intent(in) :: dt
    real(dp), intent(inout), optional :: force(3)
    real(dp), intent(inout), optional :: dissipated
    integer :: k, i
    real(dp) :: vi(3), vnew(3), tn, scale
    logical :: hit

    if (present(dissipated)) call friction_record_reset(wn)
    do k = 1, size(wn%nodes)
       i = wn%nodes(k)
       if (.not. active(i)) cycle
       vi = 0
       vi(1:ndim) = v(:, i)
       call surface_node_velocity(wn%normal(:, k), vw, mu, vi, vnew, tn, scale, hit)
       if (.not. hit) then
          if (present(dissipated) .or. .not. held_this_increment(wn, k)) cycle
          vnew = vi - dot_product(vi - vw, wn%normal(:, k)) * wn%normal(:, k)
       end if
       if (present(force)) force = force - mass(i) * (vnew - vi) / dt
       if (present(dissipated)) then
          wn%booked(k) = mass(i) * tn * tn * scale * (1 - scale)
          dissipated = dissipated + wn%booked(k)
          call friction_record(wn, k, ndim, vi - vw, dot_product(vi - vw, wn%normal(:, k)), wn%normal(:, k), &
               vnew - vw)
       end if
       v(:, i) = vnew(1:ndim)
    end do
  end subroutine surface_wall_project

  !> Particles of a block (x(nb, nd), v(nb, nd)) behind the rigid surface at `offset`: put back
  !> onto its closest point, with the nodes' rule on their velocity relative to the wall (the
  !> approaching normal part goes, Coulomb on the rest). n_guarded counts them.
  subroutine surface_guard_block(surf, offset, vw, mu, nb, nd, x, v, n_guarded)
    type(rigid_surface_t), intent(in) :: surf
    real(dp), intent(in) :: offset(3), vw(3), mu
    integer, intent(in) :: nb, nd
    real(dp), intent(inout) :: x(nb, nd), v(nb, nd)
    integer, intent(inout) :: n_guarded
    integer :: p
    real(dp) :: gap, normal(3), cp(3), vi(3), vnew(3), tn, scale
    logical :: hit

    do p = 1, nb
       normal = 0
       call wall_closest_point(surf, offset(1:nd), x(p, :), gap, normal(1:nd), cp(1:nd))
       if (.not. gap < 0) cycle
       x(p, :) = cp(1:nd)
       vi = 0
       vi(1:nd) = v(p, :)
       call surface_node_velocity(normal, vw, mu, vi, vnew, tn, scale, hit)
       v(p, :) = vnew(1:nd)
       n_guarded = n_guarded + 1
    end do
  end subroutine surface_guard_block

  ! ------------------------------------------------------------------------------------------
  ! Friction dissipation at nodes a later wall moves again (corners)
  ! ------------------------------------------------------------------------------------------

  !> Node k was held by this wall in the increment's first projection (its approaching normal
  !> velocity removed; the friction record's hit). The particles moved with that velocity, so
  !> the node did not leave the wall in this increment, and the remapped velocity the strain
  !> rate is taken from must not say otherwise. Why it matters: the remap (a PIC smoothing of
  !> the grid velocity) gives a held node a normal velocity of either sign. Removing only the
  !> approaching one booked, in every cycle of a ringing body on a floor, the compression and
  !> not the expansion beside the wall: the stress ratcheted ahead of the positions, the block
  !> settled on a floor stood higher than its strain said (gravity's work 29 % of the closed
  !> form, ALLWK 8.4·10⁻³ against 2.9·10⁻² J, in the 1D column of docs/stability.md) and
  !> ETOTAL rose by up to half the largest energy, more the larger the increment.
  pure logical function held_this_increment(wn, k)
    type(wall_nodes_t), intent(in) :: wn
    integer, intent(in) :: k
    held_this_increment = .false.
    if (.not. allocated(wn%hit)) return
    if (size(wn%hit) /= size(wn%nodes)) return
    held_this_increment = wn%hit(k)
  end function held_this_increment

  !> Size the wall's friction record to its node list (a rigid surface's list changes every
  !> increment) and clear the hits.
  subroutine friction_record_reset(wn)
    type(wall_nodes_t), intent(inout) :: wn
    integer :: n

    n = size(wn%nodes)
    if (allocated(wn%hit)) then
       if (size(wn%hit) /= n) deallocate (wn%hit, wn%dv, wn%v_after, wn%booked)
    end if
    if (.not. allocated(wn%hit)) allocate (wn%hit(n), wn%dv(3, n), wn%v_after(3, n), wn%booked(n))
    wn%hit = .false.
  end subroutine friction_record_reset

  !> Node k of the wall was projected by friction: keep the tangential velocity (relative to the
  !> wall) that friction took, vt − vt_new, and the node's velocity after this wall (relative
  !> velocities for a moving wall: the slip is relative to it).
  pure subroutine friction_record(wn, k, ndim, vi, vn, n, vnew)
    type(wall_nodes_t), intent(inout) :: wn
    integer, intent(in) :: k, ndim
    real(dp), intent(in) :: vi(3), vn, n(3), vnew(3)

    wn%hit(k) = .true.
    wn%dv(:, k) = (vi - vn * n) - vnew
    wn%v_after(:, k) = 0
    wn%v_after(1:ndim, k) = vnew(1:ndim)
  end subroutine friction_record

  !> After all walls of an increment: a node that a later wall moved again (a corner of two
  !> walls, a wall meeting a symmetry plane) does not slip with the velocity its friction was
  !> booked for. Friction's work is its force, −m dv/Δt, on the velocity the node keeps, v:
  !> m dv·v per increment (for a node no other wall touches v = vt_new and this is the booked
  !> m (|vt| − |vt_new|) |vt_new|, left as it was, bit for bit). So for each node whose velocity
  !> changed after this wall, the booked amount is replaced by m max(0, dv·v): in a corner the
  !> floor's friction books a slip along the floor that the side wall then stops, and a body at
  !> rest there raised ALLFD every increment (tests/stability corner). `vw`: the wall's velocity
  !> (a rigid surface; 0 for a fixed wall), since the slip is relative to it.
  subroutine wall_corner_dissipation(wn, ndim, mass, v, vw, dissipated)
    type(wall_nodes_t), intent(in) :: wn
    integer, intent(in) :: ndim
    real(dp), intent(in) :: mass(:), v(:, :), vw(3)
    real(dp), intent(inout) :: dissipated
    integer :: k, i
    real(dp) :: vrel(3)

    if (.not. allocated(wn%hit)) return
    do k = 1, size(wn%nodes)
       if (.not. wn%hit(k)) cycle
       i = wn%nodes(k)
       vrel = 0
       vrel(1:ndim) = v(:, i) - vw(1:ndim)
       ! unchanged since this wall (exactly: a difference of 0 in every component)
       if (all(abs(vrel(1:ndim) - wn%v_after(1:ndim, k)) <= 0)) cycle
       dissipated = dissipated - wn%booked(k) + mass(i) * max(0.0_dp, dot_product(wn%dv(:, k), vrel))
    end do
  end subroutine wall_corner_dissipation
end module mpm_walls
