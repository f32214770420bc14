!> bulkflow's *SURFACE, TYPE=FACETS: a 3D rigid wall of flat triangles and quadrilaterals, one
!> facet per data line (x1, y1, z1, x2, y2, z2, x3, y3, z3[, x4, y4, z4]), material on the side of
!> the right-hand normal of the point order. The reader writes it for R3D3/R3D4 walls
!> (scene_discrete_rigid), each line at its element's file:line; it may also be written by hand.
!> Checked here, before increment 1: a facet of (nearly) zero area, a quad that is folded,
!> not convex, or warped out of its plane by more than quad_warp_limit of its shorter diagonal.
!> Points of different facets that coincide exactly (the same node) become one vertex, so the
!> contact sees the edges and corners the facets share (contact_facets).
module scene_facet_surface
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_block_t
  use model_surfaces, only: rigid_surface_t, shape_facets
  use contact_facets, only: facet_relative_area, quad_warp, triangle_normal
  use scene_util, only: itoa, rtoa, get_real, expect_fields, expect_lines
  implicit none
  private

  public :: read_facets

  !> Smallest accepted 2 area / (longest edge)^2 of a triangle (equilateral: 0.87): below it the
  !> facet's normal is round-off.
  real(dp), parameter, public :: facet_area_limit = 1.0e-6_dp
  !> Largest accepted warping of a quad (quad_warp: out-of-plane offset of its diagonals over the
  !> shorter diagonal). The two triangles the quad is stored as then differ from Abaqus's bilinear
  !> R3D4 surface by at most 0.05 % of the facet size; meshed planar, cylindrical and conical walls
  !> have planar quads (warp at round-off).
  real(dp), parameter, public :: quad_warp_limit = 1.0e-3_dp

contains

  subroutine read_facets(blk, ndim, rs, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: ndim
    type(rigid_surface_t), intent(inout) :: rs
    type(error_t), intent(inout) :: err
    character(len=*), parameter :: expected = 'x1, y1, z1, x2, y2, z2, x3, y3, z3[, x4, y4, z4] (a triangle ' // &
         'or a quad)'
    real(dp), allocatable :: points(:, :)
    integer, allocatable :: tris(:, :)
    real(dp) :: p(3, 4)
    integer :: il, k, j, np, nv, nt, vid(4)

    call expect_lines(blk, 1, huge(1), 'one facet per line: ' // expected, err)
    if (err%raised) return
    if (ndim /= 3) then
       call raise_error(blk%lines(1)%file, blk%lines(1)%line, '3D rigid facet (R3D3/R3D4 element or ' // &
            'TYPE=FACETS) in a 2D model; expected R2D2 elements or TYPE=SEGMENTS for a 2D wall', err)
       return
    end if
    allocate (points(3, 4 * blk%n_lines), tris(3, 2 * blk%n_lines))
    nv = 0
    nt = 0
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         call expect_fields(blk, dl, 9, 12, expected, err)
         if (err%raised) return
         np = dl%n_fields() / 3
         if (3 * np /= dl%n_fields()) then
            call raise_error(dl%file, dl%line, 'facet with ' // itoa(dl%n_fields()) // &
                 ' coordinates; expected ' // expected, err)
            return
         end if
         do k = 1, np
            do j = 1, 3
               call get_real(dl, 3 * (k - 1) + j, p(j, k), err)
               if (err%raised) return
            end do
         end do
         call check_facet(dl%file, dl%line, p(:, 1:np), err)
         if (err%raised) return
         do k = 1, np
            vid(k) = vertex_index(points, nv, p(:, k))
         end do
         nt = nt + 1
         tris(:, nt) = vid(1:3)
         if (np == 4) then
            nt = nt + 1
            tris(:, nt) = [vid(1), vid(3), vid(4)]
         end if
       end associate
    end do
    rs%shape = shape_facets
    rs%n_facets = nt
    rs%facet_points = points(:, 1:nv)
    rs%facet_tris = tris(:, 1:nt)
    allocate (rs%segments(0))
    rs%n_segments = 0
  end subroutine read_facets

  !> A triangle of non-zero area; a quad whose four corner triangles have areas above the limit
  !> and normals on one side (convex, not folded) and whose warping is within quad_warp_limit.
  subroutine check_facet(file, line, p, err)
    character(len=*), intent(in) :: file
    integer, intent(in) :: line
    real(dp), intent(in) :: p(:, :)
    type(error_t), intent(inout) :: err
    real(dp) :: ratio, warp, n(3)
    integer :: k, a, b, c

    do k = 1, merge(1, 4, size(p, 2) == 3)
       a = k
       b = mod(k, size(p, 2)) + 1
       c = mod(k + 1, size(p, 2)) + 1
       ratio = facet_relative_area(p(:, a), p(:, b), p(:, c))
       if (.not. (ratio > facet_area_limit)) then
          call raise_error(file, line, 'rigid facet of zero area (2 area / longest edge^2 = ' // rtoa(ratio) // &
               ', corner ' // itoa(b) // '); expected ' // trim(merge('3 distinct points  ', &
               '4 corners of a quad', size(p, 2) == 3)) // ' not on one line', err)
          return
       end if
    end do
    if (size(p, 2) == 3) return
    n = triangle_normal(p(:, 1), p(:, 2), p(:, 3)) + triangle_normal(p(:, 1), p(:, 3), p(:, 4))
    do k = 1, 4
       a = k
       b = mod(k, 4) + 1
       c = mod(k + 1, 4) + 1
       if (.not. (dot_product(triangle_normal(p(:, a), p(:, b), p(:, c)), n) > 0)) then
          call raise_error(file, line, 'rigid quad facet is folded or not convex at corner ' // &
               itoa(b) // '; expected 4 corners in order around a convex quad', err)
          return
       end if
    end do
    warp = quad_warp(p(:, 1), p(:, 2), p(:, 3), p(:, 4))
    if (warp > quad_warp_limit) then
       call raise_error(file, line, 'rigid quad facet is warped: its diagonals are ' // rtoa(warp) // &
            ' of the shorter diagonal out of one plane (limit ' // rtoa(quad_warp_limit) // &
            '); expected a planar quad (or split it into two R3D3 triangles)', err)
    end if
  end subroutine check_facet

  !> Index of point x among points(:, 1:nv), appended if no point coincides exactly.
  integer function vertex_index(points, nv, x) result(id)
    real(dp), intent(inout) :: points(:, :)
    integer, intent(inout) :: nv
    real(dp), intent(in) :: x(3)

    do id = 1, nv
       if (all(abs(points(:, id) - x) <= 0.0_dp)) return
    end do
    nv = nv + 1
    points(:, nv) = x
    id = nv
  end function vertex_index
end module scene_facet_surface
