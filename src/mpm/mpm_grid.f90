!> The structured background grid: node arrays reset every increment (the grid carries no
!> history). Node (i, j[, k]) (0-based) has index 1 + i + n1 (j + n2 k) and position lo + (i, j, k) h.
module mpm_grid
  use, intrinsic :: iso_fortran_env, only: int64
  use base_kinds, only: dp
  implicit none
  private

  type, public :: grid_t
     integer :: ndim = 0
     integer :: n(3) = 1                    !< nodes per direction
     integer :: nn = 0                      !< nodes in all
     real(dp) :: lo(3) = 0, h = 0
     !> node (i, j, k) of this grid is node (i, j, k) + offset of the whole grid at lo: a rank's
     !> held box of a spatially decomposed grid (mpm_domain); 0 for the whole grid
     integer :: offset(3) = 0
     real(dp), allocatable :: mass(:)       !< (nn)
     !> (nn) the mass the particles of this model gave each node, before a mirror plane folded
     !> its image's in (mpm_mirror); weights wall forces and energies. = mass without mirrors.
     real(dp), allocatable :: mass_own(:)
     real(dp), allocatable :: mom(:, :)     !< (ndim, nn) momentum at t_n (P2G)
     real(dp), allocatable :: force(:, :)   !< (ndim, nn) internal + external force
     real(dp), allocatable :: v_old(:, :)   !< (ndim, nn) velocity at t_n
     real(dp), allocatable :: v_new(:, :)   !< (ndim, nn) velocity at t_n+1 (after walls)
     logical, allocatable :: active(:)      !< mass above the cut-off this increment
   contains
     procedure :: position => grid_position
  end type grid_t

  public :: grid_init, grid_init_box, grid_reset, grid_reset_sums, grid_node_index, grid_clear
  public :: grid_node_count, grid_sum_length

contains

  !> The whole grid from lo to hi with cell h. With nodes = .false. only its geometry (sizes,
  !> positions): a spatially decomposed run allocates its held box only (mpm_halo domain_regrid),
  !> so no rank's peak memory holds the whole grid's node arrays.
  subroutine grid_init(g, ndim, lo, hi, h, nodes)
    type(grid_t), intent(out) :: g
    integer, intent(in) :: ndim
    real(dp), intent(in) :: lo(3), hi(3), h
    logical, intent(in), optional :: nodes
    integer :: k

    g%ndim = ndim
    g%h = h
    g%lo = lo
    g%n = 1
    do k = 1, ndim
       ! nodes up to the first node line at or beyond hi
       g%n(k) = ceiling((hi(k) - lo(k)) / h - 1.0e-9_dp) + 1
    end do
    ! the reader refused grids beyond 2147483647 nodes (scene_mpm check_mpm_size): nn fits
    g%nn = int(grid_node_count(g%n))
    if (present(nodes)) then
       if (.not. nodes) return
    end if
    allocate (g%mass(g%nn), g%mass_own(g%nn), g%mom(ndim, g%nn), g%force(ndim, g%nn), g%v_old(ndim, g%nn), &
         g%v_new(ndim, g%nn), g%active(g%nn))
    call grid_reset(g)
  end subroutine grid_init

  !> The box of n(3) nodes from node `offset` of the whole grid at lo with cell h (positions are
  !> the whole grid's: lo + (offset + (i, j, k)) h).
  subroutine grid_init_box(g, ndim, lo, h, offset, n)
    type(grid_t), intent(out) :: g
    integer, intent(in) :: ndim, offset(3), n(3)
    real(dp), intent(in) :: lo(3), h

    g%ndim = ndim
    g%h = h
    g%lo = lo
    g%offset = offset
    g%n = n
    g%nn = int(grid_node_count(g%n))
    allocate (g%mass(g%nn), g%mass_own(g%nn), g%mom(ndim, g%nn), g%force(ndim, g%nn), g%v_old(ndim, g%nn), &
         g%v_new(ndim, g%nn), g%active(g%nn))
    call grid_reset(g)
  end subroutine grid_init_box

  !> Nodes of a grid with n(k) nodes per direction, in 64 bits: a product of counts that a
  !> small cell takes beyond 2^31 (issue 16).
  pure integer(int64) function grid_node_count(n) result(count)
    integer, intent(in) :: n(3)
    count = product(int(n, int64))
  end function grid_node_count

  !> Values one reduction of the grid's mass, momentum and force moves over the ranks,
  !> nn (1 + 2 ndim): beyond 2^31 already for 3D grids of 307 M nodes.
  pure integer(int64) function grid_sum_length(nn, ndim) result(length)
    integer, intent(in) :: nn, ndim
    length = int(nn, int64) * (1 + 2 * ndim)
  end function grid_sum_length

  subroutine grid_reset(g)
    type(grid_t), intent(inout) :: g
    call grid_reset_sums(g)
    g%mass_own = 0
    g%v_old = 0
    g%v_new = 0
    g%active = .false.
  end subroutine grid_reset

  !> Zero what P2G sums into (mass, momentum, force). The increment calls only this: mass_own,
  !> active, v_old and v_new are written for every node after P2G (the grid update writes
  !> zero velocities on inactive nodes), so zeroing them as well was wasted stores.
  subroutine grid_reset_sums(g)
    type(grid_t), intent(inout) :: g
    call grid_clear(g%nn, g%mass)
    call grid_clear(g%ndim * g%nn, g%mom)
    call grid_clear(g%ndim * g%nn, g%force)
  end subroutine grid_reset_sums

  !> a(1:n) = 0 for a whole contiguous grid array. Why not `g%mom = 0`: gfortran scalarised the
  !> (ndim, nn) assignment column by column and called memset for every node (two calls a node
  !> per increment in grid_reset_sums alone); one explicit-shape loop is one memset.
  pure subroutine grid_clear(n, a)
    integer, intent(in) :: n
    real(dp), intent(out) :: a(n)
    a = 0
  end subroutine grid_clear

  !> Position of node `node` (1-based index).
  pure function grid_position(g, node) result(x)
    class(grid_t), intent(in) :: g
    integer, intent(in) :: node
    real(dp) :: x(3)

    x = g%lo + g%h * real(grid_node_index(g, node) + g%offset, dp)
    if (g%ndim == 2) x(3) = 0
  end function grid_position

  !> The 0-based (i, j, k) of node `node` (1-based index; k = 0 in 2D).
  pure function grid_node_index(g, node) result(idx)
    type(grid_t), intent(in) :: g
    integer, intent(in) :: node
    integer :: idx(3), r

    r = node - 1
    idx(1) = mod(r, g%n(1))
    r = r / g%n(1)
    idx(2) = mod(r, g%n(2))
    idx(3) = r / g%n(2)
  end function grid_node_index
end module mpm_grid
