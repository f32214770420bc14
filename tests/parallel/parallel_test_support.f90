!> What the MPI tests of src/parallel share: test meshes built in code (2D quads, 3D hexes,
!> structured or with scrambled numbering so that global element order is not geometric),
!> deterministic "random-looking" element contributions, the serial reference assembly, and a
!> tiny check/report layer (every rank checks, the failures are counted over all ranks).
module parallel_test_support
  use, intrinsic :: iso_fortran_env, only: int64, output_unit, error_unit
  use mpi_f08, only: MPI_Comm
  use material_kinds, only: dp
  use model_mesh, only: mesh_t, element_cpe4r, element_c3d8r
  use parallel_comm, only: comm_rank, comm_sum
  implicit none
  private

  public :: test_mesh_t, test_meshes
  public :: quad_mesh, hex_mesh, add_orphan_nodes
  public :: contribution, serial_assembly
  public :: check, check_summary, same_bits, eq

  !> A named test mesh.
  type :: test_mesh_t
     character(len=40) :: name = ''
     type(mesh_t) :: mesh
  end type test_mesh_t

  integer(int64), parameter :: lcg_a = 48271, lcg_m = 2147483647   ! MINSTD: products fit 64 bits

  integer :: n_checks = 0, n_failed = 0

contains

  !> The meshes every test runs on: structured and scrambled, 2D and 3D, with degenerate
  !> elements and element-less nodes, tiny ones (fewer elements than ranks) and an empty one.
  subroutine test_meshes(meshes)
    type(test_mesh_t), allocatable, intent(out) :: meshes(:)

    allocate (meshes(10))
    meshes(1)%name = 'quad 40x25 structured'
    call quad_mesh(40, 25, .false., meshes(1)%mesh)
    meshes(2)%name = 'quad 37x23 scrambled, skewed'
    call quad_mesh(37, 23, .true., meshes(2)%mesh)
    ! a collapsed quad (one node twice in its connectivity) and two nodes without elements
    meshes(2)%mesh%conn(4, 17) = meshes(2)%mesh%conn(3, 17)
    call add_orphan_nodes(meshes(2)%mesh, 2)
    meshes(3)%name = 'hex 8x7x6 structured'
    call hex_mesh(8, 7, 6, .false., meshes(3)%mesh)
    meshes(4)%name = 'hex 9x5x7 scrambled'
    call hex_mesh(9, 5, 7, .true., meshes(4)%mesh)
    meshes(5)%name = 'quad 200x1 strip'
    call quad_mesh(200, 1, .true., meshes(5)%mesh)
    meshes(6)%name = 'quad 1x3 (3 elements)'
    call quad_mesh(1, 3, .true., meshes(6)%mesh)
    meshes(7)%name = 'quad 1x1 (1 element)'
    call quad_mesh(1, 1, .false., meshes(7)%mesh)
    meshes(8)%name = 'hex 1x1x2 (2 elements)'
    call hex_mesh(1, 1, 2, .true., meshes(8)%mesh)
    meshes(9)%name = 'no elements, 3 nodes'
    call quad_mesh(0, 0, .false., meshes(9)%mesh)
    call add_orphan_nodes(meshes(9)%mesh, 2)
    meshes(10)%name = 'quad 12x12 all centroids tied'
    call quad_mesh(12, 12, .true., meshes(10)%mesh)
    ! every element gets the same centroid: RCB order is decided by element index alone
    meshes(10)%mesh%x0 = 1
  end subroutine test_meshes

  !> nx x ny unit quads (CPE4R). scrambled: skewed, perturbed coordinates, node and element
  !> numbers shuffled, the starting slot of each element rotated.
  subroutine quad_mesh(nx, ny, scrambled, mesh)
    integer, intent(in) :: nx, ny
    logical, intent(in) :: scrambled
    type(mesh_t), intent(out) :: mesh
    integer, allocatable :: node_perm(:), elem_perm(:)
    integer :: i, j, e, n, r, corner(4)
    integer(int64) :: state

    mesh%ndim = 2
    mesh%element_type = element_cpe4r
    mesh%nen = 4
    mesh%n_nodes = (nx + 1) * (ny + 1)
    mesh%n_elems = nx * ny
    allocate (mesh%x0(2, mesh%n_nodes), mesh%conn(4, mesh%n_elems))
    state = 12345
    call permutation(mesh%n_nodes, scrambled, state, node_perm)
    call permutation(mesh%n_elems, scrambled, state, elem_perm)
    do j = 0, ny
       do i = 0, nx
          n = node_perm(1 + i + j * (nx + 1))
          mesh%x0(:, n) = [real(i, dp), real(j, dp)]
          if (scrambled) then
             mesh%x0(1, n) = mesh%x0(1, n) + 0.3_dp * j + 0.05_dp * uniform(state)
             mesh%x0(2, n) = mesh%x0(2, n) + 0.05_dp * uniform(state)
          end if
       end do
    end do
    do j = 0, ny - 1
       do i = 0, nx - 1
          e = elem_perm(1 + i + j * nx)
          corner = [1 + i + j * (nx + 1), 2 + i + j * (nx + 1), 2 + i + (j + 1) * (nx + 1), &
               1 + i + (j + 1) * (nx + 1)]
          r = 0
          if (scrambled) r = int(mod(next(state), 4_int64))
          mesh%conn(:, e) = node_perm(cshift(corner, r))
       end do
    end do
    call finish(mesh)
  end subroutine quad_mesh

  !> nx x ny x nz unit hexes (C3D8R), optionally scrambled like quad_mesh.
  subroutine hex_mesh(nx, ny, nz, scrambled, mesh)
    integer, intent(in) :: nx, ny, nz
    logical, intent(in) :: scrambled
    type(mesh_t), intent(out) :: mesh
    integer, allocatable :: node_perm(:), elem_perm(:)
    integer :: i, j, k, e, n, corner(8)
    integer(int64) :: state

    mesh%ndim = 3
    mesh%element_type = element_c3d8r
    mesh%nen = 8
    mesh%n_nodes = (nx + 1) * (ny + 1) * (nz + 1)
    mesh%n_elems = nx * ny * nz
    allocate (mesh%x0(3, mesh%n_nodes), mesh%conn(8, mesh%n_elems))
    state = 777
    call permutation(mesh%n_nodes, scrambled, state, node_perm)
    call permutation(mesh%n_elems, scrambled, state, elem_perm)
    do k = 0, nz
       do j = 0, ny
          do i = 0, nx
             n = node_perm(node_number(i, j, k))
             mesh%x0(:, n) = [real(i, dp), real(j, dp), real(k, dp)]
             if (scrambled) mesh%x0(:, n) = mesh%x0(:, n) + 0.05_dp * [uniform(state), &
                  uniform(state), uniform(state)] + [0.2_dp * k, 0.0_dp, 0.0_dp]
          end do
       end do
    end do
    do k = 0, nz - 1
       do j = 0, ny - 1
          do i = 0, nx - 1
             e = elem_perm(1 + i + nx * (j + ny * k))
             corner = [node_number(i, j, k), node_number(i + 1, j, k), node_number(i + 1, j + 1, k), &
                  node_number(i, j + 1, k), node_number(i, j, k + 1), node_number(i + 1, j, k + 1), &
                  node_number(i + 1, j + 1, k + 1), node_number(i, j + 1, k + 1)]
             mesh%conn(:, e) = node_perm(corner)
          end do
       end do
    end do
    call finish(mesh)

  contains

    pure integer function node_number(i, j, k)
      integer, intent(in) :: i, j, k
      node_number = 1 + i + (nx + 1) * (j + (ny + 1) * k)
    end function node_number
  end subroutine hex_mesh

  !> Append `n` nodes that no element uses (like rigid-body reference nodes).
  subroutine add_orphan_nodes(mesh, n)
    type(mesh_t), intent(inout) :: mesh
    integer, intent(in) :: n
    real(dp), allocatable :: x0(:, :)
    integer :: i

    allocate (x0(mesh%ndim, mesh%n_nodes + n))
    x0(:, 1:mesh%n_nodes) = mesh%x0(:, 1:mesh%n_nodes)
    do i = 1, n
       x0(:, mesh%n_nodes + i) = -10.0_dp * i
    end do
    call move_alloc(x0, mesh%x0)
    mesh%n_nodes = mesh%n_nodes + n
    call finish(mesh)
  end subroutine add_orphan_nodes

  subroutine finish(mesh)
    type(mesh_t), intent(inout) :: mesh
    integer :: i

    if (allocated(mesh%node_id)) deallocate (mesh%node_id)
    if (allocated(mesh%elem_id)) deallocate (mesh%elem_id)
    if (allocated(mesh%elem_section)) deallocate (mesh%elem_section)
    allocate (mesh%node_id(mesh%n_nodes), mesh%elem_id(mesh%n_elems), mesh%elem_section(mesh%n_elems))
    mesh%node_id = [(i, i = 1, mesh%n_nodes)]
    mesh%elem_id = [(i, i = 1, mesh%n_elems)]
    mesh%elem_section = 1
  end subroutine finish

  !> Identity, or a Fisher-Yates shuffle.
  subroutine permutation(n, shuffle, state, perm)
    integer, intent(in) :: n
    logical, intent(in) :: shuffle
    integer(int64), intent(inout) :: state
    integer, allocatable, intent(out) :: perm(:)
    integer :: i, j, t

    allocate (perm(n))
    perm = [(i, i = 1, n)]
    if (.not. shuffle) return
    do i = n, 2, -1
       j = 1 + int(mod(next(state), int(i, int64)))
       t = perm(i)
       perm(i) = perm(j)
       perm(j) = t
    end do
  end subroutine permutation

  !> MINSTD step; returns the new state (1 .. 2^31-2).
  integer(int64) function next(state)
    integer(int64), intent(inout) :: state
    state = mod(lcg_a * state, lcg_m)
    next = state
  end function next

  !> Uniform in [-1, 1).
  real(dp) function uniform(state)
    integer(int64), intent(inout) :: state
    uniform = 2 * real(next(state), dp) / real(lcg_m, dp) - 1
  end function uniform

  !> A deterministic "random" contribution of element e (global), component c, slot a:
  !> random sign, mantissa and binary exponent in [-20, 20], so that the rounding of a sum
  !> depends on its order.
  pure real(dp) function contribution(e, c, a)
    integer, intent(in) :: e, c, a
    integer(int64) :: s
    integer :: i

    s = 1 + mod(int(e, int64) * 7919 + int(c, int64) * 104729 + int(a, int64) * 1299709, lcg_m - 1)
    do i = 1, 4
       s = mod(lcg_a * s, lcg_m)
    end do
    contribution = real(s, dp) / real(lcg_m, dp) - 0.5_dp
    s = mod(lcg_a * s, lcg_m)
    contribution = scale(contribution, int(mod(s, 41_int64)) - 20)
  end function contribution

  !> The definition of the assembly: f(:, n) = ((0 + c_1) + c_2) + ... over (element, slot)
  !> in ascending order, on the whole mesh (reverse = .true.: descending element order, to
  !> show the contributions are order-sensitive).
  subroutine serial_assembly(mesh, ncomp, f, reverse)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: ncomp
    real(dp), allocatable, intent(out) :: f(:, :)
    logical, intent(in), optional :: reverse
    integer :: e, a, c, e0, e1, step

    allocate (f(ncomp, mesh%n_nodes))
    f = 0
    e0 = 1
    e1 = mesh%n_elems
    step = 1
    if (present(reverse)) then
       if (reverse) then
          e0 = mesh%n_elems
          e1 = 1
          step = -1
       end if
    end if
    do e = e0, e1, step
       do a = 1, mesh%nen
          do c = 1, ncomp
             f(c, mesh%conn(a, e)) = f(c, mesh%conn(a, e)) + contribution(e, c, a)
          end do
       end do
    end do
  end subroutine serial_assembly

  !> Bitwise equality of two real arrays of the same size.
  pure logical function same_bits(x, y)
    real(dp), intent(in) :: x(:), y(:)
    same_bits = size(x) == size(y)
    if (same_bits) same_bits = all(transfer(x, 0_int64, size(x)) == transfer(y, 0_int64, size(y)))
  end function same_bits

  !> Numerical equality of reals (0 = -0, NaN never equal), for exact expectations in the
  !> tests without tripping -Wcompare-reals.
  elemental logical function eq(x, y)
    real(dp), intent(in) :: x, y
    eq = x <= y .and. x >= y
  end function eq

  !> Record one check on this rank; a failure is printed with the rank.
  subroutine check(ok, what, rank)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    integer, intent(in) :: rank

    n_checks = n_checks + 1
    if (.not. ok) then
       n_failed = n_failed + 1
       write (error_unit, '(a, i0, a)') 'FAIL [rank ', rank, '] ' // what
       flush (error_unit)
    end if
  end subroutine check

  !> Total failures over all ranks (collective); rank 0 prints the summary line.
  integer function check_summary(comm, program_name) result(failed)
    type(MPI_Comm), intent(in) :: comm
    character(len=*), intent(in) :: program_name
    integer :: checks

    failed = n_failed
    checks = n_checks
    call comm_sum(comm, failed)
    call comm_sum(comm, checks)
    if (comm_rank(comm) == 0) then
       write (output_unit, '(a, 2(a, i0), a)') program_name, ': ', checks, ' checks over all ranks, ', &
            failed, ' failed'
       flush (output_unit)
    end if
  end function check_summary

end module parallel_test_support
