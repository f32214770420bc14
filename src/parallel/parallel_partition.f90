!> Domain decomposition of the Lagrangian mesh: elements split among the ranks of a
!> communicator by recursive coordinate bisection (RCB) of the element centroids, and the
!> exchange pattern that makes the assembly of nodal vectors independent of the split
!> (parallel_assembly).
!>
!> Every rank holds the whole model (the input is read everywhere), so every rank computes the
!> same decomposition of the whole mesh by itself, with no communication, and knows for every
!> shared node which remote elements contribute to it and in which order their values arrive.
!> That costs O(n_elems * nen) integers per rank, which the replicated model costs anyway.
!>
!> Conventions (docs/solver_interfaces.md §4):
!> * local elements: ascending global index; local nodes: every node of a local element,
!>   ascending global index; conn in local node indices;
!> * a node belongs to every rank that has one of its elements; it is owned by the lowest of
!>   them (output writes owned nodes only, sums over nodes count owned nodes only);
!> * nodes no element uses (e.g. a rigid body's reference node) are held and owned by rank 0,
!>   so that the owned nodes of all ranks are exactly all nodes.
module parallel_partition
  use, intrinsic :: iso_fortran_env, only: int64
  use mpi_f08, only: MPI_Comm
  use base_kinds, only: dp
  use model, only: model_t
  use model_mesh, only: mesh_t
  use model_sets, only: sorted_position
  use error_report, only: error_t, raise_error
  use parallel_comm, only: comm_rank, comm_size, comm_min, comm_max, comm_sum
  implicit none
  private

  public :: partition_t, partition_model, partition_mesh, rcb_assign
  public :: local_node_index, local_elem_index, owned_node_indices, partition_summary

  !> How the nodes shared with other ranks are assembled (built by partition_mesh, used by
  !> parallel_assembly only; the components are public so that module can read them, but they
  !> are nobody else's business).
  !>
  !> Contributions: one per (element, slot) pair whose node is shared. Per call of the assembly
  !> a work array w(ncomp, n_local_contrib + n_recv) holds first the local contributions
  !> (column j: fe(contrib_elem(j), :, contrib_slot(j))), then what the neighbours sent.
  type, public :: exchange_plan_t
     integer :: n_shared = 0
     integer, allocatable :: shared_node(:)     !< (n_shared) local indices of shared nodes, ascending
     integer, allocatable :: source_ptr(:)      !< (n_shared+1) shared node i sums w(:, source(source_ptr(i):source_ptr(i+1)-1))
     integer, allocatable :: source(:)          !<   in ascending (global element, slot) order
     integer :: n_local_contrib = 0
     integer, allocatable :: contrib_elem(:)    !< (n_local_contrib) local element index
     integer, allocatable :: contrib_slot(:)    !< (n_local_contrib) node slot 1..nen
     integer :: n_neighbours = 0
     integer, allocatable :: neighbour(:)       !< (n_neighbours) ranks sharing nodes with us, ascending
     integer, allocatable :: send_ptr(:)        !< (n_neighbours+1) into send_contrib
     integer, allocatable :: send_contrib(:)    !< local contributions sent, in the receiver's order
     integer, allocatable :: recv_ptr(:)        !< (n_neighbours+1) columns received (0-based offsets)
  end type exchange_plan_t

  !> This rank's part of the mesh.
  type, public :: partition_t
     type(MPI_Comm) :: comm                     !< the communicator the partition was made on
     integer :: rank = 0, nranks = 1
     integer :: ndim = 0, nen = 0
     integer :: n_global_elems = 0, n_global_nodes = 0
     integer :: n_local_elems = 0
     integer, allocatable :: elem_global(:)     !< (n_local_elems) global element index, ascending
     integer :: n_local_nodes = 0
     integer, allocatable :: node_global(:)     !< (n_local_nodes) global node index, ascending
     logical, allocatable :: node_owned(:)      !< (n_local_nodes) this rank is the node's owner
     integer :: n_owned_nodes = 0
     logical, allocatable :: node_shared(:)     !< (n_local_nodes) another rank holds the node too
     integer, allocatable :: conn(:, :)         !< (nen, n_local_elems) local node indices
     type(exchange_plan_t) :: plan              !< private to parallel_assembly
  end type partition_t

contains

  !> Split the model's elements among the ranks of `comm` (collective in spirit: every rank
  !> must call it with the same model, but it communicates nothing).
  subroutine partition_model(model, comm, part, err)
    type(model_t), intent(in) :: model             !< the whole model, the same on every rank
    type(MPI_Comm), intent(in) :: comm             !< communicator; every rank gets a part (maybe empty)
    type(partition_t), intent(out) :: part         !< this rank's part
    type(error_t), intent(inout), optional :: err  !< set on an invalid mesh, else stop

    call partition_mesh(model%mesh, comm, part, err)
  end subroutine partition_model

  !> partition_model for a bare mesh.
  subroutine partition_mesh(mesh, comm, part, err)
    type(mesh_t), intent(in) :: mesh               !< the whole mesh, the same on every rank
    type(MPI_Comm), intent(in) :: comm             !< communicator
    type(partition_t), intent(out) :: part         !< this rank's part
    type(error_t), intent(inout), optional :: err  !< set on an invalid mesh, else stop
    integer, allocatable :: elem_rank(:), node_elem_ptr(:), node_elem(:, :), g2l(:)
    real(dp), allocatable :: centroid(:, :)
    integer :: ne, nn, nen, e, a, i, g, le
    logical, allocatable :: held(:)

    part%comm = comm
    part%rank = comm_rank(comm)
    part%nranks = comm_size(comm)
    ne = mesh%n_elems
    nn = mesh%n_nodes
    nen = mesh%nen
    part%ndim = mesh%ndim
    part%nen = nen
    part%n_global_elems = ne
    part%n_global_nodes = nn

    ! The model builder validates the mesh; this only keeps a bad one from crashing here.
    ! Every rank sees the same mesh, so every rank fails alike and none is left waiting.
    if (ne > 0) then
       if (nen < 1 .or. size(mesh%conn, 1) < nen .or. size(mesh%conn, 2) < ne) then
          call raise_error('', 0, 'partition: mesh connectivity has the wrong shape', err)
          return
       end if
       if (any(mesh%conn(1:nen, 1:ne) < 1) .or. any(mesh%conn(1:nen, 1:ne) > nn)) then
          call raise_error('', 0, 'partition: mesh connectivity refers to a node that does not exist', err)
          return
       end if
       if (size(mesh%x0, 1) < mesh%ndim .or. size(mesh%x0, 2) < nn) then
          call raise_error('', 0, 'partition: mesh coordinates have the wrong shape', err)
          return
       end if
    end if

    ! 1. Every element's rank, the same on every rank.
    allocate (centroid(mesh%ndim, ne), elem_rank(ne))
    do e = 1, ne
       centroid(:, e) = 0
       do a = 1, nen
          centroid(:, e) = centroid(:, e) + mesh%x0(1:mesh%ndim, mesh%conn(a, e))
       end do
       centroid(:, e) = centroid(:, e) / nen
    end do
    call rcb_assign(centroid, part%nranks, elem_rank)

    ! 2. Node -> (element, slot) lists, each in ascending (element, slot) order.
    call node_elements(mesh, node_elem_ptr, node_elem)

    ! 3. Local elements, nodes and connectivity.
    part%n_local_elems = count(elem_rank == part%rank)
    allocate (part%elem_global(part%n_local_elems))
    part%elem_global = pack([(e, e = 1, ne)], elem_rank == part%rank)

    allocate (held(nn))
    held = .false.
    ! (loops, not held(conn(:, e)) = .true.: a collapsed element repeats a node, and a vector
    ! subscript with repeated values may not be assigned to)
    do le = 1, part%n_local_elems
       do a = 1, nen
          held(mesh%conn(a, part%elem_global(le))) = .true.
       end do
    end do
    if (part%rank == 0) then
       ! nodes without elements go to rank 0
       do g = 1, nn
          if (node_elem_ptr(g + 1) == node_elem_ptr(g)) held(g) = .true.
       end do
    end if
    part%n_local_nodes = count(held)
    allocate (part%node_global(part%n_local_nodes), part%node_owned(part%n_local_nodes), &
         part%node_shared(part%n_local_nodes), g2l(nn))
    g2l = 0
    i = 0
    do g = 1, nn
       if (held(g)) then
          i = i + 1
          part%node_global(i) = g
          g2l(g) = i
       end if
    end do

    allocate (part%conn(nen, part%n_local_elems))
    do le = 1, part%n_local_elems
       part%conn(:, le) = g2l(mesh%conn(1:nen, part%elem_global(le)))
    end do

    ! 4. Owner = lowest rank holding the node; shared = some other rank holds it too.
    do i = 1, part%n_local_nodes
       g = part%node_global(i)
       if (node_elem_ptr(g + 1) == node_elem_ptr(g)) then
          part%node_owned(i) = .true.
          part%node_shared(i) = .false.
       else
          associate (ranks => elem_rank(node_elem(1, node_elem_ptr(g):node_elem_ptr(g + 1) - 1)))
            part%node_owned(i) = minval(ranks) == part%rank
            part%node_shared(i) = any(ranks /= part%rank)
          end associate
       end if
    end do
    part%n_owned_nodes = count(part%node_owned)

    ! 5. The exchange plan for the shared nodes.
    call build_plan(part, elem_rank, node_elem_ptr, node_elem)
  end subroutine partition_mesh

  !> Recursive coordinate bisection: element e goes to elem_part(e) in 0 .. nparts-1.
  !>
  !> A range of parts [r0, r0+np) with n elements is split into np/2 (rounded down) and the
  !> rest, the first getting floor(n * (np/2) / np) elements: those with the smallest
  !> centroid coordinate along the axis of largest centroid extent (the first such axis on a
  !> tie), equal coordinates ordered by element index. Every part then gets floor(n/nparts) or
  !> ceil(n/nparts) elements, for any nparts, also more parts than elements. Only the order of
  !> reals is compared, so the result is the same on every rank.
  pure subroutine rcb_assign(centroid, nparts, elem_part)
    real(dp), intent(in) :: centroid(:, :)   !< (ndim, n_elems) element centroids
    integer, intent(in) :: nparts            !< number of parts (>= 1)
    integer, intent(out) :: elem_part(:)     !< (n_elems) part of each element, 0-based
    integer, allocatable :: order(:), buffer(:)
    integer :: e, n

    n = size(centroid, 2)
    allocate (order(n), buffer(n))
    order = [(e, e = 1, n)]
    call bisect(centroid, order, buffer, elem_part, 1, n, 0, max(nparts, 1))
  end subroutine rcb_assign

  !> One step of rcb_assign: elements order(lo:hi) go to parts r0 .. r0+np-1.
  pure recursive subroutine bisect(centroid, order, buffer, elem_part, lo, hi, r0, np)
    real(dp), intent(in) :: centroid(:, :)
    integer, intent(inout) :: order(:), buffer(:), elem_part(:)
    integer, intent(in) :: lo, hi, r0, np
    integer :: axis, d, n_left, pl
    real(dp) :: extent, best

    if (np == 1 .or. hi < lo) then
       elem_part(order(lo:hi)) = r0
       return
    end if
    ! axis of largest extent of the centroids in this range
    axis = 1
    best = -1
    do d = 1, size(centroid, 1)
       extent = maxval(centroid(d, order(lo:hi))) - minval(centroid(d, order(lo:hi)))
       if (extent > best) then
          best = extent
          axis = d
       end if
    end do
    call merge_sort(order(lo:hi), buffer(lo:hi), centroid(axis, :))
    pl = np / 2
    ! 64-bit product: n * pl overflows 32 bits beyond ~2e9 / nparts elements
    n_left = int(int(hi - lo + 1, int64) * pl / np)
    call bisect(centroid, order, buffer, elem_part, lo, lo + n_left - 1, r0, pl)
    call bisect(centroid, order, buffer, elem_part, lo + n_left, hi, r0 + pl, np - pl)
  end subroutine bisect

  !> Sort element indices by (key(e), e): a total order, so the result does not depend on the
  !> algorithm. Top-down merge sort, insertion sort below 16 entries.
  pure recursive subroutine merge_sort(idx, buf, key)
    integer, intent(inout) :: idx(:)
    integer, intent(inout) :: buf(:)      !< scratch, same size as idx
    real(dp), intent(in) :: key(:)
    integer :: n, mid, i, j, k, t

    n = size(idx)
    if (n < 16) then
       do i = 2, n
          t = idx(i)
          j = i - 1
          do while (j >= 1)
             if (.not. before(t, idx(j))) exit
             idx(j + 1) = idx(j)
             j = j - 1
          end do
          idx(j + 1) = t
       end do
       return
    end if
    mid = n / 2
    call merge_sort(idx(1:mid), buf(1:mid), key)
    call merge_sort(idx(mid + 1:n), buf(mid + 1:n), key)
    if (.not. before(idx(mid + 1), idx(mid))) return    ! already in order
    buf(1:n) = idx(1:n)
    i = 1
    j = mid + 1
    do k = 1, n
       if (j > n) then
          idx(k) = buf(i)
          i = i + 1
       else if (i > mid) then
          idx(k) = buf(j)
          j = j + 1
       else if (before(buf(j), buf(i))) then
          idx(k) = buf(j)
          j = j + 1
       else
          idx(k) = buf(i)
          i = i + 1
       end if
    end do

  contains

    pure logical function before(p, q)
      integer, intent(in) :: p, q
      ! (.not. key(q) < key(p)) is key(p) == key(q) here, without comparing reals for equality
      before = key(p) < key(q) .or. (.not. key(q) < key(p) .and. p < q)
    end function before
  end subroutine merge_sort

  !> CSR lists node -> (element, slot): node_elem(:, node_elem_ptr(g) : node_elem_ptr(g+1)-1)
  !> are the (element, slot) pairs with conn(slot, element) = g, in ascending (element, slot)
  !> order, i.e. the order in which the assembly adds them up.
  pure subroutine node_elements(mesh, ptr, list)
    type(mesh_t), intent(in) :: mesh
    integer, allocatable, intent(out) :: ptr(:), list(:, :)
    integer, allocatable :: next(:)
    integer :: e, a, g

    allocate (ptr(mesh%n_nodes + 1), list(2, mesh%n_elems * mesh%nen), next(mesh%n_nodes))
    ptr = 0
    do e = 1, mesh%n_elems
       do a = 1, mesh%nen
          g = mesh%conn(a, e)
          ptr(g + 1) = ptr(g + 1) + 1
       end do
    end do
    ptr(1) = 1
    do g = 1, mesh%n_nodes
       ptr(g + 1) = ptr(g + 1) + ptr(g)
    end do
    next = ptr(1:mesh%n_nodes)
    do e = 1, mesh%n_elems
       do a = 1, mesh%nen
          g = mesh%conn(a, e)
          list(:, next(g)) = [e, a]
          next(g) = next(g) + 1
       end do
    end do
  end subroutine node_elements

  !> The exchange plan of part%rank. Rank q sends rank p, for the nodes both hold in ascending
  !> global order, q's own contributions to each node in ascending (element, slot) order. Both
  !> sides derive that order from the global lists, so only values travel.
  subroutine build_plan(part, elem_rank, ptr, list)
    type(partition_t), intent(inout) :: part
    integer, intent(in) :: elem_rank(:), ptr(:), list(:, :)
    integer, allocatable :: nbr_of(:), n_send(:), n_recv(:), seen(:), recv_next(:), send_next(:)
    integer, allocatable :: g2l_elem(:)
    integer :: me, i, g, k, q, nb, j, c, n_src, n_loc

    associate (plan => part%plan)
      me = part%rank
      plan%n_shared = count(part%node_shared)
      allocate (plan%shared_node(plan%n_shared))
      plan%shared_node = pack([(i, i = 1, part%n_local_nodes)], part%node_shared)

      ! Neighbours, and per neighbour the number of values sent and received:
      ! to q go our contributions to the nodes q holds, from q come q's contributions.
      allocate (nbr_of(0:part%nranks - 1), seen(0:part%nranks - 1))
      allocate (n_send(0:part%nranks - 1), n_recv(0:part%nranks - 1))
      nbr_of = 0
      seen = 0
      n_send = 0
      n_recv = 0
      n_src = 0
      n_loc = 0
      do i = 1, plan%n_shared
         g = part%node_global(plan%shared_node(i))
         n_src = n_src + ptr(g + 1) - ptr(g)
         n_loc = n_loc + count(elem_rank(list(1, ptr(g):ptr(g + 1) - 1)) == me)
         do k = ptr(g), ptr(g + 1) - 1
            q = elem_rank(list(1, k))
            if (q == me) cycle
            n_recv(q) = n_recv(q) + 1
            if (seen(q) /= i) then
               ! first contribution of q to this node: q holds the node, send it ours
               seen(q) = i
               n_send(q) = n_send(q) + count(elem_rank(list(1, ptr(g):ptr(g + 1) - 1)) == me)
            end if
         end do
      end do
      plan%n_neighbours = count(n_recv > 0)
      allocate (plan%neighbour(plan%n_neighbours), plan%send_ptr(plan%n_neighbours + 1), &
           plan%recv_ptr(plan%n_neighbours + 1))
      plan%neighbour = pack([(q, q = 0, part%nranks - 1)], n_recv > 0)
      plan%send_ptr(1) = 1
      plan%recv_ptr(1) = 0
      do nb = 1, plan%n_neighbours
         q = plan%neighbour(nb)
         nbr_of(q) = nb
         plan%send_ptr(nb + 1) = plan%send_ptr(nb) + n_send(q)
         plan%recv_ptr(nb + 1) = plan%recv_ptr(nb) + n_recv(q)
      end do

      ! Sources of every shared node, local contributions and send lists, in one pass.
      allocate (g2l_elem(size(elem_rank)))
      g2l_elem = 0
      g2l_elem(part%elem_global) = [(i, i = 1, part%n_local_elems)]
      plan%n_local_contrib = n_loc
      allocate (plan%source_ptr(plan%n_shared + 1), plan%source(n_src), &
           plan%contrib_elem(n_loc), plan%contrib_slot(n_loc), &
           plan%send_contrib(plan%send_ptr(plan%n_neighbours + 1) - 1))
      allocate (recv_next(plan%n_neighbours), send_next(plan%n_neighbours))
      recv_next = plan%recv_ptr(1:plan%n_neighbours)
      send_next = plan%send_ptr(1:plan%n_neighbours)
      seen = 0
      plan%source_ptr(1) = 1
      n_src = 0
      n_loc = 0
      do i = 1, plan%n_shared
         g = part%node_global(plan%shared_node(i))
         j = n_loc      ! this node's local contributions will be n_loc+1 ..
         do k = ptr(g), ptr(g + 1) - 1
            q = elem_rank(list(1, k))
            n_src = n_src + 1
            if (q == me) then
               n_loc = n_loc + 1
               plan%contrib_elem(n_loc) = g2l_elem(list(1, k))
               plan%contrib_slot(n_loc) = list(2, k)
               plan%source(n_src) = n_loc
            else
               nb = nbr_of(q)
               recv_next(nb) = recv_next(nb) + 1
               ! received columns follow the local ones; fixed up below once n_loc is final
               plan%source(n_src) = -recv_next(nb)
               seen(q) = i
            end if
         end do
         ! every rank that has a contribution here holds the node and gets all of ours
         do k = ptr(g), ptr(g + 1) - 1
            q = elem_rank(list(1, k))
            if (q == me) cycle
            if (seen(q) /= i) cycle       ! already sent to q for this node
            seen(q) = -i
            nb = nbr_of(q)
            do c = j + 1, n_loc
               plan%send_contrib(send_next(nb)) = c
               send_next(nb) = send_next(nb) + 1
            end do
         end do
         plan%source_ptr(i + 1) = n_src + 1
      end do
      where (plan%source < 0) plan%source = n_loc - plan%source
    end associate
  end subroutine build_plan

  !> Local index of global node `global` on this rank, 0 if the rank does not hold it.
  pure integer function local_node_index(part, global)
    type(partition_t), intent(in) :: part   !< partition
    integer, intent(in) :: global           !< global node index
    local_node_index = sorted_position(part%node_global, global)
  end function local_node_index

  !> Local index of global element `global` on this rank, 0 if it is another rank's.
  pure integer function local_elem_index(part, global)
    type(partition_t), intent(in) :: part   !< partition
    integer, intent(in) :: global           !< global element index
    local_elem_index = sorted_position(part%elem_global, global)
  end function local_elem_index

  !> Local indices of the nodes this rank owns (writes to output, counts in nodal sums).
  pure function owned_node_indices(part) result(idx)
    type(partition_t), intent(in) :: part   !< partition
    integer, allocatable :: idx(:)
    integer :: i

    allocate (idx(part%n_owned_nodes))
    idx = pack([(i, i = 1, part%n_local_nodes)], part%node_owned)
  end function owned_node_indices

  !> One line for the run log, the same on every rank (collective), e.g.
  !> "4 ranks: elements per rank 2500..2501, shared nodes 101 (max 51 on a rank), neighbours <= 2".
  function partition_summary(part) result(text)
    type(partition_t), intent(in) :: part   !< partition
    character(len=:), allocatable :: text
    integer :: min_elems, maxima(3), n_shared_total
    character(len=200) :: buf

    min_elems = part%n_local_elems
    call comm_min(part%comm, min_elems)
    maxima(1) = part%n_local_elems
    maxima(2) = part%plan%n_shared
    maxima(3) = part%plan%n_neighbours
    call comm_max(part%comm, maxima)
    ! a shared node counted once, by its owner
    n_shared_total = count(part%node_shared .and. part%node_owned)
    call comm_sum(part%comm, n_shared_total)
    write (buf, '(i0, a, i0, a, i0, a, i0, a, i0, a, i0)') part%nranks, ' ranks: elements per rank ', &
         min_elems, '..', maxima(1), ', shared nodes ', n_shared_total, ' (max ', maxima(2), &
         ' on a rank), neighbours <= ', maxima(3)
    text = trim(buf)
  end function partition_summary
end module parallel_partition
