!> The finite-element mesh of a scene: reference node coordinates, one continuum element
!> type per model (CPE4R in 2D plane strain, C3D8R in 3D), connectivity by internal index,
!> and the user's node and element numbers for messages and output.
module model_mesh
  use base_kinds, only: dp
  use model_sets, only: sorted_position
  implicit none
  private

  integer, parameter, public :: element_cpe4r = 1
  integer, parameter, public :: element_c3d8r = 2
  integer, parameter, public :: element_cax4r = 3  !< 2D axisymmetric, x = r, y = z

  type, public :: mesh_t
     integer :: ndim = 0                      !< 2 (plane strain) or 3
     integer :: n_nodes = 0
     real(dp), allocatable :: x0(:, :)        !< (ndim, n_nodes) reference coordinates
     integer, allocatable :: node_id(:)       !< user node number of each internal node
     integer :: element_type = 0              !< element_cpe4r, element_c3d8r or element_cax4r
     integer :: nen = 0                       !< nodes per element: 4 or 8
     integer :: n_elems = 0
     integer, allocatable :: conn(:, :)       !< (nen, n_elems) internal node indices
     integer, allocatable :: elem_id(:)       !< user element number of each internal element
     integer, allocatable :: elem_section(:)  !< section index of each element (0: none yet)
   contains
     procedure :: node_index
     procedure :: elem_index
  end type mesh_t

contains

  !> Internal index of a user node number, 0 when absent. Node numbers are kept sorted
  !> by the model builder (node_id ascending), so this is a binary search.
  pure integer function node_index(this, id)
    class(mesh_t), intent(in) :: this
    integer, intent(in) :: id
    node_index = sorted_position(this%node_id(1:this%n_nodes), id)
  end function node_index

  !> Internal index of a user element number, 0 when absent (elem_id ascending).
  pure integer function elem_index(this, id)
    class(mesh_t), intent(in) :: this
    integer, intent(in) :: id
    elem_index = sorted_position(this%elem_id(1:this%n_elems), id)
  end function elem_index
end module model_mesh
