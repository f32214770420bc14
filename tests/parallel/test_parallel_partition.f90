!> MPI test of parallel_partition, run by CTest on 1, 2, 3 and 4 ranks: on every test mesh,
!> every element is on exactly one rank, local elements and nodes are ascending and complete,
!> the local connectivity matches the global one, the owned nodes partition all nodes (owner =
!> lowest holder), the shared flags match, RCB balances elements within one, and the index
!> look-ups work; ranks with no element (more ranks than elements) get a valid empty part.
!> Also RCB itself (serially, many part counts), partition_model and a bad mesh.
program test_parallel_partition
  use mpi_f08, only: MPI_Comm, MPI_COMM_WORLD, MPI_Init, MPI_Finalize
  use material_kinds, only: dp
  use model, only: model_t
  use model_mesh, only: mesh_t
  use error_report, only: error_t
  use parallel_comm, only: comm_rank, comm_size, comm_sum, comm_min, comm_max
  use parallel_partition, only: partition_t, partition_mesh, partition_model, rcb_assign, &
       local_node_index, local_elem_index, owned_node_indices, partition_summary
  use parallel_test_support, only: test_mesh_t, test_meshes, quad_mesh, hex_mesh, check, &
       check_summary
  implicit none

  type(MPI_Comm) :: comm
  type(test_mesh_t), allocatable :: meshes(:)
  integer :: m, rank, nranks, failed

  call MPI_Init()
  ! The test program owns the world; the library only ever sees the communicator it is given.
  comm = MPI_COMM_WORLD
  rank = comm_rank(comm)
  nranks = comm_size(comm)

  call test_meshes(meshes)
  do m = 1, size(meshes)
     call check_partition(meshes(m)%mesh, trim(meshes(m)%name))
  end do
  call check_rcb_balance()
  call check_partition_model()
  call check_bad_mesh()

  failed = check_summary(comm, 'test_parallel_partition')
  call MPI_Finalize()
  if (failed > 0) error stop 1

contains

  subroutine check_partition(mesh, name)
    type(mesh_t), intent(in) :: mesh
    character(len=*), intent(in) :: name
    type(partition_t) :: part, again
    integer, allocatable :: per_elem(:), owned(:), holders(:), lowest(:), uses(:), iota(:)
    logical, allocatable :: expect_held(:)
    integer :: i, le, g, a, n_min, n_max, ne, nn, idx
    logical :: ok
    character(len=:), allocatable :: summary

    ne = mesh%n_elems
    nn = mesh%n_nodes
    call partition_mesh(mesh, comm, part)

    call check(part%rank == rank .and. part%nranks == nranks .and. &
         part%n_global_elems == ne .and. part%n_global_nodes == nn .and. &
         part%nen == mesh%nen .and. part%ndim == mesh%ndim, name // ': header fields', rank)

    ! every element exactly once, locals ascending
    allocate (per_elem(ne))
    per_elem = 0
    do le = 1, part%n_local_elems
       per_elem(part%elem_global(le)) = per_elem(part%elem_global(le)) + 1
    end do
    call comm_sum(comm, per_elem)
    call check(all(per_elem == 1), name // ': every element on exactly one rank', rank)
    call check(size(part%elem_global) == part%n_local_elems, name // ': elem_global size', rank)
    call check(all(part%elem_global(2:) > part%elem_global(:part%n_local_elems - 1)), &
         name // ': local elements ascending', rank)

    ! balance within one element
    n_min = part%n_local_elems
    n_max = part%n_local_elems
    call comm_min(comm, n_min)
    call comm_max(comm, n_max)
    call check(n_max - n_min <= 1, name // ': RCB balance within one element', rank)

    ! local nodes = nodes of local elements (+ element-less nodes on rank 0), ascending
    allocate (uses(nn), expect_held(nn), iota(nn))
    iota = [(i, i = 1, nn)]
    uses = 0
    do i = 1, ne
       do a = 1, mesh%nen
          uses(mesh%conn(a, i)) = 1
       end do
    end do
    expect_held = .false.
    do le = 1, part%n_local_elems
       do a = 1, mesh%nen
          expect_held(mesh%conn(a, part%elem_global(le))) = .true.
       end do
    end do
    if (rank == 0) expect_held = expect_held .or. uses == 0
    ok = part%n_local_nodes == count(expect_held) .and. size(part%node_global) == part%n_local_nodes
    if (ok) ok = all(part%node_global == pack(iota, expect_held))
    call check(ok, name // ': local nodes are the nodes of local elements, ascending', rank)

    ! local connectivity
    ok = all(shape(part%conn) == [mesh%nen, part%n_local_elems])
    if (ok .and. part%n_local_elems > 0) then
       do le = 1, part%n_local_elems
          ok = ok .and. all(part%node_global(part%conn(:, le)) == mesh%conn(:, part%elem_global(le)))
       end do
    end if
    call check(ok, name // ': local connectivity matches the global one', rank)

    ! owned nodes partition all nodes, owner = lowest holder; shared = more than one holder
    allocate (owned(nn), holders(nn), lowest(nn))
    owned = 0
    holders = 0
    lowest = huge(1)
    do i = 1, part%n_local_nodes
       g = part%node_global(i)
       if (part%node_owned(i)) owned(g) = 1
       holders(g) = 1
       lowest(g) = rank
    end do
    call comm_sum(comm, owned)
    call comm_sum(comm, holders)
    call comm_min(comm, lowest)
    call check(all(owned == 1), name // ': every node owned by exactly one rank', rank)
    ok = .true.
    do i = 1, part%n_local_nodes
       g = part%node_global(i)
       ok = ok .and. (part%node_owned(i) .eqv. lowest(g) == rank) .and. &
            (part%node_shared(i) .eqv. holders(g) > 1)
    end do
    call check(ok, name // ': owner is the lowest holder, shared flags right', rank)
    call check(part%n_owned_nodes == count(part%node_owned), name // ': n_owned_nodes', rank)
    call check(all(owned_node_indices(part) == pack(iota(:part%n_local_nodes), part%node_owned)) &
         .and. size(owned_node_indices(part)) == part%n_owned_nodes, name // ': owned_node_indices', rank)

    ! look-ups, both for held and for absent indices
    ok = .true.
    do g = 1, nn
       idx = local_node_index(part, g)
       if (expect_held(g)) then
          ok = ok .and. idx > 0
          if (idx > 0) ok = ok .and. part%node_global(idx) == g
       else
          ok = ok .and. idx == 0
       end if
    end do
    ok = ok .and. local_node_index(part, 0) == 0 .and. local_node_index(part, nn + 1) == 0
    call check(ok, name // ': local_node_index', rank)
    ok = .true.
    do g = 1, ne
       idx = local_elem_index(part, g)
       if (idx > 0) ok = ok .and. part%elem_global(idx) == g
    end do
    ok = ok .and. count([(local_elem_index(part, g) > 0, g = 1, ne)]) == part%n_local_elems
    call check(ok, name // ': local_elem_index', rank)

    ! deterministic: a second partition is the same
    call partition_mesh(mesh, comm, again)
    ok = again%n_local_elems == part%n_local_elems .and. again%n_local_nodes == part%n_local_nodes
    if (ok) ok = all(again%elem_global == part%elem_global) .and. all(again%node_global == part%node_global)
    call check(ok, name // ': partition is deterministic', rank)

    summary = partition_summary(part)
    if (rank == 0) print '(a)', '  ' // name // ': ' // summary
  end subroutine check_partition

  !> rcb_assign alone, on this rank: counts floor/ceil(n/nparts) for 1..17 parts and more parts
  !> than elements; the first cut of a 40x25 grid is across its long side.
  subroutine check_rcb_balance()
    type(mesh_t) :: mesh
    real(dp), allocatable :: c(:, :)
    integer, allocatable :: owner(:)
    integer :: np, p, n, k, e, lo, hi
    logical :: ok

    do k = 1, 3
       select case (k)
       case (1)
          call quad_mesh(40, 25, .false., mesh)
       case (2)
          call hex_mesh(9, 5, 7, .true., mesh)
       case default
          call quad_mesh(1, 3, .false., mesh)
       end select
       call centroids(mesh, c)
       n = mesh%n_elems
       allocate (owner(n))
       ok = .true.
       do np = 1, 17
          call rcb_assign(c, np, owner)
          ok = ok .and. all(owner >= 0 .and. owner < np)
          do p = 0, np - 1
             ok = ok .and. (count(owner == p) == n / np .or. count(owner == p) == (n + np - 1) / np)
          end do
       end do
       call check(ok, 'rcb_assign: parts of floor/ceil(n/nparts) elements, 1..17 parts', rank)
       if (k == 1) then
          call rcb_assign(c, 2, owner)
          lo = 0
          hi = 0
          do e = 1, n
             if (owner(e) == 0) lo = max(lo, nint(c(1, e) - 0.5_dp))
          end do
          hi = minval(nint(pack(c(1, :), owner == 1) - 0.5_dp))
          call check(lo < hi .and. count(owner == 0) == 500, 'rcb_assign: first cut across x', rank)
       end if
       deallocate (owner)
    end do
  end subroutine check_rcb_balance

  subroutine centroids(mesh, c)
    type(mesh_t), intent(in) :: mesh
    real(dp), allocatable, intent(out) :: c(:, :)
    integer :: e, a

    allocate (c(mesh%ndim, mesh%n_elems))
    do e = 1, mesh%n_elems
       c(:, e) = 0
       do a = 1, mesh%nen
          c(:, e) = c(:, e) + mesh%x0(:, mesh%conn(a, e))
       end do
       c(:, e) = c(:, e) / mesh%nen
    end do
  end subroutine centroids

  !> partition_model gives what partition_mesh gives on the model's mesh.
  subroutine check_partition_model()
    type(model_t) :: mdl
    type(partition_t) :: a, b
    logical :: ok

    call hex_mesh(4, 3, 5, .true., mdl%mesh)
    call partition_model(mdl, comm, a)
    call partition_mesh(mdl%mesh, comm, b)
    ok = a%n_local_elems == b%n_local_elems .and. a%n_local_nodes == b%n_local_nodes
    if (ok) ok = all(a%elem_global == b%elem_global) .and. all(a%node_global == b%node_global) &
         .and. all(a%conn == b%conn) .and. all(a%node_owned .eqv. b%node_owned)
    call check(ok, 'partition_model = partition_mesh of its mesh', rank)
  end subroutine check_partition_model

  !> A connectivity naming a missing node is reported through err on every rank, no hang.
  subroutine check_bad_mesh()
    type(mesh_t) :: mesh
    type(partition_t) :: part
    type(error_t) :: err

    call quad_mesh(3, 3, .false., mesh)
    mesh%conn(2, 5) = mesh%n_nodes + 1
    call partition_mesh(mesh, comm, part, err)
    call check(err%raised, 'bad connectivity: error raised', rank)
    if (err%raised) call check(index(err%message, 'does not exist') > 0, &
         'bad connectivity: message says what is wrong', rank)
  end subroutine check_bad_mesh

end program test_parallel_partition
