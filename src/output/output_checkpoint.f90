!> Checkpoint / restart files: one binary stream file per rank, `<base>.rst.<rank>`.
!>
!> Contents (docs/output_format.md): a header (magic, format version, number of ranks, this
!> rank, step, increment, step time, total time, dt, output frame count, history row count),
!> then named arrays in the order the caller puts them (name, kind, shape, raw data), then an
!> end mark. Data are the raw bytes of the doubles and integers, so a restart continues from
!> exactly the state that was saved and a restarted run repeats the uninterrupted one bit for
!> bit. The files are native-endian (little-endian on every machine we run on) and meant for
!> restarting on the same machine type with the same number of ranks.
!>
!> Writing is atomic per file: data go to `<file>.tmp`; checkpoint_end_write closes it,
!> checks that every rank wrote its file completely, and only then renames the temporary
!> files over the old checkpoint. A crash before that leaves the previous checkpoint intact;
!> a crash in the middle of the renames leaves files of two increments, which
!> checkpoint_begin_read detects (all ranks must hold the same step and increment).
!>
!> Reading checks everything a wrong restart could get wrong (rank count, names, kinds,
!> shapes, order, truncation) and fails with a message such as
!>   bulkflow: error: out/run.rst.1: expected real array "v" of shape (2,100), found real
!>   array "v" of shape (2,99)
!> All procedures are collective over `comm` (errors are agreed on: every rank gets the
!> same error), except checkpoint_discard.
module output_checkpoint
  use, intrinsic :: iso_fortran_env, only: int32, int64
  use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Allreduce, MPI_IN_PLACE, &
       MPI_INTEGER, MPI_MAX
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error, add_expectation
  use output_files, only: rename_file, delete_file, int_to_str
  use output_collective, only: agree_on_error
  implicit none
  private

  public :: checkpoint_t, checkpoint_header_t
  public :: checkpoint_begin_write, checkpoint_put, checkpoint_end_write, checkpoint_discard
  public :: checkpoint_begin_read, checkpoint_get, checkpoint_end_read, restart_begin_read
  public :: checkpoint_file_name

  character(len=8), parameter :: magic = 'BFLOWRST'
  integer(int32), parameter :: format_version = 1
  integer(int32), parameter :: kind_real64 = 1
  integer(int32), parameter :: kind_int32 = 2
  integer(int32), parameter :: tag_array = 1
  integer(int32), parameter :: tag_end = 0
  integer, parameter :: max_name_length = 256

  !> What identifies the saved state. `nranks` is filled in when writing and checked when
  !> reading; the rest is the caller's.
  type :: checkpoint_header_t
     integer :: step = 0              !< step index
     integer :: increment = 0         !< increment number
     real(dp) :: step_time = 0.0_dp
     real(dp) :: total_time = 0.0_dp
     real(dp) :: dt = 0.0_dp          !< the next time increment
     integer :: frame_count = 0       !< field frames written (field_writer_frame_count)
     integer :: history_rows = 0      !< history rows written (history_row_count)
     integer :: nranks = 0
  end type checkpoint_header_t

  !> An open checkpoint file (components private).
  type :: checkpoint_t
     private
     integer :: unit = -1
     logical :: writing = .false.
     logical :: reading = .false.
     logical :: failed = .false.      !< a read error was reported: later gets do nothing
     integer :: ios = 0               !< first write error
     type(MPI_Comm) :: comm
     integer :: rank = 0
     integer :: nranks = 1
     character(len=:), allocatable :: path
     character(len=:), allocatable :: tmp_path
  end type checkpoint_t

  !> checkpoint_put(ck, name, array): real(dp) scalar or rank 1-3, integer scalar or rank 1-2.
  interface checkpoint_put
     module procedure put_r0, put_r1, put_r2, put_r3, put_i0, put_i1, put_i2
  end interface checkpoint_put

  !> checkpoint_get(ck, name, array [, err]): array must have the shape it was saved with.
  interface checkpoint_get
     module procedure get_r0, get_r1, get_r2, get_r3, get_i0, get_i1, get_i2
  end interface checkpoint_get

contains

  !> The file of one rank: `<base>.rst.<rank>`.
  pure function checkpoint_file_name(base, rank) result(name)
    character(len=*), intent(in) :: base
    integer, intent(in) :: rank
    character(len=:), allocatable :: name

    name = base // '.rst.' // int_to_str(rank)
  end function checkpoint_file_name

  ! ---------------------------------------------------------------------------------------
  ! Writing
  ! ---------------------------------------------------------------------------------------

  subroutine checkpoint_begin_write(ck, base, comm, header, err)
    type(checkpoint_t), intent(out) :: ck
    character(len=*), intent(in) :: base
    type(MPI_Comm), intent(in) :: comm
    type(checkpoint_header_t), intent(in) :: header
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: msg, file
    logical :: any_failed

    call MPI_Comm_rank(comm, ck%rank)
    call MPI_Comm_size(comm, ck%nranks)
    ck%comm = comm
    ck%path = checkpoint_file_name(base, ck%rank)
    ck%tmp_path = ck%path // '.tmp'
    open (newunit=ck%unit, file=ck%tmp_path, access='stream', form='unformatted', &
         status='replace', action='write', iostat=ck%ios)
    if (ck%ios /= 0) then
       msg = 'cannot create ' // ck%tmp_path
       ck%unit = -1
    end if
    call agree(ck, msg, any_failed, file)
    if (any_failed) then
       call checkpoint_discard(ck)
       call raise_error(file, 0, msg, err)
       return
    end if
    ck%writing = .true.
    write (ck%unit, iostat=ck%ios) magic, format_version, int(ck%nranks, int32), &
         int(ck%rank, int32), int(header%step, int32), int(header%increment, int32), &
         header%step_time, header%total_time, header%dt, int(header%frame_count, int32), &
         int(header%history_rows, int32)
  end subroutine checkpoint_begin_write

  !> Close the temporary files and, once every rank has written its file completely,
  !> replace the previous checkpoint by them. Collective.
  subroutine checkpoint_end_write(ck, err)
    type(checkpoint_t), intent(inout) :: ck
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: msg, file
    logical :: any_failed, ok
    integer :: ios

    if (.not. ck%writing) call raise_error('checkpoint_end_write', 0, &
         'no checkpoint is being written')
    if (ck%ios == 0) write (ck%unit, iostat=ck%ios) tag_end
    close (ck%unit, iostat=ios)
    ck%unit = -1
    if (ck%ios == 0) ck%ios = ios
    if (ck%ios /= 0) msg = 'writing ' // ck%tmp_path // ' failed (disk full?); the previous ' // &
         'checkpoint is kept'
    call agree(ck, msg, any_failed, file)
    if (any_failed) then
       call checkpoint_discard(ck)
       call raise_error(file, 0, msg, err)
       return
    end if
    call rename_file(ck%tmp_path, ck%path, ok)
    if (.not. ok) msg = 'cannot rename ' // ck%tmp_path // ' to ' // ck%path
    ck%writing = .false.
    call agree(ck, msg, any_failed, file)
    if (any_failed) call raise_error(file, 0, msg, err)
  end subroutine checkpoint_end_write

  !> Abandon a checkpoint being written: close and delete the temporary file, keep the
  !> previous checkpoint. Local (not collective).
  subroutine checkpoint_discard(ck)
    type(checkpoint_t), intent(inout) :: ck
    integer :: ios

    if (ck%unit /= -1) close (ck%unit, iostat=ios)
    ck%unit = -1
    if (allocated(ck%tmp_path)) call delete_file(ck%tmp_path)
    ck%writing = .false.
  end subroutine checkpoint_discard

  !> Record header of one array; nothing is written after a write error (reported at the end).
  subroutine put_record(ck, name, kind, shape)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    integer(int32), intent(in) :: kind
    integer, intent(in) :: shape(:)

    if (.not. ck%writing) call raise_error('checkpoint_put', 0, 'array "' // name // &
         '": no checkpoint is being written')
    if (len(name) == 0 .or. len(name) > max_name_length) call raise_error('checkpoint_put', 0, &
         'array names must have 1 to ' // int_to_str(max_name_length) // ' characters')
    if (ck%ios /= 0) return
    write (ck%unit, iostat=ck%ios) tag_array, int(len(name), int32), name, kind, &
         int(size(shape), int32), int(shape, int64)
  end subroutine put_record

  subroutine put_r0(ck, name, value)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: value
    integer :: no_shape(0)

    call put_record(ck, name, kind_real64, no_shape)
    if (ck%ios == 0) write (ck%unit, iostat=ck%ios) value
  end subroutine put_r0

  subroutine put_r1(ck, name, array)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: array(:)

    call put_record(ck, name, kind_real64, shape(array))
    if (ck%ios == 0) write (ck%unit, iostat=ck%ios) array
  end subroutine put_r1

  subroutine put_r2(ck, name, array)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: array(:, :)

    call put_record(ck, name, kind_real64, shape(array))
    if (ck%ios == 0) write (ck%unit, iostat=ck%ios) array
  end subroutine put_r2

  subroutine put_r3(ck, name, array)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: array(:, :, :)

    call put_record(ck, name, kind_real64, shape(array))
    if (ck%ios == 0) write (ck%unit, iostat=ck%ios) array
  end subroutine put_r3

  subroutine put_i0(ck, name, value)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    integer :: no_shape(0)

    call put_record(ck, name, kind_int32, no_shape)
    if (ck%ios == 0) write (ck%unit, iostat=ck%ios) int(value, int32)
  end subroutine put_i0

  subroutine put_i1(ck, name, array)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    integer, intent(in) :: array(:)

    call put_record(ck, name, kind_int32, shape(array))
    if (ck%ios == 0) write (ck%unit, iostat=ck%ios) int(array, int32)
  end subroutine put_i1

  subroutine put_i2(ck, name, array)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    integer, intent(in) :: array(:, :)

    call put_record(ck, name, kind_int32, shape(array))
    if (ck%ios == 0) write (ck%unit, iostat=ck%ios) int(array, int32)
  end subroutine put_i2

  ! ---------------------------------------------------------------------------------------
  ! Reading
  ! ---------------------------------------------------------------------------------------

  !> Open this rank's file and read its header; checks the format, that it was written by
  !> as many ranks as `comm` has, and that all ranks' files belong to the same increment.
  subroutine checkpoint_begin_read(ck, base, comm, header, err)
    type(checkpoint_t), intent(out) :: ck
    character(len=*), intent(in) :: base
    type(MPI_Comm), intent(in) :: comm
    type(checkpoint_header_t), intent(out) :: header
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: msg, file
    character(len=8) :: file_magic
    integer(int32) :: version, nranks, rank, step, increment, frames, rows
    integer :: ios, same(4)
    logical :: any_failed

    call MPI_Comm_rank(comm, ck%rank)
    call MPI_Comm_size(comm, ck%nranks)
    ck%comm = comm
    ck%path = checkpoint_file_name(base, ck%rank)
    open (newunit=ck%unit, file=ck%path, access='stream', form='unformatted', status='old', &
         action='read', iostat=ios)
    if (ios /= 0) then
       ck%unit = -1
       msg = 'cannot open the file (no checkpoint written by rank ' // int_to_str(ck%rank) // &
            ' of ' // int_to_str(ck%nranks) // ')'
    else
       read (ck%unit, iostat=ios) file_magic
       if (ios /= 0 .or. file_magic /= magic) then
          msg = 'not a bulkflow restart file'
       else
          read (ck%unit, iostat=ios) version, nranks, rank, step, increment, header%step_time, &
               header%total_time, header%dt, frames, rows
          if (ios /= 0) then
             msg = 'truncated header'
          else if (version /= format_version) then
             msg = 'format version ' // int_to_str(int(version)) // ', this program reads ' // &
                  int_to_str(int(format_version))
          else if (nranks /= ck%nranks) then
             msg = 'written by a run on ' // int_to_str(int(nranks)) // ' ranks, this run has ' // &
                  int_to_str(ck%nranks) // ' (restart with the same number of ranks)'
          else if (rank /= ck%rank) then
             msg = 'written by rank ' // int_to_str(int(rank)) // ', read by rank ' // &
                  int_to_str(ck%rank)
          end if
       end if
    end if
    if (.not. allocated(msg)) then
       header%step = step
       header%increment = increment
       header%frame_count = frames
       header%history_rows = rows
       header%nranks = nranks
    end if
    call agree(ck, msg, any_failed, file)
    if (.not. any_failed) then
       same = [header%step, -header%step, header%increment, -header%increment]
       call MPI_Allreduce(MPI_IN_PLACE, same, 4, MPI_INTEGER, MPI_MAX, comm)
       if (same(1) /= -same(2) .or. same(3) /= -same(4)) then
          file = base // '.rst.*'
          msg = 'the ranks'' restart files are of different increments (' // &
               int_to_str(-same(4)) // ' to ' // int_to_str(same(3)) // &
               '): a checkpoint was interrupted while its files were being replaced'
          any_failed = .true.
       end if
    end if
    if (any_failed) then
       call fail_read(ck, file, msg, err)
       return
    end if
    ck%reading = .true.
  end subroutine checkpoint_begin_read

  !> checkpoint_begin_read for a --restart: the error, if any, also says what a restart needs
  !> (the same number of ranks; a checkpoint of this --output written by an earlier run).
  subroutine restart_begin_read(ck, base, comm, header, err)
    type(checkpoint_t), intent(out) :: ck
    character(len=*), intent(in) :: base
    type(MPI_Comm), intent(in) :: comm
    type(checkpoint_header_t), intent(out) :: header
    type(error_t), intent(inout) :: err
    integer :: nranks

    call checkpoint_begin_read(ck, base, comm, header, err)
    if (.not. err%raised) return
    if (index(err%message, 'this run has') > 0) then
       call add_expectation(err, 'a restart on as many ranks as the run that wrote the checkpoint')
    else
       call MPI_Comm_size(comm, nranks)
       call add_expectation(err, 'a checkpoint ' // base // '.rst.* written by an earlier run of this scene on ' // &
            int_to_str(nranks) // ' rank(s) with the same --output (*RESTART, WRITE or --stop-after)')
    end if
  end subroutine restart_begin_read

  !> Check that everything was read (the end mark follows) and close. Collective.
  subroutine checkpoint_end_read(ck, err)
    type(checkpoint_t), intent(inout) :: ck
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: msg, file, found
    integer(int32) :: tag
    integer :: ios
    logical :: any_failed

    if (ck%failed) return
    if (.not. ck%reading) call raise_error('checkpoint_end_read', 0, &
         'no checkpoint is being read')
    read (ck%unit, iostat=ios) tag
    if (ios /= 0) then
       msg = 'truncated file (no end mark)'
    else if (tag /= tag_end) then
       call read_description(ck, tag, found)
       msg = 'the file holds more arrays than this run reads; the next is ' // found
    end if
    call agree(ck, msg, any_failed, file)
    if (any_failed) then
       call fail_read(ck, file, msg, err)
       return
    end if
    close (ck%unit, iostat=ios)
    ck%unit = -1
    ck%reading = .false.
  end subroutine checkpoint_end_read

  !> Read the next record's description and compare it with what the caller expects;
  !> true when the data may be read. Collective (errors agreed).
  logical function next_record_matches(ck, name, kind, shape, err) result(ok)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    integer(int32), intent(in) :: kind
    integer, intent(in) :: shape(:)
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: msg, found, file_name, file
    integer(int32) :: tag, name_len, file_kind, file_rank
    integer(int64), allocatable :: file_shape(:)
    integer :: ios
    logical :: any_failed

    ok = .false.
    if (ck%failed) return
    if (.not. ck%reading) call raise_error('checkpoint_get', 0, 'array "' // name // &
         '": no checkpoint is being read')
    read (ck%unit, iostat=ios) tag
    if (ios /= 0) then
       msg = 'truncated file: expected ' // describe(kind, name, int(shape, int64))
    else if (tag == tag_end) then
       msg = 'expected ' // describe(kind, name, int(shape, int64)) // ', found the end of the file'
    else if (tag /= tag_array) then
       msg = 'damaged file: expected ' // describe(kind, name, int(shape, int64))
    else
       read (ck%unit, iostat=ios) name_len
       if (ios == 0 .and. (name_len < 1 .or. name_len > max_name_length)) ios = -1
       if (ios == 0) then
          allocate (character(len=name_len) :: file_name)
          read (ck%unit, iostat=ios) file_name, file_kind, file_rank
       end if
       if (ios == 0 .and. (file_rank < 0 .or. file_rank > 7)) ios = -1
       if (ios == 0) then
          allocate (file_shape(file_rank))
          read (ck%unit, iostat=ios) file_shape
       end if
       if (ios /= 0) then
          msg = 'damaged file: expected ' // describe(kind, name, int(shape, int64))
       else
          found = describe(file_kind, file_name, file_shape)
          if (file_name /= name .or. file_kind /= kind .or. size(file_shape) /= size(shape)) then
             msg = 'expected ' // describe(kind, name, int(shape, int64)) // ', found ' // found
          else if (any(file_shape /= shape)) then
             msg = 'expected ' // describe(kind, name, int(shape, int64)) // ', found ' // found
          end if
       end if
    end if
    call agree(ck, msg, any_failed, file)
    if (any_failed) then
       call fail_read(ck, file, msg, err)
       return
    end if
    ok = .true.
  end function next_record_matches

  !> After a record's data: a read error there means the file is shorter than its record.
  subroutine check_data(ck, name, ios, err)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    integer, intent(in) :: ios
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: msg, file
    logical :: any_failed

    if (ios /= 0) msg = 'truncated file in the data of "' // name // '"'
    call agree(ck, msg, any_failed, file)
    if (any_failed) call fail_read(ck, file, msg, err)
  end subroutine check_data

  !> The description of a record the caller did not ask for (for checkpoint_end_read).
  subroutine read_description(ck, tag, text)
    type(checkpoint_t), intent(inout) :: ck
    integer(int32), intent(in) :: tag
    character(len=:), allocatable, intent(out) :: text
    character(len=:), allocatable :: file_name
    integer(int32) :: name_len, file_kind, file_rank
    integer(int64), allocatable :: file_shape(:)
    integer :: ios

    text = 'unreadable'
    if (tag /= tag_array) return
    read (ck%unit, iostat=ios) name_len
    if (ios /= 0 .or. name_len < 1 .or. name_len > max_name_length) return
    allocate (character(len=name_len) :: file_name)
    read (ck%unit, iostat=ios) file_name, file_kind, file_rank
    if (ios /= 0 .or. file_rank < 0 .or. file_rank > 7) return
    allocate (file_shape(file_rank))
    read (ck%unit, iostat=ios) file_shape
    if (ios /= 0) return
    text = describe(file_kind, file_name, file_shape)
  end subroutine read_description

  !> 'real array "v" of shape (2,100)', 'integer scalar "n"'.
  pure function describe(kind, name, shape) result(text)
    integer(int32), intent(in) :: kind
    character(len=*), intent(in) :: name
    integer(int64), intent(in) :: shape(:)
    character(len=:), allocatable :: text
    character(len=24) :: buf
    integer :: i

    select case (kind)
    case (kind_real64)
       text = 'real'
    case (kind_int32)
       text = 'integer'
    case default
       text = 'unknown-kind'
    end select
    if (size(shape) == 0) then
       text = text // ' scalar "' // name // '"'
       return
    end if
    text = text // ' array "' // name // '" of shape ('
    do i = 1, size(shape)
       write (buf, '(i0)') shape(i)
       if (i > 1) text = text // ','
       text = text // trim(buf)
    end do
    text = text // ')'
  end function describe

  !> Agree on an error between the ranks; the message and file name of the lowest failing
  !> rank go to all.
  subroutine agree(ck, msg, any_failed, file)
    type(checkpoint_t), intent(in) :: ck
    character(len=:), allocatable, intent(inout) :: msg
    logical, intent(out) :: any_failed
    character(len=:), allocatable, intent(out) :: file

    file = ck%path
    call agree_on_error(ck%comm, allocated(msg), msg, any_failed, file)
  end subroutine agree

  subroutine fail_read(ck, file, msg, err)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: file
    character(len=*), intent(in) :: msg
    type(error_t), intent(inout), optional :: err
    integer :: ios

    if (ck%unit /= -1) close (ck%unit, iostat=ios)
    ck%unit = -1
    ck%failed = .true.
    ck%reading = .false.
    call raise_error(file, 0, msg, err)
  end subroutine fail_read

  subroutine get_r0(ck, name, value, err)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    real(dp), intent(inout) :: value
    type(error_t), intent(inout), optional :: err
    integer :: ios, no_shape(0)

    if (.not. next_record_matches(ck, name, kind_real64, no_shape, err)) return
    read (ck%unit, iostat=ios) value
    call check_data(ck, name, ios, err)
  end subroutine get_r0

  subroutine get_r1(ck, name, array, err)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    real(dp), intent(inout) :: array(:)
    type(error_t), intent(inout), optional :: err
    integer :: ios

    if (.not. next_record_matches(ck, name, kind_real64, shape(array), err)) return
    read (ck%unit, iostat=ios) array
    call check_data(ck, name, ios, err)
  end subroutine get_r1

  subroutine get_r2(ck, name, array, err)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    real(dp), intent(inout) :: array(:, :)
    type(error_t), intent(inout), optional :: err
    integer :: ios

    if (.not. next_record_matches(ck, name, kind_real64, shape(array), err)) return
    read (ck%unit, iostat=ios) array
    call check_data(ck, name, ios, err)
  end subroutine get_r2

  subroutine get_r3(ck, name, array, err)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    real(dp), intent(inout) :: array(:, :, :)
    type(error_t), intent(inout), optional :: err
    integer :: ios

    if (.not. next_record_matches(ck, name, kind_real64, shape(array), err)) return
    read (ck%unit, iostat=ios) array
    call check_data(ck, name, ios, err)
  end subroutine get_r3

  subroutine get_i0(ck, name, value, err)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    integer, intent(inout) :: value
    type(error_t), intent(inout), optional :: err
    integer(int32) :: v
    integer :: ios, no_shape(0)

    if (.not. next_record_matches(ck, name, kind_int32, no_shape, err)) return
    read (ck%unit, iostat=ios) v
    call check_data(ck, name, ios, err)
    if (ios == 0) value = v
  end subroutine get_i0

  subroutine get_i1(ck, name, array, err)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    integer, intent(inout) :: array(:)
    type(error_t), intent(inout), optional :: err
    integer(int32), allocatable :: v(:)
    integer :: ios

    if (.not. next_record_matches(ck, name, kind_int32, shape(array), err)) return
    allocate (v(size(array)))
    read (ck%unit, iostat=ios) v
    call check_data(ck, name, ios, err)
    if (ios == 0) array = v
  end subroutine get_i1

  subroutine get_i2(ck, name, array, err)
    type(checkpoint_t), intent(inout) :: ck
    character(len=*), intent(in) :: name
    integer, intent(inout) :: array(:, :)
    type(error_t), intent(inout), optional :: err
    integer(int32), allocatable :: v(:, :)
    integer :: ios

    if (.not. next_record_matches(ck, name, kind_int32, shape(array), err)) return
    allocate (v(size(array, 1), size(array, 2)))
    read (ck%unit, iostat=ios) v
    call check_data(ck, name, ios, err)
    if (ios == 0) array = v
  end subroutine get_i2

end module output_checkpoint
