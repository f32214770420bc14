!> Field output of a point cloud moving through a uniform background grid (the particles of a
!> material-point run): one HDF5 file written collectively by all ranks through MPI-IO, as the
!> element field file (output_hdf5), with the same row transfer (output_hdf5_rows), the same
!> HDF5 primitives (output_hdf5_basics), the same restart rule for frames (output_hdf5_frames)
!> and the same XDMF writer (output_xdmf, topologies Polyvertex and 3DCoRectMesh).
!>
!> Layout (shapes as h5py shows them; docs/output_format.md, "Material-point (MPM) runs"):
!>   /                      attribute format (the caller's name, e.g. "bulkflow-mpm")
!>   /grid                  attributes ndim, n (nodes per direction, 3), lo (3), h
!>   /particles/NNNNNN      one group per frame, attributes step, increment, count (int32),
!>                          step_time, total_time (1-element arrays); point fields (count, ncomp)
!>                          or (count,), rows = the points of rank 0, then rank 1, ... each in
!>                          the order the rank passes them (so the file is the one a gather
!>                          to rank 0 in rank order would write)
!>   /grid/NNNNNN           grid fields (nz, ny, nx[, ncomp]) of the frame, written by rank 0
!>                          (every rank holds the whole grid)
!>   BASE.xmf               the points: one Polyvertex grid per frame
!>   BASE_grid.xmf          the grid: one 3DCoRectMesh per frame
!> Which fields the XDMF files show is fixed when the file is opened (every frame has them),
!> so a restart rebuilds the XDMF from the frames' counts and times alone.
!>
!> Every routine is collective over the writer's communicator.
module output_points
  use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Allreduce, MPI_Exscan, MPI_Bcast, &
       MPI_INTEGER, MPI_LOGICAL, MPI_SUM, MPI_INFO_NULL
  use hdf5
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use output_files, only: base_name, file_exists
  use output_collective, only: agree_on_error
  use output_xdmf, only: xdmf_mesh_t, xdmf_frame_t, xdmf_write, xdmf_add_attribute, xdmf_center_node
  use output_hdf5_basics, only: hdf5_error_context, check, collective_transfer, create_shaped_dataset, &
       write_attr_string, write_attr_ints, write_attr_reals, read_attr_ints, read_attr_reals
  use output_hdf5_rows, only: write_rows_real, write_rows_int, write_whole_real, write_box_real
  use output_hdf5_frames, only: frame_sequence, grow_frames
  implicit none
  private

  public :: point_writer_t, point_writer_open, point_writer_frame, point_writer_field, &
       point_writer_scalar, point_writer_ints, point_writer_grid_field, point_writer_end_frame, &
       point_writer_close, point_writer_frame_count

  !> Names of the XDMF attributes and their component counts.
  type :: shown_t
     character(len=:), allocatable :: name
     integer :: ncomp = 1
  end type shown_t

  !> An open point file. Components are private: use the procedures.
  type :: point_writer_t
     private
     type(MPI_Comm) :: comm
     integer :: rank = 0
     integer :: nranks = 1
     character(len=:), allocatable :: h5_path, xmf_path, grid_xmf_path
     integer(hid_t) :: file = -1
     integer(hid_t) :: xfer = -1
     integer(hid_t) :: points = -1          !< the open frame's /particles/NNNNNN
     integer(hid_t) :: grid = -1            !< the open frame's /grid/NNNNNN
     logical :: frame_open = .false.
     integer :: n_frames = 0                !< frames completed
     integer :: n_local = 0                 !< this rank's points in the open frame
     integer :: first = 0                   !< rows before this rank's (open frame)
     type(xdmf_mesh_t) :: point_mesh, grid_mesh
     type(xdmf_frame_t), allocatable :: frames(:), grid_frames(:)
     type(shown_t), allocatable :: shown(:), grid_shown(:)
  end type point_writer_t

contains

  !> Create `<path_base>.h5`, `.xmf` and `_grid.xmf` (or with restart_frames reopen them, check
  !> the grid and keep that many frames). ndim, n (nodes per direction, 1 in the missing
  !> ones), lo and h describe the grid; shown/shown_ncomp and grid_shown/grid_shown_ncomp the
  !> fields the XDMF files show. A problem goes to err when given, else stops.
  subroutine point_writer_open(w, path_base, comm, format, ndim, n, lo, h, shown, shown_ncomp, &
       grid_shown, grid_shown_ncomp, restart_frames, err)
    type(point_writer_t), intent(out) :: w
    character(len=*), intent(in) :: path_base
    type(MPI_Comm), intent(in) :: comm
    character(len=*), intent(in) :: format
    integer, intent(in) :: ndim
    integer, intent(in) :: n(3)
    real(dp), intent(in) :: lo(3)
    real(dp), intent(in) :: h
    character(len=*), intent(in) :: shown(:)
    integer, intent(in) :: shown_ncomp(:)
    character(len=*), intent(in) :: grid_shown(:)
    integer, intent(in) :: grid_shown_ncomp(:)
    integer, intent(in), optional :: restart_frames
    type(error_t), intent(inout), optional :: err
    integer(hid_t) :: fapl, grp
    integer :: hdferr, i
    character(len=:), allocatable :: msg
    logical :: any_failed

    call MPI_Comm_rank(comm, w%rank)
    call MPI_Comm_size(comm, w%nranks)
    w%comm = comm
    w%h5_path = path_base // '.h5'
    w%xmf_path = path_base // '.xmf'
    w%grid_xmf_path = path_base // '_grid.xmf'
    allocate (w%shown(size(shown)), w%grid_shown(size(grid_shown)))
    do i = 1, size(shown)
       w%shown(i)%name = trim(shown(i))
       w%shown(i)%ncomp = shown_ncomp(i)
    end do
    do i = 1, size(grid_shown)
       w%grid_shown(i)%name = trim(grid_shown(i))
       w%grid_shown(i)%ncomp = grid_shown_ncomp(i)
    end do
    w%point_mesh%h5_file = base_name(w%h5_path)
    w%point_mesh%topology = 'Polyvertex'
    w%point_mesh%collection = 'particles'
    w%grid_mesh%h5_file = w%point_mesh%h5_file
    w%grid_mesh%topology = '3DCoRectMesh'
    w%grid_mesh%collection = 'grid'
    w%grid_mesh%grid_n = n
    w%grid_mesh%origin = lo
    w%grid_mesh%spacing = h
    allocate (w%frames(16), w%grid_frames(16))

    call hdf5_error_context(w%h5_path)
    call h5open_f(hdferr)
    call check(hdferr, 'h5open')
    call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, hdferr)
    call h5pset_fapl_mpio_f(fapl, comm%MPI_VAL, MPI_INFO_NULL%MPI_VAL, hdferr)
    call check(hdferr, 'h5pset_fapl_mpio')
    if (present(restart_frames)) then
       call reopen(w, fapl, ndim, n, lo, h, restart_frames, msg)
       call agree_on_error(comm, allocated(msg), msg, any_failed)
       if (any_failed) then
          call h5pclose_f(fapl, hdferr)
          call point_writer_close(w)
          call raise_error(w%h5_path, 0, msg, err)
          return
       end if
    else
       call h5fcreate_f(w%h5_path, H5F_ACC_TRUNC_F, w%file, hdferr, access_prp=fapl)
       call check(hdferr, 'creating the file')
       call write_attr_string(w%file, 'format', format)
       call h5gcreate_f(w%file, 'particles', grp, hdferr)
       call check(hdferr, 'creating group /particles')
       call h5gclose_f(grp, hdferr)
       call h5gcreate_f(w%file, 'grid', grp, hdferr)
       call check(hdferr, 'creating group /grid')
       call write_attr_ints(grp, 'ndim', [ndim])
       call write_attr_ints(grp, 'n', n)
       call write_attr_reals(grp, 'lo', lo)
       call write_attr_reals(grp, 'h', [h])
       call h5gclose_f(grp, hdferr)
    end if
    call h5pclose_f(fapl, hdferr)
    call collective_transfer(w%xfer)
    call h5fflush_f(w%file, H5F_SCOPE_GLOBAL_F, hdferr)
    call rewrite_xdmf(w, err)
  end subroutine point_writer_open

  !> Start a frame of the points this rank holds (n_local of them). Collective.
  subroutine point_writer_frame(w, step, increment, step_time, total_time, n_local)
    type(point_writer_t), intent(inout) :: w
    integer, intent(in) :: step
    integer, intent(in) :: increment
    real(dp), intent(in) :: step_time
    real(dp), intent(in) :: total_time
    integer, intent(in) :: n_local
    integer :: hdferr, total
    character(len=6) :: tag

    if (w%frame_open) call point_writer_end_frame(w)
    call hdf5_error_context(w%h5_path)
    w%n_local = n_local
    w%first = 0
    call MPI_Exscan(n_local, w%first, 1, MPI_INTEGER, MPI_SUM, w%comm)
    if (w%rank == 0) w%first = 0
    call MPI_Allreduce(n_local, total, 1, MPI_INTEGER, MPI_SUM, w%comm)
    write (tag, '(i6.6)') w%n_frames
    call h5gcreate_f(w%file, 'particles/' // tag, w%points, hdferr)
    call check(hdferr, 'creating frame /particles/' // tag)
    call write_attr_ints(w%points, 'step', [step])
    call write_attr_ints(w%points, 'increment', [increment])
    call write_attr_ints(w%points, 'count', [total])
    call write_attr_reals(w%points, 'step_time', [step_time])
    call write_attr_reals(w%points, 'total_time', [total_time])
    call h5gcreate_f(w%file, 'grid/' // tag, w%grid, hdferr)
    call check(hdferr, 'creating frame /grid/' // tag)
    call add_frame(w, tag, total, total_time)
    w%frame_open = .true.
  end subroutine point_writer_frame

  !> A point field values(ncomp, n_local) of the open frame: dataset (count, ncomp), 2-D also
  !> for one component unless one_dimensional (then (count,)).
  subroutine point_writer_field(w, name, values, one_dimensional)
    type(point_writer_t), intent(inout) :: w
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:, :)
    logical, intent(in), optional :: one_dimensional
    integer(hid_t) :: dset
    integer :: hdferr
    logical :: flat

    flat = .false.
    if (present(one_dimensional)) flat = one_dimensional
    if (flat) then
       call create_shaped_dataset(w%points, name, H5T_IEEE_F64LE, [int(total_rows(w), hsize_t)], dset)
    else
       call create_shaped_dataset(w%points, name, H5T_IEEE_F64LE, &
            [int(size(values, 1), hsize_t), int(total_rows(w), hsize_t)], dset)
    end if
    call write_rows_real(w%comm, w%rank, w%nranks, w%xfer, w%h5_path, dset, size(values, 1), &
         local_rows(w), values)
    call h5dclose_f(dset, hdferr)
  end subroutine point_writer_field

  !> A one-value point field values(n_local): dataset (count,).
  subroutine point_writer_scalar(w, name, values)
    type(point_writer_t), intent(inout) :: w
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:)

    call point_writer_field(w, name, reshape(values, [1, size(values)]), one_dimensional=.true.)
  end subroutine point_writer_scalar

  !> An integer point field values(n_local): dataset (count,) int32.
  subroutine point_writer_ints(w, name, values)
    type(point_writer_t), intent(inout) :: w
    character(len=*), intent(in) :: name
    integer, intent(in) :: values(:)
    integer(hid_t) :: dset
    integer :: hdferr

    call create_shaped_dataset(w%points, name, H5T_STD_I32LE, [int(total_rows(w), hsize_t)], dset)
    call write_rows_int(w%comm, w%rank, w%nranks, w%xfer, w%h5_path, dset, 1, local_rows(w), &
         reshape(values, [1, size(values)]))
    call h5dclose_f(dset, hdferr)
  end subroutine point_writer_ints

  !> A nodal field of the grid, values(ncomp * nodes) with the components fastest, then x, y, z
  !> (rank 0 writes the whole grid, or each rank its box): dataset (nz, ny, nx[, ncomp]).
  subroutine point_writer_grid_field(w, name, values, ncomp, box_offset, box_count)
    type(point_writer_t), intent(inout) :: w
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:)
    integer, intent(in) :: ncomp
    !> with these, values is this rank's box of nodes (write_box_real); without, rank 0's
    !> values are the whole grid
    integer, intent(in), optional :: box_offset(3), box_count(3)
    integer(hsize_t), allocatable :: dims(:)
    integer(hid_t) :: dset
    integer :: hdferr

    ! allocate(source=): gfortran 12 at -O0 takes an assignment into an unallocated array for
    ! a read of its bounds (maybe-uninitialized under -Werror)
    if (ncomp == 1) then
       allocate (dims, source=int(w%grid_mesh%grid_n, hsize_t))
    else
       allocate (dims, source=[int(ncomp, hsize_t), int(w%grid_mesh%grid_n, hsize_t)])
    end if
    call create_shaped_dataset(w%grid, name, H5T_IEEE_F64LE, dims, dset)
    if (present(box_offset) .and. present(box_count)) then
       call write_box_real(w%xfer, dset, values, ncomp, box_offset, box_count)
    else
       call write_whole_real(w%xfer, dset, values, w%rank == 0)
    end if
    call h5dclose_f(dset, hdferr)
  end subroutine point_writer_grid_field

  !> Finish the open frame: flush the file, then rewrite the XDMF files to list it.
  subroutine point_writer_end_frame(w, err)
    type(point_writer_t), intent(inout) :: w
    type(error_t), intent(inout), optional :: err
    integer :: hdferr

    if (.not. w%frame_open) return
    call h5gclose_f(w%points, hdferr)
    call h5gclose_f(w%grid, hdferr)
    w%frame_open = .false.
    w%n_frames = w%n_frames + 1
    call h5fflush_f(w%file, H5F_SCOPE_GLOBAL_F, hdferr)
    call check(hdferr, 'flushing the file')
    call rewrite_xdmf(w, err)
  end subroutine point_writer_end_frame

  !> Frames completed so far (what a checkpoint records).
  pure integer function point_writer_frame_count(w)
    type(point_writer_t), intent(in) :: w

    point_writer_frame_count = w%n_frames
  end function point_writer_frame_count

  subroutine point_writer_close(w)
    type(point_writer_t), intent(inout) :: w
    integer :: hdferr

    if (w%file == -1) return
    call point_writer_end_frame(w)
    if (w%xfer /= -1) call h5pclose_f(w%xfer, hdferr)
    call h5fclose_f(w%file, hdferr)
    w%file = -1
    w%xfer = -1
  end subroutine point_writer_close

  ! ---------------------------------------------------------------------------------------

  pure integer function total_rows(w)
    type(point_writer_t), intent(in) :: w

    total_rows = w%frames(w%n_frames + 1)%n_points
  end function total_rows

  !> Global 1-based rows of this rank's points: after those of the lower ranks.
  pure function local_rows(w) result(rows)
    type(point_writer_t), intent(in) :: w
    integer :: rows(w%n_local)
    integer :: k

    rows = [(w%first + k, k = 1, w%n_local)]
  end function local_rows

  !> The XDMF descriptions of frame `tag` (0-based index n_frames): points and grid.
  subroutine add_frame(w, tag, count, time)
    type(point_writer_t), intent(inout) :: w
    character(len=*), intent(in) :: tag
    integer, intent(in) :: count
    real(dp), intent(in) :: time
    integer :: i, f

    f = w%n_frames + 1
    call grow_frames(w%frames, w%n_frames)
    call grow_frames(w%grid_frames, w%n_frames)
    associate (p => w%frames(f), g => w%grid_frames(f))
      p%name = 'particles_' // tag
      p%time = time
      p%n_points = count
      p%geometry = '/particles/' // tag // '/coordinates'
      p%n_attributes = 0
      do i = 1, size(w%shown)
         call xdmf_add_attribute(p, w%shown(i)%name, '/particles/' // tag // '/' // w%shown(i)%name, &
              xdmf_center_node, w%shown(i)%ncomp)
      end do
      g%name = 'grid_' // tag
      g%time = time
      g%geometry = ''
      g%n_attributes = 0
      do i = 1, size(w%grid_shown)
         call xdmf_add_attribute(g, w%grid_shown(i)%name, '/grid/' // tag // '/' // w%grid_shown(i)%name, &
              xdmf_center_node, w%grid_shown(i)%ncomp)
      end do
    end associate
  end subroutine add_frame

  !> Rank 0 rewrites both XDMF files for the completed frames.
  subroutine rewrite_xdmf(w, err)
    type(point_writer_t), intent(inout) :: w
    type(error_t), intent(inout), optional :: err
    logical :: ok, ok_grid

    ok = .true.
    ok_grid = .true.
    if (w%rank == 0) then
       call xdmf_write(w%xmf_path, w%point_mesh, w%frames, w%n_frames, ok)
       call xdmf_write(w%grid_xmf_path, w%grid_mesh, w%grid_frames, w%n_frames, ok_grid)
       ok = ok .and. ok_grid
    end if
    call MPI_Bcast(ok, 1, MPI_LOGICAL, 0, w%comm)
    if (.not. ok) call raise_error(w%xmf_path, 0, 'cannot write the XDMF files', err)
  end subroutine rewrite_xdmf

  !> Reopen the file of an interrupted run: its grid must be the scene's; keep frames
  !> 0..keep-1, delete later ones (written after the checkpoint) and rebuild the XDMF frame
  !> lists from the kept frames' counts and times. msg is allocated when it cannot serve.
  subroutine reopen(w, fapl, ndim, n, lo, h, keep, msg)
    type(point_writer_t), intent(inout) :: w
    integer(hid_t), intent(in) :: fapl
    integer, intent(in) :: ndim, n(3)
    real(dp), intent(in) :: lo(3), h
    integer, intent(in) :: keep
    character(len=:), allocatable, intent(out) :: msg
    integer(hid_t) :: parts, grid, frame
    integer :: hdferr, f, n_found, f_ndim(1), f_n(3), count(1)
    real(dp) :: f_lo(3), f_h(1), time(1)
    character(len=6) :: tag
    character(len=96) :: text
    logical :: exists

    if (.not. file_exists(w%h5_path)) then
       msg = 'cannot restart: the file does not exist'
       return
    end if
    ! A file that is not HDF5 is reported by us, not by HDF5's error stack on stderr.
    call h5eset_auto_f(0, hdferr)
    call h5fopen_f(w%h5_path, H5F_ACC_RDWR_F, w%file, hdferr, access_prp=fapl)
    if (hdferr < 0) then
       w%file = -1
       call h5eset_auto_f(1, hdferr)
       msg = 'cannot restart: the file cannot be opened as an HDF5 file'
       return
    end if
    call h5lexists_f(w%file, 'grid', exists, hdferr)
    if (exists) call h5lexists_f(w%file, 'particles', exists, hdferr)
    call h5eset_auto_f(1, hdferr)
    if (.not. exists .or. hdferr < 0) then
       msg = 'cannot restart: not the field output of a material-point run (no /grid, /particles)'
       return
    end if
    call h5gopen_f(w%file, 'grid', grid, hdferr)
    call check(hdferr, 'opening /grid')
    call read_attr_ints(grid, 'ndim', f_ndim)
    call read_attr_ints(grid, 'n', f_n)
    call read_attr_reals(grid, 'lo', f_lo)
    call read_attr_reals(grid, 'h', f_h)
    if (f_ndim(1) /= ndim .or. any(f_n /= n) .or. any(abs(f_lo - lo) > 0) .or. abs(f_h(1) - h) > 0) then
       write (text, '(i0,a,i0,a,i0,a,es12.5)') f_n(1), ' x ', f_n(2), ' x ', f_n(3), ' nodes, cell ', f_h(1)
       msg = 'cannot restart: the file holds a grid of ' // trim(text)
       write (text, '(i0,a,i0,a,i0,a,es12.5)') n(1), ' x ', n(2), ' x ', n(3), ' nodes, cell ', h
       msg = msg // '; expected the scene''s grid of ' // trim(text)
       call h5gclose_f(grid, hdferr)
       return
    end if
    call h5gopen_f(w%file, 'particles', parts, hdferr)
    call check(hdferr, 'opening /particles')
    call frame_sequence(parts, '/particles', keep, n_found, msg)
    if (allocated(msg)) then
       if (index(msg, 'cannot restart') /= 1) msg = 'cannot restart: ' // msg
       call h5gclose_f(parts, hdferr)
       call h5gclose_f(grid, hdferr)
       return
    end if
    ! Frames written after the checkpoint by the interrupted run go; the restarted run writes
    ! them again.
    do f = keep, n_found - 1
       write (tag, '(i6.6)') f
       call h5ldelete_f(parts, tag, hdferr)
       call check(hdferr, 'deleting frame /particles/' // tag)
       call h5lexists_f(grid, tag, exists, hdferr)
       if (exists) call h5ldelete_f(grid, tag, hdferr)
       call check(hdferr, 'deleting frame /grid/' // tag)
    end do
    w%n_frames = 0
    do f = 0, keep - 1
       write (tag, '(i6.6)') f
       call h5gopen_f(parts, tag, frame, hdferr)
       call check(hdferr, 'opening frame /particles/' // tag)
       call read_attr_ints(frame, 'count', count)
       call read_attr_reals(frame, 'total_time', time)
       call h5gclose_f(frame, hdferr)
       call add_frame(w, tag, count(1), time(1))
       w%n_frames = w%n_frames + 1
    end do
    call h5gclose_f(parts, hdferr)
    call h5gclose_f(grid, hdferr)
  end subroutine reopen

end module output_points
