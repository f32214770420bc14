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
  use material_kinds, only: dp
  use error_report, only: raise_error
  use parallel_comm, only: comm_min, comm_max, comm_sum, comm_sum_exact
  use parallel_partition, only: partition_t
  implicit none
  private

  public :: assemble_element_vectors
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
    ! work(:, 1:n_loc): our contributions to shared nodes; work(:, n_loc+1:): the neighbours'
    real(dp), allocatable, asynchronous :: work(:, :), send_buf(:, :)
    type(MPI_Request), allocatable :: req(:)
    integer :: k, nb, nnb, n_loc, n_cols

    if (size(fe, 1) /= part%n_local_elems .or. size(fe, 2) /= ncomp .or. &
         size(fe, 3) /= part%nen) then
       call raise_error('', 0, 'assemble_element_vectors: fe must be (n_local_elems, ncomp, nen)')
    end if
    if (size(f, 1) /= ncomp .or. size(f, 2) /= part%n_local_nodes) then
       call raise_error('', 0, 'assemble_element_vectors: f must be (ncomp, n_local_nodes)')
    end if

    associate (plan => part%plan)
      nnb = plan%n_neighbours
      n_loc = plan%n_local_contrib
      n_cols = n_loc + plan%recv_ptr(nnb + 1)
      allocate (work(ncomp, n_cols), send_buf(ncomp, plan%send_ptr(nnb + 1) - 1), req(2 * nnb))

      ! 1. Receive the neighbours' contributions straight into their columns of `work`
      !    (contiguous sections: MPI gets their address, no temporary copy).
      do nb = 1, nnb
         call MPI_Irecv(work(:, n_loc + plan%recv_ptr(nb) + 1:n_loc + plan%recv_ptr(nb + 1)), &
              ncomp * (plan%recv_ptr(nb + 1) - plan%recv_ptr(nb)), MPI_DOUBLE_PRECISION, &
              plan%neighbour(nb), assembly_tag, part%comm, req(nb))
      end do

      ! 2. Our contributions to shared nodes: staged, packed per neighbour, sent.
      if (n_loc > 0) call stage(part%n_local_elems, ncomp, part%nen, fe, n_loc, &
           plan%contrib_elem, plan%contrib_slot, work(:, 1:n_loc))
      do nb = 1, nnb
         do k = plan%send_ptr(nb), plan%send_ptr(nb + 1) - 1
            send_buf(:, k) = work(:, plan%send_contrib(k))
         end do
         call MPI_Isend(send_buf(:, plan%send_ptr(nb):plan%send_ptr(nb + 1) - 1), &
              ncomp * (plan%send_ptr(nb + 1) - plan%send_ptr(nb)), MPI_DOUBLE_PRECISION, &
              plan%neighbour(nb), assembly_tag, part%comm, req(nnb + nb))
      end do

      ! 3. While the messages travel: the scatter, final for every node only we hold.
      call scatter(part%n_local_elems, part%nen, ncomp, part%n_local_nodes, part%conn, fe, f)

      ! 4. Shared nodes: all contributions again, from zero, in global element order.
      if (nnb > 0) then
         call MPI_Waitall(2 * nnb, req, MPI_STATUSES_IGNORE)
         ! keep the compiler from moving reads of `work` before the wait
         call MPI_F_sync_reg(work)
      end if
      if (plan%n_shared > 0) call resum_shared(ncomp, part%n_local_nodes, plan%n_shared, &
           plan%shared_node, plan%source_ptr, plan%source, n_cols, work, f)
    end associate
  end subroutine assemble_element_vectors

  !> f = 0, then f(:, conn(a, e)) += fe(e, :, a) for e ascending, a ascending. Explicit-shape
  !> dummies and a literal component count for ncomp = 2, 3 (the usual ndim): with both the
  !> compiler keeps the loop tight, 2-3 times faster than on assumed-shape arrays with a
  !> variable ncomp.
  pure subroutine scatter(ne, nen, ncomp, nn, conn, fe, f)
    integer, intent(in) :: ne, nen, ncomp, nn
    integer, intent(in) :: conn(nen, ne)
    real(dp), intent(in) :: fe(ne, ncomp, nen)
    real(dp), intent(out) :: f(ncomp, nn)
    integer :: e, a, c, node

    f = 0
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
  end subroutine scatter

  !> w(:, j) = fe(elem(j), :, slot(j)): the contributions other ranks need.
  pure subroutine stage(ne, ncomp, nen, fe, n, elem, slot, w)
    integer, intent(in) :: ne, ncomp, nen, n
    real(dp), intent(in) :: fe(ne, ncomp, nen)
    integer, intent(in) :: elem(n), slot(n)
    real(dp), intent(out) :: w(ncomp, n)
    integer :: j, c

    do j = 1, n
       do c = 1, ncomp
          w(c, j) = fe(elem(j), c, slot(j))
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
