!> MPI test of the reductions, run by CTest on 1, 2, 3 and 4 ranks: comm_* and global_*
!> min/max/sum of integers and reals (scalars and arrays), broadcasts, comm_any, and the exact
!> sum: the same bits for any rank count and any spreading of the values, exact on sums that
!> cancel, within one unit in the last place of a quad-precision reference.
program test_parallel_reductions
  use, intrinsic :: iso_fortran_env, only: real128
  use mpi_f08, only: MPI_Comm, MPI_COMM_WORLD, MPI_COMM_SELF, MPI_Init, MPI_Finalize
  use material_kinds, only: dp
  use model_mesh, only: mesh_t
  use parallel_comm, only: comm_rank, comm_size, comm_barrier, comm_min, comm_max, comm_sum, &
       comm_any, comm_bcast, comm_sum_exact, comm_sum_pieces
  use parallel_partition, only: partition_t, partition_mesh
  use parallel_assembly, only: global_min, global_max, global_sum, global_sum_exact
  use parallel_test_support, only: quad_mesh, contribution, check, check_summary, same_bits, eq
  implicit none

  type(MPI_Comm) :: comm
  integer :: rank, nranks, failed

  call MPI_Init()
  comm = MPI_COMM_WORLD
  rank = comm_rank(comm)
  nranks = comm_size(comm)

  call check_plain_reductions()
  call check_partition_reductions()
  call check_broadcasts()
  call check_exact_sums()
  call check_sum_in_pieces()
  call comm_barrier(comm)

  failed = check_summary(comm, 'test_parallel_reductions')
  call MPI_Finalize()
  if (failed > 0) error stop 1

contains

  !> A sum split into MPI calls of at most `piece` values (how arrays beyond 2^31 values are
  !> reduced) gives the bits of the sum in one call, for pieces that divide the length and not.
  subroutine check_sum_in_pieces()
    use, intrinsic :: iso_fortran_env, only: int64
    real(dp) :: whole(23), split(23), matrix(3, 5)
    integer :: i, piece

    do i = 1, 23
       whole(i) = (rank + 1) * 0.1_dp * i + 1.0_dp / (i + rank)
    end do
    split = whole
    call comm_sum(comm, whole)
    do piece = 1, 24
       split = [((rank + 1) * 0.1_dp * i + 1.0_dp / (i + rank), i = 1, 23)]
       call comm_sum_pieces(comm, split, 23_int64, int(piece, int64))
       call check(same_bits(split, whole), 'comm_sum_pieces equals one comm_sum', rank)
    end do
    matrix = reshape([(real(i * (rank + 1), dp), i = 1, 15)], [3, 5])
    call comm_sum(comm, matrix)
    call check(all(eq(matrix, reshape([(real(i * nranks * (nranks + 1) / 2, dp), i = 1, 15)], [3, 5]))), &
         'comm_sum of a matrix (through comm_sum_pieces)', rank)
  end subroutine check_sum_in_pieces

  subroutine check_plain_reductions()
    integer :: i, ia(3)
    real(dp) :: x, xa(2)
    logical :: flag

    i = rank + 1
    call comm_min(comm, i)
    call check(i == 1, 'comm_min integer', rank)
    i = rank + 1
    call comm_max(comm, i)
    call check(i == nranks, 'comm_max integer', rank)
    i = rank + 1
    call comm_sum(comm, i)
    call check(i == nranks * (nranks + 1) / 2, 'comm_sum integer', rank)
    ia = [rank, -rank, 2]
    call comm_sum(comm, ia)
    call check(all(ia == [nranks * (nranks - 1) / 2, -nranks * (nranks - 1) / 2, 2 * nranks]), &
         'comm_sum integer array', rank)
    ia = [rank, -rank, 7]
    call comm_min(comm, ia)
    call check(all(ia == [0, 1 - nranks, 7]), 'comm_min integer array', rank)
    ia = [rank, -rank, 7]
    call comm_max(comm, ia)
    call check(all(ia == [nranks - 1, 0, 7]), 'comm_max integer array', rank)

    x = 0.5_dp * (rank + 1)
    call comm_min(comm, x)
    call check(eq(x, 0.5_dp), 'comm_min real', rank)
    x = 0.5_dp * (rank + 1)
    call comm_max(comm, x)
    call check(eq(x, 0.5_dp * nranks), 'comm_max real', rank)
    x = 0.5_dp * (rank + 1)
    call comm_sum(comm, x)
    call check(eq(x, 0.25_dp * nranks * (nranks + 1)), 'comm_sum real', rank)
    xa = [1.0_dp, -0.25_dp * rank]
    call comm_sum(comm, xa)
    call check(all(eq(xa, [real(nranks, dp), -0.125_dp * nranks * (nranks - 1)])), 'comm_sum real array', rank)
    xa = [real(rank, dp), -real(rank, dp)]
    call comm_min(comm, xa)
    call check(all(eq(xa, [0.0_dp, real(1 - nranks, dp)])), 'comm_min real array', rank)
    xa = [real(rank, dp), -real(rank, dp)]
    call comm_max(comm, xa)
    call check(all(eq(xa, [real(nranks - 1, dp), 0.0_dp])), 'comm_max real array', rank)

    flag = rank == nranks - 1
    call comm_any(comm, flag)
    call check(flag, 'comm_any: true somewhere', rank)
    flag = .false.
    call comm_any(comm, flag)
    call check(.not. flag, 'comm_any: false everywhere', rank)
  end subroutine check_plain_reductions

  !> global_* on a partition: the stable time increment is a min over elements, energies sums.
  subroutine check_partition_reductions()
    type(mesh_t) :: mesh
    type(partition_t) :: part
    real(dp) :: dt, energy, e_exact, e_serial, v(3)
    real(dp), allocatable :: per_elem(:)
    integer :: n, le, i, ia(2)

    call quad_mesh(13, 7, .true., mesh)
    call partition_mesh(mesh, comm, part)
    ! element "dt" = 1 + global index / 1000: the minimum is element 1's, wherever it is
    dt = huge(1.0_dp)
    do le = 1, part%n_local_elems
       dt = min(dt, 1 + part%elem_global(le) / 1000.0_dp)
    end do
    call global_min(part, dt)
    call check(eq(dt, 1 + 1 / 1000.0_dp), 'global_min: stable increment over elements', rank)
    n = part%n_local_elems
    call global_sum(part, n)
    call check(n == mesh%n_elems, 'global_sum integer: element count', rank)
    ia = [part%n_local_elems, -part%n_local_elems]
    call global_max(part, ia)
    call check(ia(1) >= (mesh%n_elems + nranks - 1) / nranks .and. ia(2) <= 0, 'global_max integer array', rank)
    call global_min(part, ia)
    call check(ia(1) >= 0, 'global_min integer array', rank)

    ! per-element energies that are exact binary fractions: any order sums them exactly
    allocate (per_elem(part%n_local_elems))
    do le = 1, part%n_local_elems
       per_elem(le) = part%elem_global(le) * 0.25_dp
    end do
    energy = sum(per_elem)
    call global_sum(part, energy)
    call check(eq(energy, 0.125_dp * mesh%n_elems * (mesh%n_elems + 1)), 'global_sum real', rank)
    v = [energy, -energy, 1.0_dp]
    call global_max(part, v)
    call global_min(part, v)
    call check(eq(v(3), 1.0_dp), 'global_max/min real array', rank)
    call global_sum(part, v)
    call check(eq(v(3), real(nranks, dp)), 'global_sum real array', rank)

    ! order-sensitive energies: the exact sum equals the exact sum of all values on one rank
    do le = 1, part%n_local_elems
       per_elem(le) = contribution(part%elem_global(le), 1, 1)
    end do
    call global_sum_exact(part, per_elem, e_exact)
    call comm_sum_exact(MPI_COMM_SELF, [(contribution(i, 1, 1), i = 1, mesh%n_elems)], e_serial)
    call check(same_bits([e_exact], [e_serial]), 'global_sum_exact: same bits as on one rank', rank)
    dt = e_exact
    call global_max(part, dt)
    call check(same_bits([dt], [e_exact]), 'global_sum_exact: same bits on every rank', rank)
  end subroutine check_partition_reductions

  subroutine check_broadcasts()
    integer :: i, ia(3), root
    real(dp) :: x, xa(2)
    logical :: flag
    character(len=12) :: text

    root = nranks - 1
    i = -1
    ia = -1
    x = -1
    xa = -1
    flag = .false.
    text = 'nothing'
    if (rank == root) then
       i = 42
       ia = [1, 2, 3]
       x = 0.1_dp
       xa = [0.2_dp, -0.3_dp]
       flag = .true.
       text = 'from root'
    end if
    call comm_bcast(comm, i, root)
    call comm_bcast(comm, ia, root)
    call comm_bcast(comm, x, root)
    call comm_bcast(comm, xa, root)
    call comm_bcast(comm, flag, root)
    call comm_bcast(comm, text, root)
    call check(i == 42 .and. all(ia == [1, 2, 3]), 'comm_bcast integers', rank)
    call check(eq(x, 0.1_dp) .and. all(eq(xa, [0.2_dp, -0.3_dp])), 'comm_bcast reals', rank)
    call check(flag .and. text == 'from root', 'comm_bcast logical and string', rank)
  end subroutine check_broadcasts

  subroutine check_exact_sums()
    integer, parameter :: n = 20000
    real(dp), allocatable :: all_values(:), mine(:), cols(:, :)
    real(dp) :: total, serial, tiny_sub, plain, both(2), both_serial(2)
    real(real128) :: quad
    integer :: i

    allocate (all_values(n))
    do i = 1, n
       all_values(i) = contribution(i, 2, 3)
    end do
    ! reference: on one rank, everything
    call comm_sum_exact(MPI_COMM_SELF, all_values, serial)
    ! round robin over the ranks
    mine = all_values(rank + 1:n:nranks)
    call comm_sum_exact(comm, mine, total)
    call check(same_bits([total], [serial]), 'comm_sum_exact: round robin = one rank, bitwise', rank)
    ! reversed blocks: another spreading, another local order
    mine = all_values(((rank + 1) * n) / nranks:(rank * n) / nranks + 1:-1)
    call comm_sum_exact(comm, mine, total)
    call check(same_bits([total], [serial]), 'comm_sum_exact: reversed blocks = one rank, bitwise', rank)
    ! accuracy: exponents span 2^-20 .. 2^20, so a quad-precision sum is exact here
    quad = 0
    do i = 1, n
       quad = quad + real(all_values(i), real128)
    end do
    call check(abs(real(quad, dp) - serial) <= spacing(serial), 'comm_sum_exact: within 1 ulp of the exact sum', rank)
    plain = sum(all_values)
    call check(abs(plain - serial) < 1.0e-9_dp * maxval(abs(all_values)), 'comm_sum_exact: close to a plain sum', rank)

    ! cancellation: 1e100 + 1 - 1e100 = 1 exactly, the three values on different ranks
    mine = pack([1.0e100_dp, 1.0_dp, -1.0e100_dp], [(modulo(i, nranks) == rank, i = 0, 2)])
    call comm_sum_exact(comm, mine, total)
    call check(eq(total, 1.0_dp), 'comm_sum_exact: 1e100 + 1 - 1e100 = 1', rank)
    ! subnormals next to the largest double
    tiny_sub = scale(1.0_dp, minexponent(1.0_dp) - digits(1.0_dp))
    mine = pack([huge(1.0_dp), tiny_sub, -huge(1.0_dp), tiny_sub], [(modulo(i, nranks) == rank, i = 0, 3)])
    call comm_sum_exact(comm, mine, total)
    call check(eq(total, 2 * tiny_sub) .and. total > 0, 'comm_sum_exact: huge - huge + 2 smallest subnormals', rank)
    ! negative total, and a rank with nothing to add
    if (rank == 0) then
       mine = [-3.5_dp, 1.25_dp]
    else
       deallocate (mine)
       allocate (mine(0))
    end if
    call comm_sum_exact(comm, mine, total)
    call check(eq(total, -2.25_dp), 'comm_sum_exact: negative total, empty ranks', rank)

    ! several sums in one reduction
    allocate (cols(size(all_values(rank + 1:n:nranks)), 2))
    cols(:, 1) = all_values(rank + 1:n:nranks)
    cols(:, 2) = -2 * cols(:, 1)
    call comm_sum_exact(comm, cols, both)
    call comm_sum_exact(MPI_COMM_SELF, reshape([all_values, -2 * all_values], [n, 2]), both_serial)
    call check(same_bits(both, both_serial) .and. same_bits([both(1)], [serial]), &
         'comm_sum_exact: columns, bitwise', rank)
  end subroutine check_exact_sums

end program test_parallel_reductions
