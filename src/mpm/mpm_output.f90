!> Field output of a material-point run: the particles (and the grid's nodal mass and velocity)
!> in one HDF5 file, with XDMF companions so ParaView shows the particles as points.
!>
!>   BASE.h5   /particles/NNNNNN   one group per frame, attributes step (int), increment (int),
!>                                 step_time, total_time, count (int); datasets (rows = particles,
!>                                 shapes as h5py shows them): coordinates (n, 3) (z = 0 in 2D),
!>                                 V (n, 3), S (n, ncomp) global Cauchy stress in VUMAT order,
!>                                 LE (n, ncomp), density (n), mass (n), volume (n), id (n) int32,
!>                                 material (n) int32 (1-based *MATERIAL order), SDV (n, nsdv)
!>             /grid               attributes ndim, n (3), lo (3), h
!>             /grid/NNNNNN        mass (nz, ny, nx), V (nz, ny, nx, 3) of the frame's increment
!>                                 (nz = 1 in 2D), after the walls
!>   BASE.xmf       particles: one Polyvertex grid per frame (temporal collection)
!>   BASE_grid.xmf  background grid: CoRectMesh with nodal mass and V
!>
!> Serial (rank 0 writes what it gathered): plain HDF5 calls, no MPI-IO.
!>
!> Restart (mpm_checkpoint): mpm_writer_open(..., restart_frames=n) reopens BASE.h5, checks its
!> grid against the scene's, keeps frames 0..n-1, deletes later ones (written by the
!> interrupted run after its checkpoint) and rewrites the XDMF files from what it kept.
module mpm_output
  use, intrinsic :: iso_fortran_env, only: int32
  use hdf5
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use output_files, only: file_exists, int_to_str
  use output_hdf5, only: frame_sequence
  use mpm_particles, only: particle_block_t
  use mpm_grid, only: grid_t
  implicit none
  private

  type, public :: mpm_writer_t
     private
     character(len=:), allocatable :: base, h5_name
     integer(hid_t) :: file = -1
     integer :: n_frames = 0
     integer :: ndim = 0, ncomp = 0, nsdv = 0
     integer, allocatable :: counts(:)
     real(dp), allocatable :: times(:)
  end type mpm_writer_t

  public :: mpm_writer_open, mpm_writer_frame, mpm_writer_close, mpm_writer_frame_count

contains

  subroutine check(hdferr, what)
    integer, intent(in) :: hdferr
    character(len=*), intent(in) :: what
    if (hdferr < 0) call raise_error('', 0, 'HDF5 error while ' // what)
  end subroutine check

  !> Create BASE.h5 (or, with restart_frames, reopen it keeping that many frames; a problem
  !> then goes to err when given, else stops).
  subroutine mpm_writer_open(wr, base, g, ncomp, nsdv, restart_frames, err)
    type(mpm_writer_t), intent(out) :: wr
    character(len=*), intent(in) :: base
    type(grid_t), intent(in) :: g
    integer, intent(in) :: ncomp, nsdv
    integer, intent(in), optional :: restart_frames
    type(error_t), intent(inout), optional :: err
    integer :: hdferr
    integer(hid_t) :: grp
    character(len=:), allocatable :: msg

    wr%base = base
    wr%h5_name = base // '.h5'
    wr%ndim = g%ndim
    wr%ncomp = ncomp
    wr%nsdv = nsdv
    allocate (wr%counts(0), wr%times(0))
    call h5open_f(hdferr)
    call check(hdferr, 'opening the HDF5 library')
    if (present(restart_frames)) then
       call reopen(wr, g, restart_frames, msg)
       if (allocated(msg)) then
          call mpm_writer_close(wr)
          call raise_error(wr%h5_name, 0, msg, err)
          return
       end if
       call write_xdmf(wr, g)
       return
    end if
    call h5fcreate_f(wr%h5_name, H5F_ACC_TRUNC_F, wr%file, hdferr)
    call check(hdferr, 'creating ' // wr%h5_name)
    call write_attr_string(wr%file, 'format', 'bulkflow-mpm')
    call h5gcreate_f(wr%file, 'particles', grp, hdferr)
    call h5gclose_f(grp, hdferr)
    call h5gcreate_f(wr%file, 'grid', grp, hdferr)
    call write_attr_int(grp, 'ndim', [g%ndim])
    call write_attr_int(grp, 'n', g%n)
    call write_attr_real(grp, 'lo', g%lo)
    call write_attr_real(grp, 'h', [g%h])
    call h5gclose_f(grp, hdferr)
  end subroutine mpm_writer_open

  !> One frame: every particle of every block (in block order) and the grid.
  subroutine mpm_writer_frame(wr, blocks, nblocks, g, step, increment, step_time, total_time)
    type(mpm_writer_t), intent(inout) :: wr
    type(particle_block_t), intent(in) :: blocks(:)
    integer, intent(in) :: nblocks
    type(grid_t), intent(in) :: g
    integer, intent(in) :: step, increment
    real(dp), intent(in) :: step_time, total_time
    character(len=6) :: tag
    integer(hid_t) :: grp
    integer :: hdferr, n, ib, p, r, nd, nsv
    real(dp), allocatable :: xyz(:, :), vel(:, :), s(:, :), le(:, :), dens(:), mass(:), vol(:), sdv(:, :)
    real(dp), allocatable :: gv(:, :)
    integer(int32), allocatable :: id(:), mat(:)
    real(dp) :: detf
    integer, allocatable :: grown_i(:)
    real(dp), allocatable :: grown_r(:)

    nd = wr%ndim
    n = sum(blocks(1:nblocks)%count)
    allocate (xyz(3, n), vel(3, n), s(wr%ncomp, n), le(wr%ncomp, n), dens(n), mass(n), vol(n), &
         sdv(max(1, wr%nsdv), n), id(n), mat(n))
    xyz = 0
    vel = 0
    sdv = 0
    r = 0
    do ib = 1, nblocks
       associate (b => blocks(ib))
         nsv = min(size(b%state, 2), wr%nsdv)
         do p = 1, b%count
            r = r + 1
            xyz(1:nd, r) = b%x(p, :)
            vel(1:nd, r) = b%v(p, :)
            s(:, r) = b%stress_global(p, :)
            le(:, r) = b%log_strain(p, :)
            if (nd == 2) then
               detf = b%f(p, 1, 1) * b%f(p, 2, 2) - b%f(p, 1, 2) * b%f(p, 2, 1)
            else
               detf = b%f(p, 1, 1) * (b%f(p, 2, 2) * b%f(p, 3, 3) - b%f(p, 2, 3) * b%f(p, 3, 2)) &
                    - b%f(p, 1, 2) * (b%f(p, 2, 1) * b%f(p, 3, 3) - b%f(p, 2, 3) * b%f(p, 3, 1)) &
                    + b%f(p, 1, 3) * (b%f(p, 2, 1) * b%f(p, 3, 2) - b%f(p, 2, 2) * b%f(p, 3, 1))
            end if
            vol(r) = b%vol0(p) * detf
            mass(r) = b%mass(p)
            dens(r) = b%mass(p) / vol(r)
            if (nsv > 0) sdv(1:nsv, r) = b%state(p, 1:nsv)
            id(r) = b%number(p)
            mat(r) = b%material
         end do
       end associate
    end do
    write (tag, '(i6.6)') wr%n_frames
    call h5gcreate_f(wr%file, 'particles/' // tag, grp, hdferr)
    call check(hdferr, 'creating frame ' // tag)
    call write_attr_int(grp, 'step', [step])
    call write_attr_int(grp, 'increment', [increment])
    call write_attr_int(grp, 'count', [n])
    call write_attr_real(grp, 'step_time', [step_time])
    call write_attr_real(grp, 'total_time', [total_time])
    call write_r2(grp, 'coordinates', xyz)
    call write_r2(grp, 'V', vel)
    call write_r2(grp, 'S', s)
    call write_r2(grp, 'LE', le)
    call write_r1(grp, 'density', dens)
    call write_r1(grp, 'mass', mass)
    call write_r1(grp, 'volume', vol)
    if (wr%nsdv > 0) call write_r2(grp, 'SDV', sdv)
    call write_i1(grp, 'id', id)
    call write_i1(grp, 'material', mat)
    call h5gclose_f(grp, hdferr)
    ! grid
    allocate (gv(3, g%nn))
    gv = 0
    gv(1:nd, :) = g%v_new
    call h5gcreate_f(wr%file, 'grid/' // tag, grp, hdferr)
    ! shaped like the grid ((nz,) ny, nx[, 3] as h5py shows them) so the XDMF CoRectMesh reads them
    call write_shaped(grp, 'mass', g%mass, [integer(hsize_t) :: g%n])
    call write_shaped(grp, 'V', reshape(gv, [3 * g%nn]), [integer(hsize_t) :: 3, g%n])
    call h5gclose_f(grp, hdferr)
    call h5fflush_f(wr%file, H5F_SCOPE_GLOBAL_F, hdferr)
    wr%n_frames = wr%n_frames + 1
    grown_i = [wr%counts, n]
    call move_alloc(grown_i, wr%counts)
    grown_r = [wr%times, total_time]
    call move_alloc(grown_r, wr%times)
    call write_xdmf(wr, g)
  end subroutine mpm_writer_frame

  !> Frames written so far (what a checkpoint records).
  pure integer function mpm_writer_frame_count(wr)
    type(mpm_writer_t), intent(in) :: wr
    mpm_writer_frame_count = wr%n_frames
  end function mpm_writer_frame_count

  !> Reopen the file of an interrupted run and keep its first `keep` frames; msg is allocated
  !> (and the file possibly left open: the caller closes it) when it cannot serve the restart.
  subroutine reopen(wr, g, keep, msg)
    type(mpm_writer_t), intent(inout) :: wr
    type(grid_t), intent(in) :: g
    integer, intent(in) :: keep
    character(len=:), allocatable, intent(out) :: msg
    integer(hid_t) :: parts, grid, frame
    integer :: hdferr, f, n_found, ndim(1), n(3), count(1)
    real(dp) :: lo(3), h(1), time(1)
    character(len=6) :: tag
    character(len=96) :: text
    logical :: exists

    if (.not. file_exists(wr%h5_name)) then
       msg = 'cannot restart: the file does not exist'
       return
    end if
    ! A file that is not HDF5 is reported by us, not by HDF5's error stack on stderr.
    call h5eset_auto_f(0, hdferr)
    call h5fopen_f(wr%h5_name, H5F_ACC_RDWR_F, wr%file, hdferr)
    if (hdferr < 0) then
       wr%file = -1
       call h5eset_auto_f(1, hdferr)
       msg = 'cannot restart: the file cannot be opened as an HDF5 file'
       return
    end if
    call h5lexists_f(wr%file, 'grid', exists, hdferr)
    if (exists) call h5lexists_f(wr%file, 'particles', exists, hdferr)
    if (.not. exists .or. hdferr < 0) then
       call h5eset_auto_f(1, hdferr)
       msg = 'cannot restart: not the field output of a material-point run (no /grid, /particles)'
       return
    end if
    call h5eset_auto_f(1, hdferr)
    call h5gopen_f(wr%file, 'grid', grid, hdferr)
    call check(hdferr, 'opening /grid')
    call read_attr_int(grid, 'ndim', ndim)
    call read_attr_int(grid, 'n', n)
    call read_attr_real(grid, 'lo', lo)
    call read_attr_real(grid, 'h', h)
    if (ndim(1) /= g%ndim .or. any(n /= g%n) .or. any(abs(lo - g%lo) > 0) .or. abs(h(1) - g%h) > 0) then
       write (text, '(i0,a,i0,a,i0,a,es12.5)') n(1), ' x ', n(2), ' x ', n(3), ' nodes, cell ', h(1)
       msg = 'cannot restart: the file holds a grid of ' // trim(text)
       write (text, '(i0,a,i0,a,i0,a,es12.5)') g%n(1), ' x ', g%n(2), ' x ', g%n(3), ' nodes, cell ', g%h
       msg = msg // '; expected the scene''s grid of ' // trim(text)
       call h5gclose_f(grid, hdferr)
       return
    end if
    call h5gopen_f(wr%file, 'particles', parts, hdferr)
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
    ! what the XDMF files list: every kept frame's particle count and time
    deallocate (wr%counts, wr%times)
    allocate (wr%counts(keep), wr%times(keep))
    do f = 0, keep - 1
       write (tag, '(i6.6)') f
       call h5gopen_f(parts, tag, frame, hdferr)
       call check(hdferr, 'opening frame /particles/' // tag)
       call read_attr_int(frame, 'count', count)
       call read_attr_real(frame, 'total_time', time)
       call h5gclose_f(frame, hdferr)
       wr%counts(f + 1) = count(1)
       wr%times(f + 1) = time(1)
    end do
    wr%n_frames = keep
    call h5gclose_f(parts, hdferr)
    call h5gclose_f(grid, hdferr)
    call h5fflush_f(wr%file, H5F_SCOPE_GLOBAL_F, hdferr)
  end subroutine reopen

  subroutine mpm_writer_close(wr)
    type(mpm_writer_t), intent(inout) :: wr
    integer :: hdferr
    if (wr%file /= -1) then
       call h5fclose_f(wr%file, hdferr)
       wr%file = -1
    end if
  end subroutine mpm_writer_close

  subroutine write_xdmf(wr, g)
    type(mpm_writer_t), intent(in) :: wr
    type(grid_t), intent(in) :: g
    integer :: u, i, slash
    character(len=6) :: tag
    character(len=:), allocatable :: h5
    character(len=64) :: dims, gdims

    slash = index(wr%h5_name, '/', back=.true.)
    h5 = wr%h5_name(slash + 1:)
    open (newunit=u, file=wr%base // '.xmf', status='replace', action='write')
    write (u, '(a)') '<?xml version="1.0" ?>'
    write (u, '(a)') '<Xdmf Version="3.0"><Domain>'
    write (u, '(a)') '<Grid Name="particles" GridType="Collection" CollectionType="Temporal">'
    do i = 1, wr%n_frames
       write (tag, '(i6.6)') i - 1
       write (dims, '(i0)') wr%counts(i)
       write (u, '(a)') '<Grid Name="particles_' // tag // '" GridType="Uniform">'
       write (u, '(a,es24.16,a)') '<Time Value="', wr%times(i), '"/>'
       write (u, '(a)') '<Topology TopologyType="Polyvertex" NumberOfElements="' // trim(dims) // '"/>'
       write (u, '(a)') '<Geometry GeometryType="XYZ"><DataItem Dimensions="' // trim(dims) // &
            ' 3" NumberType="Float" Precision="8" Format="HDF">' // h5 // ':/particles/' // tag // &
            '/coordinates</DataItem></Geometry>'
       call attribute(u, 'V', 'Vector', trim(dims) // ' 3', h5 // ':/particles/' // tag // '/V')
       call attribute(u, 'density', 'Scalar', trim(dims), h5 // ':/particles/' // tag // '/density')
       call attribute(u, 'mass', 'Scalar', trim(dims), h5 // ':/particles/' // tag // '/mass')
       write (gdims, '(i0,a,i0)') wr%counts(i), ' ', wr%ncomp
       call attribute(u, 'S', 'Matrix', trim(gdims), h5 // ':/particles/' // tag // '/S')
       write (u, '(a)') '</Grid>'
    end do
    write (u, '(a)') '</Grid></Domain></Xdmf>'
    close (u)
    ! the background grid
    open (newunit=u, file=wr%base // '_grid.xmf', status='replace', action='write')
    write (u, '(a)') '<?xml version="1.0" ?>'
    write (u, '(a)') '<Xdmf Version="3.0"><Domain>'
    write (u, '(a)') '<Grid Name="grid" GridType="Collection" CollectionType="Temporal">'
    ! 2D grids too as a 3D CoRectMesh one node thick (ParaView's XDMF reader then takes the
    ! vector attribute; with 2DCoRectMesh it failed to read it)
    write (gdims, '(i0,a,i0,a,i0)') g%n(3), ' ', g%n(2), ' ', g%n(1)
    do i = 1, wr%n_frames
       write (tag, '(i6.6)') i - 1
       write (u, '(a)') '<Grid Name="grid_' // tag // '" GridType="Uniform">'
       write (u, '(a,es24.16,a)') '<Time Value="', wr%times(i), '"/>'
       write (u, '(a)') '<Topology TopologyType="3DCoRectMesh" Dimensions="' // trim(gdims) // '"/>'
       write (u, '(a)') '<Geometry GeometryType="ORIGIN_DXDYDZ">'
       write (u, '(a,3es24.16,a)') '<DataItem Dimensions="3" Format="XML">', g%lo(3), g%lo(2), g%lo(1), &
            '</DataItem>'
       write (u, '(a,3es24.16,a)') '<DataItem Dimensions="3" Format="XML">', g%h, g%h, g%h, '</DataItem>'
       write (u, '(a)') '</Geometry>'
       call attribute(u, 'mass', 'Scalar', trim(gdims), h5 // ':/grid/' // tag // '/mass', 'Node')
       call attribute(u, 'V', 'Vector', trim(gdims) // ' 3', h5 // ':/grid/' // tag // '/V', 'Node')
       write (u, '(a)') '</Grid>'
    end do
    write (u, '(a)') '</Grid></Domain></Xdmf>'
    close (u)
  end subroutine write_xdmf

  subroutine attribute(u, name, kind, dims, path, center)
    integer, intent(in) :: u
    character(len=*), intent(in) :: name, kind, dims, path
    character(len=*), intent(in), optional :: center
    character(len=:), allocatable :: c
    c = 'Node'
    if (present(center)) c = center
    write (u, '(a)') '<Attribute Name="' // name // '" AttributeType="' // kind // '" Center="' // c // &
         '"><DataItem Dimensions="' // dims // '" NumberType="Float" Precision="8" Format="HDF">' // &
         path // '</DataItem></Attribute>'
  end subroutine attribute

  subroutine write_r2(loc, name, a)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: a(:, :)
    integer(hsize_t) :: dims(2)
    integer(hid_t) :: space, dset
    integer :: hdferr
    dims = shape(a, kind=hsize_t)
    call h5screate_simple_f(2, dims, space, hdferr)
    call h5dcreate_f(loc, name, H5T_NATIVE_DOUBLE, space, dset, hdferr)
    call check(hdferr, 'creating dataset ' // name)
    if (size(a) > 0) call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, a, dims, hdferr)
    call check(hdferr, 'writing dataset ' // name)
    call h5dclose_f(dset, hdferr)
    call h5sclose_f(space, hdferr)
  end subroutine write_r2

  !> A flat buffer written as a dataset of Fortran shape dims (h5py shows it reversed).
  subroutine write_shaped(loc, name, a, dims)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: a(:)
    integer(hsize_t), intent(in) :: dims(:)
    integer(hid_t) :: space, dset
    integer :: hdferr
    call h5screate_simple_f(size(dims), dims, space, hdferr)
    call h5dcreate_f(loc, name, H5T_NATIVE_DOUBLE, space, dset, hdferr)
    call check(hdferr, 'creating dataset ' // name)
    if (size(a) > 0) call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, a, dims, hdferr)
    call check(hdferr, 'writing dataset ' // name)
    call h5dclose_f(dset, hdferr)
    call h5sclose_f(space, hdferr)
  end subroutine write_shaped

  subroutine write_r1(loc, name, a)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: a(:)
    call write_shaped(loc, name, a, shape(a, kind=hsize_t))
  end subroutine write_r1

  subroutine write_i1(loc, name, a)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer(int32), intent(in) :: a(:)
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: space, dset
    integer :: hdferr
    dims = shape(a, kind=hsize_t)
    call h5screate_simple_f(1, dims, space, hdferr)
    call h5dcreate_f(loc, name, H5T_NATIVE_INTEGER, space, dset, hdferr)
    call check(hdferr, 'creating dataset ' // name)
    if (size(a) > 0) call h5dwrite_f(dset, H5T_NATIVE_INTEGER, a, dims, hdferr)
    call check(hdferr, 'writing dataset ' // name)
    call h5dclose_f(dset, hdferr)
    call h5sclose_f(space, hdferr)
  end subroutine write_i1

  subroutine write_attr_int(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: v(:)
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: space, attr
    integer :: hdferr
    dims = size(v)
    call h5screate_simple_f(1, dims, space, hdferr)
    call h5acreate_f(loc, name, H5T_NATIVE_INTEGER, space, attr, hdferr)
    call h5awrite_f(attr, H5T_NATIVE_INTEGER, v, dims, hdferr)
    call check(hdferr, 'writing attribute ' // name)
    call h5aclose_f(attr, hdferr)
    call h5sclose_f(space, hdferr)
  end subroutine write_attr_int

  subroutine read_attr_int(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(out) :: v(:)
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: attr
    integer :: hdferr
    dims = size(v)
    v = 0
    call h5aopen_f(loc, name, attr, hdferr)
    call check(hdferr, 'opening attribute ' // name)
    call h5aread_f(attr, H5T_NATIVE_INTEGER, v, dims, hdferr)
    call check(hdferr, 'reading attribute ' // name)
    call h5aclose_f(attr, hdferr)
  end subroutine read_attr_int

  subroutine read_attr_real(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: v(:)
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: attr
    integer :: hdferr
    dims = size(v)
    v = 0
    call h5aopen_f(loc, name, attr, hdferr)
    call check(hdferr, 'opening attribute ' // name)
    call h5aread_f(attr, H5T_NATIVE_DOUBLE, v, dims, hdferr)
    call check(hdferr, 'reading attribute ' // name)
    call h5aclose_f(attr, hdferr)
  end subroutine read_attr_real

  subroutine write_attr_real(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: v(:)
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: space, attr
    integer :: hdferr
    dims = size(v)
    call h5screate_simple_f(1, dims, space, hdferr)
    call h5acreate_f(loc, name, H5T_NATIVE_DOUBLE, space, attr, hdferr)
    call h5awrite_f(attr, H5T_NATIVE_DOUBLE, v, dims, hdferr)
    call check(hdferr, 'writing attribute ' // name)
    call h5aclose_f(attr, hdferr)
    call h5sclose_f(space, hdferr)
  end subroutine write_attr_real

  subroutine write_attr_string(loc, name, text)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name, text
    integer(hsize_t) :: dims(1)
    integer(hid_t) :: space, attr, stype
    integer :: hdferr
    dims = 1
    call h5tcopy_f(H5T_NATIVE_CHARACTER, stype, hdferr)
    call h5tset_size_f(stype, int(len(text), size_t), hdferr)
    call h5screate_f(H5S_SCALAR_F, space, hdferr)
    call h5acreate_f(loc, name, stype, space, attr, hdferr)
    call h5awrite_f(attr, stype, text, dims, hdferr)
    call check(hdferr, 'writing attribute ' // name)
    call h5aclose_f(attr, hdferr)
    call h5sclose_f(space, hdferr)
    call h5tclose_f(stype, hdferr)
  end subroutine write_attr_string
end module mpm_output
