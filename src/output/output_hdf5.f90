!> Field output: one HDF5 file per run, written collectively by all ranks through MPI-IO,
!> and its XDMF companion (output_xdmf) so ParaView opens the result as a time series.
!>
!> Layout (full description in docs/output_format.md; shapes as h5py/C show them):
!>   /                      attributes format = "bulkflow-fields", format_version = 1
!>   /mesh                  attributes ndim, nen, element_type ("CPE4R" | "CAX4R" | "C3D8R")
!>   /mesh/coordinates      (n_nodes, 3) float64, reference configuration, z = 0 in 2D
!>   /mesh/connectivity     (n_elems, nen) int32, 0-based global node indices (XDMF's convention)
!>   /mesh/node_id          (n_nodes,) int32, user node numbers
!>   /mesh/element_id       (n_elems,) int32, user element numbers
!>   /frames/NNNNNN         one group per frame (NNNNNN = 0-based frame index, 6 digits) with
!>                          attributes step, increment (int32), step_time, total_time (float64)
!>   /frames/NNNNNN/<name>  node field (n_nodes, ncomp) or element field (n_elems, ncomp);
!>                          one-component fields are 1-D; attribute center = "Node" | "Cell"
!>   /frames/NNNNNN/coordinates   (n_nodes, 3) current coordinates, when the caller writes them
!>
!> Rows are global indices (node i of the model is row i-1), so the file does not depend on the
!> number of ranks. Each node row comes from the node's owner only (`node_owned`), each
!> element row from the rank holding the element. The rows are first exchanged (one
!> all-to-all) so that every rank holds one contiguous block of rows, then written in one
!> collective transfer, each rank selecting its block as a single hyperslab; a rank with no
!> rows takes part with an empty selection (see `redistribute` for why).
!>
!> Every routine here is collective over the writer's communicator: all ranks call it, with
!> the same name and component count. Argument errors found on one rank are agreed on
!> (output_collective) so every rank returns the same error.
!>
!> Restart: field_writer_open(..., restart_frames=n) reopens the file, keeps frames 0..n-1,
!> deletes any later frame (written after the checkpoint by the interrupted run) and goes on
!> with frame n; the XDMF is rebuilt from what the file holds (output_hdf5_frames).
!>
!> This module owns the writer and its public procedures; the HDF5 primitives are in
!> output_hdf5_basics, the collective row transfer in output_hdf5_rows.
module output_hdf5
  use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Allreduce, MPI_Bcast, &
       MPI_IN_PLACE, MPI_INTEGER, MPI_LOGICAL, MPI_MAX, MPI_SUM, MPI_INFO_NULL
  use hdf5
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use model_mesh, only: element_cpe4r, element_c3d8r, element_cax4r
  use output_files, only: base_name, int_to_str, file_exists
  use output_collective, only: agree_on_error
  use output_xdmf, only: xdmf_mesh_t, xdmf_frame_t, xdmf_write, xdmf_add_attribute, &
       xdmf_center_node, xdmf_center_cell
  use output_hdf5_basics, only: hdf5_error_context, check, collective_transfer, create_dataset, write_attr_int, &
       write_attr_real, write_attr_string
  use output_hdf5_rows, only: write_rows_real, write_rows_int
  use output_hdf5_frames, only: reopen_frames, frame_path, new_xdmf_frame, &
       grow_frames, coordinates_name
  implicit none
  private

  public :: field_writer_t
  public :: field_writer_open, field_writer_frame, field_writer_end_frame
  public :: field_writer_coordinates, field_writer_node_field, field_writer_element_field
  public :: field_writer_close, field_writer_frame_count

  integer, parameter :: format_version = 1

  !> An open field file. Components are private: use the procedures.
  type :: field_writer_t
     private
     logical :: is_open = .false.
     type(MPI_Comm) :: comm
     integer :: rank = 0
     integer :: nranks = 1
     character(len=:), allocatable :: h5_path
     character(len=:), allocatable :: xmf_path
     integer(hid_t) :: file = -1
     integer(hid_t) :: xfer = -1          !< collective transfer property list
     integer(hid_t) :: frame_group = -1
     integer :: ndim = 0
     integer :: nen = 0
     integer :: n_nodes = 0
     integer :: n_elems = 0
     logical :: frame_open = .false.
     integer :: n_frames = 0              !< frames started (the open one included)
     type(xdmf_mesh_t) :: mesh
     type(xdmf_frame_t), allocatable :: frames(:)
  end type field_writer_t

contains

  ! ---------------------------------------------------------------------------------------
  ! Public procedures
  ! ---------------------------------------------------------------------------------------

  !> Create `<path_base>.h5` and `<path_base>.xmf` and write the mesh, or with
  !> `restart_frames` reopen them and keep the first `restart_frames` frames.
  !>
  !> Each rank passes its own part of the mesh: its local nodes (ascending global indices
  !> `node_global`, `node_owned` true on exactly one rank per node, user numbers `node_id`,
  !> reference coordinates `x0(ndim, :)`) and its elements (ascending `elem_global`, user
  !> numbers `elem_id`, connectivity `conn(nen, :)` in GLOBAL 1-based node indices, i.e.
  !> part%node_global(part%conn)). A serial caller passes everything (all nodes owned).
  !> On a restart the mesh arguments are only checked against the file's sizes.
  subroutine field_writer_open(w, path_base, comm, ndim, element_type, n_nodes, n_elems, &
       node_global, node_owned, node_id, x0, elem_global, elem_id, conn, restart_frames, err)
    type(field_writer_t), intent(out) :: w
    character(len=*), intent(in) :: path_base
    type(MPI_Comm), intent(in) :: comm
    integer, intent(in) :: ndim
    integer, intent(in) :: element_type          !< element_cpe4r or element_c3d8r (model_mesh)
    integer, intent(in) :: n_nodes                !< global counts
    integer, intent(in) :: n_elems
    integer, intent(in) :: node_global(:)
    logical, intent(in) :: node_owned(:)
    integer, intent(in) :: node_id(:)
    real(dp), intent(in) :: x0(:, :)
    integer, intent(in) :: elem_global(:)
    integer, intent(in) :: elem_id(:)
    integer, intent(in) :: conn(:, :)
    integer, intent(in), optional :: restart_frames
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: msg
    logical :: failed, any_failed
    integer :: counts(2), hdferr
    integer(hid_t) :: fapl

    call MPI_Comm_rank(comm, w%rank)
    call MPI_Comm_size(comm, w%nranks)
    w%comm = comm
    w%h5_path = path_base // '.h5'
    w%xmf_path = path_base // '.xmf'
    w%ndim = ndim
    w%n_nodes = n_nodes
    w%n_elems = n_elems
    w%nen = size(conn, 1)

    ! Argument checks, agreed between ranks before any collective HDF5 call.
    failed = .false.
    select case (element_type)
    case (element_cpe4r)
       w%mesh%topology = 'Quadrilateral'
       if (ndim /= 2 .or. w%nen /= 4) call fail('CPE4R needs ndim = 2 and 4 nodes per element')
    case (element_cax4r)
       w%mesh%topology = 'Quadrilateral'
       if (ndim /= 2 .or. w%nen /= 4) call fail('CAX4R needs ndim = 2 and 4 nodes per element')
    case (element_c3d8r)
       w%mesh%topology = 'Hexahedron'
       if (ndim /= 3 .or. w%nen /= 8) call fail('C3D8R needs ndim = 3 and 8 nodes per element')
    case default
       call fail('unknown element type ' // int_to_str(element_type))
    end select
    if (size(node_owned) /= size(node_global) .or. size(node_id) /= size(node_global) .or. &
         size(x0, 2) /= size(node_global) .or. size(x0, 1) /= ndim) &
         call fail('node_global, node_owned, node_id and x0(ndim, :) must have the same length')
    if (size(elem_id) /= size(elem_global) .or. size(conn, 2) /= size(elem_global)) &
         call fail('elem_global, elem_id and conn(nen, :) must have the same length')
    call check_indices('node_global', node_global, n_nodes)
    call check_indices('elem_global', elem_global, n_elems)
    if (size(conn) > 0) then
       if (minval(conn) < 1 .or. maxval(conn) > n_nodes) &
            call fail('conn must hold global node indices in 1..' // int_to_str(n_nodes))
    end if
    if (present(restart_frames)) then
       if (restart_frames < 0) call fail('restart_frames must not be negative')
       if (.not. file_exists(w%h5_path)) call fail('cannot restart: the file does not exist')
    end if
    call agree_on_error(comm, failed, msg, any_failed)
    if (any_failed) then
       call raise_error(w%h5_path, 0, msg, err)
       return
    end if
    ! Every node must have exactly one owner and every element one holder, else rows of the
    ! global datasets would be left unwritten (or written twice).
    counts = [count(node_owned), size(elem_global)]
    call MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_INTEGER, MPI_SUM, comm)
    if (counts(1) /= n_nodes .or. counts(2) /= n_elems) then
       call raise_error(w%h5_path, 0, 'the ranks own ' // &
            int_to_str(counts(1)) // ' nodes and hold ' // int_to_str(counts(2)) // &
            ' elements, expected ' // int_to_str(n_nodes) // ' and ' // int_to_str(n_elems), err)
       return
    end if

    call hdf5_error_context(w%h5_path)
    call h5open_f(hdferr)
    call check(hdferr, 'h5open')
    call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, hdferr)
    call check(hdferr, 'creating the file access property list')
    call h5pset_fapl_mpio_f(fapl, comm%MPI_VAL, MPI_INFO_NULL%MPI_VAL, hdferr)
    call check(hdferr, 'h5pset_fapl_mpio')
    if (present(restart_frames)) then
       call h5fopen_f(w%h5_path, H5F_ACC_RDWR_F, w%file, hdferr, access_prp=fapl)
       call check(hdferr, 'opening the file for appending')
    else
       call h5fcreate_f(w%h5_path, H5F_ACC_TRUNC_F, w%file, hdferr, access_prp=fapl)
       call check(hdferr, 'creating the file')
    end if
    call h5pclose_f(fapl, hdferr)
    call collective_transfer(w%xfer)
    w%is_open = .true.

    w%mesh%h5_file = base_name(w%h5_path)
    w%mesh%connectivity = '/mesh/connectivity'
    w%mesh%n_nodes = n_nodes
    w%mesh%n_elems = n_elems
    w%mesh%nen = w%nen
    allocate (w%frames(16))

    if (present(restart_frames)) then
       call reopen_frames(w%file, w%n_nodes, w%nen, w%n_elems, restart_frames, w%frames, w%n_frames, msg)
       if (allocated(msg)) then
          call close_handles(w)
          call raise_error(w%h5_path, 0, msg, err)
          return
       end if
    else
       call write_mesh(w, element_type, node_global, node_owned, node_id, x0, elem_global, &
            elem_id, conn)
    end if
    call h5fflush_f(w%file, H5F_SCOPE_GLOBAL_F, hdferr)
    call check(hdferr, 'flushing the file')
    call rewrite_xdmf(w, err)

  contains

    subroutine fail(text)
      character(len=*), intent(in) :: text

      if (failed) return        ! keep the first problem
      failed = .true.
      msg = text // ' (rank ' // int_to_str(w%rank) // ')'
    end subroutine fail

    subroutine check_indices(what, idx, n)
      character(len=*), intent(in) :: what
      integer, intent(in) :: idx(:)
      integer, intent(in) :: n

      if (size(idx) == 0) return
      if (minval(idx) < 1 .or. maxval(idx) > n) then
         call fail(what // ' must lie in 1..' // int_to_str(n))
      else if (size(idx) > 1) then
         if (any(idx(2:) <= idx(:size(idx) - 1))) call fail(what // ' must be strictly ascending')
      end if
    end subroutine check_indices

  end subroutine field_writer_open

  !> Start a frame (ends the previous one if still open). Collective.
  subroutine field_writer_frame(w, step, step_time, total_time, increment)
    type(field_writer_t), intent(inout) :: w
    integer, intent(in) :: step           !< step index
    real(dp), intent(in) :: step_time
    real(dp), intent(in) :: total_time
    integer, intent(in) :: increment      !< increment number
    integer(hid_t) :: gcpl
    integer :: hdferr
    character(len=6) :: tag

    call require_open(w, 'field_writer_frame')
    if (w%frame_open) call field_writer_end_frame(w)

    write (tag, '(i6.6)') w%n_frames
    ! Creation order is tracked so that a restart lists the fields in the order written,
    ! and the rebuilt XDMF is identical to the one of an uninterrupted run.
    call h5pcreate_f(H5P_GROUP_CREATE_F, gcpl, hdferr)
    call h5pset_link_creation_order_f(gcpl, ior(H5P_CRT_ORDER_TRACKED_F, H5P_CRT_ORDER_INDEXED_F), &
         hdferr)
    call check(hdferr, 'h5pset_link_creation_order')
    call h5gcreate_f(w%file, '/frames/' // tag, w%frame_group, hdferr, gcpl_id=gcpl)
    call check(hdferr, 'creating group /frames/' // tag)
    call h5pclose_f(gcpl, hdferr)
    call write_attr_int(w%frame_group, 'step', step)
    call write_attr_int(w%frame_group, 'increment', increment)
    call write_attr_real(w%frame_group, 'step_time', step_time)
    call write_attr_real(w%frame_group, 'total_time', total_time)

    call grow_frames(w%frames, w%n_frames)
    w%n_frames = w%n_frames + 1
    call new_xdmf_frame(w%frames(w%n_frames), tag, total_time)
    w%frame_open = .true.
  end subroutine field_writer_frame

  !> Finish the open frame: flush the HDF5 file so the frame is on disk, then rewrite the
  !> XDMF so that it lists it. Called by field_writer_frame/close when omitted. Collective.
  subroutine field_writer_end_frame(w, err)
    type(field_writer_t), intent(inout) :: w
    type(error_t), intent(inout), optional :: err
    integer :: hdferr

    call require_open(w, 'field_writer_end_frame')
    if (.not. w%frame_open) return
    call h5gclose_f(w%frame_group, hdferr)
    w%frame_open = .false.
    call h5fflush_f(w%file, H5F_SCOPE_GLOBAL_F, hdferr)
    call check(hdferr, 'flushing the file')
    call rewrite_xdmf(w, err)
  end subroutine field_writer_end_frame

  !> Current node coordinates x(ndim, n_local) of the open frame, written as
  !> /frames/NNNNNN/coordinates (n_nodes, 3); the frame's XDMF geometry then uses them, so
  !> ParaView shows the deformed configuration directly. Without this call a frame is drawn
  !> on the reference mesh (U can still be applied with Warp By Vector). Collective.
  subroutine field_writer_coordinates(w, node_global, node_owned, x, err)
    type(field_writer_t), intent(inout) :: w
    integer, intent(in) :: node_global(:)
    logical, intent(in) :: node_owned(:)
    real(dp), intent(in) :: x(:, :)
    type(error_t), intent(inout), optional :: err
    real(dp), allocatable :: buf(:, :)
    integer, allocatable :: rows(:)
    character(len=:), allocatable :: msg
    logical :: any_failed
    integer(hid_t) :: dset
    integer :: i, k

    call require_frame(w, 'field_writer_coordinates')
    call node_arguments_problem(w, node_global, node_owned, size(x, 2), msg)
    if (.not. allocated(msg) .and. size(x, 1) /= w%ndim) msg = 'x must be (ndim, n_local)'
    call agree_on_error(w%comm, allocated(msg), msg, any_failed)
    if (any_failed) then
       call raise_error(w%h5_path, 0, 'coordinates: ' // msg, err)
       return
    end if
    rows = pack(node_global, node_owned)
    allocate (buf(3, size(rows)))
    buf = 0.0_dp
    k = 0
    do i = 1, size(node_global)
       if (.not. node_owned(i)) cycle
       k = k + 1
       buf(1:w%ndim, k) = x(:, i)
    end do
    call create_dataset(w%frame_group, coordinates_name, H5T_IEEE_F64LE, 3, w%n_nodes, dset)
    call write_attr_string(dset, 'center', 'Node')
    call write_rows_real(w%comm, w%rank, w%nranks, w%xfer, w%h5_path, dset, 3, rows, buf)
    call h5dclose_f(dset, i)
    w%frames(w%n_frames)%geometry = frame_path(w%n_frames - 1) // '/' // coordinates_name
  end subroutine field_writer_coordinates

  !> A node field values(ncomp, n_local) of the open frame; rows written by owners. Collective.
  subroutine field_writer_node_field(w, name, node_global, node_owned, values, err)
    type(field_writer_t), intent(inout) :: w
    character(len=*), intent(in) :: name
    integer, intent(in) :: node_global(:)
    logical, intent(in) :: node_owned(:)
    real(dp), intent(in) :: values(:, :)
    type(error_t), intent(inout), optional :: err
    real(dp), allocatable :: buf(:, :)
    integer, allocatable :: rows(:)
    character(len=:), allocatable :: msg
    integer(hid_t) :: dset
    integer :: i, k, ncomp

    call require_frame(w, 'field_writer_node_field')
    ncomp = size(values, 1)
    call node_arguments_problem(w, node_global, node_owned, size(values, 2), msg)
    if (.not. field_agreed(w, name, ncomp, msg, err)) return

    rows = pack(node_global, node_owned)
    allocate (buf(ncomp, size(rows)))
    k = 0
    do i = 1, size(node_global)
       if (.not. node_owned(i)) cycle
       k = k + 1
       buf(:, k) = values(:, i)
    end do
    call create_dataset(w%frame_group, name, H5T_IEEE_F64LE, ncomp, w%n_nodes, dset)
    call write_attr_string(dset, 'center', 'Node')
    call write_rows_real(w%comm, w%rank, w%nranks, w%xfer, w%h5_path, dset, ncomp, rows, buf)
    call h5dclose_f(dset, i)
    call xdmf_add_attribute(w%frames(w%n_frames), name, frame_path(w%n_frames - 1) // '/' // name, &
         xdmf_center_node, ncomp)
  end subroutine field_writer_node_field

  !> An element field values(n_local_elems, ncomp) (the block layout of the element
  !> arrays) of the open frame. Collective.
  subroutine field_writer_element_field(w, name, elem_global, values, err)
    type(field_writer_t), intent(inout) :: w
    character(len=*), intent(in) :: name
    integer, intent(in) :: elem_global(:)
    real(dp), intent(in) :: values(:, :)
    type(error_t), intent(inout), optional :: err
    real(dp), allocatable :: buf(:, :)
    character(len=:), allocatable :: msg
    integer(hid_t) :: dset
    integer :: ncomp, hdferr

    call require_frame(w, 'field_writer_element_field')
    ncomp = size(values, 2)
    if (size(values, 1) /= size(elem_global)) then
       msg = 'values must be (n_local_elems, ncomp) with n_local_elems = size(elem_global)'
    else if (size(elem_global) > 0) then
       if (minval(elem_global) < 1 .or. maxval(elem_global) > w%n_elems) then
          msg = 'elem_global must lie in 1..' // int_to_str(w%n_elems)
       else if (size(elem_global) > 1) then
          if (any(elem_global(2:) <= elem_global(:size(elem_global) - 1))) &
               msg = 'elem_global must be strictly ascending'
       end if
    end if
    if (.not. field_agreed(w, name, ncomp, msg, err)) return

    ! (element, component) in memory -> (component, element) rows of the file.
    allocate (buf(ncomp, size(elem_global)))
    buf = transpose(values)
    call create_dataset(w%frame_group, name, H5T_IEEE_F64LE, ncomp, w%n_elems, dset)
    call write_attr_string(dset, 'center', 'Cell')
    call write_rows_real(w%comm, w%rank, w%nranks, w%xfer, w%h5_path, dset, ncomp, elem_global, buf)
    call h5dclose_f(dset, hdferr)
    call xdmf_add_attribute(w%frames(w%n_frames), name, frame_path(w%n_frames - 1) // '/' // name, &
         xdmf_center_cell, ncomp)
  end subroutine field_writer_element_field

  !> End the open frame, close the file. Collective. The XDMF is complete afterwards.
  subroutine field_writer_close(w, err)
    type(field_writer_t), intent(inout) :: w
    type(error_t), intent(inout), optional :: err

    if (.not. w%is_open) return
    call hdf5_error_context(w%h5_path)
    if (w%frame_open) call field_writer_end_frame(w, err)
    call close_handles(w)
  end subroutine field_writer_close

  !> Frames written so far (the open one included): what a checkpoint records and
  !> field_writer_open(..., restart_frames=) takes back.
  pure integer function field_writer_frame_count(w)
    type(field_writer_t), intent(in) :: w

    field_writer_frame_count = w%n_frames
  end function field_writer_frame_count

  ! ---------------------------------------------------------------------------------------
  ! Mesh
  ! ---------------------------------------------------------------------------------------

  subroutine write_mesh(w, element_type, node_global, node_owned, node_id, x0, elem_global, &
       elem_id, conn)
    type(field_writer_t), intent(inout) :: w
    integer, intent(in) :: element_type
    integer, intent(in) :: node_global(:)
    logical, intent(in) :: node_owned(:)
    integer, intent(in) :: node_id(:)
    real(dp), intent(in) :: x0(:, :)
    integer, intent(in) :: elem_global(:)
    integer, intent(in) :: elem_id(:)
    integer, intent(in) :: conn(:, :)
    integer(hid_t) :: group, dset, root
    real(dp), allocatable :: xbuf(:, :)
    integer, allocatable :: rows(:), ibuf(:, :)
    integer :: hdferr, i, k

    call h5gopen_f(w%file, '/', root, hdferr)
    call write_attr_string(root, 'format', 'bulkflow-fields')
    call write_attr_int(root, 'format_version', format_version)
    call h5gclose_f(root, hdferr)

    call h5gcreate_f(w%file, '/mesh', group, hdferr)
    call check(hdferr, 'creating /mesh')
    call write_attr_int(group, 'ndim', w%ndim)
    call write_attr_int(group, 'nen', w%nen)
    if (element_type == element_cpe4r) then
       call write_attr_string(group, 'element_type', 'CPE4R')
    else if (element_type == element_cax4r) then
       call write_attr_string(group, 'element_type', 'CAX4R')
    else
       call write_attr_string(group, 'element_type', 'C3D8R')
    end if

    rows = pack(node_global, node_owned)
    allocate (xbuf(3, size(rows)), ibuf(1, size(rows)))
    xbuf = 0.0_dp       ! z = 0 in 2D: ParaView wants XYZ
    k = 0
    do i = 1, size(node_global)
       if (.not. node_owned(i)) cycle
       k = k + 1
       xbuf(1:w%ndim, k) = x0(:, i)
       ibuf(1, k) = node_id(i)
    end do
    call create_dataset(group, 'coordinates', H5T_IEEE_F64LE, 3, w%n_nodes, dset)
    call write_rows_real(w%comm, w%rank, w%nranks, w%xfer, w%h5_path, dset, 3, rows, xbuf)
    call h5dclose_f(dset, hdferr)
    call create_dataset(group, 'node_id', H5T_STD_I32LE, 1, w%n_nodes, dset)
    call write_rows_int(w%comm, w%rank, w%nranks, w%xfer, w%h5_path, dset, 1, rows, ibuf)
    call h5dclose_f(dset, hdferr)
    deallocate (ibuf)

    allocate (ibuf(w%nen, size(elem_global)))
    ibuf = conn - 1         ! XDMF topologies index nodes from 0
    call create_dataset(group, 'connectivity', H5T_STD_I32LE, w%nen, w%n_elems, dset)
    call write_rows_int(w%comm, w%rank, w%nranks, w%xfer, w%h5_path, dset, w%nen, elem_global, ibuf)
    call h5dclose_f(dset, hdferr)
    deallocate (ibuf)
    allocate (ibuf(1, size(elem_global)))
    ibuf(1, :) = elem_id
    call create_dataset(group, 'element_id', H5T_STD_I32LE, 1, w%n_elems, dset)
    call write_rows_int(w%comm, w%rank, w%nranks, w%xfer, w%h5_path, dset, 1, elem_global, ibuf)
    call h5dclose_f(dset, hdferr)
    call h5gclose_f(group, hdferr)

    call h5gcreate_f(w%file, '/frames', group, hdferr)
    call check(hdferr, 'creating /frames')
    call h5gclose_f(group, hdferr)
  end subroutine write_mesh


  !> Rank 0 writes the XDMF of the completed frames; the outcome is shared with all ranks.
  subroutine rewrite_xdmf(w, err)
    type(field_writer_t), intent(inout) :: w
    type(error_t), intent(inout), optional :: err
    logical :: ok
    integer :: n_done

    ok = .true.
    if (w%rank == 0) then
       n_done = w%n_frames
       if (w%frame_open) n_done = n_done - 1
       call xdmf_write(w%xmf_path, w%mesh, w%frames, n_done, ok)
    end if
    call MPI_Bcast(ok, 1, MPI_LOGICAL, 0, w%comm)
    if (.not. ok) call raise_error(w%xmf_path, 0, 'cannot write the XDMF file', err)
  end subroutine rewrite_xdmf

  !> Problems with the node arguments of a field call on this rank (msg unallocated: none).
  !> A subroutine, not a function: assigning an unallocated function result is undefined.
  subroutine node_arguments_problem(w, node_global, node_owned, n_values, msg)
    type(field_writer_t), intent(in) :: w
    integer, intent(in) :: node_global(:)
    logical, intent(in) :: node_owned(:)
    integer, intent(in) :: n_values
    character(len=:), allocatable, intent(out) :: msg

    if (size(node_owned) /= size(node_global) .or. n_values /= size(node_global)) then
       msg = 'node_global, node_owned and the columns of values must have the same length'
    else if (size(node_global) > 0) then
       if (minval(node_global) < 1 .or. maxval(node_global) > w%n_nodes) then
          msg = 'node_global must lie in 1..' // int_to_str(w%n_nodes)
       else if (size(node_global) > 1) then
          if (any(node_global(2:) <= node_global(:size(node_global) - 1))) &
               msg = 'node_global must be strictly ascending'
       end if
    end if
  end subroutine node_arguments_problem

  !> Common checks of a field call, agreed by all ranks: the local argument problem `msg`,
  !> a valid and new name, the same component count everywhere. False after raising.
  logical function field_agreed(w, name, ncomp, msg, err) result(ok)
    type(field_writer_t), intent(in) :: w
    character(len=*), intent(in) :: name
    integer, intent(in) :: ncomp
    character(len=:), allocatable, intent(inout) :: msg
    type(error_t), intent(inout), optional :: err
    integer :: comps(2), hdferr
    logical :: any_failed, exists

    if (.not. allocated(msg)) then
       if (len_trim(name) == 0 .or. len_trim(name) /= len(name) .or. scan(name, '/.') > 0) then
          msg = 'invalid field name "' // name // '"'
       else if (name == coordinates_name) then
          msg = 'the name "' // coordinates_name // '" is reserved for field_writer_coordinates'
       else if (ncomp < 1) then
          msg = 'a field needs at least one component'
       end if
    end if
    call agree_on_error(w%comm, allocated(msg), msg, any_failed)
    if (.not. any_failed) then
       comps = [ncomp, -ncomp]
       call MPI_Allreduce(MPI_IN_PLACE, comps, 2, MPI_INTEGER, MPI_MAX, w%comm)
       if (comps(1) /= -comps(2)) then
          msg = 'ranks disagree on the number of components (' // int_to_str(-comps(2)) // &
               ' to ' // int_to_str(comps(1)) // ')'
          any_failed = .true.
       else
          call h5lexists_f(w%frame_group, name, exists, hdferr)
          if (exists) then
             msg = 'field written twice in one frame'
             any_failed = .true.
          end if
       end if
    end if
    ok = .not. any_failed
    if (.not. ok) call raise_error(w%h5_path, 0, 'field "' // &
         name // '": ' // msg, err)
  end function field_agreed

  subroutine close_handles(w)
    type(field_writer_t), intent(inout) :: w
    integer :: hdferr

    if (w%frame_open) call h5gclose_f(w%frame_group, hdferr)
    w%frame_open = .false.
    call h5pclose_f(w%xfer, hdferr)
    call h5fclose_f(w%file, hdferr)
    call check(hdferr, 'closing the file')
    w%is_open = .false.
  end subroutine close_handles

  subroutine require_open(w, what)
    type(field_writer_t), intent(in) :: w
    character(len=*), intent(in) :: what

    if (.not. w%is_open) call raise_error(what, 0, 'the field writer is not open')
    call hdf5_error_context(w%h5_path)
  end subroutine require_open

  subroutine require_frame(w, what)
    type(field_writer_t), intent(in) :: w
    character(len=*), intent(in) :: what

    call require_open(w, what)
    if (.not. w%frame_open) call raise_error(what, 0, 'no frame is open ' // &
         '(call field_writer_frame first)')
  end subroutine require_frame

end module output_hdf5
