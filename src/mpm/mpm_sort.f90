!> Particle order by grid cell (`*MPM CONTROLS, SORT=n`, docs/keywords.md): every n increments
!> the particles of this rank are put in the order of the grid cell that holds them, across
!> the blocks of one material and spacing, by a stable counting sort on the cell's node index
!> (x fastest, then y, then z: the grid arrays' memory order). The blocks keep their counts,
!> so the VUMAT work sets and every per-block size stay; a block then holds particles of
!> neighbouring cells, and the particle-major transfers (mpm_transfer's scatter_particles,
!> g2p_particles) walk the grid in memory order, each node's sums coming from a few
!> consecutive particles.
!>
!> What it changes: the order of the particles in the blocks (so in the field file; every
!> particle keeps its id) and thereby the order of the P2G and remap sums at a node, which
!> changes results by round-off only (measured: src/mpm/README.md, "Speed"). Deterministic:
!> the order depends on the positions and the increment number alone, so a restarted run
!> sorts at the same increments as the uninterrupted one.
module mpm_sort
  use base_kinds, only: dp
  use mpm_particles, only: particle_block_t
  implicit none
  private

  public :: sort_due, sort_blocks, cell_keys, counting_order

contains

  !> Is the sort due at increment `increment` with interval `every` (0: never)?
  pure logical function sort_due(every, increment)
    integer, intent(in) :: every, increment
    sort_due = .false.
    if (every > 0) sort_due = mod(increment, every) == 0
  end function sort_due

  !> Sort the particles of blocks(1:nblocks) by cell, within each group of blocks of one
  !> material and particle size (half). lo, h, n: the grid's origin, spacing, nodes per direction.
  subroutine sort_blocks(blocks, nblocks, ndim, lo, h, n)
    type(particle_block_t), intent(inout) :: blocks(:)
    integer, intent(in) :: nblocks, ndim
    real(dp), intent(in) :: lo(3), h
    integer, intent(in) :: n(3)
    logical :: done(nblocks)
    integer, allocatable :: list(:)
    integer :: ib, jb, nl

    done = .false.
    allocate (list(nblocks))
    do ib = 1, nblocks
       if (done(ib)) cycle
       nl = 0
       do jb = ib, nblocks
          if (done(jb)) cycle
          if (blocks(jb)%material /= blocks(ib)%material .or. abs(blocks(jb)%half - blocks(ib)%half) > 0) cycle
          nl = nl + 1
          list(nl) = jb
          done(jb) = .true.
       end do
       call sort_group(blocks, list(1:nl), ndim, lo, h, n)
    end do
  end subroutine sort_blocks

  !> Cell key of each of nb particles at x(nb, ndim): 1 + i + n1 (j + n2 k) of the cell's
  !> lowest node (i, j, k), clamped to the grid (a particle outside is the stencil's error).
  pure subroutine cell_keys(nb, ndim, lo, h, n, x, key)
    integer, intent(in) :: nb, ndim
    real(dp), intent(in) :: lo(3), h
    integer, intent(in) :: n(3)
    real(dp), intent(in) :: x(nb, ndim)
    integer, intent(out) :: key(nb)
    integer :: p, k, stride, ic

    key = 1
    stride = 1
    do k = 1, ndim
       do p = 1, nb
          ic = min(max(int((x(p, k) - lo(k)) / h), 0), n(k) - 1)
          key(p) = key(p) + stride * ic
       end do
       stride = stride * n(k)
    end do
  end subroutine cell_keys

  !> Stable counting sort: order(j) is the j-th item by key (keys in 1..nkeys); items of equal
  !> key keep their order.
  pure subroutine counting_order(nitems, key, nkeys, order)
    integer, intent(in) :: nitems, nkeys
    integer, intent(in) :: key(nitems)
    integer, intent(out) :: order(nitems)
    integer, allocatable :: first(:)
    integer :: j, k, total, c

    allocate (first(nkeys + 1), source=0)
    do j = 1, nitems
       first(key(j)) = first(key(j)) + 1
    end do
    total = 0
    do k = 1, nkeys + 1
       c = first(k)
       first(k) = total + 1
       total = total + c
    end do
    do j = 1, nitems
       order(first(key(j))) = j
       first(key(j)) = first(key(j)) + 1
    end do
  end subroutine counting_order

  !> Sort the particles of the blocks `list` (one material and size) by cell over all of them.
  subroutine sort_group(blocks, list, ndim, lo, h, n)
    type(particle_block_t), intent(inout) :: blocks(:)
    integer, intent(in) :: list(:)
    integer, intent(in) :: ndim
    real(dp), intent(in) :: lo(3), h
    integer, intent(in) :: n(3)
    integer, allocatable :: key(:), order(:), dest(:), itmp(:)
    real(dp), allocatable :: tmp(:, :)
    integer :: ntot, nkeys, j0, k, ib, j, field, ncol_max

    ntot = 0
    ncol_max = ndim * ndim
    do k = 1, size(list)
       associate (b => blocks(list(k)))
         ntot = ntot + b%count
         ncol_max = max(ncol_max, size(b%stress, 2), size(b%state, 2), size(b%field, 2))
       end associate
    end do
    if (ntot < 2) return
    nkeys = n(1) * n(2) * n(3)
    allocate (key(ntot), order(ntot), dest(ntot))
    j0 = 0
    do k = 1, size(list)
       associate (b => blocks(list(k)))
         call cell_keys(b%count, ndim, lo, h, n, b%x, key(j0 + 1:j0 + b%count))
         j0 = j0 + b%count
       end associate
    end do
    call counting_order(ntot, key, nkeys, order)
    ! dest(j): the new place of the particle now at place j (places counted over the blocks)
    do j = 1, ntot
       dest(order(j)) = j
    end do
    if (all(dest == [(j, j = 1, ntot)])) return
    allocate (tmp(ntot, ncol_max), itmp(ntot))
    j0 = 0
    do k = 1, size(list)
       ib = list(k)
       itmp(dest(j0 + 1:j0 + blocks(ib)%count)) = blocks(ib)%number
       j0 = j0 + blocks(ib)%count
    end do
    j0 = 0
    do k = 1, size(list)
       ib = list(k)
       blocks(ib)%number = itmp(j0 + 1:j0 + blocks(ib)%count)
       j0 = j0 + blocks(ib)%count
    end do
    do field = 1, 13
       j0 = 0
       do k = 1, size(list)
          ib = list(k)
          call block_field(blocks(ib), field, ndim, tmp, dest(j0 + 1:), .true.)
          j0 = j0 + blocks(ib)%count
       end do
       j0 = 0
       do k = 1, size(list)
          ib = list(k)
          call block_field(blocks(ib), field, ndim, tmp(j0 + 1:, :), dest, .false.)
          j0 = j0 + blocks(ib)%count
       end do
    end do
  end subroutine sort_group

  !> Real per-particle field `field` (1..13) of block b: scatter its rows to tmp(dest(r), :)
  !> (gather = true), or take them back from tmp(1:count, :) (gather = false; dest unused).
  subroutine block_field(b, field, ndim, tmp, dest, gather)
    type(particle_block_t), intent(inout) :: b
    integer, intent(in) :: field, ndim
    real(dp), intent(inout) :: tmp(:, :)
    integer, intent(in) :: dest(:)
    logical, intent(in) :: gather
    integer :: m

    ! F and R (count, nd, nd) go as (count, nd²) arrays (sequence association)
    m = b%count
    select case (field)
    case (1); call rows(m, ndim, b%x)
    case (2); call rows(m, ndim, b%v)
    case (3); call rows(m, 1, b%mass)
    case (4); call rows(m, 1, b%vol0)
    case (5); call rows(m, ndim * ndim, b%f)
    case (6); call rows(m, ndim * ndim, b%rot)
    case (7); call rows(m, size(b%stress, 2), b%stress)
    case (8); call rows(m, size(b%stress_global, 2), b%stress_global)
    case (9); call rows(m, size(b%state, 2), b%state)
    case (10); call rows(m, size(b%field, 2), b%field)
    case (11); call rows(m, 1, b%e_int)
    case (12); call rows(m, 1, b%e_inel)
    case default; call rows(m, size(b%log_strain, 2), b%log_strain)
    end select

  contains

    !> a(m, nc): the field as an explicit-shape array (F and R (m, nd, nd) as (m, nd²)).
    subroutine rows(m, nc, a)
      integer, intent(in) :: m, nc
      real(dp), intent(inout) :: a(m, nc)
      integer :: r, c

      if (gather) then
         do c = 1, nc
            do r = 1, m
               tmp(dest(r), c) = a(r, c)
            end do
         end do
      else
         do c = 1, nc
            do r = 1, m
               a(r, c) = tmp(r, c)
            end do
         end do
      end if
    end subroutine rows
  end subroutine block_field
end module mpm_sort
