!> MPI test of parallel_assembly, run by CTest on 1, 2, 3 and 4 ranks: on every test mesh the
!> assembled nodal vectors are BITWISE equal to the serial assembly of the whole mesh (computed
!> on every rank), for 1, 2 and 3 components, on every rank holding the node, also when the
!> assembly is repeated, and also block by block as the element phase assembles
!> (assembly_start/add_block/finish with blocks of several sizes: staging across block edges).
!> The contributions have random signs and exponents, so the sums depend
!> on their order; the test checks that too (the reverse order gives other bits).
program test_parallel_assembly
  use mpi_f08, only: MPI_Comm, MPI_COMM_WORLD, MPI_Init, MPI_Finalize
  use material_kinds, only: dp
  use model_mesh, only: mesh_t
  use parallel_comm, only: comm_rank
  use parallel_partition, only: partition_t, partition_mesh
  use parallel_assembly, only: assemble_element_vectors, block_assembly_t, block_assembly_init, &
       assembly_start, assembly_add_block, assembly_finish
  use parallel_test_support, only: test_mesh_t, test_meshes, contribution, serial_assembly, &
       check, check_summary, same_bits
  implicit none

  type(MPI_Comm) :: comm
  type(test_mesh_t), allocatable :: meshes(:)
  integer :: m, rank, failed

  call MPI_Init()
  comm = MPI_COMM_WORLD
  rank = comm_rank(comm)

  call test_meshes(meshes)
  do m = 1, size(meshes)
     call check_assembly(meshes(m)%mesh, trim(meshes(m)%name))
  end do

  failed = check_summary(comm, 'test_parallel_assembly')
  call MPI_Finalize()
  if (failed > 0) error stop 1

contains

  subroutine check_assembly(mesh, name)
    type(mesh_t), intent(in) :: mesh
    character(len=*), intent(in) :: name
    type(partition_t) :: part
    real(dp), allocatable :: fe(:, :, :), f(:, :), f_again(:, :), ref(:, :), rev(:, :)
    integer :: ncomp, le, c, a, max_uses, ib
    integer, parameter :: block_sizes(3) = [1, 7, 64]
    character(len=2) :: size_tag
    integer, allocatable :: uses(:)
    character(len=1) :: tag

    call partition_mesh(mesh, comm, part)
    allocate (uses(mesh%n_nodes))
    uses = 0
    do le = 1, mesh%n_elems
       do a = 1, mesh%nen
          uses(mesh%conn(a, le)) = uses(mesh%conn(a, le)) + 1
       end do
    end do
    max_uses = maxval(uses)
    do ncomp = 1, 3
       write (tag, '(i1)') ncomp
       allocate (fe(part%n_local_elems, ncomp, part%nen), f(ncomp, part%n_local_nodes), &
            f_again(ncomp, part%n_local_nodes))
       do a = 1, part%nen
          do c = 1, ncomp
             do le = 1, part%n_local_elems
                fe(le, c, a) = contribution(part%elem_global(le), c, a)
             end do
          end do
       end do
       call assemble_element_vectors(part, ncomp, fe, f)
       call assemble_element_vectors(part, ncomp, fe, f_again)
       call serial_assembly(mesh, ncomp, ref)

       call check(same_bits(reshape(f, [size(f)]), reshape(ref(:, part%node_global), [size(f)])), &
            name // ', ncomp ' // tag // ': bitwise equal to the serial assembly', rank)
       call check(same_bits(reshape(f, [size(f)]), reshape(f_again, [size(f)])), &
            name // ', ncomp ' // tag // ': repeated assembly gives the same bits', rank)
       do ib = 1, size(block_sizes)
          call assemble_in_blocks(part, ncomp, block_sizes(ib), fe, f_again)
          write (size_tag, '(i2)') block_sizes(ib)
          call check(same_bits(reshape(f_again, [size(f)]), reshape(ref(:, part%node_global), [size(f)])), &
               name // ', ncomp ' // tag // ', blocks of ' // adjustl(size_tag) // &
               ': bitwise equal to the serial assembly', rank)
       end do
       ! (a + b = b + a exactly: only nodes with three or more contributions can tell)
       if (mesh%n_elems > 100 .and. max_uses >= 3) then
          call serial_assembly(mesh, ncomp, rev, reverse=.true.)
          call check(.not. same_bits(reshape(ref, [size(ref)]), reshape(rev, [size(rev)])), &
               name // ', ncomp ' // tag // ': sums are order-sensitive (test is meaningful)', rank)
       end if
       deallocate (fe, f, f_again)
    end do
  end subroutine check_assembly

  !> The element phase's form: blocks of `block` consecutive local elements (the last shorter).
  subroutine assemble_in_blocks(part, ncomp, block, fe, f)
    type(partition_t), intent(in) :: part
    integer, intent(in) :: ncomp, block
    real(dp), intent(in) :: fe(:, :, :)
    real(dp), contiguous, intent(out) :: f(:, :)
    type(block_assembly_t) :: ba
    integer :: first, nb

    call block_assembly_init(part, ncomp, ba)
    call assembly_start(f)
    do first = 1, part%n_local_elems, block
       nb = min(block, part%n_local_elems - first + 1)
       call assembly_add_block(part, ba, first, nb, fe(first:first + nb - 1, :, :), f)
    end do
    call assembly_finish(part, ba, f)
  end subroutine assemble_in_blocks

end program test_parallel_assembly
