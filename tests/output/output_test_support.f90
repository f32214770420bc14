!> Helpers of the output test programs: checks that count failures on every rank, and the
!> small structured meshes (2D CPE4R, 3D C3D8R) with a deliberately scattered distribution
!> of elements over ranks, so that each rank's rows of the global datasets form several runs.
!> check_output_fields.py rebuilds the same meshes and field values.
module output_test_support
  use mpi_f08, only: MPI_Comm, MPI_COMM_WORLD, MPI_Comm_rank, MPI_Allreduce, MPI_IN_PLACE, &
       MPI_INTEGER, MPI_SUM
  use material_kinds, only: dp
  implicit none
  private

  public :: check, check_message, failures_everywhere
  public :: test_mesh_t, make_mesh, element_rank

  integer :: n_failures = 0

  !> A structured mesh and this rank's part of it.
  type :: test_mesh_t
     integer :: ndim, nen, n_nodes, n_elems
     real(dp), allocatable :: x0(:, :)          !< (ndim, n_nodes) global
     integer, allocatable :: conn(:, :)         !< (nen, n_elems) global 1-based
     integer, allocatable :: node_global(:)     !< local part
     logical, allocatable :: node_owned(:)
     integer, allocatable :: elem_global(:)
  end type test_mesh_t

contains

  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    integer :: rank

    if (ok) return
    call MPI_Comm_rank(MPI_COMM_WORLD, rank)
    write (*, '(a, i0, 2a)') 'FAIL [rank ', rank, '] ', what
    n_failures = n_failures + 1
  end subroutine check

  !> `message` must contain `expected`.
  subroutine check_message(raised, message, expected, what)
    logical, intent(in) :: raised
    character(len=:), allocatable, intent(in) :: message
    character(len=*), intent(in) :: expected
    character(len=*), intent(in) :: what

    if (.not. raised) then
       call check(.false., what // ': no error raised')
    else if (.not. allocated(message)) then
       call check(.false., what // ': error without message')
    else
       call check(index(message, expected) > 0, what // ': message "' // message // &
            '" lacks "' // expected // '"')
    end if
  end subroutine check_message

  !> Total failures over all ranks (collective).
  integer function failures_everywhere()
    failures_everywhere = n_failures
    call MPI_Allreduce(MPI_IN_PLACE, failures_everywhere, 1, MPI_INTEGER, MPI_SUM, MPI_COMM_WORLD)
  end function failures_everywhere

  !> Rank holding element e (1-based) among `active` ranks: scattered on purpose.
  pure integer function element_rank(e, active)
    integer, intent(in) :: e
    integer, intent(in) :: active

    element_rank = mod(7 * (e - 1) + 3, active)
  end function element_rank

  !> ndim = 2: nx*ny quads on [0, nx/2] x [0, ny/4]; ndim = 3: nx*ny*nz hexes. Elements go
  !> to ranks 0..active-1; nodes are local to a rank when one of its elements uses them,
  !> owned by the lowest such rank.
  subroutine make_mesh(ndim, nx, ny, nz, rank, active, m)
    integer, intent(in) :: ndim
    integer, intent(in) :: nx
    integer, intent(in) :: ny
    integer, intent(in) :: nz
    integer, intent(in) :: rank
    integer, intent(in) :: active
    type(test_mesh_t), intent(out) :: m
    integer, allocatable :: owner(:)
    logical, allocatable :: local(:)
    integer :: i, j, k, e, g, nxn, nyn

    m%ndim = ndim
    nxn = nx + 1
    nyn = ny + 1
    if (ndim == 2) then
       m%nen = 4
       m%n_nodes = nxn * nyn
       m%n_elems = nx * ny
    else
       m%nen = 8
       m%n_nodes = nxn * nyn * (nz + 1)
       m%n_elems = nx * ny * nz
    end if
    allocate (m%x0(ndim, m%n_nodes), m%conn(m%nen, m%n_elems))
    do g = 1, m%n_nodes
       i = mod(g - 1, nxn)
       j = mod((g - 1) / nxn, nyn)
       k = (g - 1) / (nxn * nyn)
       m%x0(1, g) = 0.5_dp * i
       m%x0(2, g) = 0.25_dp * j
       if (ndim == 3) m%x0(3, g) = 0.125_dp * k
    end do
    do e = 1, m%n_elems
       i = mod(e - 1, nx)
       j = mod((e - 1) / nx, ny)
       k = (e - 1) / (nx * ny)
       g = 1 + i + nxn * j + nxn * nyn * k
       m%conn(1:4, e) = [g, g + 1, g + 1 + nxn, g + nxn]
       if (ndim == 3) m%conn(5:8, e) = m%conn(1:4, e) + nxn * nyn
    end do

    allocate (owner(m%n_nodes), local(m%n_nodes))
    owner = huge(0)
    local = .false.
    do e = 1, m%n_elems
       owner(m%conn(:, e)) = min(owner(m%conn(:, e)), element_rank(e, active))
       if (element_rank(e, active) == rank) local(m%conn(:, e)) = .true.
    end do
    allocate (m%elem_global(0), m%node_global(0))
    if (rank < active) then
       m%elem_global = pack([(e, e = 1, m%n_elems)], &
            [(element_rank(e, active) == rank, e = 1, m%n_elems)])
       m%node_global = pack([(g, g = 1, m%n_nodes)], local)
    end if
    allocate (m%node_owned(size(m%node_global)))
    m%node_owned = owner(m%node_global) == rank
  end subroutine make_mesh

end module output_test_support
