!> The frames of a field file (output_hdf5): their names (/frames/NNNNNN), their XDMF
!> descriptions, and what a restart does with a file written by the interrupted run: check
!> the frames are numbered consecutively, drop those after the checkpoint, rebuild the XDMF
!> frame list from what the file holds. The layout: docs/output_format.md.
module output_hdf5_frames
  use hdf5
  use base_kinds, only: dp
  use output_files, only: int_to_str
  use output_xdmf, only: xdmf_frame_t, xdmf_add_attribute, xdmf_center_node, xdmf_center_cell
  use output_hdf5_basics, only: check, dataset_space, read_attr_real, read_attr_string
  implicit none
  private

  public :: reopen_frames, frame_sequence, frame_path, new_xdmf_frame, move_frame, grow_frames

  !> Dataset name reserved for the current coordinates of a frame.
  character(len=*), parameter, public :: coordinates_name = 'coordinates'

contains

  !> Reopened file: check the mesh sizes, drop frames >= keep, and rebuild the frame list of
  !> the XDMF from the kept frames. `msg` allocated on a problem (the same on every rank:
  !> all ranks read the same file).
  subroutine reopen_frames(file, n_nodes, nen, n_elems, keep, frames, n_frames, msg)
    integer(hid_t), intent(in) :: file
    integer, intent(in) :: n_nodes
    integer, intent(in) :: nen
    integer, intent(in) :: n_elems
    integer, intent(in) :: keep
    type(xdmf_frame_t), allocatable, intent(inout) :: frames(:)
    integer, intent(inout) :: n_frames       !< set to keep on success
    character(len=:), allocatable, intent(out) :: msg
    integer(hsize_t) :: dims(2)
    integer(hid_t) :: group, fgroup, dset
    type(xdmf_frame_t), allocatable :: grown(:)
    integer :: hdferr, storage, n_links, max_corder, f, n_found, a, nd, ncomp
    integer(size_t) :: name_len
    character(len=256) :: link_name
    character(len=4) :: center
    character(len=6) :: tag
    real(dp) :: time

    call dataset_dims('/mesh/coordinates', nd, dims)
    if (nd /= 2 .or. dims(1) /= 3 .or. dims(2) /= n_nodes) then
       msg = 'the file holds a mesh of another size than the model''s (' // &
            int_to_str(n_nodes) // ' nodes expected)'
       return
    end if
    call dataset_dims('/mesh/connectivity', nd, dims)
    if (nd /= 2 .or. dims(1) /= nen .or. dims(2) /= n_elems) then
       msg = 'the file holds a mesh of another size than the model''s (' // &
            int_to_str(n_elems) // ' elements of ' // int_to_str(nen) // ' nodes expected)'
       return
    end if

    call h5gopen_f(file, '/frames', group, hdferr)
    call check(hdferr, 'opening /frames')
    call frame_sequence(group, '/frames', keep, n_found, msg)
    if (allocated(msg)) then
       call h5gclose_f(group, hdferr)
       return
    end if
    ! Frames written after the checkpoint by the interrupted run go; the restarted run
    ! writes them again.
    do f = keep, n_found - 1
       write (tag, '(i6.6)') f
       call h5ldelete_f(group, tag, hdferr)
       call check(hdferr, 'deleting frame ' // tag)
    end do

    if (size(frames) < keep) then
       allocate (grown(keep))
       call move_alloc(grown, frames)
    end if
    do f = 0, keep - 1
       write (tag, '(i6.6)') f
       call h5gopen_f(group, tag, fgroup, hdferr)
       call check(hdferr, 'opening frame ' // tag)
       call read_attr_real(fgroup, 'total_time', time)
       call new_xdmf_frame(frames(f + 1), tag, time)
       call h5gget_info_f(fgroup, storage, n_links, max_corder, hdferr)
       do a = 0, n_links - 1
          link_name = ''
          call h5lget_name_by_idx_f(fgroup, '.', H5_INDEX_CRT_ORDER_F, H5_ITER_INC_F, &
               int(a, hsize_t), link_name, hdferr, size=name_len)
          call check(hdferr, 'listing frame ' // tag)
          call h5dopen_f(fgroup, trim(link_name), dset, hdferr)
          call check(hdferr, 'opening ' // tag // '/' // trim(link_name))
          call read_attr_string(dset, 'center', center)
          call dataset_space(dset, nd, dims)
          call h5dclose_f(dset, hdferr)
          ncomp = 1
          if (nd == 2) ncomp = int(dims(1))
          if (trim(link_name) == coordinates_name) then
             frames(f + 1)%geometry = frame_path(f) // '/' // coordinates_name
          else if (center == 'Node') then
             call xdmf_add_attribute(frames(f + 1), trim(link_name), &
                  frame_path(f) // '/' // trim(link_name), xdmf_center_node, ncomp)
          else
             call xdmf_add_attribute(frames(f + 1), trim(link_name), &
                  frame_path(f) // '/' // trim(link_name), xdmf_center_cell, ncomp)
          end if
       end do
       call h5gclose_f(fgroup, hdferr)
    end do
    call h5gclose_f(group, hdferr)
    n_frames = keep

  contains

    subroutine dataset_dims(path, ndims, d)
      character(len=*), intent(in) :: path
      integer, intent(out) :: ndims
      integer(hsize_t), intent(out) :: d(2)
      integer(hid_t) :: ds
      integer :: e

      call h5dopen_f(file, path, ds, e)
      call check(e, 'opening ' // path)
      call dataset_space(ds, ndims, d)
      call h5dclose_f(ds, e)
    end subroutine dataset_dims

  end subroutine reopen_frames

  !> The frames 000000, 000001, ... of an output group (where: its path, for the message) that a
  !> restart reopens to keep the first `keep`: n_found of them; msg is allocated when they are
  !> not numbered consecutively or fewer than keep.
  subroutine frame_sequence(group, where, keep, n_found, msg)
    integer(hid_t), intent(in) :: group
    character(len=*), intent(in) :: where
    integer, intent(in) :: keep
    integer, intent(out) :: n_found
    character(len=:), allocatable, intent(inout) :: msg
    integer :: hdferr, storage, n_links, max_corder, f
    character(len=6) :: tag
    logical :: exists

    call h5gget_info_f(group, storage, n_links, max_corder, hdferr)
    call check(hdferr, 'h5gget_info ' // where)
    n_found = 0
    do f = 0, n_links - 1
       write (tag, '(i6.6)') f
       call h5lexists_f(group, tag, exists, hdferr)
       if (.not. exists) exit
       n_found = n_found + 1
    end do
    if (n_found /= n_links) then
       msg = where // ' holds ' // int_to_str(n_links) // ' entries but its frames 000000.. are ' // &
            'not numbered consecutively'
    else if (n_found < keep) then
       msg = 'cannot restart at frame ' // int_to_str(keep) // ': the file holds only ' // &
            int_to_str(n_found) // ' frames'
    end if
  end subroutine frame_sequence

  !> The HDF5 path of frame `index` (0-based): /frames/NNNNNN.
  pure function frame_path(index) result(path)
    integer, intent(in) :: index
    character(len=:), allocatable :: path
    character(len=6) :: tag

    write (tag, '(i6.6)') index
    path = '/frames/' // tag
  end function frame_path

  !> The XDMF description of a new frame NNNNNN (`tag`) at `time`, on the reference geometry.
  subroutine new_xdmf_frame(frame, tag, time)
    type(xdmf_frame_t), intent(out) :: frame
    character(len=*), intent(in) :: tag
    real(dp), intent(in) :: time

    frame%name = 'frame_' // tag
    frame%time = time
    frame%geometry = '/mesh/coordinates'
    frame%n_attributes = 0
  end subroutine new_xdmf_frame

  !> Room for one more frame description after the first n_used (the list doubles when full).
  subroutine grow_frames(frames, n_used)
    type(xdmf_frame_t), allocatable, intent(inout) :: frames(:)
    integer, intent(in) :: n_used
    type(xdmf_frame_t), allocatable :: grown(:)
    integer :: i

    if (n_used < size(frames)) return
    allocate (grown(2 * size(frames)))
    do i = 1, n_used
       call move_frame(frames(i), grown(i))
    end do
    call move_alloc(grown, frames)
  end subroutine grow_frames

  !> Move a frame description (with its allocatable components) without copying the strings.
  subroutine move_frame(from, to)
    type(xdmf_frame_t), intent(inout) :: from
    type(xdmf_frame_t), intent(inout) :: to

    to%time = from%time
    to%n_points = from%n_points
    to%n_attributes = from%n_attributes
    call move_alloc(from%name, to%name)
    call move_alloc(from%geometry, to%geometry)
    if (allocated(from%attributes)) call move_alloc(from%attributes, to%attributes)
  end subroutine move_frame

end module output_hdf5_frames
