!> Thin wrappers around the MPI calls the solver needs, always on a communicator handed in by
!> the caller (the library never names MPI_COMM_WORLD, so tests and embedding codes can run it
!> on any sub-communicator).
!>
!> * `comm_rank`, `comm_size`, `comm_barrier`
!> * `comm_min`, `comm_max`, `comm_sum`: in-place all-reductions of integers and real(dp)
!>   scalars and arrays (every rank ends with the result)
!> * `comm_bcast`: integers, reals, logicals, strings from a root rank
!> * `comm_max_owner`: element-wise maximum over the ranks and the lowest rank that holds it
!> * `comm_allgather`: every rank's array of one length, side by side in rank order, on every rank
!> * `comm_send`, `comm_recv`: blocking point-to-point transfer of integer and real(dp) arrays
!> * `comm_sum_exact`: an all-reduced sum of real(dp) values that is EXACT before one final
!>   rounding, hence identical whatever the number of ranks and however the values are spread
!>   over them (a plain MPI_SUM depends on both)
!>
!> MPI errors are left to the communicator's error handler (MPI_ERRORS_ARE_FATAL by default),
!> so the wrappers pass no ierror.
module parallel_comm
  use, intrinsic :: iso_fortran_env, only: int64
  use mpi_f08, only: MPI_Comm, MPI_Datatype, MPI_Op, MPI_Comm_rank, MPI_Comm_size, MPI_Barrier, &
       MPI_Allreduce, MPI_Bcast, MPI_IN_PLACE, MPI_MIN, MPI_MAX, MPI_SUM, MPI_LOR, MPI_MAXLOC, &
       MPI_INTEGER, MPI_INTEGER8, MPI_DOUBLE_PRECISION, MPI_2DOUBLE_PRECISION, MPI_LOGICAL, MPI_CHARACTER, &
       MPI_Send, MPI_Recv, MPI_STATUS_IGNORE, MPI_Allgather
  use base_kinds, only: dp
  implicit none
  private

  public :: comm_rank, comm_size, comm_barrier
  public :: comm_min, comm_max, comm_sum, comm_any
  public :: comm_bcast
  public :: comm_sum_exact
  public :: comm_max_owner, comm_send, comm_recv
  public :: comm_allgather
  public :: comm_sum_pieces

  !> True on every rank where the flag is true on at least one rank (arrays: element by element).
  interface comm_any
     module procedure any_scalar, any_array
  end interface comm_any

  !> Blocking send of an integer or real(dp) array to rank `dest` with message tag `tag`.
  interface comm_send
     module procedure send_int_array, send_real_array
  end interface comm_send

  !> Blocking receive of an integer or real(dp) array (its whole size) from rank `source`.
  interface comm_recv
     module procedure recv_int_array, recv_real_array
  end interface comm_recv

  !> In-place global minimum over the ranks of `comm` (arrays: element by element).
  interface comm_min
     module procedure min_int, min_int_array, min_real, min_real_array
  end interface comm_min

  !> In-place global maximum.
  interface comm_max
     module procedure max_int, max_int_array, max_real, max_real_array
  end interface comm_max

  !> In-place global sum. Real sums are NOT reproducible across rank counts (MPI's reduction
  !> order depends on the number of ranks); use comm_sum_exact where that matters.
  interface comm_sum
     module procedure sum_int, sum_int_array, sum_real, sum_real_array, sum_real_matrix
  end interface comm_sum

  !> Broadcast from `root` (in place).
  interface comm_bcast
     module procedure bcast_int, bcast_int_array, bcast_real, bcast_real_array, bcast_logical, &
          bcast_string
  end interface comm_bcast

  !> all(:, r) ← rank r's `mine` (every rank passes the same length). Collective.
  interface comm_allgather
     module procedure allgather_int, allgather_real
  end interface comm_allgather

  !> Exact all-reduced sum: of a rank-1 array into a scalar, or of each column of a rank-2
  !> array into a rank-1 result (one reduction for several sums).
  interface comm_sum_exact
     module procedure sum_exact_1, sum_exact_2
  end interface comm_sum_exact

  ! The exact accumulator: a fixed-point integer of `acc_words` digits of 32 bits, held in 64-bit
  ! words so that up to 2^30 additions fit before the carries must be propagated. Digit k stands
  ! for 2^(32 k + acc_lsb) (k = 0 .. acc_words-1); acc_lsb is the weight of the last mantissa bit
  ! of the smallest subnormal, and 70 digits reach past the largest double (2^1024) with room
  ! for carries.
  integer, parameter :: acc_words = 70
  integer, parameter :: acc_lsb = -1126
  integer, parameter :: acc_flush = 2**30
  integer(int64), parameter :: digit_mask = int(z'FFFFFFFF', int64)
  !> Most values one MPI reduction call carries (comm_sum_pieces).
  integer(int64), parameter, public :: max_reduce_count = 2_int64**30

contains

  !> Rank of this process in `comm` (0-based).
  integer function comm_rank(comm)
    type(MPI_Comm), intent(in) :: comm   !< communicator
    call MPI_Comm_rank(comm, comm_rank)
  end function comm_rank

  !> Number of ranks in `comm`.
  integer function comm_size(comm)
    type(MPI_Comm), intent(in) :: comm   !< communicator
    call MPI_Comm_size(comm, comm_size)
  end function comm_size

  !> Wait until every rank of `comm` gets here.
  subroutine comm_barrier(comm)
    type(MPI_Comm), intent(in) :: comm   !< communicator
    call MPI_Barrier(comm)
  end subroutine comm_barrier

  !> True on every rank when `flag` is true on at least one (e.g. "some rank failed").
  subroutine any_scalar(comm, flag)
    type(MPI_Comm), intent(in) :: comm   !< communicator
    logical, intent(inout) :: flag       !< local flag in, global OR out
    call MPI_Allreduce(MPI_IN_PLACE, flag, 1, MPI_LOGICAL, MPI_LOR, comm)
  end subroutine any_scalar

  subroutine any_array(comm, flags)
    type(MPI_Comm), intent(in) :: comm
    logical, contiguous, intent(inout) :: flags(:)
    call MPI_Allreduce(MPI_IN_PLACE, flags, size(flags), MPI_LOGICAL, MPI_LOR, comm)
  end subroutine any_array

  !> values(i) ← its maximum over the ranks, owner(i) ← the lowest rank holding that maximum
  !> (MPI_MAXLOC; ties go to the lower rank, so exactly one rank is the owner). Collective.
  subroutine comm_max_owner(comm, values, owner)
    type(MPI_Comm), intent(in) :: comm
    real(dp), intent(inout) :: values(:)
    integer, intent(out) :: owner(:)     !< size(values)
    real(dp) :: pair(2, size(values))
    integer :: i, rank

    call MPI_Comm_rank(comm, rank)
    do i = 1, size(values)
       pair(1, i) = values(i)
       pair(2, i) = real(rank, dp)
    end do
    call MPI_Allreduce(MPI_IN_PLACE, pair, size(values), MPI_2DOUBLE_PRECISION, MPI_MAXLOC, comm)
    do i = 1, size(values)
       values(i) = pair(1, i)
       owner(i) = nint(pair(2, i))
    end do
  end subroutine comm_max_owner

  subroutine allgather_int(comm, mine, all)
    type(MPI_Comm), intent(in) :: comm
    integer, contiguous, intent(in) :: mine(:)
    integer, contiguous, intent(out) :: all(:, 0:)     !< (size(mine), 0:nranks − 1)
    call MPI_Allgather(mine, size(mine), MPI_INTEGER, all, size(mine), MPI_INTEGER, comm)
  end subroutine allgather_int

  subroutine allgather_real(comm, mine, all)
    type(MPI_Comm), intent(in) :: comm
    real(dp), contiguous, intent(in) :: mine(:)
    real(dp), contiguous, intent(out) :: all(:, 0:)    !< (size(mine), 0:nranks − 1)
    call MPI_Allgather(mine, size(mine), MPI_DOUBLE_PRECISION, all, size(mine), MPI_DOUBLE_PRECISION, comm)
  end subroutine allgather_real

  ! --- point to point -------------------------------------------------------------------------

  subroutine send_int_array(comm, x, dest, tag)
    type(MPI_Comm), intent(in) :: comm
    integer, contiguous, intent(in) :: x(:)
    integer, intent(in) :: dest, tag
    call MPI_Send(x, size(x), MPI_INTEGER, dest, tag, comm)
  end subroutine send_int_array

  subroutine send_real_array(comm, x, dest, tag)
    type(MPI_Comm), intent(in) :: comm
    real(dp), contiguous, intent(in) :: x(:)
    integer, intent(in) :: dest, tag
    call MPI_Send(x, size(x), MPI_DOUBLE_PRECISION, dest, tag, comm)
  end subroutine send_real_array

  subroutine recv_int_array(comm, x, source, tag)
    type(MPI_Comm), intent(in) :: comm
    integer, contiguous, intent(inout) :: x(:)
    integer, intent(in) :: source, tag
    call MPI_Recv(x, size(x), MPI_INTEGER, source, tag, comm, MPI_STATUS_IGNORE)
  end subroutine recv_int_array

  subroutine recv_real_array(comm, x, source, tag)
    type(MPI_Comm), intent(in) :: comm
    real(dp), contiguous, intent(inout) :: x(:)
    integer, intent(in) :: source, tag
    call MPI_Recv(x, size(x), MPI_DOUBLE_PRECISION, source, tag, comm, MPI_STATUS_IGNORE)
  end subroutine recv_real_array

  ! --- reductions ------------------------------------------------------------------------------

  subroutine min_int(comm, x)
    type(MPI_Comm), intent(in) :: comm
    integer, intent(inout) :: x
    call MPI_Allreduce(MPI_IN_PLACE, x, 1, MPI_INTEGER, MPI_MIN, comm)
  end subroutine min_int

  subroutine min_int_array(comm, x)
    type(MPI_Comm), intent(in) :: comm
    integer, contiguous, intent(inout) :: x(:)
    call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_INTEGER, MPI_MIN, comm)
  end subroutine min_int_array

  subroutine min_real(comm, x)
    type(MPI_Comm), intent(in) :: comm
    real(dp), intent(inout) :: x
    call MPI_Allreduce(MPI_IN_PLACE, x, 1, MPI_DOUBLE_PRECISION, MPI_MIN, comm)
  end subroutine min_real

  subroutine min_real_array(comm, x)
    type(MPI_Comm), intent(in) :: comm
    real(dp), contiguous, intent(inout) :: x(:)
    call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_DOUBLE_PRECISION, MPI_MIN, comm)
  end subroutine min_real_array

  subroutine max_int(comm, x)
    type(MPI_Comm), intent(in) :: comm
    integer, intent(inout) :: x
    call MPI_Allreduce(MPI_IN_PLACE, x, 1, MPI_INTEGER, MPI_MAX, comm)
  end subroutine max_int

  subroutine max_int_array(comm, x)
    type(MPI_Comm), intent(in) :: comm
    integer, contiguous, intent(inout) :: x(:)
    call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_INTEGER, MPI_MAX, comm)
  end subroutine max_int_array

  subroutine max_real(comm, x)
    type(MPI_Comm), intent(in) :: comm
    real(dp), intent(inout) :: x
    call MPI_Allreduce(MPI_IN_PLACE, x, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
  end subroutine max_real

  subroutine max_real_array(comm, x)
    type(MPI_Comm), intent(in) :: comm
    real(dp), contiguous, intent(inout) :: x(:)
    call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_DOUBLE_PRECISION, MPI_MAX, comm)
  end subroutine max_real_array

  subroutine sum_int(comm, x)
    type(MPI_Comm), intent(in) :: comm
    integer, intent(inout) :: x
    call MPI_Allreduce(MPI_IN_PLACE, x, 1, MPI_INTEGER, MPI_SUM, comm)
  end subroutine sum_int

  subroutine sum_int_array(comm, x)
    type(MPI_Comm), intent(in) :: comm
    integer, contiguous, intent(inout) :: x(:)
    call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_INTEGER, MPI_SUM, comm)
  end subroutine sum_int_array

  subroutine sum_real(comm, x)
    type(MPI_Comm), intent(in) :: comm
    real(dp), intent(inout) :: x
    call MPI_Allreduce(MPI_IN_PLACE, x, 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
  end subroutine sum_real

  subroutine sum_real_array(comm, x)
    type(MPI_Comm), intent(in) :: comm
    real(dp), contiguous, intent(inout) :: x(:)
    call comm_sum_pieces(comm, x, size(x, kind=int64), max_reduce_count)
  end subroutine sum_real_array

  subroutine sum_real_matrix(comm, x)
    type(MPI_Comm), intent(in) :: comm
    real(dp), contiguous, intent(inout) :: x(:, :)
    call comm_sum_pieces(comm, x, size(x, kind=int64), max_reduce_count)
  end subroutine sum_real_matrix

  !> In-place sum of the n values of x over the ranks, `piece` values per MPI call at most: an
  !> MPI count is a default integer, and a replicated 3D grid of 307 M nodes already sums more
  !> than 2^31 − 1 values at once (mpm_musl). n is 64-bit; below `piece` it is one call, as
  !> before. Public with its piece size for the test of the splitting.
  subroutine comm_sum_pieces(comm, x, n, piece)
    type(MPI_Comm), intent(in) :: comm
    integer(int64), intent(in) :: n
    real(dp), intent(inout) :: x(n)
    integer(int64), intent(in) :: piece
    integer(int64) :: first, count

    first = 1
    do while (first <= n)
       count = min(piece, n - first + 1)
       call MPI_Allreduce(MPI_IN_PLACE, x(first:first + count - 1), int(count), MPI_DOUBLE_PRECISION, &
            MPI_SUM, comm)
       first = first + count
    end do
  end subroutine comm_sum_pieces

  ! --- broadcasts ------------------------------------------------------------------------------

  subroutine bcast_int(comm, x, root)
    type(MPI_Comm), intent(in) :: comm
    integer, intent(inout) :: x
    integer, intent(in) :: root
    call MPI_Bcast(x, 1, MPI_INTEGER, root, comm)
  end subroutine bcast_int

  subroutine bcast_int_array(comm, x, root)
    type(MPI_Comm), intent(in) :: comm
    integer, contiguous, intent(inout) :: x(:)
    integer, intent(in) :: root
    call MPI_Bcast(x, size(x), MPI_INTEGER, root, comm)
  end subroutine bcast_int_array

  subroutine bcast_real(comm, x, root)
    type(MPI_Comm), intent(in) :: comm
    real(dp), intent(inout) :: x
    integer, intent(in) :: root
    call MPI_Bcast(x, 1, MPI_DOUBLE_PRECISION, root, comm)
  end subroutine bcast_real

  subroutine bcast_real_array(comm, x, root)
    type(MPI_Comm), intent(in) :: comm
    real(dp), contiguous, intent(inout) :: x(:)
    integer, intent(in) :: root
    call MPI_Bcast(x, size(x), MPI_DOUBLE_PRECISION, root, comm)
  end subroutine bcast_real_array

  subroutine bcast_logical(comm, x, root)
    type(MPI_Comm), intent(in) :: comm
    logical, intent(inout) :: x
    integer, intent(in) :: root
    call MPI_Bcast(x, 1, MPI_LOGICAL, root, comm)
  end subroutine bcast_logical

  !> A fixed-length string: every rank must pass the same length.
  subroutine bcast_string(comm, x, root)
    type(MPI_Comm), intent(in) :: comm
    character(len=*), intent(inout) :: x
    integer, intent(in) :: root
    call MPI_Bcast(x, len(x), MPI_CHARACTER, root, comm)
  end subroutine bcast_string

  ! --- exact sums ------------------------------------------------------------------------------

  !> Sum of `values` over all ranks of `comm`, the same bits whatever the rank count and the
  !> distribution of the values: each rank adds its values exactly into a fixed-point
  !> accumulator, the accumulators are summed as integers (associative, so the MPI reduction
  !> order cannot matter), and the exact total is rounded once. A NaN or infinity anywhere
  !> makes the result NaN/infinity like an ordinary sum. Collective.
  subroutine sum_exact_1(comm, values, total)
    type(MPI_Comm), intent(in) :: comm       !< communicator
    real(dp), intent(in) :: values(:)        !< this rank's values
    real(dp), intent(out) :: total           !< the sum over all ranks (same on every rank)
    real(dp) :: totals(1)

    call sum_exact_2(comm, reshape(values, [size(values), 1]), totals)
    total = totals(1)
  end subroutine sum_exact_1

  !> Exact sums of the columns of `values` over all ranks: totals(j) = Σ values(:, j).
  subroutine sum_exact_2(comm, values, totals)
    type(MPI_Comm), intent(in) :: comm       !< communicator
    real(dp), intent(in) :: values(:, :)     !< this rank's values, one column per sum
    real(dp), intent(out) :: totals(:)       !< size(values, 2) sums, the same on every rank
    integer(int64), allocatable :: acc(:, :)
    real(dp), allocatable :: inexact(:)
    integer :: i, j, m, since_flush

    m = size(values, 2)
    allocate (acc(0:acc_words - 1, m), inexact(m))
    acc = 0
    inexact = 0
    do j = 1, m
       since_flush = 0
       do i = 1, size(values, 1)
          if (abs(values(i, j)) <= huge(1.0_dp)) then
             call accumulate(acc(:, j), values(i, j))
             since_flush = since_flush + 1
             if (since_flush == acc_flush) then
                call propagate_carries(acc(:, j))
                since_flush = 0
             end if
          else
             ! NaN or infinity: carried on the side, where ordinary arithmetic propagates it
             inexact(j) = inexact(j) + values(i, j)
          end if
       end do
       call propagate_carries(acc(:, j))
    end do
    ! After propagation every digit is below 2^32 in magnitude, so the integer sum over ranks
    ! cannot overflow for any realistic number of ranks.
    call MPI_Allreduce(MPI_IN_PLACE, acc, size(acc), MPI_INTEGER8, MPI_SUM, comm)
    call MPI_Allreduce(MPI_IN_PLACE, inexact, m, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
    do j = 1, m
       call propagate_carries(acc(:, j))
       totals(j) = accumulator_value(acc(:, j)) + inexact(j)
    end do
  end subroutine sum_exact_2

  !> acc += x exactly, for finite x. x = m 2^p with an integer |m| < 2^53; the 53 bits, shifted
  !> to their place, straddle at most three 32-bit digits.
  pure subroutine accumulate(acc, x)
    integer(int64), intent(inout) :: acc(0:)
    real(dp), intent(in) :: x
    integer(int64) :: m
    integer :: e, pos, k, s

    if (.not. abs(x) > 0) return            ! zero (NaN and infinity never get here)
    e = exponent(x)
    m = int(scale(abs(x), digits(x) - e), int64)
    pos = e - digits(x) - acc_lsb          ! bit position of m's last bit in the accumulator
    k = pos / 32
    s = pos - 32 * k
    if (x < 0) then
       acc(k) = acc(k) - iand(ishft(m, s), digit_mask)
       acc(k + 1) = acc(k + 1) - iand(ishft(m, s - 32), digit_mask)
       acc(k + 2) = acc(k + 2) - ishft(m, s - 64)
    else
       acc(k) = acc(k) + iand(ishft(m, s), digit_mask)
       acc(k + 1) = acc(k + 1) + iand(ishft(m, s - 32), digit_mask)
       acc(k + 2) = acc(k + 2) + ishft(m, s - 64)
    end if
  end subroutine accumulate

  !> Bring every digit but the last into [0, 2^32), moving the excess up; the last digit
  !> carries the sign. The result is the unique representation of the accumulated integer,
  !> which is what makes the final rounding reproducible.
  pure subroutine propagate_carries(acc)
    integer(int64), intent(inout) :: acc(0:)
    integer(int64) :: carry
    integer :: k

    do k = 0, size(acc) - 2
       carry = shifta(acc(k), 32)          ! floor(acc(k) / 2^32), also for negative digits
       acc(k) = acc(k) - ishft(carry, 32)
       acc(k + 1) = acc(k + 1) + carry
    end do
  end subroutine propagate_carries

  !> The accumulated value as a double: digits summed from the most significant down, which
  !> keeps the error within a few units in the last place (the input, being canonical, fixes
  !> the output bits).
  pure real(dp) function accumulator_value(acc_in) result(value)
    integer(int64), intent(in) :: acc_in(0:)
    integer(int64) :: acc(0:size(acc_in) - 1)
    real(dp) :: sign
    integer :: k, top

    acc = acc_in
    sign = 1
    top = size(acc) - 1
    if (acc(top) < 0) then
       ! negative total: negate the digits and make them canonical again
       sign = -1
       acc = -acc
       call propagate_carries(acc)
    end if
    value = 0
    do k = top, 0, -1
       if (acc(k) /= 0) value = value + scale(real(acc(k), dp), 32 * k + acc_lsb)
    end do
    value = sign * value
  end function accumulator_value

end module parallel_comm
