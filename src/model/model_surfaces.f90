!> Surfaces: element-face surfaces of the deformable mesh (the nodes that touch walls) and
!> analytic rigid surfaces (walls) that move with a reference node.
module model_surfaces
  use base_kinds, only: dp
  use model_sets, only: name_length
  implicit none
  private

  integer, parameter, public :: segment_line = 1
  integer, parameter, public :: segment_arc = 2

  !> Abaqus face numbering: local nodes of face S1..S4 of CPE4R/CAX4R and S1..S6 of C3D8R. In
  !> this order (ξ from the first node to the second, η from the first to the last), the face's
  !> x_ξ × x_η (3D) or the edge's left normal (2D) points into the element.
  integer, parameter, public :: cpe4r_faces(2, 4) = reshape([1, 2, 2, 3, 3, 4, 4, 1], [2, 4])
  integer, parameter, public :: c3d8r_faces(4, 6) = reshape([1, 2, 3, 4, 5, 8, 7, 6, 1, 5, 6, 2, &
       2, 6, 7, 3, 3, 7, 8, 4, 4, 8, 5, 1], [4, 6])

  !> *SURFACE, TYPE=ELEMENT: faces S1..S4 (CPE4R) or S1..S6 (C3D8R) of listed elements.
  type, public :: element_surface_t
     character(len=name_length) :: name = ''
     integer, allocatable :: elems(:)   !< internal element indices
     integer, allocatable :: faces(:)   !< face number of each entry (1..4 or 1..6)
     integer, allocatable :: nodes(:)   !< the distinct internal nodes of those faces, ascending
  end type element_surface_t

  !> One piece of a 2D analytic rigid surface (*SURFACE, TYPE=SEGMENTS): a straight line
  !> from p0 to p1, or a circular arc from p0 to p1 about `centre` (less than 180 degrees,
  !> as Abaqus requires). Coordinates are those of the reference configuration.
  type, public :: segment_t
     integer :: kind = segment_line
     real(dp) :: p0(2) = 0, p1(2) = 0, centre(2) = 0
  end type segment_t

  !> Shapes of a 3D rigid surface (rigid_surface_t%shape; 2D surfaces are segment chains).
  integer, parameter, public :: shape_plane = 0        !< bulkflow's TYPE=PLANE: point, normal
  integer, parameter, public :: shape_facets = 1       !< R3D3/R3D4 walls (TYPE=FACETS): triangles
  integer, parameter, public :: shape_cylinder = 2     !< TYPE=CYLINDER: profile swept along axes(:, 3)
  integer, parameter, public :: shape_revolution = 3   !< TYPE=REVOLUTION: (r, z) profile about axes(:, 3)

  !> An analytic rigid surface. 2D: a chain of segments. 3D: a plane through `point` with
  !> unit `normal` (bulkflow's *SURFACE, TYPE=PLANE). The material lies on the side the
  !> normal points to (2D: the left of the direction of travel along the segments, which
  !> is Abaqus's convention for TYPE=SEGMENTS). The surface translates with ref_node.
  !> 3D shapes other than the plane (`shape`): facets (triangles facet_tris over the vertices
  !> facet_points, material on the side of the right-hand normal), or the segment chain as a
  !> profile in the local frame with origin `point` and orthonormal axes(:, 1:3) (CYLINDER: the
  !> profile's x, y along axes 1, 2; REVOLUTION: r radial, z along axes(:, 3)).
  type, public :: rigid_surface_t
     character(len=name_length) :: name = ''
     integer :: ndim = 0
     integer :: n_segments = 0
     type(segment_t), allocatable :: segments(:)
     real(dp) :: point(3) = 0, normal(3) = 0
     integer :: ref_node = 0              !< internal node index of the *RIGID BODY reference node (0: fixed)
     integer :: shape = shape_plane
     integer :: n_facets = 0
     real(dp), allocatable :: facet_points(:, :)   !< (3, vertices)
     integer, allocatable :: facet_tris(:, :)      !< (3, n_facets): vertex indices, right-hand order
     real(dp) :: axes(3, 3) = 0
  end type rigid_surface_t
end module model_surfaces
