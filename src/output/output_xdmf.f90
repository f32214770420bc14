!> The XDMF companion of the HDF5 field file: a small XML text that tells ParaView (and VisIt)
!> how to read the HDF5 datasets as a time series of unstructured grids.
!>
!> Layout written (docs/output_format.md has the full description):
!>   Domain / Grid "bulkflow" (Collection, Temporal) / one Uniform Grid per frame with
!>   Time = total time, Topology (Quadrilateral | Hexahedron) from /mesh/connectivity,
!>   Geometry XYZ from /mesh/coordinates or the frame's own current coordinates, and one
!>   Attribute per field dataset of the frame.
!>   Two more topologies serve point writers (output_points, the MPM's particles): Polyvertex,
!>   a cloud of points whose number changes from frame to frame (each point its own cell), and
!>   3DCoRectMesh, a uniform grid given by origin and spacing (no geometry dataset). A 2-D grid
!>   is written as a 3-D one a node thick: with 2DCoRectMesh ParaView's XDMF reader failed to
!>   read a vector attribute.
!>
!> Attribute types: 1 component -> Scalar, 3 -> Vector, anything else -> Matrix with
!> Dimensions "n ncomp". Why not Tensor6 for 6-component stresses: readers convert Tensor6
!> from the XDMF component order (xx, xy, xz, yy, yz, zz) to their own, which would scramble
!> the VUMAT order (11, 22, 33, 12, 23, 31) we store; a Matrix is read as a plain
!> multi-component array whose components keep our order, and 2-component plane-strain
!> vectors (which a Vector, always 3 components, cannot describe) and 4-component
!> plane-strain tensors go the same way.
!>
!> The file is rewritten as a whole after every frame (to a temporary file renamed over the
!> old one), so it always describes exactly the frames completed so far.
module output_xdmf
  use base_kinds, only: dp
  use output_files, only: rename_file, int_to_str
  implicit none
  private

  public :: xdmf_attribute_t, xdmf_frame_t, xdmf_mesh_t
  public :: xdmf_write, xdmf_add_attribute, xdmf_attribute_type

  integer, parameter, public :: xdmf_center_node = 1
  integer, parameter, public :: xdmf_center_cell = 2

  !> One field of one frame.
  type :: xdmf_attribute_t
     character(len=:), allocatable :: name      !< name shown by ParaView (U, S, PEEQ, ...)
     character(len=:), allocatable :: dataset   !< absolute path inside the HDF5 file
     integer :: center = xdmf_center_node       !< xdmf_center_node or xdmf_center_cell
     integer :: ncomp = 1
  end type xdmf_attribute_t

  !> One output frame: a grid of the temporal collection.
  type :: xdmf_frame_t
     real(dp) :: time = 0.0_dp                  !< total time
     integer :: n_points = 0                    !< Polyvertex: the frame's number of points
     character(len=:), allocatable :: name      !< grid name, e.g. frame_000003
     character(len=:), allocatable :: geometry  !< dataset of the node coordinates (n_nodes, 3)
     integer :: n_attributes = 0
     type(xdmf_attribute_t), allocatable :: attributes(:)
  end type xdmf_frame_t

  !> What every frame shares: the HDF5 file and the topology.
  type :: xdmf_mesh_t
     character(len=:), allocatable :: h5_file       !< HDF5 file name relative to the .xmf
     character(len=:), allocatable :: topology      !< Quadrilateral, Hexahedron, Polyvertex or 3DCoRectMesh
     character(len=:), allocatable :: connectivity  !< dataset path (n_elems, nen), 0-based
     character(len=:), allocatable :: collection    !< name of the temporal collection (default bulkflow)
     integer :: n_nodes = 0
     integer :: n_elems = 0
     integer :: nen = 0
     integer :: grid_n(3) = 1                       !< 3DCoRectMesh: nodes in x, y, z
     real(dp) :: origin(3) = 0.0_dp                 !< 3DCoRectMesh: first node (x, y, z)
     real(dp) :: spacing(3) = 0.0_dp               !< 3DCoRectMesh: node distance in x, y, z
  end type xdmf_mesh_t

contains

  !> XDMF AttributeType for a field with `ncomp` components (see the module header).
  pure function xdmf_attribute_type(ncomp) result(kind)
    integer, intent(in) :: ncomp
    character(len=:), allocatable :: kind

    select case (ncomp)
    case (1)
       kind = 'Scalar'
    case (3)
       kind = 'Vector'
    case default
       kind = 'Matrix'
    end select
  end function xdmf_attribute_type

  !> Append a field to a frame's attribute list (grows the list by doubling).
  subroutine xdmf_add_attribute(frame, name, dataset, center, ncomp)
    type(xdmf_frame_t), intent(inout) :: frame
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: dataset
    integer, intent(in) :: center
    integer, intent(in) :: ncomp
    type(xdmf_attribute_t), allocatable :: grown(:)
    integer :: i

    if (.not. allocated(frame%attributes)) allocate (frame%attributes(8))
    if (frame%n_attributes == size(frame%attributes)) then
       allocate (grown(2 * size(frame%attributes)))
       do i = 1, frame%n_attributes
          call move_alloc(frame%attributes(i)%name, grown(i)%name)
          call move_alloc(frame%attributes(i)%dataset, grown(i)%dataset)
          grown(i)%center = frame%attributes(i)%center
          grown(i)%ncomp = frame%attributes(i)%ncomp
       end do
       call move_alloc(grown, frame%attributes)
    end if
    frame%n_attributes = frame%n_attributes + 1
    associate (a => frame%attributes(frame%n_attributes))
      a%name = name
      a%dataset = dataset
      a%center = center
      a%ncomp = ncomp
    end associate
  end subroutine xdmf_add_attribute

  !> Write the whole .xmf for frames(1:n_frames); `ok` false if the file could not be
  !> written. Written to `<path>.tmp` first and renamed, so readers never see half a file.
  subroutine xdmf_write(path, mesh, frames, n_frames, ok)
    character(len=*), intent(in) :: path
    type(xdmf_mesh_t), intent(in) :: mesh
    type(xdmf_frame_t), intent(in) :: frames(:)
    integer, intent(in) :: n_frames
    logical, intent(out) :: ok
    integer :: unit, ios, f, a, n_nodes
    character(len=:), allocatable :: tmp, collection
    character(len=32) :: tbuf

    tmp = path // '.tmp'
    open (newunit=unit, file=tmp, status='replace', action='write', form='formatted', &
         iostat=ios)
    if (ios /= 0) then
       ok = .false.
       return
    end if
    call put('<?xml version="1.0" ?>')
    call put('<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>')
    call put('<Xdmf Version="2.0">')
    call put(' <Domain>')
    collection = 'bulkflow'
    if (allocated(mesh%collection)) collection = mesh%collection
    call put('  <Grid Name="' // xml_escape(collection) // '" GridType="Collection" CollectionType="Temporal">')
    do f = 1, n_frames
       ! 17 significant digits: the time reads back as exactly the double we hold.
       write (tbuf, '(es25.16e3)') frames(f)%time
       call put('   <Grid Name="' // xml_escape(frames(f)%name) // '" GridType="Uniform">')
       call put('    <Time Value="' // trim(adjustl(tbuf)) // '"/>')
       select case (mesh%topology)
       case ('Polyvertex')
          n_nodes = frames(f)%n_points
          call put('    <Topology TopologyType="Polyvertex" NumberOfElements="' // int_to_str(n_nodes) // '"/>')
          call geometry_xyz()
       case ('3DCoRectMesh')
          n_nodes = product(mesh%grid_n)
          call put('    <Topology TopologyType="3DCoRectMesh" Dimensions="' // grid_dims() // '"/>')
          call put('    <Geometry GeometryType="ORIGIN_DXDYDZ">')
          call xml_triple(mesh%origin)
          call xml_triple(mesh%spacing)
          call put('    </Geometry>')
       case default
          n_nodes = mesh%n_nodes
          call put('    <Topology TopologyType="' // mesh%topology // '" NumberOfElements="' // &
               int_to_str(mesh%n_elems) // '">')
          call data_item(mesh%n_elems, mesh%nen, 'Int', 4, mesh%connectivity)
          call put('    </Topology>')
          call geometry_xyz()
       end select
       do a = 1, frames(f)%n_attributes
          associate (att => frames(f)%attributes(a))
            if (att%center == xdmf_center_node) then
               call put('    <Attribute Name="' // xml_escape(att%name) // '" AttributeType="' // &
                    xdmf_attribute_type(att%ncomp) // '" Center="Node">')
               call data_item(n_nodes, att%ncomp, 'Float', 8, att%dataset)
            else
               call put('    <Attribute Name="' // xml_escape(att%name) // '" AttributeType="' // &
                    xdmf_attribute_type(att%ncomp) // '" Center="Cell">')
               call data_item(mesh%n_elems, att%ncomp, 'Float', 8, att%dataset)
            end if
            call put('    </Attribute>')
          end associate
       end do
       call put('   </Grid>')
    end do
    call put('  </Grid>')
    call put(' </Domain>')
    call put('</Xdmf>')
    ok = ios == 0
    close (unit, iostat=ios)
    ok = ok .and. ios == 0
    if (ok) call rename_file(tmp, path, ok)

  contains

    !> One line; the first write error is kept in `ios`.
    subroutine put(text)
      character(len=*), intent(in) :: text
      integer :: ios_line

      if (ios /= 0) return
      write (unit, '(a)', iostat=ios_line) text
      ios = ios_line
    end subroutine put

    !> The frame's point coordinates (n_nodes, 3).
    subroutine geometry_xyz()
      call put('    <Geometry GeometryType="XYZ">')
      call data_item(n_nodes, 3, 'Float', 8, frames(f)%geometry)
      call put('    </Geometry>')
    end subroutine geometry_xyz

    !> "nz ny nx": a uniform grid's node counts in XDMF's (slowest first) order.
    function grid_dims() result(dims)
      character(len=:), allocatable :: dims

      dims = int_to_str(mesh%grid_n(3)) // ' ' // int_to_str(mesh%grid_n(2)) // ' ' // &
           int_to_str(mesh%grid_n(1))
    end function grid_dims

    !> Origin or spacing of a uniform grid as an inline DataItem, z first.
    subroutine xml_triple(v)
      real(dp), intent(in) :: v(3)
      character(len=32) :: b(3)
      integer :: i

      do i = 1, 3
         write (b(i), '(es25.16e3)') v(4 - i)
      end do
      call put('     <DataItem Dimensions="3" Format="XML">' // trim(adjustl(b(1))) // ' ' // &
           trim(adjustl(b(2))) // ' ' // trim(adjustl(b(3))) // '</DataItem>')
    end subroutine xml_triple

    !> A DataItem referring to an HDF5 dataset; one-component data is one-dimensional; on a
    !> uniform grid the rows are the grid's nodes "nz ny nx".
    subroutine data_item(n, ncomp, number_type, precision, dataset)
      integer, intent(in) :: n
      integer, intent(in) :: ncomp
      character(len=*), intent(in) :: number_type
      integer, intent(in) :: precision
      character(len=*), intent(in) :: dataset
      character(len=:), allocatable :: dims

      if (mesh%topology == '3DCoRectMesh') then
         dims = grid_dims()
      else
         dims = int_to_str(n)
      end if
      if (ncomp /= 1) dims = dims // ' ' // int_to_str(ncomp)
      call put('     <DataItem Dimensions="' // dims // '" NumberType="' // number_type // &
           '" Precision="' // int_to_str(precision) // '" Format="HDF">' // &
           xml_escape(mesh%h5_file) // ':' // xml_escape(dataset) // '</DataItem>')
    end subroutine data_item

  end subroutine xdmf_write

  !> Replace the characters XML reserves (& < > ") by their entities.
  pure function xml_escape(text) result(out)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: out
    integer :: i

    out = ''
    do i = 1, len(text)
       select case (text(i:i))
       case ('&')
          out = out // '&amp;'
       case ('<')
          out = out // '&lt;'
       case ('>')
          out = out // '&gt;'
       case ('"')
          out = out // '&quot;'
       case default
          out = out // text(i:i)
       end select
    end do
  end function xml_escape

end module output_xdmf
