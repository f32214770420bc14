!> The spatial decomposition of the MPM grid (`*MPM CONTROLS, DECOMPOSITION=SPATIAL`): which
!> box of grid cells each rank owns, which nodes it holds, and the plan of the halo sums.
!>
!> * Boxes: recursive coordinate bisection of the cells on particle counts (`rcb_boxes`, a pure
!>   function of the counts), every cut on a node plane. The boxes tile the grid's cells; a
!>   particle belongs to the rank whose box holds its cell floor((x − lo)/h).
!> * Owned nodes: the nodes of the box's cells with index c0 .. c1 per axis (the last node plane
!>   goes with the last cell): every node has exactly one owner.
!> * Held nodes: the owned box widened by the stencil's reach, cells c0 − gl .. c1 + gh with
!>   gl = nsup − 2, gh = nsup − 1 (uGIMP's 3-node stencil: 1 below, 2 above; linear: 0 and 1),
!>   and across a mirrored symmetry plane (mpm_mirror) to the image nodes of the held nodes
!>   within two cells of it, so a rank can fold its nodes itself.
!> * Plan: per neighbour, the held nodes it owns (this rank's partial sums go there, the totals
!>   come back) and the owned nodes it holds (its partials come in, the totals go out), both in
!>   ascending node index, derived alike on both sides from the boxes: messages carry values only.
!>   Node numbers of the plan and the owned mask are those of the rank's grid, the held box
!>   (mpm_grid's offset = held_lo).
module mpm_domain
  use base_kinds, only: dp
  implicit none
  private

  type, public :: domain_t
     logical :: on = .false.
     integer :: rank = 0, nranks = 1, ndim = 2
     integer :: n(3) = 1                 !< grid nodes per direction
     integer :: ncell(3) = 1             !< cells per direction (1 in 2D's third)
     integer :: gl = 0, gh = 0           !< ghost node layers below / above a box
     integer, allocatable :: box(:, :, :)   !< (2, 3, 0:nranks − 1) cell range [lo, hi] (0-based)
     integer :: held_lo(3) = 0, held_hi(3) = 0   !< this rank's held node range (0-based)
     integer :: nl(3) = 0                !< nodes per direction of the held box (the rank's grid)
     logical, allocatable :: owned(:)    !< (nodes of the held box) node owned by this rank
     integer, allocatable :: nbr(:)      !< neighbour ranks, ascending
     integer, allocatable :: send_first(:), send_nodes(:)   !< per neighbour: held nodes it owns
     integer, allocatable :: recv_first(:), recv_nodes(:)   !< per neighbour: owned nodes it holds
     integer, allocatable :: shared(:)   !< owned nodes some neighbour holds (ascending)
     integer, allocatable :: mirror_axis(:), mirror_layer(:)   !< mirrored planes (node layer)
     real(dp) :: rebalance = 0.02_dp     !< re-partition when max/mean − 1 of the counts exceeds it (and new boxes gain)
     integer :: rebalance_every = 20     !< increments between the imbalance checks
     integer :: rebalances = 0           !< re-partitions done in this run
     integer, allocatable :: sent(:)     !< (0:nranks − 1) particles migrated to each rank (increment ends)
  end type domain_t

  public :: rcb_boxes, domain_init, domain_build, cell_of, rank_of_cell, held_range, owned_range

contains

  !> Boxes of cells for nparts ranks by recursive coordinate bisection of counts(c1, c2, c3)
  !> (particles per cell): a range of np parts is split into np/2 and the rest across the axis
  !> of the box's largest extent in cells (the lower axis on a tie), on the node plane whose
  !> lower side's count is closest to total·(np/2)/np (the lower plane on a tie), each side
  !> keeping at least one cell. A box of one cell with several parts gives its cell to the
  !> first and empty boxes (hi < lo) to the others. Pure: the same counts give the same boxes.
  pure function rcb_boxes(counts, nparts) result(box)
    integer, intent(in) :: counts(:, :, :)
    integer, intent(in) :: nparts
    integer :: box(2, 3, 0:nparts - 1)
    integer :: full(2, 3)

    full(1, :) = 0
    full(2, :) = shape(counts) - 1
    call split(full, 0, nparts, box)
  contains
    pure recursive subroutine split(b, first, np, out)
      integer, intent(in) :: b(2, 3), first, np
      integer, intent(inout) :: out(2, 3, 0:nparts - 1)
      integer :: axis, k, ext(3), nlo, c, best_c, left(2, 3), right(2, 3)
      integer(kind=8) :: total, below, slice
      real(dp) :: target, best, diff

      if (np == 1) then
         out(:, :, first) = b
         return
      end if
      ext = b(2, :) - b(1, :) + 1
      axis = 0
      do k = 1, 3
         if (ext(k) < 2) cycle
         if (axis == 0) then
            axis = k
         else if (ext(k) > ext(axis)) then
            axis = k
         end if
      end do
      if (axis == 0) then
         out(:, :, first) = b
         do k = first + 1, first + np - 1
            out(1, :, k) = 0
            out(2, :, k) = -1
         end do
         return
      end if
      nlo = np / 2
      total = box_count(b)
      target = real(total, dp) * nlo / np
      below = 0
      best = huge(1.0_dp)
      best_c = b(1, axis) + 1
      do c = b(1, axis) + 1, b(2, axis)
         ! cells b(1) .. c − 1 below the plane c
         left = b
         left(1, axis) = c - 1
         left(2, axis) = c - 1
         slice = box_count(left)
         below = below + slice
         diff = abs(real(below, dp) - target)
         if (diff < best) then
            best = diff
            best_c = c
         end if
      end do
      left = b
      left(2, axis) = best_c - 1
      right = b
      right(1, axis) = best_c
      call split(left, first, nlo, out)
      call split(right, first + nlo, np - nlo, out)
    end subroutine split

    pure integer(kind=8) function box_count(b)
      integer, intent(in) :: b(2, 3)
      box_count = sum(int(counts(b(1, 1) + 1:b(2, 1) + 1, b(1, 2) + 1:b(2, 2) + 1, b(1, 3) + 1:b(2, 3) + 1), 8))
    end function box_count
  end function rcb_boxes

  !> The fixed part of a decomposition: grid sizes, ghost widths, mirrored planes.
  subroutine domain_init(d, rank, nranks, ndim, n, nsup, mirror_axis, mirror_layer, rebalance)
    type(domain_t), intent(inout) :: d
    integer, intent(in) :: rank, nranks, ndim, n(3), nsup
    integer, intent(in) :: mirror_axis(:), mirror_layer(:)
    real(dp), intent(in) :: rebalance

    d%on = .true.
    d%rank = rank
    d%nranks = nranks
    d%ndim = ndim
    d%n = n
    d%ncell = 1
    d%ncell(1:ndim) = n(1:ndim) - 1
    d%gl = nsup - 2
    d%gh = nsup - 1
    d%mirror_axis = mirror_axis
    d%mirror_layer = mirror_layer
    d%rebalance = rebalance
    if (allocated(d%sent)) deallocate (d%sent)
    allocate (d%sent(0:nranks - 1), source=0)
  end subroutine domain_init

  !> Owned mask, held range and exchange plan of this rank for the boxes box(2, 3, 0:nranks − 1).
  subroutine domain_build(d, box)
    type(domain_t), intent(inout) :: d
    integer, intent(in) :: box(:, :, 0:)
    integer :: r, k, nn, olo(3), ohi(3), hlo(3), hhi(3), ns, nr, nbr(d%nranks), i, j, l, node
    integer, allocatable :: sfirst(:), rfirst(:), snodes(:), rnodes(:)
    logical, allocatable :: is_shared(:)

    d%box = box
    call held_range(d, d%rank, d%held_lo, d%held_hi)
    d%nl = max(0, d%held_hi - d%held_lo + 1)
    nn = product(d%nl)
    if (allocated(d%owned)) deallocate (d%owned)
    allocate (d%owned(nn), is_shared(nn))
    d%owned = .false.
    is_shared = .false.
    call owned_range(d, d%rank, olo, ohi)
    do k = olo(3), ohi(3)
       do j = olo(2), ohi(2)
          do i = olo(1), ohi(1)
             d%owned(local_node(i, j, k)) = .true.
          end do
       end do
    end do
    allocate (sfirst(d%nranks + 1), rfirst(d%nranks + 1), snodes(0), rnodes(0))
    sfirst(1) = 1
    rfirst(1) = 1
    ns = 0
    do r = 0, d%nranks - 1
       if (r == d%rank) cycle
       ! held here ∩ owned there: this rank's partials go to r
       call owned_range(d, r, olo, ohi)
       hlo = max(d%held_lo, olo)
       hhi = min(d%held_hi, ohi)
       snodes = [snodes, box_nodes(hlo, hhi)]
       ! owned here ∩ held there: r's partials come here
       call owned_range(d, d%rank, olo, ohi)
       call held_range(d, r, hlo, hhi)
       rnodes = [rnodes, box_nodes(max(hlo, olo), min(hhi, ohi))]
       if (size(snodes) + 1 == sfirst(ns + 1) .and. size(rnodes) + 1 == rfirst(ns + 1)) cycle
       ns = ns + 1
       nbr(ns) = r
       sfirst(ns + 1) = size(snodes) + 1
       rfirst(ns + 1) = size(rnodes) + 1
    end do
    d%nbr = nbr(1:ns)
    d%send_first = sfirst(1:ns + 1)
    d%recv_first = rfirst(1:ns + 1)
    d%send_nodes = snodes
    d%recv_nodes = rnodes
    is_shared(rnodes) = .true.
    nr = count(is_shared)
    if (allocated(d%shared)) deallocate (d%shared)
    allocate (d%shared(nr))
    l = 0
    do node = 1, nn
       if (.not. is_shared(node)) cycle
       l = l + 1
       d%shared(l) = node
    end do
  contains
    !> Node indices (this rank's grid) of the node box lo..hi (0-based, whole grid, inclusive,
    !> inside the held box), ascending; none when empty.
    function box_nodes(lo, hi) result(list)
      integer, intent(in) :: lo(3), hi(3)
      integer, allocatable :: list(:)
      integer :: a, b, c, m
      allocate (list(max(0, product(max(0, hi - lo + 1)))))
      m = 0
      do c = lo(3), hi(3)
         do b = lo(2), hi(2)
            do a = lo(1), hi(1)
               m = m + 1
               list(m) = local_node(a, b, c)
            end do
         end do
      end do
    end function box_nodes

    !> This rank's grid's node of the whole grid's node (a, b, c) (0-based, inside the held box).
    pure integer function local_node(a, b, c)
      integer, intent(in) :: a, b, c
      local_node = 1 + (a - d%held_lo(1)) + d%nl(1) * ((b - d%held_lo(2)) + d%nl(2) * (c - d%held_lo(3)))
    end function local_node
  end subroutine domain_build

  !> Owned node range of rank r (0-based, inclusive; empty: hi < lo).
  pure subroutine owned_range(d, r, lo, hi)
    type(domain_t), intent(in) :: d
    integer, intent(in) :: r
    integer, intent(out) :: lo(3), hi(3)
    integer :: k

    lo = 0
    hi = 0
    do k = 1, d%ndim
       lo(k) = d%box(1, k, r)
       hi(k) = d%box(2, k, r)
       if (hi(k) == d%ncell(k) - 1) hi(k) = d%n(k) - 1
    end do
    if (any(d%box(2, 1:d%ndim, r) < d%box(1, 1:d%ndim, r))) hi = lo - 1
  end subroutine owned_range

  !> Held node range of rank r: its cells widened by the ghost layers, then over mirrored planes.
  pure subroutine held_range(d, r, lo, hi)
    type(domain_t), intent(in) :: d
    integer, intent(in) :: r
    integer, intent(out) :: lo(3), hi(3)
    integer :: k, a, l

    lo = 0
    hi = 0
    if (any(d%box(2, 1:d%ndim, r) < d%box(1, 1:d%ndim, r))) then
       hi = lo - 1
       return
    end if
    do k = 1, d%ndim
       lo(k) = max(0, d%box(1, k, r) - d%gl)
       hi(k) = min(d%n(k) - 1, d%box(2, k, r) + d%gh)
    end do
    do k = 1, size(d%mirror_axis)
       a = d%mirror_axis(k)
       l = d%mirror_layer(k)
       ! the fold pairs nodes one and two cells either side of the plane
       if (hi(a) >= l - 2 .and. lo(a) <= l + 2) then
          lo(a) = min(lo(a), max(0, l - 2))
          hi(a) = max(hi(a), min(d%n(a) - 1, l + 2))
       end if
    end do
  end subroutine held_range

  !> The cell (0-based, per axis) of position x, as the stencil computes it, clipped to the grid.
  pure function cell_of(d, lo, h, x) result(c)
    type(domain_t), intent(in) :: d
    real(dp), intent(in) :: lo(3), h, x(:)
    integer :: c(3), k

    c = 0
    do k = 1, d%ndim
       c(k) = min(max(floor((x(k) - lo(k)) / h), 0), d%ncell(k) - 1)
    end do
  end function cell_of

  !> The rank whose box holds cell c.
  pure integer function rank_of_cell(d, c) result(r)
    type(domain_t), intent(in) :: d
    integer, intent(in) :: c(3)
    integer :: k

    do r = 0, d%nranks - 1
       k = d%ndim
       if (all(c(1:k) >= d%box(1, 1:k, r)) .and. all(c(1:k) <= d%box(2, 1:k, r))) return
    end do
    r = 0
  end function rank_of_cell
end module mpm_domain
