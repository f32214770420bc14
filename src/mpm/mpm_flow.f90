!> Particles in and out at the end of an MPM increment: particles behind an active wall are put
!> back onto it, the outflow removes the particles below its level (their mass, count and
!> energy counted), the inflow tops up lattice columns that sank below its level. Particle
!> masses never change, so M0 + M_in − M_out = M holds to round-off.
module mpm_flow
  use base_kinds, only: dp
  use model, only: model_t
  use mpm_scene, only: mpm_wall_t, mpm_inflow_t
  use mpm_state, only: mpm_state_t
  use mpm_particles, only: particle_block_size, block_keep, drop_empty_blocks
  use mpm_walls, only: wall_contains, wall_distance, wall_rows_behind, wall_slide_velocity
  use mpm_lattice, only: add_particles
  use parallel_comm, only: comm_allgather
  implicit none
  private

  public :: guard_particles, outflow, inflow

contains

  !> Particles behind an active wall (within its extent) go back onto it, without their normal
  !> velocity into the wall.
  subroutine guard_particles(walls, st)
    type(mpm_wall_t), intent(in) :: walls(:)
    type(mpm_state_t), intent(inout) :: st
    integer :: k, ib, p, nd, j, nrows, rows(particle_block_size)
    real(dp) :: x(3), d, n(3), dist(particle_block_size)

    nd = st%nd
    do k = 1, size(walls)
       associate (w => walls(k))
         if (.not. w%active(st%step)) cycle
         n = w%normal
         do ib = 1, st%nblocks
            associate (b => st%blocks(ib))
              ! the few particles behind the wall first, then each of them as before
              call wall_rows_behind(w, b%count, nd, b%x, 0.0_dp, dist, nrows, rows)
              do j = 1, nrows
                 p = rows(j)
                 x = 0
                 x(1:nd) = b%x(p, :)
                 d = wall_distance(w, x)
                 if (.not. wall_contains(w, nd, x, 0.0_dp)) cycle
                 b%x(p, :) = b%x(p, :) - d * n(1:nd)
                 ! The velocity into the wall goes, with the wall's own Coulomb law on what is
                 ! left (wall_slide_velocity, as on the wall's nodes): a frictionless put-back
                 ! let the particles put back slide along a rough wall (the ch. 4 hopper's
                 ! discharge rates moved < 0.2 % with the friction, src/mpm/README.md).
                 b%v(p, :) = wall_slide_velocity(w, nd, b%v(p, :))
                 st%n_guarded = st%n_guarded + 1
              end do
            end associate
         end do
       end associate
    end do
  end subroutine guard_particles

  !> Remove the particles whose centre is below `level` (coordinate 2); count their mass and
  !> energy. Blocks that become empty leave the list (the others keep their order).
  subroutine outflow(st, level)
    type(mpm_state_t), intent(inout) :: st
    real(dp), intent(in) :: level
    integer :: ib, p, nk
    integer, allocatable :: keep(:)

    do ib = 1, st%nblocks
       if (all(st%blocks(ib)%x(:, 2) >= level)) cycle
       associate (b => st%blocks(ib))
         allocate (keep(b%count))
         nk = 0
         do p = 1, b%count
            if (b%x(p, 2) >= level) then
               nk = nk + 1
               keep(nk) = p
            else
               st%mass_out = st%mass_out + b%mass(p)
               st%n_out = st%n_out + 1
               st%e_out = st%e_out + 0.5_dp * b%mass(p) * sum(b%v(p, :)**2) + b%mass(p) * b%e_int(p)
            end if
         end do
         call block_keep(b, keep(1:nk))
         deallocate (keep)
       end associate
    end do
    call drop_empty_blocks(st%blocks, st%nblocks)
  end subroutine outflow

  !> Keep the free surface at the inflow level: in each lattice column of the band, when the top
  !> particle is more than one spacing below the level, a particle is added one spacing above it
  !> with its velocity (zero stress, F = I).
  subroutine inflow(m, st, q)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(mpm_inflow_t), intent(in) :: q
    real(dp) :: dx
    integer :: nc(3), ib, p, ic, jc, col, n, nd, ncol, ix, iz
    real(dp), allocatable :: top(:), vtop(:, :), pts(:, :)
    logical, allocatable :: seen(:)
    real(dp) :: v(3)

    nd = st%nd
    dx = m%mpm%cell / q%ppc
    nc = 1
    nc(1) = max(1, nint((q%hi(1) - q%lo(1)) / dx))
    if (nd == 3) nc(3) = max(1, nint((q%hi(3) - q%lo(3)) / dx))
    ncol = nc(1) * nc(3)
    allocate (top(ncol), vtop(3, ncol), pts(3, ncol), seen(ncol))
    seen = .false.
    top = 0
    vtop = 0
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         do p = 1, b%count
            ix = floor((b%x(p, 1) - q%lo(1)) / dx)
            if (ix < 0 .or. ix >= nc(1)) cycle
            iz = 0
            if (nd == 3) then
               iz = floor((b%x(p, 3) - q%lo(3)) / dx)
               if (iz < 0 .or. iz >= nc(3)) cycle
            end if
            col = 1 + ix + nc(1) * iz
            if (.not. seen(col) .or. b%x(p, 2) > top(col)) then
               seen(col) = .true.
               top(col) = b%x(p, 2)
               vtop(1:nd, col) = b%v(p, :)
            end if
         end do
       end associate
    end do
    if (st%nranks > 1) call global_tops(st, ncol, seen, top, vtop)
    n = 0
    v = 0
    do jc = 0, nc(3) - 1
       do ic = 0, nc(1) - 1
          col = 1 + ic + nc(1) * jc
          ! empty columns (no material under the band) get nothing: inflow tops up, never rains
          if (.not. seen(col)) cycle
          if (top(col) + dx > q%level) cycle
          n = n + 1
          pts(:, n) = 0
          pts(1, n) = q%lo(1) + (ic + 0.5_dp) * dx
          pts(2, n) = top(col) + dx
          if (nd == 3) pts(3, n) = q%lo(3) + (jc + 0.5_dp) * dx
          v = v + vtop(:, col)
       end do
    end do
    if (n == 0) return
    ! the column's top velocity, averaged over the new layer (avoids an impact on arrival)
    v = v / n
    ! every rank found the same layer; rank 0 owns the new particles
    if (st%rank == 0) call add_particles(m, st, q%material, q%ppc, pts(:, 1:n), v)
    st%mass_in = st%mass_in + n * m%materials(q%material)%density * dx**nd
    st%n_in = st%n_in + n
    st%e_in = st%e_in + 0.5_dp * n * m%materials(q%material)%density * dx**nd * sum(v**2)
  end subroutine inflow

  !> The highest particle of every inflow column over all ranks and its velocity (the lowest
  !> rank wins a tie, so exactly one rank supplies it). One all-gather of every rank's
  !> (top, velocity) per column: the increment's other collectives already make the ranks wait
  !> for each other, so each one less is a synchronisation less.
  subroutine global_tops(st, ncol, seen, top, vtop)
    type(mpm_state_t), intent(in) :: st
    integer, intent(in) :: ncol
    logical, intent(inout) :: seen(ncol)
    real(dp), intent(inout) :: top(ncol), vtop(3, ncol)
    real(dp) :: mine(4 * ncol), all(4 * ncol, 0:st%nranks - 1)
    integer :: c, r, owner

    do c = 1, ncol
       mine(4 * c - 3) = -huge(1.0_dp)
       if (seen(c)) mine(4 * c - 3) = top(c)
       mine(4 * c - 2:4 * c) = vtop(:, c)
    end do
    call comm_allgather(st%comm, mine, all)
    do c = 1, ncol
       owner = 0
       do r = 1, st%nranks - 1
          if (all(4 * c - 3, r) > all(4 * c - 3, owner)) owner = r
       end do
       seen(c) = all(4 * c - 3, owner) > -huge(1.0_dp)
       top(c) = all(4 * c - 3, owner)
       vtop(:, c) = 0
       if (seen(c)) vtop(:, c) = all(4 * c - 2:4 * c, owner)
    end do
  end subroutine global_tops
end module mpm_flow
