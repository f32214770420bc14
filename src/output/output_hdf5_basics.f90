!> HDF5 primitives of the field file (output_hdf5): scalar attributes, contiguous datasets,
!> dataspaces of a block of rows, and the stop on a failed HDF5 call. A failure names the file
!> given by the last hdf5_error_context call (the low-level helpers have no writer at hand).
module output_hdf5_basics
  use, intrinsic :: iso_c_binding, only: c_loc, c_char, c_ptr, c_int, c_int64_t
  use hdf5
  use base_kinds, only: dp
  use error_report, only: raise_error
  implicit none
  private

  public :: hdf5_error_context, check, collective_transfer
  public :: dataset_space, create_dataset, create_shaped_dataset, dataset_rows, block_spaces
  public :: write_attr_int, write_attr_real, write_attr_string, read_attr_real, read_attr_string
  public :: write_attr_ints, write_attr_reals, read_attr_ints, read_attr_reals

  !> The file named in messages of failed HDF5 calls (set by each public procedure of
  !> output_hdf5): such failures are fatal.
  character(len=:), allocatable :: error_context

  interface
     !> HDF5's C call (no Fortran wrapper in HDF5 1.10): H5FD_MPIO_INDIVIDUAL_IO = 1
     integer(c_int) function h5pset_dxpl_mpio_collective_opt(dxpl, mode) &
          bind(c, name='H5Pset_dxpl_mpio_collective_opt')
       import :: c_int, c_int64_t
       integer(c_int64_t), value :: dxpl   !< hid_t: int64_t since HDF5 1.10
       integer(c_int), value :: mode
     end function h5pset_dxpl_mpio_collective_opt
  end interface

contains

  !> The transfer property list of a field file's writes: collective HDF5 calls (every rank
  !> takes part in each, the metadata stay consistent) whose raw data each rank writes to the
  !> file itself (MPI-IO individual I/O). Why not MPI-IO's collective buffering: its
  !> aggregator (rank 0 on one machine) gathers every rank's part of a dataset before writing,
  !> so rank 0's memory held the whole particle set at every frame (scripts/bench_memory.py:
  !> data per rank on 4 ranks 0.33 of one rank's with it, 0.26 without). Each rank's part is one
  !> contiguous block of rows (output_hdf5_rows) or one box of grid nodes: little to gain from
  !> aggregating.
  subroutine collective_transfer(xfer)
    integer(hid_t), intent(out) :: xfer
    integer :: hdferr

    call h5pcreate_f(H5P_DATASET_XFER_F, xfer, hdferr)
    call check(hdferr, 'creating the transfer property list')
    call h5pset_dxpl_mpio_f(xfer, H5FD_MPIO_COLLECTIVE_F, hdferr)
    call check(hdferr, 'h5pset_dxpl_mpio')
    hdferr = int(h5pset_dxpl_mpio_collective_opt(int(xfer, c_int64_t), 1_c_int))
    call check(hdferr, 'h5pset_dxpl_mpio_collective_opt')
  end subroutine collective_transfer

  !> Name `path` in the messages of HDF5 calls that fail from now on.
  subroutine hdf5_error_context(path)
    character(len=*), intent(in) :: path

    error_context = path
  end subroutine hdf5_error_context

  !> Rank and dimensions (Fortran order, at most 2) of a dataset.
  subroutine dataset_space(dset, ndims, dims)
    integer(hid_t), intent(in) :: dset
    integer, intent(out) :: ndims
    integer(hsize_t), intent(out) :: dims(2)
    integer(hsize_t) :: maxdims(2)
    integer(hid_t) :: space
    integer :: hdferr

    dims = 0
    call h5dget_space_f(dset, space, hdferr)
    call h5sget_simple_extent_ndims_f(space, ndims, hdferr)
    if (ndims >= 1 .and. ndims <= 2) then
       call h5sget_simple_extent_dims_f(space, dims(1:ndims), maxdims(1:ndims), hdferr)
    end if
    call h5sclose_f(space, hdferr)
  end subroutine dataset_space

  !> A (nrows, ncomp) dataset, (nrows,) for one component; contiguous, never filled: every
  !> row is written once, and skipping the fill saves writing the whole dataset twice.
  subroutine create_dataset(loc, name, file_type, ncomp, nrows, dset)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: file_type
    integer, intent(in) :: ncomp
    integer, intent(in) :: nrows
    integer(hid_t), intent(out) :: dset

    if (ncomp == 1) then
       call create_shaped_dataset(loc, name, file_type, [int(nrows, hsize_t)], dset)
    else
       call create_shaped_dataset(loc, name, file_type, [int(ncomp, hsize_t), int(nrows, hsize_t)], dset)
    end if
  end subroutine create_dataset

  !> A dataset of any Fortran shape `dims` (h5py shows it reversed), contiguous, never filled:
  !> the particle fields that keep a second dimension of one component (SDV of one state
  !> variable) and the nodal fields of a structured grid.
  subroutine create_shaped_dataset(loc, name, file_type, dims, dset)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: file_type
    integer(hsize_t), intent(in) :: dims(:)
    integer(hid_t), intent(out) :: dset
    integer(hid_t) :: space, dcpl
    integer :: hdferr

    call h5screate_simple_f(size(dims), dims, space, hdferr)
    call check(hdferr, 'creating the dataspace of ' // name)
    call h5pcreate_f(H5P_DATASET_CREATE_F, dcpl, hdferr)
    call h5pset_fill_time_f(dcpl, H5D_FILL_TIME_NEVER_F, hdferr)
    call h5dcreate_f(loc, name, file_type, space, dset, hdferr, dcpl_id=dcpl)
    call check(hdferr, 'creating dataset ' // name)
    call h5pclose_f(dcpl, hdferr)
    call h5sclose_f(space, hdferr)
  end subroutine create_shaped_dataset

  !> Number of rows of a dataset (its last Fortran-order dimension).
  integer function dataset_rows(dset)
    integer(hid_t), intent(in) :: dset
    integer(hsize_t) :: dims(2)
    integer :: ndims

    call dataset_space(dset, ndims, dims)
    dataset_rows = int(dims(ndims))
  end function dataset_rows

  !> File and memory dataspaces of the block first..first+count-1; with count = 0 both
  !> selections are empty (a one-row memory space selecting nothing), so that a rank
  !> without rows still joins the collective transfer. The dataset's rank (not ncomp) decides
  !> between rows of one value and rows of ncomp values: a (1, nrows) dataset is 2-D.
  subroutine block_spaces(dset, ncomp, first, count, file_space, mem_space)
    integer(hid_t), intent(in) :: dset
    integer, intent(in) :: ncomp
    integer, intent(in) :: first
    integer, intent(in) :: count
    integer(hid_t), intent(out) :: file_space
    integer(hid_t), intent(out) :: mem_space
    integer(hsize_t) :: dims(2)
    integer :: hdferr, ndims

    call dataset_space(dset, ndims, dims)
    call h5dget_space_f(dset, file_space, hdferr)
    call check(hdferr, 'getting a file dataspace')
    if (ndims == 1) then
       call h5screate_simple_f(1, [int(max(count, 1), hsize_t)], mem_space, hdferr)
    else
       call h5screate_simple_f(2, [int(ncomp, hsize_t), int(max(count, 1), hsize_t)], mem_space, hdferr)
    end if
    call check(hdferr, 'creating a memory dataspace')
    if (count == 0) then
       call h5sselect_none_f(file_space, hdferr)
       call h5sselect_none_f(mem_space, hdferr)
    else if (ndims == 1) then
       call h5sselect_hyperslab_f(file_space, H5S_SELECT_SET_F, [int(first - 1, hsize_t)], &
            [int(count, hsize_t)], hdferr)
    else
       call h5sselect_hyperslab_f(file_space, H5S_SELECT_SET_F, [0_hsize_t, int(first - 1, hsize_t)], &
            [int(ncomp, hsize_t), int(count, hsize_t)], hdferr)
    end if
    call check(hdferr, 'selecting rows')
  end subroutine block_spaces

  ! Attributes: metadata writes are collective in parallel HDF5, so every rank calls these
  ! with the same value.

  subroutine write_attr_int(loc, name, value)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    integer, target :: v
    integer(hid_t) :: space, attr
    integer :: hdferr

    v = value
    call h5screate_f(H5S_SCALAR_F, space, hdferr)
    call h5acreate_f(loc, name, H5T_STD_I32LE, space, attr, hdferr)
    call check(hdferr, 'creating attribute ' // name)
    call h5awrite_f(attr, H5T_NATIVE_INTEGER, c_loc(v), hdferr)
    call check(hdferr, 'writing attribute ' // name)
    call h5aclose_f(attr, hdferr)
    call h5sclose_f(space, hdferr)
  end subroutine write_attr_int

  subroutine write_attr_real(loc, name, value)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value
    real(dp), target :: v
    integer(hid_t) :: space, attr
    integer :: hdferr

    v = value
    call h5screate_f(H5S_SCALAR_F, space, hdferr)
    call h5acreate_f(loc, name, H5T_IEEE_F64LE, space, attr, hdferr)
    call check(hdferr, 'creating attribute ' // name)
    call h5awrite_f(attr, H5T_NATIVE_DOUBLE, c_loc(v), hdferr)
    call check(hdferr, 'writing attribute ' // name)
    call h5aclose_f(attr, hdferr)
    call h5sclose_f(space, hdferr)
  end subroutine write_attr_real

  !> A fixed-length, null-padded string attribute (h5py reads it as bytes).
  subroutine write_attr_string(loc, name, value)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    character(len=*), intent(in) :: value
    character(kind=c_char), target :: chars(len(value))
    integer(hid_t) :: space, attr, stype
    integer :: hdferr, i

    do i = 1, len(value)
       chars(i) = value(i:i)
    end do
    call string_type(len(value), stype)
    call h5screate_f(H5S_SCALAR_F, space, hdferr)
    call h5acreate_f(loc, name, stype, space, attr, hdferr)
    call check(hdferr, 'creating attribute ' // name)
    call h5awrite_f(attr, stype, c_loc(chars), hdferr)
    call check(hdferr, 'writing attribute ' // name)
    call h5aclose_f(attr, hdferr)
    call h5sclose_f(space, hdferr)
    call h5tclose_f(stype, hdferr)
  end subroutine write_attr_string

  !> Attributes of a 1-D dataspace of size(values) (a point writer's frame and grid
  !> attributes: h5py shows arrays, also of one value).
  subroutine write_attr_ints(loc, name, values)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: values(:)
    integer, target :: v(size(values))

    v = values
    call write_attr_array(loc, name, H5T_STD_I32LE, H5T_NATIVE_INTEGER, size(values), c_loc(v))
  end subroutine write_attr_ints

  subroutine write_attr_reals(loc, name, values)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: values(:)
    real(dp), target :: v(size(values))

    v = values
    call write_attr_array(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, size(values), c_loc(v))
  end subroutine write_attr_reals

  subroutine write_attr_array(loc, name, file_type, mem_type, n, ptr)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: file_type
    integer(hid_t), intent(in) :: mem_type
    integer, intent(in) :: n
    type(c_ptr), intent(in) :: ptr
    integer(hid_t) :: space, attr
    integer :: hdferr

    call h5screate_simple_f(1, [int(n, hsize_t)], space, hdferr)
    call h5acreate_f(loc, name, file_type, space, attr, hdferr)
    call check(hdferr, 'creating attribute ' // name)
    call h5awrite_f(attr, mem_type, ptr, hdferr)
    call check(hdferr, 'writing attribute ' // name)
    call h5aclose_f(attr, hdferr)
    call h5sclose_f(space, hdferr)
  end subroutine write_attr_array

  !> An integer attribute of size(values) values (what write_attr_ints wrote).
  subroutine read_attr_ints(loc, name, values)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(out) :: values(:)
    integer, target :: v(size(values))

    call read_attr_array(loc, name, H5T_NATIVE_INTEGER, c_loc(v))
    values = v
  end subroutine read_attr_ints

  subroutine read_attr_reals(loc, name, values)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: values(:)
    real(dp), target :: v(size(values))

    call read_attr_array(loc, name, H5T_NATIVE_DOUBLE, c_loc(v))
    values = v
  end subroutine read_attr_reals

  subroutine read_attr_array(loc, name, mem_type, ptr)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: mem_type
    type(c_ptr), intent(in) :: ptr
    type(c_ptr) :: p
    integer(hid_t) :: attr
    integer :: hdferr

    p = ptr
    call h5aopen_f(loc, name, attr, hdferr)
    call check(hdferr, 'opening attribute ' // name)
    call h5aread_f(attr, mem_type, p, hdferr)
    call check(hdferr, 'reading attribute ' // name)
    call h5aclose_f(attr, hdferr)
  end subroutine read_attr_array

  subroutine read_attr_real(loc, name, value)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: value
    real(dp), target :: v
    type(c_ptr) :: ptr
    integer(hid_t) :: attr
    integer :: hdferr

    call h5aopen_f(loc, name, attr, hdferr)
    call check(hdferr, 'opening attribute ' // name)
    ptr = c_loc(v)      ! h5aread_f wants a variable (intent inout), not an expression
    call h5aread_f(attr, H5T_NATIVE_DOUBLE, ptr, hdferr)
    call check(hdferr, 'reading attribute ' // name)
    call h5aclose_f(attr, hdferr)
    value = v
  end subroutine read_attr_real

  subroutine read_attr_string(loc, name, value)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    character(len=*), intent(out) :: value
    character(kind=c_char), target :: chars(len(value))
    type(c_ptr) :: ptr
    integer(hid_t) :: attr, stype
    integer :: hdferr, i

    chars = ' '
    call string_type(len(value), stype)
    call h5aopen_f(loc, name, attr, hdferr)
    call check(hdferr, 'opening attribute ' // name)
    ptr = c_loc(chars)
    call h5aread_f(attr, stype, ptr, hdferr)
    call check(hdferr, 'reading attribute ' // name)
    call h5aclose_f(attr, hdferr)
    call h5tclose_f(stype, hdferr)
    do i = 1, len(value)
       value(i:i) = chars(i)
    end do
  end subroutine read_attr_string

  subroutine string_type(n, stype)
    integer, intent(in) :: n
    integer(hid_t), intent(out) :: stype
    integer :: hdferr

    call h5tcopy_f(H5T_FORTRAN_S1, stype, hdferr)
    call h5tset_size_f(stype, int(n, size_t), hdferr)
    call h5tset_strpad_f(stype, H5T_STR_NULLPAD_F, hdferr)
    call check(hdferr, 'creating a string type')
  end subroutine string_type

  !> An HDF5 call failed: an I/O problem we cannot recover from (disk full, permissions,
  !> a damaged file), so stop with the operation named.
  subroutine check(hdferr, what)
    integer, intent(in) :: hdferr
    character(len=*), intent(in) :: what

    if (hdferr < 0) call raise_error(error_context, 0, 'HDF5: ' // what // ' failed')
  end subroutine check

end module output_hdf5_basics
