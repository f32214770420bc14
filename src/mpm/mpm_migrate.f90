!> Particles between the ranks of a spatially decomposed MPM run (mpm_domain): the first split
!> of the set-up's particles, the migration of the particles whose position left the rank's box
!> (end of every increment), and the re-partition when the particle counts drift apart.
!>
!> A particle travels as one row of reals: material, half-length, number, x, v, mass, V0, F, R,
!> σ (corotational and global), specific energies, LE, state and field variables (the widths of
!> its material's blocks) — everything a block holds across increments (the stencil is made again
!> at the next P2G). Received rows are appended in the order they come (source rank, then the
!> sender's block order) to blocks of their material and spacing (≤ particle_block_size each),
!> so a run is deterministic for a given rank count.
module mpm_migrate
  use base_kinds, only: dp
  use model, only: model_t
  use mpm_state, only: mpm_state_t
  use mpm_particles, only: particle_block_t, particle_block_size, block_allocate, block_grow, block_keep, &
       drop_empty_blocks
  use mpm_domain, only: domain_init, domain_build, rcb_boxes, cell_of, rank_of_cell
  use parallel_exchange, only: exchange_all
  use mpm_halo, only: domain_regrid
  use parallel_comm, only: comm_sum, comm_max
  implicit none
  private

  public :: decompose_start, decompose_boxes, migrate_particles, repartition, record_length, &
       pack_record, unpack_records, domain_increment_end

contains

  !> Reals of one particle's row for a material with nsv state and nfv field columns.
  pure integer function record_length(nd, nc, nsv, nfv)
    integer, intent(in) :: nd, nc, nsv, nfv
    record_length = 3 + 2 * nd + 2 + 2 * nd * nd + 3 * nc + 2 + nsv + nfv
  end function record_length

  !> Row p of block b into buf(pos:), pos advanced past it.
  subroutine pack_record(b, p, nd, buf, pos)
    type(particle_block_t), intent(in) :: b
    integer, intent(in) :: p, nd
    real(dp), intent(inout) :: buf(:)
    integer, intent(inout) :: pos
    integer :: nc

    nc = size(b%stress, 2)
    call put([real(b%material, dp), b%half, real(b%number(p), dp)])
    call put(b%x(p, :))
    call put(b%v(p, :))
    call put([b%mass(p), b%vol0(p)])
    call put(reshape(b%f(p, :, :), [nd * nd]))
    call put(reshape(b%rot(p, :, :), [nd * nd]))
    call put(b%stress(p, :))
    call put(b%stress_global(p, :))
    call put([b%e_int(p), b%e_inel(p)])
    call put(b%log_strain(p, :))
    call put(b%state(p, :))
    call put(b%field(p, :))
  contains
    subroutine put(v)
      real(dp), intent(in) :: v(:)
      buf(pos:pos + size(v) - 1) = v
      pos = pos + size(v)
    end subroutine put
  end subroutine pack_record

  !> Append the rows buf(1:n) (pack_record's) to the rank's blocks: a run of rows of one
  !> material and spacing fills the last block of that kind, then new blocks.
  subroutine unpack_records(m, st, buf)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    real(dp), intent(in) :: buf(:)
    integer :: pos, mat, ib, first, nd, nc, nsv, nfv, len
    real(dp) :: half

    nd = st%nd
    nc = st%nc
    pos = 1
    do while (pos <= size(buf))
       mat = nint(buf(pos))
       half = buf(pos + 1)
       nsv = max(1, m%materials(mat)%nstatev)
       nfv = max(1, m%materials(mat)%nfieldv)
       len = record_length(nd, nc, nsv, nfv)
       ib = 0
       if (st%nblocks > 0) then
          associate (b => st%blocks(st%nblocks))
            if (b%material == mat .and. abs(b%half - half) <= 1.0e-12_dp * half .and. &
                 b%count < particle_block_size) ib = st%nblocks
          end associate
       end if
       if (ib == 0) then
          call append_block(st)
          ib = st%nblocks
          call block_allocate(st%blocks(ib), 0, nd, nc, nsv, nfv, st%nsup)
          st%blocks(ib)%material = mat
          st%blocks(ib)%half = half
       end if
       associate (b => st%blocks(ib))
         ! the rows of this kind that still fit, in one growth
         first = b%count + 1
         call block_grow(b, b%count + run_length(pos, len, particle_block_size - b%count), nd)
         do while (first <= b%count)
            call take(b, first)
            first = first + 1
         end do
       end associate
    end do
  contains
    !> Rows from pos on of the same material and half as the one at pos, at most room.
    integer function run_length(start, rec, room) result(k)
      integer, intent(in) :: start, rec, room
      integer :: q
      k = 0
      q = start
      do while (q <= size(buf) .and. k < room)
         if (nint(buf(q)) /= mat .or. abs(buf(q + 1) - half) > 1.0e-12_dp * half) exit
         k = k + 1
         q = q + rec
      end do
    end function run_length

    subroutine take(b, p)
      type(particle_block_t), intent(inout) :: b
      integer, intent(in) :: p
      b%number(p) = nint(buf(pos + 2))
      pos = pos + 3
      b%x(p, :) = get(nd)
      b%v(p, :) = get(nd)
      b%mass(p) = buf(pos)
      b%vol0(p) = buf(pos + 1)
      pos = pos + 2
      b%f(p, :, :) = reshape(get(nd * nd), [nd, nd])
      b%rot(p, :, :) = reshape(get(nd * nd), [nd, nd])
      b%stress(p, :) = get(nc)
      b%stress_global(p, :) = get(nc)
      b%e_int(p) = buf(pos)
      b%e_inel(p) = buf(pos + 1)
      pos = pos + 2
      b%log_strain(p, :) = get(nc)
      b%state(p, :) = get(nsv)
      b%field(p, :) = get(nfv)
    end subroutine take

    function get(k) result(v)
      integer, intent(in) :: k
      real(dp) :: v(k)
      v = buf(pos:pos + k - 1)
      pos = pos + k
    end function get
  end subroutine unpack_records

  !> One more (empty) slot at the end of st%blocks.
  subroutine append_block(st)
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), allocatable :: grown(:)
    if (.not. allocated(st%blocks)) allocate (st%blocks(16))
    if (st%nblocks == size(st%blocks)) then
       allocate (grown(2 * max(1, st%nblocks)))
       grown(1:st%nblocks) = st%blocks(1:st%nblocks)
       call move_alloc(grown, st%blocks)
    end if
    st%nblocks = st%nblocks + 1
  end subroutine append_block

  !> The destination rank of every particle of the rank (dest(p, ib)), from its cell (cell_of's
  !> formula, written out so the loop over a block vectorises), and per block how many go to
  !> another rank (most increments: none, and the caller skips those blocks).
  subroutine destinations(st, dest, leaving)
    type(mpm_state_t), intent(in) :: st
    integer, intent(out) :: dest(:, :)          !< (particle_block_size, nblocks)
    integer, intent(out) :: leaving(:)          !< (nblocks)
    integer :: ib, p, c(3), r, k, nd, ck, last(3), blo(3), bhi(3)
    logical :: inside(particle_block_size)
    real(dp) :: lo(3), h

    r = st%dom%rank
    nd = st%nd
    lo = st%g%lo
    h = st%g%h
    last = st%dom%ncell - 1
    blo = st%dom%box(1, :, r)
    bhi = st%dom%box(2, :, r)
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         inside(1:b%count) = .true.
         do k = 1, nd
            do p = 1, b%count
               ck = min(max(floor((b%x(p, k) - lo(k)) / h), 0), last(k))
               inside(p) = inside(p) .and. ck >= blo(k) .and. ck <= bhi(k)
            end do
         end do
         dest(1:b%count, ib) = r
         leaving(ib) = b%count - count(inside(1:b%count))
         if (leaving(ib) == 0) cycle
         do p = 1, b%count
            if (inside(p)) cycle
            c = cell_of(st%dom, lo, h, b%x(p, :))
            dest(p, ib) = rank_of_cell(st%dom, c)
         end do
       end associate
    end do
  end subroutine destinations

  !> Send every particle whose cell is in another rank's box to that rank; keep the others (blocks
  !> keep their order, emptied blocks leave). With compact, the kept particles are re-packed into
  !> full blocks too (after a re-partition). Collective.
  subroutine migrate_particles(m, st, compact)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    logical, intent(in) :: compact
    integer, allocatable :: dest(:, :), leaving(:), keep(:), first(:), rfirst(:), slen(:)
    real(dp), allocatable :: sbuf(:), rbuf(:), kept(:)
    integer :: ib, p, r, nr, nk, pos, len, me, nown, own_pos

    nr = st%nranks
    me = st%rank
    allocate (dest(particle_block_size, max(1, st%nblocks)), leaving(max(1, st%nblocks)), first(0:nr), &
         rfirst(0:nr), slen(0:nr - 1))
    call destinations(st, dest, leaving)
    ! sizes per destination rank (this rank's own rows apart: kept, or re-packed with compact)
    slen = 0
    nown = 0
    own_pos = 1
    do ib = 1, st%nblocks
       if (leaving(ib) == 0 .and. .not. compact) cycle
       len = record_length(st%nd, st%nc, size(st%blocks(ib)%state, 2), size(st%blocks(ib)%field, 2))
       do p = 1, st%blocks(ib)%count
          r = dest(p, ib)
          if (r /= me) then
             slen(r) = slen(r) + len
             if (.not. compact) st%dom%sent(r) = st%dom%sent(r) + 1
          else if (compact) then
             nown = nown + len
          end if
       end do
    end do
    first(0) = 1
    do r = 0, nr - 1
       first(r + 1) = first(r) + slen(r)
    end do
    allocate (sbuf(first(nr) - 1), kept(nown))
    ! rows in rank order, block order within a rank
    do r = 0, nr - 1
       if (r == me .and. .not. compact) cycle
       if (slen(r) == 0 .and. r /= me) cycle
       pos = first(r)
       do ib = 1, st%nblocks
          if (leaving(ib) == 0 .and. r /= me) cycle
          do p = 1, st%blocks(ib)%count
             if (dest(p, ib) /= r) cycle
             if (r == me) then
                call pack_record(st%blocks(ib), p, st%nd, kept, own_pos)
             else
                call pack_record(st%blocks(ib), p, st%nd, sbuf, pos)
             end if
          end do
       end do
    end do
    call exchange_all(st%comm, nr, first, sbuf, rfirst, rbuf)
    if (compact) then
       st%nblocks = 0
       call unpack_records(m, st, kept)
    else
       allocate (keep(particle_block_size))
       do ib = 1, st%nblocks
          if (leaving(ib) == 0) cycle
          nk = 0
          do p = 1, st%blocks(ib)%count
             if (dest(p, ib) /= me) cycle
             nk = nk + 1
             keep(nk) = p
          end do
          call block_keep(st%blocks(ib), keep(1:nk))
       end do
       call drop_empty_blocks(st%blocks, st%nblocks)
    end if
    call unpack_records(m, st, rbuf)
  end subroutine migrate_particles

  !> Particles per cell over all ranks (cells of the grid, (c1, c2, c3)). Collective.
  subroutine global_cell_counts(st, counts)
    type(mpm_state_t), intent(in) :: st
    integer, allocatable, intent(out) :: counts(:, :, :)
    integer :: ib, p, c(3)
    integer, allocatable :: flat(:)

    allocate (counts(st%dom%ncell(1), st%dom%ncell(2), st%dom%ncell(3)))
    counts = 0
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         do p = 1, b%count
            c = cell_of(st%dom, st%g%lo, st%g%h, b%x(p, :))
            counts(c(1) + 1, c(2) + 1, c(3) + 1) = counts(c(1) + 1, c(2) + 1, c(3) + 1) + 1
         end do
       end associate
    end do
    allocate (flat(size(counts)), source=reshape(counts, [size(counts)]))
    call comm_sum(st%comm, flat)
    counts = reshape(flat, shape(counts))
  end subroutine global_cell_counts

  !> The domain before any particle exists: the mirrored planes' node layers and the ranks'
  !> layout (mpm_domain's domain_init); decompose_boxes then cuts it by the particle counts.
  subroutine decompose_start(st, rebalance)
    type(mpm_state_t), intent(inout) :: st
    real(dp), intent(in) :: rebalance
    integer, allocatable :: axis(:), layer(:)
    integer :: k, nmir

    nmir = count(st%mirrored)
    allocate (axis(nmir), layer(nmir))
    nmir = 0
    do k = 1, size(st%mirrored)
       if (.not. st%mirrored(k)) cycle
       nmir = nmir + 1
       axis(nmir) = st%mirror(k)%axis
       ! the plane's node layer along its axis (every plane node has it)
       layer(nmir) = plane_layer(st, k)
    end do
    call domain_init(st%dom, st%rank, st%nranks, st%nd, st%g%n, st%nsup, axis, layer, rebalance)
  end subroutine decompose_start

  !> The first partition: the ranks' boxes from the particle counts per cell of the whole set
  !> (every rank has the same counts: the same boxes, no communication).
  subroutine decompose_boxes(st, counts)
    type(mpm_state_t), intent(inout) :: st
    integer, intent(in) :: counts(:, :, :)
    call domain_build(st%dom, rcb_boxes(counts, st%nranks))
  end subroutine decompose_boxes

  !> The node layer of mirrored plane k along its axis.
  integer function plane_layer(st, k) result(layer)
    type(mpm_state_t), intent(in) :: st
    integer, intent(in) :: k
    integer :: r, a

    a = st%mirror(k)%axis
    layer = -1
    if (size(st%mirror(k)%plane) == 0) return
    r = st%mirror(k)%plane(1) - 1
    if (a >= 2) r = r / st%g%n(1)
    if (a == 3) r = r / st%g%n(2)
    layer = mod(r, st%g%n(a))
  end function plane_layer

  !> The imbalance of the particle counts, max/mean − 1 (0 without particles). Collective.
  real(dp) function count_imbalance(st) result(imbalance)
    type(mpm_state_t), intent(in) :: st
    integer :: n(1), nmax(1)

    n(1) = sum(st%blocks(1:st%nblocks)%count)
    nmax = n
    call comm_sum(st%comm, n)
    call comm_max(st%comm, nmax)
    imbalance = 0
    if (n(1) > 0) imbalance = real(nmax(1), dp) * st%nranks / n(1) - 1
  end function count_imbalance

  !> max/mean − 1 of the counts per box for the boxes box(2, 3, 0:nranks − 1).
  pure real(dp) function boxes_imbalance(counts, box) result(imbalance)
    integer, intent(in) :: counts(:, :, :), box(:, :, 0:)
    integer(kind=8) :: n, nmax, total
    integer :: r

    total = 0
    nmax = 0
    do r = 0, size(box, 3) - 1
       n = 0
       if (all(box(2, :, r) >= box(1, :, r))) n = sum(int(counts(box(1, 1, r) + 1:box(2, 1, r) + 1, &
            box(1, 2, r) + 1:box(2, 2, r) + 1, box(1, 3, r) + 1:box(2, 3, r) + 1), 8))
       total = total + n
       nmax = max(nmax, n)
    end do
    imbalance = 0
    if (total > 0) imbalance = real(nmax, dp) * size(box, 3) / real(total, dp) - 1
  end function boxes_imbalance

  !> The new boxes box(2, 3, 0:nranks − 1), the plan for them, the rank's grid on its new held
  !> box, and every particle to its new owner, re-packed into full blocks. The walls' node lists
  !> are the caller's (mpm_setup). Collective.
  subroutine repartition(m, st, box)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer, intent(in) :: box(:, :, 0:)

    call domain_build(st%dom, box)
    call domain_regrid(st)
    call migrate_particles(m, st, .true.)
    st%dom%rebalances = st%dom%rebalances + 1
  end subroutine repartition

  !> The end of an increment of a decomposed run: particles that left the box go to their new
  !> owner; every dom%rebalance_every increments the counts are compared and, above the
  !> threshold, the grid is partitioned again (increment boundaries only) — but only when the
  !> new boxes would lower the imbalance by more than half the threshold: the cuts fall on node
  !> planes, so the best partition can itself sit above a small threshold, and re-partitioning
  !> to no gain every check costs more than the imbalance (REBALANCE=0.01 on the ch. 4 hopper: 1441 re-partitions
  !> and twice the wall time without this test). Collective; every rank takes the same decision
  !> from the same global counts.
  subroutine domain_increment_end(m, st, regridded)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    logical, intent(out) :: regridded   !< re-partitioned: the grid is a new box
    integer, allocatable :: counts(:, :, :), box(:, :, :)
    real(dp) :: now

    regridded = .false.
    call migrate_particles(m, st, .false.)
    if (mod(st%increment, st%dom%rebalance_every) /= 0) return
    now = count_imbalance(st)
    if (.not. now > st%dom%rebalance) return
    call global_cell_counts(st, counts)
    box = rcb_boxes(counts, st%nranks)
    if (.not. boxes_imbalance(counts, box) < now - 0.5_dp * st%dom%rebalance) return
    call repartition(m, st, box)
    regridded = .true.
  end subroutine domain_increment_end
end module mpm_migrate
