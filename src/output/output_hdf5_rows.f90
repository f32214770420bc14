!> The collective write of a field file's rows (output_hdf5): rows scattered over the ranks
!> are exchanged so that every rank holds one contiguous block of them, then written in one
!> collective transfer (each rank's block a single hyperslab; see redistribute for why).
module output_hdf5_rows
  use, intrinsic :: iso_c_binding, only: c_loc
  use mpi_f08, only: MPI_Comm, MPI_Datatype, MPI_Alltoall, MPI_Alltoallv, MPI_INTEGER, MPI_DOUBLE_PRECISION, &
       MPI_Type_contiguous, MPI_Type_commit, MPI_Type_free
  use hdf5
  use base_kinds, only: dp
  use error_report, only: raise_error
  use output_files, only: int_to_str
  use output_hdf5_basics, only: check, dataset_rows, block_spaces
  implicit none
  private

  public :: write_rows_real, write_rows_int, write_whole_real, write_box_real

contains

  !> The contiguous block of rows rank `r` writes: rows 1..n split evenly, the first
  !> mod(n, nranks) ranks taking one more.
  pure subroutine block_of(n, nranks, r, first, count)
    integer, intent(in) :: n
    integer, intent(in) :: nranks
    integer, intent(in) :: r
    integer, intent(out) :: first
    integer, intent(out) :: count
    integer :: base, rem

    base = n / nranks
    rem = mod(n, nranks)
    first = r * base + min(r, rem) + 1
    count = base
    if (r < rem) count = base + 1
  end subroutine block_of

  !> The rank whose block holds row g (the inverse of block_of).
  pure integer function block_rank(n, nranks, g)
    integer, intent(in) :: n
    integer, intent(in) :: nranks
    integer, intent(in) :: g
    integer :: base, rem, big

    base = n / nranks
    rem = mod(n, nranks)
    big = rem * (base + 1)
    if (g <= big) then
       block_rank = (g - 1) / (base + 1)
    else
       block_rank = rem + (g - 1 - big) / base
    end if
  end function block_rank

  !> Send the packed rows buf(ncomp, size(rows)) (global 1-based, ascending) to the ranks
  !> whose blocks hold them; on return block(ncomp, count) holds this rank's block of rows
  !> first..first+count-1.
  !>
  !> Why not let every rank write its own rows: a rank's rows are scattered over the file
  !> (owned nodes of a partition are not numbered consecutively), and an HDF5 1.10
  !> selection made of many hyperslabs costs time quadratic in their number (10 s for
  !> 20 000 nodes on two ranks). One all-to-all exchange makes every rank's part one
  !> contiguous hyperslab, and the collective write is then a plain MPI-IO block write.
  subroutine redistribute(comm, rank, nranks, path, ncomp, nrows, rows, buf, first, count, block)
    type(MPI_Comm), intent(in) :: comm
    integer, intent(in) :: rank
    integer, intent(in) :: nranks
    character(len=*), intent(in) :: path    !< the file, for messages
    integer, intent(in) :: ncomp
    integer, intent(in) :: nrows
    integer, intent(in) :: rows(:)
    real(dp), intent(in) :: buf(:, :)
    integer, intent(out) :: first
    integer, intent(out) :: count
    real(dp), allocatable, intent(out) :: block(:, :)
    integer, allocatable :: send_counts(:), send_displs(:), recv_counts(:), recv_displs(:)
    integer, allocatable :: recv_rows(:)
    real(dp), allocatable :: recv_values(:, :)
    logical, allocatable :: seen(:)
    integer :: k, r, p, n_recv
    type(MPI_Datatype) :: row_type

    p = nranks
    allocate (send_counts(0:p - 1), send_displs(0:p - 1), recv_counts(0:p - 1), &
         recv_displs(0:p - 1))
    send_counts = 0
    do k = 1, size(rows)
       r = block_rank(nrows, p, rows(k))
       send_counts(r) = send_counts(r) + 1
    end do
    call MPI_Alltoall(send_counts, 1, MPI_INTEGER, recv_counts, 1, MPI_INTEGER, comm)
    send_displs(0) = 0
    recv_displs(0) = 0
    do r = 1, p - 1
       send_displs(r) = send_displs(r - 1) + send_counts(r - 1)
       recv_displs(r) = recv_displs(r - 1) + recv_counts(r - 1)
    end do
    n_recv = sum(recv_counts)
    allocate (recv_rows(n_recv), recv_values(ncomp, n_recv))
    ! Rows are ascending, so the rows for each destination are consecutive in `rows`.
    call MPI_Alltoallv(rows, send_counts, send_displs, MPI_INTEGER, recv_rows, recv_counts, &
         recv_displs, MPI_INTEGER, comm)
    ! counted in rows of ncomp values, not in values: ncomp times a displacement in rows passes
    ! 2^31 from 358 M rows of six components, and MPI counts are default integers
    call MPI_Type_contiguous(ncomp, MPI_DOUBLE_PRECISION, row_type)
    call MPI_Type_commit(row_type)
    call MPI_Alltoallv(buf, send_counts, send_displs, row_type, &
         recv_values, recv_counts, recv_displs, row_type, comm)
    call MPI_Type_free(row_type)

    call block_of(nrows, p, rank, first, count)
    allocate (block(ncomp, count), seen(count))
    seen = .false.
    do k = 1, n_recv
       r = recv_rows(k) - first + 1
       ! block_rank sent every row to the block holding it, so r is in range; a row sent
       ! twice means two ranks claim the same node.
       if (seen(r)) call raise_error(path, 0, 'row ' // &
            int_to_str(recv_rows(k)) // ' is written by two ranks (node owned twice?)')
       seen(r) = .true.
       block(:, r) = recv_values(:, k)
    end do
    if (.not. all(seen)) call raise_error(path, 0, &
         'rows left unwritten (a node without owner?)')
  end subroutine redistribute

  !> Collective write of the packed rows buf(ncomp, size(rows)) of a (nrows, ncomp)
  !> dataset ((nrows,) for one component), through redistribute.
  subroutine write_rows_real(comm, rank, nranks, xfer, path, dset, ncomp, rows, buf)
    type(MPI_Comm), intent(in) :: comm
    integer, intent(in) :: rank
    integer, intent(in) :: nranks
    integer(hid_t), intent(in) :: xfer       !< collective transfer property list
    character(len=*), intent(in) :: path
    integer(hid_t), intent(in) :: dset
    integer, intent(in) :: ncomp
    integer, intent(in) :: rows(:)
    real(dp), intent(in) :: buf(:, :)
    real(dp), allocatable, target :: block(:, :)
    real(dp), target :: idle(1)
    integer(hid_t) :: file_space, mem_space
    integer :: hdferr, first, count

    ! a dataset of no rows (an emptied MPM domain) has no storage for HDF5 to write into; every
    ! rank sees the same dimensions, so all of them skip the collective write alike
    if (dataset_rows(dset) == 0) return
    call redistribute(comm, rank, nranks, path, ncomp, dataset_rows(dset), rows, buf, first, count, block)
    call block_spaces(dset, ncomp, first, count, file_space, mem_space)
    idle = 0.0_dp
    if (count > 0) then
       call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, c_loc(block), hdferr, mem_space, file_space, xfer)
    else
       call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, c_loc(idle), hdferr, mem_space, file_space, xfer)
    end if
    call check(hdferr, 'writing a dataset')
    call h5sclose_f(mem_space, hdferr)
    call h5sclose_f(file_space, hdferr)
  end subroutine write_rows_real

  !> The same for integers (sent as doubles, exact below 2**53).
  subroutine write_rows_int(comm, rank, nranks, xfer, path, dset, ncomp, rows, buf)
    type(MPI_Comm), intent(in) :: comm
    integer, intent(in) :: rank
    integer, intent(in) :: nranks
    integer(hid_t), intent(in) :: xfer       !< collective transfer property list
    character(len=*), intent(in) :: path
    integer(hid_t), intent(in) :: dset
    integer, intent(in) :: ncomp
    integer, intent(in) :: rows(:)
    integer, intent(in) :: buf(:, :)
    real(dp), allocatable :: block(:, :), rbuf(:, :)
    integer, allocatable, target :: iblock(:, :)
    integer, target :: idle(1)
    integer(hid_t) :: file_space, mem_space
    integer :: hdferr, first, count

    ! a dataset of no rows (an emptied MPM domain) has no storage for HDF5 to write into; every
    ! rank sees the same dimensions, so all of them skip the collective write alike
    if (dataset_rows(dset) == 0) return
    allocate (rbuf(size(buf, 1), size(buf, 2)))
    rbuf = real(buf, dp)
    call redistribute(comm, rank, nranks, path, ncomp, dataset_rows(dset), rows, rbuf, first, count, block)
    allocate (iblock(ncomp, count))
    iblock = nint(block)
    call block_spaces(dset, ncomp, first, count, file_space, mem_space)
    idle = 0
    if (count > 0) then
       call h5dwrite_f(dset, H5T_NATIVE_INTEGER, c_loc(iblock), hdferr, mem_space, file_space, xfer)
    else
       call h5dwrite_f(dset, H5T_NATIVE_INTEGER, c_loc(idle), hdferr, mem_space, file_space, xfer)
    end if
    call check(hdferr, 'writing a dataset')
    call h5sclose_f(mem_space, hdferr)
    call h5sclose_f(file_space, hdferr)
  end subroutine write_rows_int

  !> Collective write of a whole dataset that every rank holds alike (the nodal fields of a
  !> background grid summed over the ranks): `writer` passes all of it in Fortran element
  !> order, the other ranks take part with empty selections.
  subroutine write_whole_real(xfer, dset, values, writer)
    integer(hid_t), intent(in) :: xfer       !< collective transfer property list
    integer(hid_t), intent(in) :: dset
    real(dp), intent(in), target :: values(:)
    logical, intent(in) :: writer
    integer(hid_t) :: file_space, mem_space
    integer :: hdferr

    if (.not. (writer .and. size(values) > 0)) then
       call write_nothing(xfer, dset)
       return
    end if
    call h5dget_space_f(dset, file_space, hdferr)
    call check(hdferr, 'getting a file dataspace')
    call h5screate_simple_f(1, [int(size(values), hsize_t)], mem_space, hdferr)
    call check(hdferr, 'creating a memory dataspace')
    call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, c_loc(values), hdferr, mem_space, file_space, xfer)
    call check(hdferr, 'writing a dataset')
    call h5sclose_f(mem_space, hdferr)
    call h5sclose_f(file_space, hdferr)
  end subroutine write_whole_real

  !> This rank's part in a collective write of dset when it has nothing to write: empty
  !> selections in the file and in a one-value memory space (a buffer still needs an address).
  subroutine write_nothing(xfer, dset)
    integer(hid_t), intent(in) :: xfer, dset
    real(dp), target :: idle(1)
    integer(hid_t) :: file_space, mem_space
    integer :: hdferr

    call h5dget_space_f(dset, file_space, hdferr)
    call check(hdferr, 'getting a file dataspace')
    call h5screate_simple_f(1, [1_hsize_t], mem_space, hdferr)
    call check(hdferr, 'creating a memory dataspace')
    idle = 0.0_dp
    call h5sselect_none_f(file_space, hdferr)
    call h5sselect_none_f(mem_space, hdferr)
    call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, c_loc(idle), hdferr, mem_space, file_space, xfer)
    call check(hdferr, 'writing a dataset')
    call h5sclose_f(mem_space, hdferr)
    call h5sclose_f(file_space, hdferr)
  end subroutine write_nothing

  !> Write this rank's box of a node dataset of dimensions ([ncomp,] n1, n2, n3): the nodes
  !> offset .. offset + count − 1 (0-based, per axis), values ordered components fastest, then
  !> the box's nodes with axis 1 fastest. Collective; a rank with an empty box writes nothing.
  !> Why boxes: a decomposed grid's ranks own disjoint boxes that tile it, so no rank holds the
  !> whole grid to write it.
  subroutine write_box_real(xfer, dset, values, ncomp, offset, count)
    integer(hid_t), intent(in) :: xfer       !< collective transfer property list
    integer(hid_t), intent(in) :: dset
    real(dp), intent(in), target :: values(:)
    integer, intent(in) :: ncomp
    integer, intent(in) :: offset(3), count(3)
    integer(hsize_t) :: start(4), extent(4)
    integer(hid_t) :: file_space, mem_space
    integer :: hdferr, rank

    if (any(count <= 0) .or. size(values) == 0) then
       call write_nothing(xfer, dset)
       return
    end if
    if (size(values) /= ncomp * product(count)) call raise_error('output_hdf5_rows', 0, &
         'a grid box of ' // int_to_str(size(values)) // ' values; expected ' // &
         int_to_str(ncomp * product(count)))
    call h5dget_space_f(dset, file_space, hdferr)
    call check(hdferr, 'getting a file dataspace')
    call h5screate_simple_f(1, [int(size(values), hsize_t)], mem_space, hdferr)
    call check(hdferr, 'creating a memory dataspace')
    if (ncomp == 1) then
       rank = 3
       start(1:3) = int(offset, hsize_t)
       extent(1:3) = int(count, hsize_t)
    else
       rank = 4
       start(1) = 0
       extent(1) = int(ncomp, hsize_t)
       start(2:4) = int(offset, hsize_t)
       extent(2:4) = int(count, hsize_t)
    end if
    call h5sselect_hyperslab_f(file_space, H5S_SELECT_SET_F, start(1:rank), extent(1:rank), hdferr)
    call check(hdferr, 'selecting a grid box')
    call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, c_loc(values), hdferr, mem_space, file_space, xfer)
    call check(hdferr, 'writing a dataset')
    call h5sclose_f(mem_space, hdferr)
    call h5sclose_f(file_space, hdferr)
  end subroutine write_box_real

end module output_hdf5_rows
