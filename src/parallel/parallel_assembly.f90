!> Assembly of per-element nodal vectors into nodal vectors, bitwise independent of the number
!> of ranks, and the reductions the solver needs on a partition.
!>
!> The rule (docs/solver_interfaces.md §4): every node's value is summed from zero over its
!> (element, slot) contributions in ascending global element index (slot order within an
!> element), f = ((0 + c_1) + c_2) + ... A serial scatter over the elements in ascending order
!> does exactly that, and so does the scatter over this rank's elements for the nodes no other
!> rank holds, because local elements are kept in ascending global order. A shared node's sum
!> would interleave elements of several ranks, so each rank sends its contributions to the
!> neighbours holding the node and every holder re-adds all of them, from zero, in the global
!> order; the plan made by partition_mesh says where each value comes from, so messages carry
!> values only, to the neighbouring ranks only.
module parallel_assembly
  use mpi_f08, only: MPI_Request, MPI_Isend, MPI_Irecv, MPI_Waitall, MPI_STATUSES_IGNORE, &
       MPI_DOUBLE_PRECISION, MPI_F_sync_reg
  use base_kinds, only: dp
  use error_report, only: raise_error
  use parallel_comm, only: comm_min, comm_max, comm_sum, comm_sum_exact
  use parallel_partition, only: partition_t
  implicit none
  private

  public :: assemble_element_vectors
  public :: block_assembly_init, assembly_start, assembly_add_block, assembly_finish
  public :: global_min, global_max, global_sum, global_sum_exact

  !> In-place minimum over the ranks of the partition (integer or real(dp), scalar or array).
  interface global_min
     module procedure min_int, min_int_array, min_real, min_real_array
  end interface global_min

  !> In-place maximum over the ranks of the partition.
  interface global_max
     module procedure max_int, max_int_array, max_real, max_real_array
  end interface global_max

  !> In-place sum over the ranks of the partition. Real sums depend on the rank count in the
  !> last bits (fine for energies); global_sum_exact does not.
  interface global_sum
     module procedure sum_int, sum_int_array, sum_real, sum_real_array
  end interface global_sum

  !> Sum of all ranks' values, exact before a single rounding, hence the same bits for any
  !> number of ranks: values(:) -> total, or values(:, m) -> totals(m) in one reduction.
  interface global_sum_exact
     module procedure sum_exact_1, sum_exact_2
  end interface global_sum_exact

  !> Assembly block by block, as the element phase makes the contributions: assembly_start
  !> zeroes f, assembly_add_block scatters one block of consecutive local elements (the blocks
  !> in ascending order) and stages its contributions to shared nodes, assembly_finish
  !> exchanges those and re-sums the shared nodes. Why: the whole-model array of element
  !> vectors the one-call form needs (n_local_elems x ndim x nen, 1.3 MB for 20 000 CPE4R) was
  !> written by the element phase and read back by the assembly every increment, far out of
  !> cache; a block's vectors are scattered while they are still in it. The same sums in the
  !> same order as assemble_element_vectors (which is built from these three), so the same bits.
  type, public :: block_assembly_t
     integer :: ncomp = 0
     integer, allocatable :: elem_contrib_ptr(:)   !< (n_local_elems+1) into elem_contrib
     integer, allocatable :: elem_contrib(:)       !< contribution indices j of each element
     real(dp), allocatable :: staged(:, :)         !< (ncomp, n_local_contrib) our contributions
  end type block_assembly_t

  ! The message tag of the assembly exchange: any fixed value does, since each pair of ranks
  ! exchanges one message per direction and call, and MPI keeps such messages in order.
  integer, parameter :: assembly_tag = 7301

contains

  !> f(:, i) = Σ of the contributions fe(e, :, a) of all elements e (on any rank) with
  !> conn(a, e) = node i, added in ascending global element order starting from zero. Every
  !> rank holding a node gets the same value, and the values do not depend on the number of
  !> ranks. Collective over the neighbours of this rank (every rank must call it).
  subroutine assemble_element_vectors(part, ncomp, fe, f)
    type(partition_t), intent(in) :: part   !< the partition
    integer, intent(in) :: ncomp            !< components per node (e.g. ndim)
    real(dp), contiguous, intent(in) :: fe(:, :, :)  !< (n_local_elems, ncomp, nen) element contributions
    real(dp), contiguous, intent(out) :: f(:, :)     !< (ncomp, n_local_nodes) assembled nodal vectors
    type(block_assembly_t) :: ba

    if (size(fe, 1) /= part%n_local_elems .or. size(fe, 2) /= ncomp .or. &
         size(fe, 3) /= part%nen) then
       call raise_error('', 0, 'assemble_element_vectors: fe must be (n_local_elems, ncomp, nen)')
    end if
    if (size(f, 1) /= ncomp .or. size(f, 2) /= part%n_local_nodes) then
       call raise_error('', 0, 'assemble_element_vectors: f must be (ncomp, n_local_nodes)')
    end if
    call block_assembly_init(part, ncomp, ba)
    call assembly_start(f)
    call assembly_add_block(part, ba, 1, part%n_local_elems, fe, f)
    call assembly_finish(part, ba, f)
  end subroutine assemble_element_vectors

  !> The per-element lists of contributions to shared nodes (from the partition's plan) and the
  !> staging array, for ncomp components per node.
  subroutine block_assembly_init(part, ncomp, ba)
    type(partition_t), intent(in) :: part
    integer, intent(in) :: ncomp
    type(block_assembly_t), intent(out) :: ba
    integer :: j, e, n_loc

    n_loc = part%plan%n_local_contrib
    ba%ncomp = ncomp
    allocate(ba%elem_contrib_ptr(part%n_local_elems + 1), ba%elem_contrib(n_loc), ba%staged(ncomp, n_loc))
    ba%elem_contrib_ptr = 0
    do j = 1, n_loc
       e = part%plan%contrib_elem(j)
       ba%elem_contrib_ptr(e + 1) = ba%elem_contrib_ptr(e + 1) + 1
    end do
    ba%elem_contrib_ptr(1) = 1
    do e = 1, part%n_local_elems
       ba%elem_contrib_ptr(e + 1) = ba%elem_contrib_ptr(e + 1) + ba%elem_contrib_ptr(e)
    end do
    ! filled in ascending j per element; elem_contrib_ptr(e) runs ahead and is reset after
    do j = 1, n_loc
       e = part%plan%contrib_elem(j)
       ba%elem_contrib(ba%elem_contrib_ptr(e)) = j
       ba%elem_contrib_ptr(e) = ba%elem_contrib_ptr(e) + 1
    end do
    do e = part%n_local_elems, 1, -1
       ba%elem_contrib_ptr(e + 1) = ba%elem_contrib_ptr(e)
    end do
    ba%elem_contrib_ptr(1) = 1
  end subroutine block_assembly_init

  !> f = 0 before the first block of an assembly.
  subroutine assembly_start(f)
    real(dp), contiguous, intent(out) :: f(:, :)

    ! As one run of memory: `f = 0` on the (ncomp, n) array was one memset call per node.
    call zero_values(size(f), f)
  end subroutine assembly_start

  pure subroutine zero_values(n, a)
    integer, intent(in) :: n
    real(dp), intent(out) :: a(n)

    a = 0
  end subroutine zero_values

  !> Adds the contributions fe(1:nb, :, :) of local elements first..first+nb-1 to f and stages
  !> those to shared nodes. Blocks must come in ascending order, each element once.
  subroutine assembly_add_block(part, ba, first, nb, fe, f)
    type(partition_t), intent(in) :: part
    type(block_assembly_t), intent(inout) :: ba
    integer, intent(in) :: first, nb
    real(dp), contiguous, intent(in) :: fe(:, :, :)  !< (nb, ncomp, nen)
    real(dp), contiguous, intent(inout) :: f(:, :)   !< (ncomp, n_local_nodes)

    call scatter_add(nb, part%nen, ba%ncomp, part%n_local_nodes, part%conn(:, first:first + nb - 1), fe, f)
    if (size(ba%elem_contrib) > 0) then
       call stage(nb, ba%ncomp, part%nen, fe, ba%elem_contrib_ptr(first:first + nb), ba%elem_contrib, &
            part%plan%contrib_slot, size(ba%elem_contrib), ba%staged)
    end if
  end subroutine assembly_add_block

  !> After the last block: the staged contributions to the neighbours, theirs to us, and every
  !> shared node summed again from zero in global element order. Collective over the
  !> neighbours of this rank (every rank must call it).
  subroutine assembly_finish(part, ba, f)
    type(partition_t), intent(in) :: part
    type(block_assembly_t), intent(in) :: ba
    real(dp), contiguous, intent(inout) :: f(:, :)
    ! work(:, 1:n_loc): our contributions to shared nodes; work(:, n_loc+1:): the neighbours'
    real(dp), allocatable, asynchronous :: work(:, :), send_buf(:, :)
    type(MPI_Request), allocatable :: req(:)
    integer :: k, nb, nnb, n_loc, n_cols, ncomp

    associate (plan => part%plan)
      nnb = plan%n_neighbours
      if (nnb == 0 .and. plan%n_shared == 0) return
      ncomp = ba%ncomp
      n_loc = plan%n_local_contrib
      n_cols = n_loc + plan%recv_ptr(nnb + 1)
      allocate (work(ncomp, n_cols), send_buf(ncomp, plan%send_ptr(nnb + 1) - 1), req(2 * nnb))

      ! Receive the neighbours' contributions straight into their columns of `work`
      ! (contiguous sections: MPI gets their address, no temporary copy).
      do nb = 1, nnb
         call MPI_Irecv(work(:, n_loc + plan%recv_ptr(nb) + 1:n_loc + plan%recv_ptr(nb + 1)), &
              ncomp * (plan%recv_ptr(nb + 1) - plan%recv_ptr(nb)), MPI_DOUBLE_PRECISION, &
              plan%neighbour(nb), assembly_tag, part%comm, req(nb))
      end do
      if (n_loc > 0) work(:, 1:n_loc) = ba%staged
      do nb = 1, nnb
         do k = plan%send_ptr(nb), plan%send_ptr(nb + 1) - 1
            send_buf(:, k) = work(:, plan%send_contrib(k))
         end do
         call MPI_Isend(send_buf(:, plan%send_ptr(nb):plan%send_ptr(nb + 1) - 1), &
              ncomp * (plan%send_ptr(nb + 1) - plan%send_ptr(nb)), MPI_DOUBLE_PRECISION, &
              plan%neighbour(nb), assembly_tag, part%comm, req(nnb + nb))
      end do
      if (nnb > 0) then
         call MPI_Waitall(2 * nnb, req, MPI_STATUSES_IGNORE)
         ! keep the compiler from moving reads of `work` before the wait
         call MPI_F_sync_reg(work)
      end if
      if (plan%n_shared > 0) call resum_shared(ncomp, part%n_local_nodes, plan%n_shared, &
           plan%shared_node, plan%source_ptr, plan%source, n_cols, work, f)
    end associate
  end subroutine assembly_finish

  !> f(:, conn(a, e)) += fe(e, :, a) for e ascending, a ascending. Explicit-shape
  !> dummies and a literal component count for ncomp = 2, 3 (the usual ndim): with both the
  !> compiler keeps the loop tight, 2-3 times faster than on assumed-shape arrays with a
  !> variable ncomp.
  pure subroutine scatter_add(ne, nen, ncomp, nn, conn, fe, f)
    integer, intent(in) :: ne, nen, ncomp, nn
    integer, intent(in) :: conn(nen, ne)
    real(dp), intent(in) :: fe(ne, ncomp, nen)
    real(dp), intent(inout) :: f(ncomp, nn)
    integer :: e, a, c, node

    select case (ncomp)
    case (2)
       do e = 1, ne
          do a = 1, nen
             node = conn(a, e)
             f(1, node) = f(1, node) + fe(e, 1, a)
             f(2, node) = f(2, node) + fe(e, 2, a)
          end do
       end do
    case (3)
       do e = 1, ne
          do a = 1, nen
             node = conn(a, e)
             f(1, node) = f(1, node) + fe(e, 1, a)
             f(2, node) = f(2, node) + fe(e, 2, a)
             f(3, node) = f(3, node) + fe(e, 3, a)
          end do
       end do
    case default
       do e = 1, ne
          do a = 1, nen
             node = conn(a, e)
             do c = 1, ncomp
                f(c, node) = f(c, node) + fe(e, c, a)
             end do
          end do
       end do
    end select
  end subroutine scatter_add

  !> w(:, j) = fe(e, :, slot(j)) for the contributions j of the block's e-th element
  !> (elem_contrib(ptr(e) : ptr(e + 1) − 1)): the values other ranks need.
  pure subroutine stage(nb, ncomp, nen, fe, ptr, elem_contrib, slot, n, w)
    integer, intent(in) :: nb, ncomp, nen, n
    real(dp), intent(in) :: fe(nb, ncomp, nen)
    integer, intent(in) :: ptr(nb + 1), elem_contrib(n), slot(n)
    real(dp), intent(inout) :: w(ncomp, n)
    integer :: e, k, j, c

    do e = 1, nb
       do k = ptr(e), ptr(e + 1) - 1
          j = elem_contrib(k)
          do c = 1, ncomp
             w(c, j) = fe(e, c, slot(j))
          end do
       end do
    end do
  end subroutine stage

  !> f(:, shared_node(i)) = ((0 + w(:, s_1)) + w(:, s_2)) + ..., the sources s_k of node i
  !> being in ascending (global element, slot) order.
  pure subroutine resum_shared(ncomp, nn, n_shared, shared_node, source_ptr, source, n_cols, w, f)
    integer, intent(in) :: ncomp, nn, n_shared, n_cols
    integer, intent(in) :: shared_node(n_shared), source_ptr(n_shared + 1), source(*)
    real(dp), intent(in) :: w(ncomp, n_cols)
    real(dp), intent(inout) :: f(ncomp, nn)
    real(dp) :: s(ncomp)
    integer :: i, k

    do i = 1, n_shared
       s = 0
       do k = source_ptr(i), source_ptr(i + 1) - 1
          s = s + w(:, source(k))
       end do
       f(:, shared_node(i)) = s
    end do
  end subroutine resum_shared

  ! --- reductions on the partition's communicator --------------------------------------------

  subroutine min_int(part, x)
    type(partition_t), intent(in) :: part
    integer, intent(inout) :: x
    call comm_min(part%comm, x)
  end subroutine min_int

  subroutine min_int_array(part, x)
    type(partition_t), intent(in) :: part
    integer, contiguous, intent(inout) :: x(:)
    call comm_min(part%comm, x)
  end subroutine min_int_array

  subroutine min_real(part, x)
    type(partition_t), intent(in) :: part
    real(dp), intent(inout) :: x
    call comm_min(part%comm, x)
  end subroutine min_real

  subroutine min_real_array(part, x)
    type(partition_t), intent(in) :: part
    real(dp), contiguous, intent(inout) :: x(:)
    call comm_min(part%comm, x)
  end subroutine min_real_array

  subroutine max_int(part, x)
    type(partition_t), intent(in) :: part
    integer, intent(inout) :: x
    call comm_max(part%comm, x)
  end subroutine max_int

  subroutine max_int_array(part, x)
    type(partition_t), intent(in) :: part
    integer, contiguous, intent(inout) :: x(:)
    call comm_max(part%comm, x)
  end subroutine max_int_array

  subroutine max_real(part, x)
    type(partition_t), intent(in) :: part
    real(dp), intent(inout) :: x
    call comm_max(part%comm, x)
  end subroutine max_real

  subroutine max_real_array(part, x)
    type(partition_t), intent(in) :: part
    real(dp), contiguous, intent(inout) :: x(:)
    call comm_max(part%comm, x)
  end subroutine max_real_array

  subroutine sum_int(part, x)
    type(partition_t), intent(in) :: part
    integer, intent(inout) :: x
    call comm_sum(part%comm, x)
  end subroutine sum_int

  subroutine sum_int_array(part, x)
    type(partition_t), intent(in) :: part
    integer, contiguous, intent(inout) :: x(:)
    call comm_sum(part%comm, x)
  end subroutine sum_int_array

  subroutine sum_real(part, x)
    type(partition_t), intent(in) :: part
    real(dp), intent(inout) :: x
    call comm_sum(part%comm, x)
  end subroutine sum_real

  subroutine sum_real_array(part, x)
    type(partition_t), intent(in) :: part
    real(dp), contiguous, intent(inout) :: x(:)
    call comm_sum(part%comm, x)
  end subroutine sum_real_array

  subroutine sum_exact_1(part, values, total)
    type(partition_t), intent(in) :: part
    real(dp), intent(in) :: values(:)
    real(dp), intent(out) :: total
    call comm_sum_exact(part%comm, values, total)
  end subroutine sum_exact_1

  subroutine sum_exact_2(part, values, totals)
    type(partition_t), intent(in) :: part
    real(dp), intent(in) :: values(:, :)
    real(dp), intent(out) :: totals(:)
    call comm_sum_exact(part%comm, values, totals)
  end subroutine sum_exact_2

end module parallel_assembly
