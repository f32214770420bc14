!> Halo sums of the spatially decomposed MPM grid (mpm_domain): after P2G every rank has its
!> own particles' partial sums on its held nodes; the partials of ghost nodes go to the nodes'
!> owners, each owner adds all partials of a node from zero in rank order (deterministic for a
!> given rank count), and sends the totals back to every rank that holds the node. Every holder
!> then has the same complete mass, momentum and force and does the mirror folds, the grid
!> update and the walls on its held nodes itself, with the same bits as the owner: so v^n and
!> v^{n+1} need no exchange of their own. Accounting (wall forces, damping and friction
!> energies, mirror reactions) counts owned nodes only (`owned_mass`) and is summed over the
!> ranks once per increment (`sum_increment_accounts`).
module mpm_halo
  use base_kinds, only: dp
  use mpm_state, only: mpm_state_t
  use mpm_domain, only: domain_t
  use mpm_grid, only: grid_t, grid_init_box, grid_node_count
  use mpm_particles, only: particle_block_t
  use error_report, only: raise_error
  use parallel_exchange, only: exchange_neighbours
  use parallel_comm, only: comm_sum
  implicit none
  private

  public :: halo_sum_p2g, halo_sum_momentum, owned_mass, sum_increment_accounts
  public :: domain_regrid, local_corners, whole_grid_shape

contains

  !> Complete the P2G sums (mass, momentum, force) on every held node. Collective.
  subroutine halo_sum_p2g(st)
    type(mpm_state_t), intent(inout) :: st
    call halo_sum(st%dom, st, 1 + 2 * st%nd, .true.)
  end subroutine halo_sum_p2g

  !> Complete the MUSL remap's momentum on every held node. Collective.
  subroutine halo_sum_momentum(st)
    type(mpm_state_t), intent(inout) :: st
    call halo_sum(st%dom, st, st%nd, .false.)
  end subroutine halo_sum_momentum

  !> nv values per node: [mass, mom(1:nd), force(1:nd)] (all) or mom(1:nd).
  subroutine halo_sum(d, st, nv, all_fields)
    type(domain_t), intent(in) :: d
    type(mpm_state_t), intent(inout) :: st
    integer, intent(in) :: nv
    logical, intent(in) :: all_fields
    real(dp), allocatable :: sbuf(:), rbuf(:), mine(:, :)
    integer :: nsend, nrecv, k, j, node, r, kn
    integer, allocatable :: sfirst(:), rfirst(:)

    nsend = size(d%send_nodes)
    nrecv = size(d%recv_nodes)
    allocate (sbuf(nv * nsend), rbuf(nv * nrecv), mine(nv, size(d%shared)))
    allocate (sfirst(size(d%send_first)), source=nv * (d%send_first - 1) + 1)
    allocate (rfirst(size(d%recv_first)), source=nv * (d%recv_first - 1) + 1)
    ! 1. this rank's partials of the nodes the neighbours own go to them
    do j = 1, nsend
       call get_node(st, d%send_nodes(j), nv, all_fields, sbuf(nv * (j - 1) + 1:nv * j))
    end do
    call exchange_neighbours(st%comm, d%nbr, sfirst, sbuf, rfirst, rbuf)
    ! 2. owned nodes the neighbours hold: every partial re-added from zero in rank order
    do j = 1, size(d%shared)
       call get_node(st, d%shared(j), nv, all_fields, mine(:, j))
       call put_node(st, d%shared(j), nv, all_fields, [(0.0_dp, k = 1, nv)], .false.)
    end do
    kn = 1
    do r = 0, d%nranks - 1
       if (r == d%rank) then
          do j = 1, size(d%shared)
             call put_node(st, d%shared(j), nv, all_fields, mine(:, j), .true.)
          end do
       end if
       if (kn > size(d%nbr)) cycle
       if (d%nbr(kn) /= r) cycle
       do j = d%recv_first(kn), d%recv_first(kn + 1) - 1
          call put_node(st, d%recv_nodes(j), nv, all_fields, rbuf(nv * (j - 1) + 1:nv * j), .true.)
       end do
       kn = kn + 1
    end do
    ! 3. the totals go back to the holders
    do j = 1, nrecv
       call get_node(st, d%recv_nodes(j), nv, all_fields, rbuf(nv * (j - 1) + 1:nv * j))
    end do
    call exchange_neighbours(st%comm, d%nbr, rfirst, rbuf, sfirst, sbuf)
    do j = 1, nsend
       node = d%send_nodes(j)
       call put_node(st, node, nv, all_fields, sbuf(nv * (j - 1) + 1:nv * j), .false.)
    end do
  end subroutine halo_sum

  subroutine get_node(st, node, nv, all_fields, v)
    type(mpm_state_t), intent(in) :: st
    integer, intent(in) :: node, nv
    logical, intent(in) :: all_fields
    real(dp), intent(out) :: v(nv)
    integer :: nd

    nd = st%nd
    if (all_fields) then
       v(1) = st%g%mass(node)
       v(2:1 + nd) = st%g%mom(:, node)
       v(2 + nd:1 + 2 * nd) = st%g%force(:, node)
    else
       v = st%g%mom(:, node)
    end if
  end subroutine get_node

  !> Node values ← v (add: ← values + v).
  subroutine put_node(st, node, nv, all_fields, v, add)
    type(mpm_state_t), intent(inout) :: st
    integer, intent(in) :: node, nv
    logical, intent(in) :: all_fields, add
    real(dp), intent(in) :: v(nv)
    integer :: nd

    nd = st%nd
    if (all_fields) then
       if (add) then
          st%g%mass(node) = st%g%mass(node) + v(1)
          st%g%mom(:, node) = st%g%mom(:, node) + v(2:1 + nd)
          st%g%force(:, node) = st%g%force(:, node) + v(2 + nd:1 + 2 * nd)
       else
          st%g%mass(node) = v(1)
          st%g%mom(:, node) = v(2:1 + nd)
          st%g%force(:, node) = v(2 + nd:1 + 2 * nd)
       end if
    else if (add) then
       st%g%mom(:, node) = st%g%mom(:, node) + v
    else
       st%g%mom(:, node) = v
    end if
  end subroutine put_node

  !> The grid's mass_own on owned nodes only (zero on ghost nodes), after the mirror folds: the
  !> walls' forces and friction work and the damping energy are weighted by it, so each node's
  !> share is booked once, by its owner.
  subroutine owned_mass(st)
    type(mpm_state_t), intent(inout) :: st
    where (.not. st%dom%owned) st%g%mass_own = 0
  end subroutine owned_mass

  !> Sum over the ranks what this increment booked on owned nodes: the wall forces (mirror
  !> reactions included) and the increments of the wall friction and damping energies since
  !> e_walls0, e_damping0. Every rank then holds the totals, as with the replicated grid. Collective.
  subroutine sum_increment_accounts(st, e_walls0, e_damping0)
    type(mpm_state_t), intent(inout) :: st
    real(dp), intent(in) :: e_walls0, e_damping0
    real(dp), allocatable :: buf(:)
    integer :: nw

    nw = size(st%wall_force, 2)
    allocate (buf(3 * nw + 2))
    buf(1:3 * nw) = reshape(st%wall_force, [3 * nw])
    buf(3 * nw + 1) = st%e_walls - e_walls0
    buf(3 * nw + 2) = st%e_damping - e_damping0
    call comm_sum(st%comm, buf)
    st%wall_force = reshape(buf(1:3 * nw), [3, nw])
    st%e_walls = e_walls0 + buf(3 * nw + 1)
    st%e_damping = e_damping0 + buf(3 * nw + 2)
  end subroutine sum_increment_accounts

  !> The whole grid's sizes and position (no node arrays): what the field output describes.
  function whole_grid_shape(st) result(gw)
    type(mpm_state_t), intent(in) :: st
    type(grid_t) :: gw
    gw%ndim = st%g%ndim
    gw%n = st%dom%n
    gw%nn = int(grid_node_count(gw%n))
    gw%lo = st%g%lo
    gw%h = st%g%h
  end function whole_grid_shape

  !> This rank's grid becomes its held box (mpm_domain: after a (re-)partition): node arrays for
  !> the held nodes only. The walls' node lists and mirrors must be found again on it (mpm_setup).
  subroutine domain_regrid(st)
    type(mpm_state_t), intent(inout) :: st
    real(dp) :: lo(3), h

    lo = st%g%lo
    h = st%g%h
    call grid_init_box(st%g, st%nd, lo, h, st%dom%held_lo, st%dom%nl)
  end subroutine domain_regrid

  !> The block's stencil corners (block_stencil's, numbered on the whole grid) in this rank's
  !> grid's numbering. A corner outside the held box is a decomposition error (a particle not
  !> in this rank's box), reported rather than written out of bounds.
  subroutine local_corners(st, b)
    type(mpm_state_t), intent(in) :: st
    type(particle_block_t), intent(inout) :: b
    integer :: p, r, idx(3), top(3)

    top = st%g%n - st%nsup
    if (st%nd == 2) top(3) = 0
    do p = 1, b%count
       r = b%corner(p) - 1
       idx(1) = mod(r, st%dom%n(1))
       r = r / st%dom%n(1)
       idx(2) = mod(r, st%dom%n(2))
       idx(3) = r / st%dom%n(2)
       idx = idx - st%g%offset
       if (any(idx < 0) .or. any(idx > top)) call raise_error('mpm_halo', 0, 'particle outside the held ' // &
            'box of its rank; expected the particles of a rank in its box (migration)')
       b%corner(p) = 1 + idx(1) + st%g%n(1) * (idx(2) + st%g%n(2) * idx(3))
    end do
  end subroutine local_corners
end module mpm_halo
