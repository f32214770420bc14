!> Particles in blocks: each block holds at most `particle_block_size` particles of one
!> material, every per-particle array stored (particle, component) so that a block's stress,
!> state and field arrays are exactly the `(nblock, n)` arrays the VUMAT receives (the same
!> door as the element blocks, src/material/material_door.f90).
!>
!> Arrays always have exactly `count` rows (the VUMAT reads them with leading dimension
!> nblock); removing (outflow) or adding (inflow) particles repacks the block's arrays. That
!> costs O(block) per change and happens for a few blocks per increment at most.
module mpm_particles
  use base_kinds, only: dp
  implicit none
  private

  integer, parameter, public :: particle_block_size = 256

  type, public :: particle_block_t
     integer :: count = 0
     integer :: material = 0
     real(dp) :: half = 0                         !< uGIMP particle half-length h/(2 ppc)
     integer, allocatable :: number(:)            !< particle id (jblock(5:) of the VUMAT)
     real(dp), allocatable :: x(:, :), v(:, :)    !< (count, ndim) position, velocity
     real(dp), allocatable :: mass(:), vol0(:)    !< mass, initial volume (thickness 1 in 2D)
     real(dp), allocatable :: f(:, :, :)          !< (count, ndim, ndim) deformation gradient
     real(dp), allocatable :: rot(:, :, :)        !< (count, ndim, ndim) R of F = RU at t_n
     real(dp), allocatable :: stress(:, :)        !< corotational Cauchy stress (VUMAT order)
     real(dp), allocatable :: stress_global(:, :) !< global stress
     real(dp), allocatable :: state(:, :), field(:, :)
     real(dp), allocatable :: e_int(:), e_inel(:) !< specific energies
     real(dp), allocatable :: log_strain(:, :)    !< accumulated corotational strain (LE)
     ! Stencil of the current increment (mpm_shape layout): first node, 1D weights and
     ! derivatives (count, nsup, ndim).
     integer, allocatable :: corner(:)
     real(dp), allocatable :: w1(:, :, :), dw1(:, :, :)
  end type particle_block_t

  public :: block_allocate, block_keep, block_grow, drop_empty_blocks

contains

  !> A block of n particles (zeros, F = R = I); whatever b held before is released. nsup:
  !> stencil nodes per direction.
  subroutine block_allocate(b, n, ndim, ncomp, nstatev, nfieldv, nsup)
    type(particle_block_t), intent(out) :: b
    integer, intent(in) :: n, ndim, ncomp, nstatev, nfieldv, nsup
    integer :: k

    b%count = n
    allocate (b%number(n), b%x(n, ndim), b%v(n, ndim), b%mass(n), b%vol0(n), b%f(n, ndim, ndim), &
         b%rot(n, ndim, ndim), b%stress(n, ncomp), b%stress_global(n, ncomp), b%state(n, nstatev), &
         b%field(n, nfieldv), b%e_int(n), b%e_inel(n), b%log_strain(n, ncomp), b%corner(n), &
         b%w1(n, nsup, ndim), b%dw1(n, nsup, ndim))
    b%number = 0
    b%x = 0
    b%v = 0
    b%mass = 0
    b%vol0 = 0
    b%f = 0
    b%rot = 0
    do k = 1, ndim
       b%f(:, k, k) = 1
       b%rot(:, k, k) = 1
    end do
    b%stress = 0
    b%stress_global = 0
    b%state = 0
    b%field = 0
    b%e_int = 0
    b%e_inel = 0
    b%log_strain = 0
    b%corner = 1
    b%w1 = 0
    b%dw1 = 0
  end subroutine block_allocate

  !> Keep the particles keep(1:nk) (ascending row numbers), drop the others.
  subroutine block_keep(b, keep)
    type(particle_block_t), intent(inout) :: b
    integer, intent(in) :: keep(:)

    b%count = size(keep)
    call keep_i1(b%number, keep)
    call keep_r2(b%x, keep)
    call keep_r2(b%v, keep)
    call keep_r1(b%mass, keep)
    call keep_r1(b%vol0, keep)
    call keep_r3(b%f, keep)
    call keep_r3(b%rot, keep)
    call keep_r2(b%stress, keep)
    call keep_r2(b%stress_global, keep)
    call keep_r2(b%state, keep)
    call keep_r2(b%field, keep)
    call keep_r1(b%e_int, keep)
    call keep_r1(b%e_inel, keep)
    call keep_r2(b%log_strain, keep)
    call keep_i1(b%corner, keep)
    call keep_r3(b%w1, keep)
    call keep_r3(b%dw1, keep)
  end subroutine block_keep

  !> Grow the block to n >= count particles; the new rows start as block_allocate leaves them.
  subroutine block_grow(b, n, ndim)
    type(particle_block_t), intent(inout) :: b
    integer, intent(in) :: n, ndim
    type(particle_block_t) :: g
    integer :: m

    m = b%count
    call block_allocate(g, n, ndim, size(b%stress, 2), size(b%state, 2), size(b%field, 2), size(b%w1, 2))
    g%material = b%material
    g%half = b%half
    g%number(1:m) = b%number
    g%x(1:m, :) = b%x
    g%v(1:m, :) = b%v
    g%mass(1:m) = b%mass
    g%vol0(1:m) = b%vol0
    g%f(1:m, :, :) = b%f
    g%rot(1:m, :, :) = b%rot
    g%stress(1:m, :) = b%stress
    g%stress_global(1:m, :) = b%stress_global
    g%state(1:m, :) = b%state
    g%field(1:m, :) = b%field
    g%e_int(1:m) = b%e_int
    g%e_inel(1:m) = b%e_inel
    g%log_strain(1:m, :) = b%log_strain
    b = g
  end subroutine block_grow

  !> Blocks emptied by removals leave the list blocks(1:nblocks); the others keep their order.
  subroutine drop_empty_blocks(blocks, nblocks)
    type(particle_block_t), intent(inout) :: blocks(:)
    integer, intent(inout) :: nblocks
    integer :: ib, j

    j = 0
    do ib = 1, nblocks
       if (blocks(ib)%count == 0) cycle
       j = j + 1
       if (j /= ib) blocks(j) = blocks(ib)
    end do
    nblocks = j
  end subroutine drop_empty_blocks

  subroutine keep_r1(a, keep)
    real(dp), allocatable, intent(inout) :: a(:)
    integer, intent(in) :: keep(:)
    real(dp), allocatable :: t(:)
    allocate (t(size(keep)))
    t = a(keep)
    call move_alloc(t, a)
  end subroutine keep_r1

  subroutine keep_r2(a, keep)
    real(dp), allocatable, intent(inout) :: a(:, :)
    integer, intent(in) :: keep(:)
    real(dp), allocatable :: t(:, :)
    allocate (t(size(keep), size(a, 2)))
    t = a(keep, :)
    call move_alloc(t, a)
  end subroutine keep_r2

  subroutine keep_r3(a, keep)
    real(dp), allocatable, intent(inout) :: a(:, :, :)
    integer, intent(in) :: keep(:)
    real(dp), allocatable :: t(:, :, :)
    allocate (t(size(keep), size(a, 2), size(a, 3)))
    t = a(keep, :, :)
    call move_alloc(t, a)
  end subroutine keep_r3

  subroutine keep_i1(a, keep)
    integer, allocatable, intent(inout) :: a(:)
    integer, intent(in) :: keep(:)
    integer, allocatable :: t(:)
    allocate (t(size(keep)))
    t = a(keep)
    call move_alloc(t, a)
  end subroutine keep_i1
end module mpm_particles
