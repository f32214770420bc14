!> Checkpoint files under MPI: a bitwise round trip of every array kind, then each way a
!> restart can go wrong, which must fail with the same clear message on every rank:
!> wrong name, shape, kind, reading past the end, arrays left unread, another rank count,
!> a missing file, files of different increments, a truncated header. Also: a checkpoint
!> abandoned half-written leaves the previous one intact.
!>   usage: test_output_checkpoint <output base>
program test_output_checkpoint
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_COMM_WORLD, MPI_Comm, MPI_Comm_rank, &
       MPI_Comm_size, MPI_Comm_split, MPI_Comm_free, MPI_Barrier
  use material_kinds, only: dp
  use error_report, only: error_t
  use output_files, only: file_exists
  use output_checkpoint, only: checkpoint_t, checkpoint_header_t, checkpoint_begin_write, &
       checkpoint_put, checkpoint_end_write, checkpoint_discard, checkpoint_begin_read, &
       checkpoint_get, checkpoint_end_read, checkpoint_file_name
  use output_test_support, only: check, check_message, failures_everywhere
  implicit none

  character(len=512) :: arg
  character(len=:), allocatable :: base
  integer :: rank, nranks, failures
  real(dp) :: r0
  real(dp), allocatable :: r1(:), r2(:, :), r3(:, :, :)
  integer :: i0
  integer, allocatable :: i1(:), i2(:, :)
  type(checkpoint_header_t) :: header

  call MPI_Init()
  call MPI_Comm_rank(MPI_COMM_WORLD, rank)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks)
  call get_command_argument(1, arg)
  if (len_trim(arg) == 0) arg = 'output_checkpoint'
  base = trim(arg)

  call make_data()
  header%step = 2
  header%increment = 12345
  header%step_time = 0.1_dp / 3.0_dp
  header%total_time = 1.0_dp / 3.0_dp + 0.1_dp / 3.0_dp
  header%dt = 1.0e-7_dp / 3.0_dp
  header%frame_count = 4
  header%history_rows = 17

  call write_all(base, header)
  call test_round_trip()
  call test_mismatches()
  call test_other_rank_count()
  call test_discard_keeps_previous()
  call test_mixed_increments()
  call test_truncated()

  failures = failures_everywhere()
  if (rank == 0) write (*, '(a, i0, a, i0)') 'test_output_checkpoint: ranks ', nranks, &
       ', failed checks ', failures
  call MPI_Finalize()
  if (failures > 0) error stop 1

contains

  !> Different sizes and values per rank; special values to make the round trip telling.
  subroutine make_data()
    integer :: seed_size, k
    integer, allocatable :: seed(:)

    call random_seed(size=seed_size)
    allocate (seed(seed_size))
    seed = 12345 + 17 * rank
    call random_seed(put=seed)
    allocate (r1(7 + rank), r2(3, 5), r3(2, 3, 4), i1(10 + rank), i2(4, 3))
    call random_number(r1)
    call random_number(r2)
    call random_number(r3)
    r1 = (r1 - 0.5_dp) * 1.0e10_dp
    r1(1) = -0.0_dp
    r1(2) = tiny(1.0_dp) / 8.0_dp        ! subnormal
    r1(3) = huge(1.0_dp)
    r1(4) = ieee_value(1.0_dp, ieee_quiet_nan)
    r0 = 1.0_dp / 3.0_dp + rank
    i0 = -7 - rank
    i1 = [(3 * rank - 5 * k, k = 1, size(i1))]
    i2 = reshape([(k * 1000 + rank, k = 1, 12)], [4, 3])
    i2(1, 1) = -huge(0)
  end subroutine make_data

  subroutine write_all(where, hdr)
    character(len=*), intent(in) :: where
    type(checkpoint_header_t), intent(in) :: hdr
    type(checkpoint_t) :: ck
    type(error_t) :: err

    call checkpoint_begin_write(ck, where, MPI_COMM_WORLD, hdr, err)
    call check(.not. err%raised, 'begin_write')
    call checkpoint_put(ck, 'r0', r0)
    call checkpoint_put(ck, 'r1', r1)
    call checkpoint_put(ck, 'r2', r2)
    call checkpoint_put(ck, 'r3', r3)
    call checkpoint_put(ck, 'i0', i0)
    call checkpoint_put(ck, 'i1', i1)
    call checkpoint_put(ck, 'i2', i2)
    call checkpoint_end_write(ck, err)
    call check(.not. err%raised, 'end_write')
    call check(.not. file_exists(checkpoint_file_name(where, rank) // '.tmp'), 'no .tmp left')
  end subroutine write_all

  logical function same_bits(a, b)
    real(dp), intent(in) :: a(:)
    real(dp), intent(in) :: b(:)

    same_bits = size(a) == size(b)
    if (same_bits) same_bits = all(transfer(a, 0_int64, size(a)) == transfer(b, 0_int64, size(b)))
  end function same_bits

  subroutine test_round_trip()
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: h
    type(error_t) :: err
    real(dp) :: s0
    real(dp), allocatable :: s1(:), s2(:, :), s3(:, :, :)
    integer :: j0
    integer, allocatable :: j1(:), j2(:, :)

    allocate (s1(size(r1)), s2(3, 5), s3(2, 3, 4), j1(size(i1)), j2(4, 3))
    s0 = 0.0_dp
    s1 = 0.0_dp
    s2 = 0.0_dp
    s3 = 0.0_dp
    j0 = 0
    j1 = 0
    j2 = 0
    call checkpoint_begin_read(ck, base, MPI_COMM_WORLD, h, err)
    call check(.not. err%raised, 'round trip: begin_read')
    call check(h%step == header%step .and. h%increment == header%increment .and. &
         h%frame_count == header%frame_count .and. h%history_rows == header%history_rows .and. &
         h%nranks == nranks, 'round trip: integer header fields')
    call check(same_bits([h%step_time, h%total_time, h%dt], &
         [header%step_time, header%total_time, header%dt]), 'round trip: real header fields')
    call checkpoint_get(ck, 'r0', s0, err)
    call checkpoint_get(ck, 'r1', s1, err)
    call checkpoint_get(ck, 'r2', s2, err)
    call checkpoint_get(ck, 'r3', s3, err)
    call checkpoint_get(ck, 'i0', j0, err)
    call checkpoint_get(ck, 'i1', j1, err)
    call checkpoint_get(ck, 'i2', j2, err)
    call checkpoint_end_read(ck, err)
    call check(.not. err%raised, 'round trip: reads')
    call check(same_bits([s0], [r0]), 'round trip: r0 bitwise')
    call check(same_bits(s1, r1), 'round trip: r1 bitwise (with -0, subnormal, huge, NaN)')
    call check(same_bits(reshape(s2, [size(s2)]), reshape(r2, [size(r2)])), 'round trip: r2 bitwise')
    call check(same_bits(reshape(s3, [size(s3)]), reshape(r3, [size(r3)])), 'round trip: r3 bitwise')
    call check(j0 == i0 .and. all(j1 == i1) .and. all(j2 == i2), 'round trip: integers')
  end subroutine test_round_trip

  subroutine test_mismatches()
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: h
    type(error_t) :: err
    real(dp) :: s0
    real(dp), allocatable :: s1(:), s2(:, :)
    integer, allocatable :: j2(:, :)

    s0 = 0.0_dp
    ! Wrong name.
    call checkpoint_begin_read(ck, base, MPI_COMM_WORLD, h, err)
    call checkpoint_get(ck, 'x', s0, err)
    call check_message(err%raised, err%message, base // '.rst.0: ' // &
         'expected real scalar "x", found real scalar "r0"', 'wrong name')
    ! Later calls after a failure do nothing (no cascade of errors).
    err = error_t()
    call checkpoint_get(ck, 'r1', s0, err)
    call check(.not. err%raised, 'no error after the first')

    ! Wrong shape: every rank reports rank 0's finding.
    allocate (s1(8))
    s1 = 0.0_dp
    err = error_t()
    call checkpoint_begin_read(ck, base, MPI_COMM_WORLD, h, err)
    call checkpoint_get(ck, 'r0', s0, err)
    call checkpoint_get(ck, 'r1', s1, err)
    call check_message(err%raised, err%message, base // '.rst.0: ' // &
         'expected real array "r1" of shape (8), found real array "r1" of shape (7)', 'wrong shape')

    ! Wrong kind.
    deallocate (s1)
    allocate (s1(size(r1)), j2(3, 5))
    j2 = 0
    err = error_t()
    call checkpoint_begin_read(ck, base, MPI_COMM_WORLD, h, err)
    call checkpoint_get(ck, 'r0', s0, err)
    call checkpoint_get(ck, 'r1', s1, err)
    call checkpoint_get(ck, 'r2', j2, err)
    call check_message(err%raised, err%message, &
         'expected integer array "r2" of shape (3,5), found real array "r2" of shape (3,5)', 'wrong kind')

    ! Arrays left unread.
    allocate (s2(3, 5))
    err = error_t()
    call checkpoint_begin_read(ck, base, MPI_COMM_WORLD, h, err)
    call checkpoint_get(ck, 'r0', s0, err)
    call checkpoint_get(ck, 'r1', s1, err)
    call checkpoint_get(ck, 'r2', s2, err)
    call checkpoint_end_read(ck, err)
    call check_message(err%raised, err%message, 'the file holds more arrays than this run reads; ' // &
         'the next is real array "r3" of shape (2,3,4)', 'unread arrays')

    ! Reading past the end.
    err = error_t()
    call read_everything(ck, err)
    call checkpoint_get(ck, 'extra', s0, err)
    call check_message(err%raised, err%message, 'expected real scalar "extra", found the end of the file', &
         'past the end')

    ! No checkpoint under that name.
    err = error_t()
    call checkpoint_begin_read(ck, base // '_missing', MPI_COMM_WORLD, h, err)
    call check_message(err%raised, err%message, 'cannot open the file', 'missing file')
  end subroutine test_mismatches

  subroutine read_everything(ck, err)
    type(checkpoint_t), intent(inout) :: ck
    type(error_t), intent(inout) :: err
    type(checkpoint_header_t) :: h
    real(dp) :: s0
    real(dp), allocatable :: s1(:), s2(:, :), s3(:, :, :)
    integer :: j0
    integer, allocatable :: j1(:), j2(:, :)

    allocate (s1(size(r1)), s2(3, 5), s3(2, 3, 4), j1(size(i1)), j2(4, 3))
    s0 = 0.0_dp
    j0 = 0
    call checkpoint_begin_read(ck, base, MPI_COMM_WORLD, h, err)
    call checkpoint_get(ck, 'r0', s0, err)
    call checkpoint_get(ck, 'r1', s1, err)
    call checkpoint_get(ck, 'r2', s2, err)
    call checkpoint_get(ck, 'r3', s3, err)
    call checkpoint_get(ck, 'i0', j0, err)
    call checkpoint_get(ck, 'i1', j1, err)
    call checkpoint_get(ck, 'i2', j2, err)
  end subroutine read_everything

  !> Files written by N ranks read by groups of other sizes.
  subroutine test_other_rank_count()
    type(MPI_Comm) :: sub
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: h
    type(error_t) :: err
    character(len=16) :: buf

    if (nranks == 1) return
    ! Rank 0 alone; the others together.
    call MPI_Comm_split(MPI_COMM_WORLD, merge(0, 1, rank == 0), rank, sub)
    call checkpoint_begin_read(ck, base, sub, h, err)
    write (buf, '(i0)') nranks
    call check_message(err%raised, err%message, 'written by a run on ' // trim(buf) // &
         ' ranks, this run has', 'other rank count')
    call MPI_Comm_free(sub)
  end subroutine test_other_rank_count

  subroutine test_discard_keeps_previous()
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: h, later
    type(error_t) :: err

    later = header
    later%increment = header%increment + 1000
    call checkpoint_begin_write(ck, base, MPI_COMM_WORLD, later, err)
    call checkpoint_put(ck, 'r0', r0 + 1.0_dp)
    call checkpoint_discard(ck)
    call check(.not. file_exists(checkpoint_file_name(base, rank) // '.tmp'), 'discard: .tmp deleted')
    call MPI_Barrier(MPI_COMM_WORLD)
    call read_everything(ck, err)
    call checkpoint_end_read(ck, err)
    call check(.not. err%raised, 'discard: previous checkpoint still reads')
    call checkpoint_begin_read(ck, base, MPI_COMM_WORLD, h, err)
    call check(h%increment == header%increment, 'discard: previous header kept')
  end subroutine test_discard_keeps_previous

  !> What a crash between the ranks' renames leaves: files of two increments.
  subroutine test_mixed_increments()
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: h, mine
    type(error_t) :: err

    if (nranks == 1) return
    mine = header
    mine%increment = header%increment + rank
    call write_all(base // '_mixed', mine)
    call checkpoint_begin_read(ck, base // '_mixed', MPI_COMM_WORLD, h, err)
    call check_message(err%raised, err%message, 'files are of different increments', &
         'mixed increments')
  end subroutine test_mixed_increments

  subroutine test_truncated()
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: h
    type(error_t) :: err
    integer :: unit

    call write_all(base // '_short', header)
    call MPI_Barrier(MPI_COMM_WORLD)
    if (rank == 0) then
       open (newunit=unit, file=checkpoint_file_name(base // '_short', 0), access='stream', &
            form='unformatted', status='replace', action='write')
       write (unit) 'BFLOWRST', 1
       close (unit)
    end if
    call MPI_Barrier(MPI_COMM_WORLD)
    call checkpoint_begin_read(ck, base // '_short', MPI_COMM_WORLD, h, err)
    call check_message(err%raised, err%message, 'truncated header', 'truncated file')
  end subroutine test_truncated

end program test_output_checkpoint
