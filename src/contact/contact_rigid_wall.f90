!> Kinematic node-to-analytic-surface contact with Coulomb friction (Abaqus/Explicit's default
!> kinematic enforcement against analytical rigid surfaces), applied to the mid-increment
!> velocities after the velocity update and before the position update (solver_interfaces.md
!> §0, §5):
!>
!>   for each slave node: x_pred = x_n + dt v_{n+1/2}, wall at t_{n+1} = reference geometry
!>   translated by offset + dt v_w. If x_pred lies behind the wall (gap g < 0):
!>     normal:     dv_n = -g/dt along the wall normal n at the closest point: the node lands
!>                 exactly on the surface (relative normal velocity closes the gap, no rebound);
!>     tangential: v_t = tangential part of (v + dv_n n - v_w);
!>                 stick if |v_t| <= mu dv_n: the relative tangential velocity is cancelled
!>                 (dv_t = -v_t); the node keeps its material point of the wall and lands on
!>                 the closest point of x_n + dt v_w (the same thing on a line or plane);
!>                 else slide: dv_t = -mu dv_n v_t/|v_t| (never reverses v_t);
!>     re-check:   after sliding on an arc, or in a concave corner, the frictional move can
!>                 leave the node slightly off the surface; a second, normal-only projection
!>                 puts it back (pushing always, pulling only while the contact stays
!>                 compressive).
!>   A node on or in front of the surface gets nothing (no adhesion).
!>
!> Why impulses and not a penalty force (thesis §3.2, eq. 3.4, F = s x): the kinematic
!> correction has no stiffness, so it neither limits the stable time increment nor lets nodes
!> penetrate; the Coulomb limit uses the impulse of the same increment, so a block on an
!> incline slides with exactly a = g(sin(alpha) - mu cos(alpha)) in the central-difference scheme.
!>
!> Outputs per slave: the contact force m dv/dt (normal + tangential; their sum over the slaves
!> is the force on the material, minus the wall reaction), a contact flag, and the frictional
!> dissipation of the increment, D = -F_t . (dt v_rel,t) = -m dv_t . v_rel (>= 0): the
!> tangential force times the relative tangential displacement of the increment. With the
!> trapezoidal external work and the central-difference kinetic energy 1/2 m v_{n-1/2}.v_{n+1/2}
!> this balances exactly while the forces are steady (a sliding block: to round-off), and to
!> O(dt^2) per increment otherwise. A sticking node does no frictional work.
module contact_rigid_wall
  use base_kinds, only: dp
  use model_surfaces, only: rigid_surface_t
  use contact_walls, only: surface_closest_point => wall_closest_point, &
       surface_coordinate_scale => wall_coordinate_scale
  implicit none
  private

  public :: rigid_wall_contact
  public :: contact_gap_tolerance

  !> Gaps within this many ulps of the coordinate magnitude count as touching (contact flag)
  !> and are not worth a second projection.
  real(dp), parameter :: gap_ulps = 64.0_dp

contains

  !> Kinematic contact of the listed slave nodes with one rigid wall (one contact pair).
  !>
  !> ndim, n       space dimension (2: wall%ndim = 2 segment chain; 3: plane) and number of
  !>               nodes in x, v, mass (the caller's node arrays)
  !> x(ndim, n)    positions at t_n
  !> v(ndim, n)    in: v_{n+1/2} after the velocity update and BCs; out: corrected for the
  !>               slaves in contact (the other nodes are not touched)
  !> mass(n)       lumped nodal masses (only scale the returned forces and work)
  !> slaves(:)     the slave nodes: distinct indices into x, v, mass
  !> dt            the increment dt_{n+1/2} > 0 (dt <= 0: nothing is done)
  !> wall          the rigid surface in reference coordinates; wall%ndim must equal ndim
  !>               (else nothing is done)
  !> offset(ndim)  translation of the wall (its reference node's displacement) at t_n
  !> wall_velocity(ndim)  velocity of the wall over the increment (reference node's v_{n+1/2});
  !>               the wall used for the test is at offset + dt wall_velocity (t_{n+1})
  !> mu            Coulomb friction coefficient (0: frictionless; huge(1._dp): rough)
  !> force(ndim, size(slaves))   contact force on each slave [force units], m dv/dt
  !> friction_work frictional dissipation of the increment summed over the slaves [energy], >= 0
  !> in_contact(size(slaves))    predicted position on or behind the wall (within round-off)
  !>
  !> Several walls acting on one node (e.g. a hopper wall and the outlet plate meeting at a
  !> concave corner) are applied one pair after the other; a node already on a surface gets
  !> nothing from that surface, so repeating the pair loop once more settles such corners.
  pure subroutine rigid_wall_contact(ndim, n, x, v, mass, slaves, dt, wall, offset, &
       wall_velocity, mu, force, friction_work, in_contact)
    integer, intent(in) :: ndim
    integer, intent(in) :: n
    real(dp), intent(in) :: x(ndim, n)
    real(dp), intent(inout) :: v(ndim, n)
    real(dp), intent(in) :: mass(n)
    integer, intent(in) :: slaves(:)
    real(dp), intent(in) :: dt
    type(rigid_surface_t), intent(in) :: wall
    real(dp), intent(in) :: offset(ndim)
    real(dp), intent(in) :: wall_velocity(ndim)
    real(dp), intent(in) :: mu
    real(dp), intent(out) :: force(ndim, size(slaves))
    real(dp), intent(out) :: friction_work
    logical, intent(out) :: in_contact(size(slaves))

    real(dp) :: offset_new(ndim), dv(ndim), work, wall_scale
    integer :: k, i

    force = 0.0_dp
    friction_work = 0.0_dp
    in_contact = .false.
    ! A wall of the other dimension (or none) cannot touch these nodes; the scene reader
    ! rejects such pairs, this only keeps the kernel from indexing out of bounds.
    if (dt <= 0.0_dp .or. wall%ndim /= ndim) return

    offset_new = offset + dt * wall_velocity
    wall_scale = max(surface_coordinate_scale(wall), maxval(abs(offset_new)))
    do k = 1, size(slaves)
       i = slaves(k)
       call node_contact(ndim, x(:, i), v(:, i), dt, wall, offset_new, wall_velocity, &
            max(mu, 0.0_dp), wall_scale, dv, work, in_contact(k))
       v(:, i) = v(:, i) + dv
       force(:, k) = mass(i) * dv / dt
       friction_work = friction_work + mass(i) * work
    end do
  end subroutine rigid_wall_contact

  !> Gaps up to this value count as touching for a point x near a wall whose coordinates are
  !> of magnitude wall_scale: a few ulps of the largest coordinate involved.
  pure real(dp) function contact_gap_tolerance(x, wall_scale) result(tol)
    real(dp), intent(in) :: x(:)
    real(dp), intent(in) :: wall_scale

    tol = gap_ulps * epsilon(1.0_dp) * max(maxval(abs(x)), wall_scale)
  end function contact_gap_tolerance

  !> One node: velocity correction dv, frictional work per unit mass (-dv_t . v_rel >= 0)
  !> and the contact flag. offset_new: wall translation at t_{n+1}.
  pure subroutine node_contact(ndim, xn, vn, dt, wall, offset_new, wall_velocity, mu, &
       wall_scale, dv, work, touching)
    integer, intent(in) :: ndim
    real(dp), intent(in) :: xn(ndim)
    real(dp), intent(in) :: vn(ndim)
    real(dp), intent(in) :: dt
    type(rigid_surface_t), intent(in) :: wall
    real(dp), intent(in) :: offset_new(ndim)
    real(dp), intent(in) :: wall_velocity(ndim)
    real(dp), intent(in) :: mu
    real(dp), intent(in) :: wall_scale
    real(dp), intent(out) :: dv(ndim)
    real(dp), intent(out) :: work
    logical, intent(out) :: touching

    ! Work vectors of at most 3 components, used as their first ndim through the associate
    ! names below: arrays sized by the dummy ndim are automatic arrays, which gfortran puts on
    ! the heap (no -fstack-arrays), so this routine made about ten malloc/free pairs per slave
    ! node per increment (a third of the contact phase).
    real(dp) :: xp_buf(3), normal_buf(3), cp_buf(3), vrel_buf(3), vt_buf(3), dvt_buf(3)
    real(dp) :: normal2_buf(3), xq_buf(3)
    real(dp) :: gap, tol, dvn, vt_norm, gap2

    associate (xp => xp_buf(1:ndim), normal => normal_buf(1:ndim), cp => cp_buf(1:ndim), &
         vrel => vrel_buf(1:ndim), vt => vt_buf(1:ndim), dvt => dvt_buf(1:ndim), &
         normal2 => normal2_buf(1:ndim), xq => xq_buf(1:ndim))
    dv = 0.0_dp
    work = 0.0_dp
    xp = xn + dt * vn
    call surface_closest_point(wall, offset_new, xp, gap, normal, cp)
    tol = contact_gap_tolerance(xp, wall_scale)
    touching = gap <= tol
    if (.not. (gap < 0.0_dp)) return

    ! Normal: the velocity change that moves the predicted position onto the surface.
    dvn = -gap / dt
    ! Tangential: Coulomb with the normal impulse of this increment.
    vrel = vn + dvn * normal - wall_velocity
    vt = vrel - dot_product(vrel, normal) * normal
    vt_norm = norm2(vt)
    if (sticks(vt_norm, mu, dvn)) then
       ! Stick: the node keeps its material point of the wall. It moves with the wall and
       ! lands on the closest point of its convected position x_c = x_n + dt v_w, i.e.
       ! v = v_w - (gap(x_c)/dt) n(x_c). On a line or a plane this is exactly the normal +
       ! tangential impulse pair above (relative tangential velocity -> 0); on an arc it also
       ! keeps the node's angle, where cancelling the tangential velocity in the frame of the
       ! predicted point would leave it O(dt^4 g^2 / R) off the circle and let it creep.
       ! Written as a correction along the normal, not as (cp - x_n)/dt, so that the
       ! round-off of the closest point cannot move the node along the wall.
       ! Static friction does no work.
       xq = xn + dt * wall_velocity
       call surface_closest_point(wall, offset_new, xq, gap2, normal2, cp)
       dv = (wall_velocity - vn) - (gap2 / dt) * normal2
       return
    end if
    ! Slide: a tangential impulse mu dv_n against the relative sliding velocity; smaller
    ! than |v_t| (else the node would stick), so it never reverses it.
    dvt = -(mu * dvn / vt_norm) * vt
    dv = dvn * normal + dvt

    ! Frictional dissipation per unit mass: the tangential impulse (per unit mass) times the
    ! relative velocity it leaves, i.e. F_t . (relative displacement) / m. dv_t opposes v_t
    ! and leaves (1 - lambda) v_t with lambda in [0, 1], so this is lambda (1 - lambda) |v_t|^2
    ! > 0. Taken before the second projection below, whose
    ! normal correction is not friction (on an arc its normal is turned by O(dt^2), which
    ! would otherwise leak a fourth-order amount of it into the frictional work).
    work = max(0.0_dp, -dot_product(dvt, vn + dv - wall_velocity))

    ! Second projection: after the tangential change the predicted position is still exactly
    ! on a straight segment or a plane, but not on an arc (a move along the tangent leaves
    ! the circle by O((dt dv_t)^2 / R)), and a frictional move in a concave corner can reach
    ! the other segment. The node is in active, compressive contact, so put it back on the
    ! surface with a normal-only correction at the new closest point (no more friction: it is
    ! second order). The closest point lies on the surface, so two passes suffice.
    ! Behind the surface: always push. In front (convex arc): pull back only while the net
    ! normal impulse stays compressive (gap2/dt <= dv_n), so this never makes the contact
    ! adhesive (a node sliding with friction over a convex arc would otherwise be lifted
    ! off it a little every increment).
    if (mu > 0.0_dp) then
       xq = xn + dt * (vn + dv)
       call surface_closest_point(wall, offset_new, xq, gap2, normal2, cp)
       if (gap2 < -tol .or. (gap2 > tol .and. gap2 <= dvn * dt)) then
          dv = dv - (gap2 / dt) * normal2
       end if
    end if
    end associate
  end subroutine node_contact

  !> Coulomb stick test |v_t| <= mu dv_n, written so that a rough wall (mu = huge) cannot
  !> overflow.
  pure logical function sticks(vt_norm, mu, dvn)
    real(dp), intent(in) :: vt_norm
    real(dp), intent(in) :: mu
    real(dp), intent(in) :: dvn

    if (.not. (vt_norm > 0.0_dp)) then
       sticks = .true.
    else if (mu >= 1.0_dp) then
       sticks = vt_norm / mu <= dvn
    else
       sticks = vt_norm <= mu * dvn
    end if
  end function sticks
end module contact_rigid_wall
