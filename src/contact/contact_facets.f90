!> Geometry of 3D faceted rigid walls (discrete rigid R3D3/R3D4 elements, bulkflow's
!> *SURFACE, TYPE=FACETS): closest point, signed gap and unit normal of a point with respect to
!> a set of triangles that share vertices (an R3D4 quad is stored as its two triangles 1-2-3 and
!> 1-3-4), and the checks the scene reader makes on a facet (area, warping of a quad).
!>
!> Conventions (src/contact/README.md, "Faceted walls"):
!>   * A triangle's material side is the side of its right-hand normal (p2 - p1) x (p3 - p1), the
!>     positive normal of a shell or rigid element in Abaqus (SPOS); the reader reverses the node
!>     order of SNEG faces.
!>   * gap > 0 on the material side, < 0 behind; `normal` is the unit vector from the closest point
!>     into the material, and x = cp + gap * normal for every feature (face, edge, vertex).
!>   * The side of a point whose closest point is an edge or a vertex shared by several triangles
!>     is decided with the pseudo-normal of that feature: the sum of the unit normals of the
!>     triangles on an edge, the angle-weighted sum at a vertex (Baerentzen and Aanaes, "Signed
!>     distance computation using the angle weighted pseudonormal", IEEE TVCG 11(3), 2005), which
!>     is exact for convex and concave corners alike (the 3D form of the 2D chain rule in
!>     contact_geometry).
!>   * Edges of one triangle only, and vertices on such edges, are the free boundary of the wall:
!>     treated as a convex edge, gap = |x - cp| >= 0, as for the free ends of a 2D chain (a node
!>     sliding off the edge of a plate is released; an analytic or discrete rigid surface is not
!>     extended beyond its edges).
module contact_facets
  use base_kinds, only: dp
  implicit none
  private

  public :: triangle_closest_point
  public :: facets_closest_point
  public :: triangle_normal
  public :: facet_relative_area
  public :: quad_warp

  !> Which feature of a triangle holds the closest point (triangle_closest_point%feature).
  integer, parameter, public :: on_face = 0     !< the interior of the triangle
  integer, parameter, public :: on_edge = 1     !< edge `which`: 1 = p1-p2, 2 = p2-p3, 3 = p3-p1
  integer, parameter, public :: on_vertex = 2   !< vertex `which` (1, 2 or 3)

contains

  !> Closest point cp of the triangle (p1, p2, p3) to x, by the Voronoi regions of its vertices,
  !> edges and face tested in turn with dot products only (C. Ericson, Real-Time Collision
  !> Detection, 2005, §5.1.5). feature/which say where cp lies. A degenerate triangle (rejected
  !> by the reader) still returns a point of it.
  pure subroutine triangle_closest_point(p1, p2, p3, x, cp, feature, which)
    real(dp), intent(in) :: p1(3), p2(3), p3(3), x(3)
    real(dp), intent(out) :: cp(3)
    integer, intent(out) :: feature, which

    real(dp) :: e12(3), e13(3), d1, d2, d3, d4, d5, d6, va, vb, vc, s, t, denom

    e12 = p2 - p1
    e13 = p3 - p1
    d1 = dot_product(e12, x - p1)
    d2 = dot_product(e13, x - p1)
    if (d1 <= 0.0_dp .and. d2 <= 0.0_dp) then
       call vertex_result(p1, 1, cp, feature, which)
       return
    end if
    d3 = dot_product(e12, x - p2)
    d4 = dot_product(e13, x - p2)
    if (d3 >= 0.0_dp .and. d4 <= d3) then
       call vertex_result(p2, 2, cp, feature, which)
       return
    end if
    vc = d1 * d4 - d3 * d2
    if (vc <= 0.0_dp .and. d1 >= 0.0_dp .and. d3 <= 0.0_dp) then
       s = d1 / (d1 - d3)
       cp = p1 + s * e12
       feature = on_edge
       which = 1
       return
    end if
    d5 = dot_product(e12, x - p3)
    d6 = dot_product(e13, x - p3)
    if (d6 >= 0.0_dp .and. d5 <= d6) then
       call vertex_result(p3, 3, cp, feature, which)
       return
    end if
    vb = d5 * d2 - d1 * d6
    if (vb <= 0.0_dp .and. d2 >= 0.0_dp .and. d6 <= 0.0_dp) then
       t = d2 / (d2 - d6)
       cp = p1 + t * e13
       feature = on_edge
       which = 3
       return
    end if
    va = d3 * d6 - d5 * d4
    if (va <= 0.0_dp .and. d4 - d3 >= 0.0_dp .and. d5 - d6 >= 0.0_dp) then
       t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
       cp = p2 + t * (p3 - p2)
       feature = on_edge
       which = 2
       return
    end if
    denom = va + vb + vc
    if (.not. (denom > 0.0_dp)) then
       call vertex_result(p1, 1, cp, feature, which)
       return
    end if
    cp = p1 + (vb / denom) * e12 + (vc / denom) * e13
    feature = on_face
    which = 0
  end subroutine triangle_closest_point

  pure subroutine vertex_result(p, k, cp, feature, which)
    real(dp), intent(in) :: p(3)
    integer, intent(in) :: k
    real(dp), intent(out) :: cp(3)
    integer, intent(out) :: feature, which

    cp = p
    feature = on_vertex
    which = k
  end subroutine vertex_result

  !> Unit right-hand normal of the triangle (p1, p2, p3); zero for a degenerate one.
  pure function triangle_normal(p1, p2, p3) result(n)
    real(dp), intent(in) :: p1(3), p2(3), p3(3)
    real(dp) :: n(3), length

    n = cross3(p2 - p1, p3 - p1)
    length = norm2(n)
    if (length > 0.0_dp) then
       n = n / length
    else
       n = 0.0_dp
    end if
  end function triangle_normal

  !> Closest point, signed gap and unit normal (into the material) of x to the triangles
  !> tris(:, 1:nt) over the vertex coordinates points(:, :). Ties: the first triangle wins, a
  !> face wins over an edge or vertex. No triangles: gap = huge.
  pure subroutine facets_closest_point(points, tris, x, gap, normal, cp)
    real(dp), intent(in) :: points(:, :)
    integer, intent(in) :: tris(:, :)
    real(dp), intent(in) :: x(3)
    real(dp), intent(out) :: gap
    real(dp), intent(out) :: normal(3)
    real(dp), intent(out) :: cp(3)

    real(dp) :: cpk(3), dk, best, r(3), rho, pseudo(3), plen
    integer :: k, fk, wk, feature, which, kbest, va, vb, n_sharing

    gap = huge(1.0_dp)
    normal = 0.0_dp
    cp = x
    if (size(tris, 2) == 0) return
    best = huge(1.0_dp)
    kbest = 1
    feature = on_vertex
    which = 1
    do k = 1, size(tris, 2)
       call triangle_closest_point(points(:, tris(1, k)), points(:, tris(2, k)), points(:, tris(3, k)), &
            x, cpk, fk, wk)
       dk = norm2(x - cpk)
       ! second clause: a tie (dk <= best once dk < best failed), without == on reals
       if (dk < best .or. (dk <= best .and. fk == on_face .and. feature /= on_face)) then
          best = dk
          kbest = k
          feature = fk
          which = wk
          cp = cpk
       end if
    end do

    associate (t => tris(:, kbest))
      if (feature == on_face) then
         ! x - cp is along the face normal; the gap from a defining vertex, not from cp (whose
         ! round-off would enter the contact's velocity correction divided by dt)
         normal = triangle_normal(points(:, t(1)), points(:, t(2)), points(:, t(3)))
         gap = dot_product(x - points(:, t(1)), normal)
         return
      end if
      if (feature == on_edge) then
         va = t(which)
         vb = t(mod(which, 3) + 1)
         call edge_pseudo_normal(points, tris, va, vb, pseudo, n_sharing)
      else
         va = t(which)
         call vertex_pseudo_normal(points, tris, va, pseudo, n_sharing)
      end if
    end associate
    r = x - cp
    rho = norm2(r)
    if (n_sharing < 2) then
       ! free boundary of the wall: a convex edge, never behind
       gap = rho
       if (rho > 0.0_dp) then
          normal = r / rho
       else
          normal = unit_or_zero(pseudo)
       end if
    else if (rho > 0.0_dp) then
       if (dot_product(r, pseudo) < 0.0_dp) then
          gap = -rho
          normal = -r / rho
       else
          gap = rho
          normal = r / rho
       end if
    else
       gap = 0.0_dp
       plen = norm2(pseudo)
       normal = unit_or_zero(pseudo)
       if (.not. (plen > 0.0_dp)) normal = triangle_normal(points(:, tris(1, kbest)), &
            points(:, tris(2, kbest)), points(:, tris(3, kbest)))
    end if
  end subroutine facets_closest_point

  !> Sum of the unit normals of the triangles having the edge (va, vb); n_sharing of them (1: a
  !> free edge of the wall).
  pure subroutine edge_pseudo_normal(points, tris, va, vb, pseudo, n_sharing)
    real(dp), intent(in) :: points(:, :)
    integer, intent(in) :: tris(:, :), va, vb
    real(dp), intent(out) :: pseudo(3)
    integer, intent(out) :: n_sharing
    integer :: k

    pseudo = 0.0_dp
    n_sharing = 0
    do k = 1, size(tris, 2)
       if (any(tris(:, k) == va) .and. any(tris(:, k) == vb)) then
          n_sharing = n_sharing + 1
          pseudo = pseudo + triangle_normal(points(:, tris(1, k)), points(:, tris(2, k)), points(:, tris(3, k)))
       end if
    end do
  end subroutine edge_pseudo_normal

  !> Angle-weighted sum of the unit normals of the triangles at vertex v. n_sharing = 2 for an
  !> interior vertex (every edge at it has two triangles), else 1 (a vertex of the free boundary).
  pure subroutine vertex_pseudo_normal(points, tris, v, pseudo, n_sharing)
    real(dp), intent(in) :: points(:, :)
    integer, intent(in) :: tris(:, :), v
    real(dp), intent(out) :: pseudo(3)
    integer, intent(out) :: n_sharing
    real(dp) :: ea(3), eb(3), cosine
    integer :: k, j, other(2), m, n_edge

    pseudo = 0.0_dp
    n_sharing = 2
    do k = 1, size(tris, 2)
       if (.not. any(tris(:, k) == v)) cycle
       m = 0
       do j = 1, 3
          if (tris(j, k) /= v) then
             m = m + 1
             other(m) = tris(j, k)
          end if
       end do
       if (m /= 2) cycle
       ea = points(:, other(1)) - points(:, v)
       eb = points(:, other(2)) - points(:, v)
       if (norm2(ea) > 0.0_dp .and. norm2(eb) > 0.0_dp) then
          cosine = max(-1.0_dp, min(1.0_dp, dot_product(ea, eb) / (norm2(ea) * norm2(eb))))
          pseudo = pseudo + acos(cosine) * triangle_normal(points(:, tris(1, k)), points(:, tris(2, k)), &
               points(:, tris(3, k)))
       end if
       do j = 1, 2
          call edge_count(tris, v, other(j), n_edge)
          if (n_edge < 2) n_sharing = 1
       end do
    end do
  end subroutine vertex_pseudo_normal

  pure subroutine edge_count(tris, va, vb, n)
    integer, intent(in) :: tris(:, :), va, vb
    integer, intent(out) :: n
    integer :: k

    n = 0
    do k = 1, size(tris, 2)
       if (any(tris(:, k) == va) .and. any(tris(:, k) == vb)) n = n + 1
    end do
  end subroutine edge_count

  !> Twice the area of the triangle over its longest edge squared: 0 for a degenerate (zero-area)
  !> triangle, sqrt(3)/2 for an equilateral one. Scale-free, so the reader can reject slivers.
  pure real(dp) function facet_relative_area(p1, p2, p3) result(ratio)
    real(dp), intent(in) :: p1(3), p2(3), p3(3)
    real(dp) :: longest

    longest = max(norm2(p2 - p1), norm2(p3 - p2), norm2(p1 - p3))
    if (longest > 0.0_dp) then
       ratio = norm2(cross3(p2 - p1, p3 - p1)) / longest**2
    else
       ratio = 0.0_dp
    end if
  end function facet_relative_area

  !> Warping of the quad p1-p2-p3-p4: the distance between the midpoints of its diagonals along
  !> the quad normal (the cross product of the diagonals), over the shorter diagonal. 0 for a
  !> planar quad. The two triangles 1-2-3, 1-3-4 the wall is stored as differ from Abaqus's
  !> bilinear R3D4 surface by at most half this distance (at the centre).
  pure real(dp) function quad_warp(p1, p2, p3, p4) result(warp)
    real(dp), intent(in) :: p1(3), p2(3), p3(3), p4(3)
    real(dp) :: n(3), shorter

    n = cross3(p3 - p1, p4 - p2)
    shorter = min(norm2(p3 - p1), norm2(p4 - p2))
    if (norm2(n) > 0.0_dp .and. shorter > 0.0_dp) then
       warp = abs(dot_product(0.5_dp * ((p1 + p3) - (p2 + p4)), n / norm2(n))) / shorter
    else
       warp = huge(1.0_dp)
    end if
  end function quad_warp

  pure function cross3(a, b) result(c)
    real(dp), intent(in) :: a(3), b(3)
    real(dp) :: c(3)

    c = [a(2) * b(3) - a(3) * b(2), a(3) * b(1) - a(1) * b(3), a(1) * b(2) - a(2) * b(1)]
  end function cross3

  pure function unit_or_zero(a) result(u)
    real(dp), intent(in) :: a(3)
    real(dp) :: u(3)

    if (norm2(a) > 0.0_dp) then
       u = a / norm2(a)
    else
       u = 0.0_dp
    end if
  end function unit_or_zero
end module contact_facets
