!> Geometry of analytic rigid surfaces for node-to-surface contact: closest point, signed
!> distance (the gap), unit normal and tangent of a point with respect to
!>   * a 2D chain of straight lines and circular arcs (*SURFACE, TYPE=SEGMENTS: START, LINE,
!>     CIRCL), consecutive segments sharing their end points, and
!>   * a 3D plane (bulkflow's *SURFACE, TYPE=PLANE: a point and a normal).
!>
!> Conventions (see src/contact/README.md for the sources):
!>   * The material lies on the side the normal points to. 2D: the normal is the direction of
!>     travel (START -> LINE/CIRCL end points) turned 90 degrees counter-clockwise, i.e. the
!>     material is on the left when walking along the chain. 3D: rigid_surface_t%normal.
!>   * gap > 0: the point is on the material side; gap < 0: it lies behind the surface
!>     (penetration). `normal` is always the unit vector pointing from the surface into the
!>     material at the closest point, so that x = cp + gap * normal exactly for every
!>     primitive used here (line, circle, vertex, plane). That is what lets the contact
!>     algorithm land a node exactly on the surface with one velocity correction.
!>   * 2D tangent = direction of travel at the closest point = (n_y, -n_x).
!>   * CIRCL: the arc goes from the previous end point to its end point around `centre`, the
!>     short way (Abaqus requires less than 180 degrees, so the sense is unique): counter-
!>     clockwise when cross(p0 - c, p1 - c) > 0, else clockwise. The radius is |p0 - c|.
!>     With the left-hand material rule a counter-clockwise arc has its material on the
!>     concave side (towards the centre), a clockwise arc on the convex side.
!>
!> Corners (closest point at a segment end point):
!>   * interior vertex, convex as seen from the material (e.g. the top of a ridge): the region
!>     of points whose closest point is the vertex lies on the material side; gap = |x - v| > 0
!>     and the normal is radial from the vertex. The corner acts as a rounded edge of zero
!>     radius: a node slides over/around it and is never pulled towards it.
!>   * interior vertex, concave as seen from the material (e.g. the bottom of a valley): the
!>     vertex region lies behind both segments; gap = -|x - v| and the normal points from x to
!>     the vertex, so the projection lands on the vertex, which satisfies both segments.
!>     The side is decided with the pseudo-normal n_A + n_B of the two segments at the vertex
!>     (the 2D case of the angle-weighted pseudo-normal), which is exact for both kinds.
!>   * free end (the START point or the last end point): treated as a convex edge, gap =
!>     |x - v| >= 0 always. A node that slides past the end of a plate is released, as in
!>     Abaqus, where an analytical surface is not extended beyond its end points.
!> A point behind the surface is in contact however deep it is (analytical rigid surfaces are
!> single-sided with unlimited depth).
module contact_geometry
  use base_kinds, only: dp
  use model_surfaces, only: segment_t, rigid_surface_t, segment_line, segment_arc
  implicit none
  private

  public :: segment_is_valid
  public :: arc_orientation
  public :: segment_closest_point
  public :: segment_end_normal
  public :: chain_closest_point
  public :: plane_closest_point
  public :: surface_closest_point
  public :: surface_coordinate_scale

  !> Where the closest point of a single segment lies (segment_closest_point%where).
  integer, parameter, public :: at_start = -1     !< the segment's first point p0
  integer, parameter, public :: at_interior = 0   !< strictly between p0 and p1
  integer, parameter, public :: at_end = 1        !< the segment's last point p1

  !> Which feature of a chain holds the closest point (chain_closest_point%feature).
  integer, parameter, public :: feature_segment = 0    !< the interior of segment iseg (or a plane)
  integer, parameter, public :: feature_vertex = 1     !< the corner shared by segments iseg, iseg+1
  integer, parameter, public :: feature_free_end = 2   !< the START point or the last end point

  !> Relative radius mismatch of a CIRCL end point accepted by segment_is_valid.
  real(dp), parameter, public :: arc_radius_tolerance = 1.0e-6_dp

contains

  ! ------------------------------------------------------------------------------------------
  ! Single segments
  ! ------------------------------------------------------------------------------------------

  !> A usable segment: a line of non-zero length, or an arc of non-zero radius whose end point
  !> is on the circle (relative arc_radius_tolerance) and whose sweep is strictly between 0
  !> and 180 degrees (Abaqus: "the arc must be less than 180 degrees"; at exactly 180 degrees
  !> the sense would be undefined). The scene reader rejects anything else.
  pure logical function segment_is_valid(seg) result(ok)
    type(segment_t), intent(in) :: seg

    real(dp) :: r0(2), r1(2), rad0, rad1

    select case (seg%kind)
    case (segment_line)
       ok = norm2(seg%p1 - seg%p0) > 0.0_dp
    case (segment_arc)
       r0 = seg%p0 - seg%centre
       r1 = seg%p1 - seg%centre
       rad0 = norm2(r0)
       rad1 = norm2(r1)
       ok = rad0 > 0.0_dp
       if (ok) ok = abs(rad1 - rad0) <= arc_radius_tolerance * rad0
       ! Sweep in (0, 180): a non-zero cross product. A zero cross product is either a
       ! zero-length arc or a half circle.
       if (ok) ok = abs(cross2(r0, r1)) > arc_radius_tolerance * rad0 * rad1
    case default
       ok = .false.
    end select
  end function segment_is_valid

  !> +1 if the arc runs counter-clockwise from p0 to p1 about its centre (the short way),
  !> -1 if clockwise. Lines: +1 (unused). A degenerate arc (zero cross product) gets +1.
  pure integer function arc_orientation(seg) result(orient)
    type(segment_t), intent(in) :: seg

    orient = 1
    if (seg%kind == segment_arc) then
       if (cross2(seg%p0 - seg%centre, seg%p1 - seg%centre) < 0.0_dp) orient = -1
    end if
  end function arc_orientation

  !> Material-side unit normal of a segment at its first (which = at_start) or last
  !> (which = at_end) point. Used for the pseudo-normal of a corner.
  pure function segment_end_normal(seg, which) result(normal)
    type(segment_t), intent(in) :: seg
    integer, intent(in) :: which
    real(dp) :: normal(2)

    real(dp) :: r(2), rad

    select case (seg%kind)
    case (segment_arc)
       if (which == at_end) then
          r = seg%p1 - seg%centre
       else
          r = seg%p0 - seg%centre
       end if
       rad = norm2(r)
       if (rad > 0.0_dp) then
          ! Counter-clockwise travel has the centre on its left: normal = -r_hat; clockwise
          ! travel has the centre on its right: normal = +r_hat.
          normal = -real(arc_orientation(seg), dp) * r / rad
       else
          normal = [0.0_dp, 1.0_dp]
       end if
    case default
       normal = line_normal(seg%p0, seg%p1)
    end select
  end function segment_end_normal

  !> Closest point of one segment to x. dist = |x - cp| >= 0 (unsigned); normal is the
  !> segment's material-side unit normal at cp (for an end point: the segment's own normal
  !> there, not the corner treatment, which needs the neighbour: see chain_closest_point).
  pure subroutine segment_closest_point(seg, x, cp, normal, dist, where)
    type(segment_t), intent(in) :: seg
    real(dp), intent(in) :: x(2)
    real(dp), intent(out) :: cp(2)
    real(dp), intent(out) :: normal(2)
    real(dp), intent(out) :: dist
    integer, intent(out) :: where

    select case (seg%kind)
    case (segment_arc)
       call arc_closest_point(seg, x, cp, normal, where)
    case default
       call line_closest_point(seg%p0, seg%p1, x, cp, normal, where)
    end select
    dist = norm2(x - cp)
  end subroutine segment_closest_point

  pure subroutine line_closest_point(p0, p1, x, cp, normal, where)
    real(dp), intent(in) :: p0(2), p1(2), x(2)
    real(dp), intent(out) :: cp(2), normal(2)
    integer, intent(out) :: where

    real(dp) :: d(2), len2, s

    normal = line_normal(p0, p1)
    d = p1 - p0
    len2 = dot_product(d, d)
    if (len2 <= 0.0_dp) then
       ! Degenerate (rejected by segment_is_valid): behave like a point.
       cp = p0
       where = at_start
       return
    end if
    s = dot_product(x - p0, d) / len2
    if (s <= 0.0_dp) then
       cp = p0
       where = at_start
    else if (s >= 1.0_dp) then
       cp = p1
       where = at_end
    else
       cp = p0 + s * d
       where = at_interior
    end if
  end subroutine line_closest_point

  pure subroutine arc_closest_point(seg, x, cp, normal, where)
    type(segment_t), intent(in) :: seg
    real(dp), intent(in) :: x(2)
    real(dp), intent(out) :: cp(2), normal(2)
    integer, intent(out) :: where

    real(dp) :: r0(2), r1(2), rx(2), rad, rho, orient
    logical :: in_span

    orient = real(arc_orientation(seg), dp)
    r0 = seg%p0 - seg%centre
    r1 = seg%p1 - seg%centre
    rx = x - seg%centre
    rad = norm2(r0)
    rho = norm2(rx)
    ! The arc spans less than 180 degrees, so its angular range is the convex wedge bounded
    ! by the rays through p0 and p1: two half-plane tests.
    in_span = orient * cross2(r0, rx) >= 0.0_dp .and. orient * cross2(rx, r1) >= 0.0_dp
    if (in_span .and. rho > 0.0_dp) then
       cp = seg%centre + (rad / rho) * rx
       normal = -orient * rx / rho
       where = at_interior
    else
       ! Outside the wedge the distance grows with the angle from x, so the nearer end point
       ! is the closest point. (x at the centre: every arc point is at distance rad.)
       if (norm2(x - seg%p0) <= norm2(x - seg%p1)) then
          cp = seg%p0
          where = at_start
       else
          cp = seg%p1
          where = at_end
       end if
       normal = segment_end_normal(seg, where)
    end if
  end subroutine arc_closest_point

  ! ------------------------------------------------------------------------------------------
  ! Chains and planes
  ! ------------------------------------------------------------------------------------------

  !> Closest point, signed gap, unit normal (into the material) and tangent (direction of
  !> travel) of the chain segs(1:n) to x. iseg: the segment holding cp (for a vertex, the
  !> one before it); feature: feature_segment | feature_vertex | feature_free_end.
  !> Ties: the first segment wins, an interior point wins over an end point.
  !> The chain must be connected (segs(k)%p1 = segs(k+1)%p0), as START/LINE/CIRCL builds it.
  pure subroutine chain_closest_point(segs, x, gap, normal, tangent, cp, feature, iseg)
    type(segment_t), intent(in) :: segs(:)
    real(dp), intent(in) :: x(2)
    real(dp), intent(out) :: gap
    real(dp), intent(out) :: normal(2)
    real(dp), intent(out) :: tangent(2)
    real(dp), intent(out) :: cp(2)
    integer, intent(out) :: feature
    integer, intent(out) :: iseg

    real(dp) :: cpk(2), nk(2), dk, best, m(2), r(2), rho, side, mlen
    integer :: k, wk, where, nseg, ia, ib

    nseg = size(segs)
    if (nseg == 0) then
       gap = huge(1.0_dp)
       normal = 0.0_dp
       tangent = 0.0_dp
       cp = x
       feature = feature_free_end
       iseg = 0
       return
    end if

    best = huge(1.0_dp)
    iseg = 1
    where = at_interior
    cp = segs(1)%p0
    normal = 0.0_dp
    do k = 1, nseg
       call segment_closest_point(segs(k), x, cpk, nk, dk, wk)
       ! Second clause: a tie (dk <= best once dk < best failed), written without == on reals.
       if (dk < best .or. (dk <= best .and. wk == at_interior .and. where /= at_interior)) then
          best = dk
          iseg = k
          where = wk
          cp = cpk
          normal = nk
       end if
    end do

    r = x - cp
    rho = norm2(r)
    if (where == at_interior) then
       feature = feature_segment
       ! x - cp is parallel to the normal. The gap is computed from the segment's defining
       ! points, not from cp, whose round-off (an ulp of the segment's coordinates) would
       ! otherwise enter the contact's velocity correction divided by dt.
       if (segs(iseg)%kind == segment_arc) then
          gap = real(arc_orientation(segs(iseg)), dp) * &
               (norm2(segs(iseg)%p0 - segs(iseg)%centre) - norm2(x - segs(iseg)%centre))
       else
          gap = dot_product(x - segs(iseg)%p0, normal)
       end if
    else
       ! The closest point is an end point of segment iseg: a corner shared with the
       ! neighbouring segment, or a free end of the chain.
       if (where == at_start .and. iseg > 1) then
          ia = iseg - 1
          ib = iseg
       else if (where == at_end .and. iseg < nseg) then
          ia = iseg
          ib = iseg + 1
       else
          ia = 0
          ib = 0
       end if
       if (ia > 0) then
          feature = feature_vertex
          iseg = ia
          m = segment_end_normal(segs(ia), at_end) + segment_end_normal(segs(ib), at_start)
          side = 1.0_dp
          if (dot_product(r, m) < 0.0_dp) side = -1.0_dp
          if (rho > 0.0_dp) then
             normal = side * r / rho
             gap = side * rho
          else
             mlen = norm2(m)
             if (mlen > 0.0_dp) then
                normal = m / mlen
             else
                normal = segment_end_normal(segs(ia), at_end)   ! a fold back by 180 degrees
             end if
             gap = 0.0_dp
          end if
       else
          feature = feature_free_end
          if (rho > 0.0_dp) then
             normal = r / rho
          end if
          gap = rho
       end if
    end if
    tangent = [normal(2), -normal(1)]
  end subroutine chain_closest_point

  !> Plane through `point` with normal `plane_normal` (any length > 0; the material is on the
  !> side it points to). Returns the signed gap, the unit normal and the foot point.
  pure subroutine plane_closest_point(point, plane_normal, x, gap, normal, cp)
    real(dp), intent(in) :: point(3)
    real(dp), intent(in) :: plane_normal(3)
    real(dp), intent(in) :: x(3)
    real(dp), intent(out) :: gap
    real(dp), intent(out) :: normal(3)
    real(dp), intent(out) :: cp(3)

    real(dp) :: len

    len = norm2(plane_normal)
    if (len <= 0.0_dp) then
       gap = huge(1.0_dp)
       normal = 0.0_dp
       cp = x
       return
    end if
    normal = plane_normal / len
    gap = dot_product(x - point, normal)
    cp = x - gap * normal
  end subroutine plane_closest_point

  !> The wall translated by `offset` (the displacement of its reference node): gap, unit
  !> normal into the material and closest point of x. Sizes: offset, x, normal, cp have
  !> wall%ndim entries (2: segment chain, 3: plane). A wall with neither returns gap = huge.
  pure subroutine surface_closest_point(wall, offset, x, gap, normal, cp)
    type(rigid_surface_t), intent(in) :: wall
    real(dp), intent(in) :: offset(:)
    real(dp), intent(in) :: x(:)
    real(dp), intent(out) :: gap
    real(dp), intent(out) :: normal(:)
    real(dp), intent(out) :: cp(:)

    real(dp) :: tangent(2)
    integer :: feature, iseg

    select case (wall%ndim)
    case (2)
       if (allocated(wall%segments)) then
          ! The chain is stored in reference coordinates: query with x - offset instead of
          ! moving every segment.
          call chain_closest_point(wall%segments(1:wall%n_segments), x(1:2) - offset(1:2), &
               gap, normal(1:2), tangent, cp(1:2), feature, iseg)
          cp(1:2) = cp(1:2) + offset(1:2)
       else
          gap = huge(1.0_dp)
          normal = 0.0_dp
          cp = x
       end if
    case (3)
       call plane_closest_point(wall%point + offset(1:3), wall%normal, x(1:3), gap, &
            normal(1:3), cp(1:3))
    case default
       gap = huge(1.0_dp)
       normal = 0.0_dp
       cp = x
    end select
  end subroutine surface_closest_point

  !> Largest coordinate magnitude that enters the wall's geometry (segment points and arc
  !> centres, or the plane point). Round-off in a gap is a few ulps of this (and of the
  !> node coordinates), which sets the contact tolerance.
  pure function surface_coordinate_scale(wall) result(scale)
    type(rigid_surface_t), intent(in) :: wall
    real(dp) :: scale

    integer :: k

    scale = 0.0_dp
    select case (wall%ndim)
    case (2)
       if (allocated(wall%segments)) then
          do k = 1, wall%n_segments
             scale = max(scale, maxval(abs(wall%segments(k)%p0)), &
                  maxval(abs(wall%segments(k)%p1)))
             if (wall%segments(k)%kind == segment_arc) &
                  scale = max(scale, maxval(abs(wall%segments(k)%centre)))
          end do
       end if
    case (3)
       scale = maxval(abs(wall%point))
    end select
  end function surface_coordinate_scale

  ! ------------------------------------------------------------------------------------------
  ! Helpers
  ! ------------------------------------------------------------------------------------------

  !> z-component of the cross product of two plane vectors.
  pure real(dp) function cross2(a, b)
    real(dp), intent(in) :: a(2), b(2)

    cross2 = a(1) * b(2) - a(2) * b(1)
  end function cross2

  !> Left unit normal of the direction p0 -> p1 (travel direction turned +90 degrees).
  pure function line_normal(p0, p1) result(normal)
    real(dp), intent(in) :: p0(2), p1(2)
    real(dp) :: normal(2)

    real(dp) :: d(2), len

    d = p1 - p0
    len = norm2(d)
    if (len > 0.0_dp) then
       normal = [-d(2), d(1)] / len
    else
       normal = [0.0_dp, 1.0_dp]
    end if
  end function line_normal
end module contact_geometry
