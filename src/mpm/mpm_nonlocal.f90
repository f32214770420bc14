!> Nonlocal averaging of a softening variable over the particles (`*NONLOCAL`, docs/nonlocal.md):
!> owns the weight, the neighbour search and the average, and the stress update of a run with the
!> option on (VUSDFLD on every block, the average, then the VUMAT with the averaged field).
!>
!> The average of particle p over the particles q of its group within the radius R:
!>     f̄_p = f_p + Σ_q w_pq V_q (f_q − f_p) / Σ_q w_pq V_q,   w_pq = (1 − r²/R²)² for r < R
!> (the bell-shaped weight of Bažant & Jirásek 2002, normalised by its discrete volume integral
!> over the material present, so a constant field is kept exactly and boundaries need no
!> special weight). Written as f_p plus a weighted mean of differences: a constant is returned
!> bit for bit, and a particle alone in its neighbourhood keeps its own value bit for bit (so a
!> length below the particle spacing is the local model exactly).
!> Why the grid is not used: the neighbours are found by binning the particles in square bins
!> of side ≥ R over their own bounding box, so the weights and the sums depend on the particles
!> alone and not on the cell: the length scale is the material's, not the mesh's.
module mpm_nonlocal
  use base_kinds, only: dp
  use model, only: model_t
  use mpm_particles, only: particle_block_t
  use mpm_sort, only: counting_order
  use mpm_state, only: mpm_state_t, det_f, fx_nonlocal, fx_material
  use mpm_stress_update, only: stress_update, field_update
  use output_effects, only: effects_t
  implicit none
  private

  public :: bell_weight, nonlocal_average, nonlocal_blocks, nonlocal_stress_update

  !> The new fields of one block between the VUSDFLD and the VUMAT (nb, nfieldv).
  type, public :: block_field_t
     real(dp), allocatable :: v(:, :)
  end type block_field_t

contains

  !> The bell-shaped weight (1 − r²/R²)² inside the radius, 0 outside (r2 = r², radius2 = R²).
  pure real(dp) function bell_weight(r2, radius2) result(w)
    real(dp), intent(in) :: r2, radius2
    w = 0
    if (r2 < radius2) w = (1 - r2 / radius2)**2
  end function bell_weight

  !> avg(p) = the nonlocal average of f over the particles of p's group within `radius` (group 0:
  !> not averaged, avg = f). x(n, nd) positions, vol(n) current volumes (> 0).
  subroutine nonlocal_average(n, nd, x, vol, f, group, radius, avg)
    integer, intent(in) :: n, nd
    real(dp), intent(in) :: x(n, nd), vol(n), f(n), radius
    integer, intent(in) :: group(n)
    real(dp), intent(out) :: avg(n)
    integer :: nbin(3), p, q, j, k, nkeys, c(3), lo3(3), hi3(3), i1, i2, i3, key
    integer, allocatable :: bin(:), order(:), first(:), gb(:)
    real(dp), allocatable :: xb(:, :), fb(:), vb(:)
    real(dp) :: xlo(3), xhi(3), side, r2, radius2, w, sw, swf, xs(nd)

    avg = f
    if (.not. any(group > 0)) return
    xlo = 0
    xhi = 0
    do k = 1, nd
       xlo(k) = minval(x(:, k), mask=group > 0)
       xhi(k) = maxval(x(:, k), mask=group > 0)
    end do
    ! bins of side ≥ R; larger when R is small against the particles' extent, so that there are
    ! about as many bins as particles (a tiny R would otherwise make a huge bin table)
    side = max(radius, (product(xhi(1:nd) - xlo(1:nd) + radius) / count(group > 0))**(1.0_dp / nd))
    nbin = 1
    do k = 1, nd
       nbin(k) = int((xhi(k) - xlo(k)) / side) + 1
    end do
    nkeys = product(nbin)
    ! key nkeys + 1: the particles not averaged, after all bins
    allocate (bin(n), order(n), first(nkeys + 2))
    do p = 1, n
       bin(p) = nkeys + 1
       if (group(p) > 0) bin(p) = bin_key(x(p, :))
    end do
    call counting_order(n, bin, nkeys + 1, order)
    ! order(first(key) : first(key + 1) − 1): the particles of bin `key` (the sort is stable)
    first = 0
    do p = 1, n
       first(bin(p)) = first(bin(p)) + 1
    end do
    j = 1
    do key = 1, nkeys + 2
       q = first(key)
       first(key) = j
       j = j + q
    end do
    ! the particles in bin order, positions (nd, n): the inner loop reads consecutive memory
    allocate (xb(nd, n), fb(n), vb(n), gb(n))
    do j = 1, n
       q = order(j)
       xb(:, j) = x(q, :)
       fb(j) = f(q)
       vb(j) = vol(q)
       gb(j) = group(q)
    end do
    radius2 = radius * radius
    do p = 1, n
       if (group(p) == 0) cycle
       xs = x(p, :)
       c = 0
       do k = 1, nd
          c(k) = min(int((xs(k) - xlo(k)) / side), nbin(k) - 1)
       end do
       lo3 = max(c - 1, 0)
       hi3 = min(c + 1, nbin - 1)
       sw = 0
       swf = 0
       do i3 = lo3(3), hi3(3)
          do i2 = lo3(2), hi3(2)
             do i1 = lo3(1), hi3(1)
                key = 1 + i1 + nbin(1) * (i2 + nbin(2) * i3)
                do j = first(key), first(key + 1) - 1
                   if (gb(j) /= group(p)) cycle
                   r2 = 0
                   do k = 1, nd
                      r2 = r2 + (xb(k, j) - xs(k))**2
                   end do
                   if (r2 >= radius2) cycle
                   w = bell_weight(r2, radius2) * vb(j)
                   sw = sw + w
                   swf = swf + w * (fb(j) - f(p))
                end do
             end do
          end do
       end do
       ! sw ≥ vol(p) > 0: p is its own neighbour at r = 0
       avg(p) = f(p) + swf / sw
    end do

  contains

    pure integer function bin_key(xp)
      real(dp), intent(in) :: xp(nd)
      integer :: kk, cc(3)
      cc = 0
      do kk = 1, nd
         cc(kk) = min(int((xp(kk) - xlo(kk)) / side), nbin(kk) - 1)
      end do
      bin_key = 1 + cc(1) + nbin(1) * (cc(2) + nbin(2) * cc(3))
    end function bin_key
  end subroutine nonlocal_average

  !> Column `column` of the blocks' new fields fields(ib)%v replaced by its nonlocal average over
  !> the particles of the same material within `radius`; only the materials with selected(material)
  !> take part. Positions are the blocks' x, volumes V0 det F (F at the start of the increment).
  subroutine nonlocal_blocks(blocks, nblocks, nd, selected, column, radius, fields)
    type(particle_block_t), intent(in) :: blocks(:)
    integer, intent(in) :: nblocks, nd, column
    logical, intent(in) :: selected(:)
    real(dp), intent(in) :: radius
    type(block_field_t), intent(inout) :: fields(:)
    real(dp), allocatable :: x(:, :), vol(:), f(:), avg(:)
    integer, allocatable :: group(:)
    integer :: n, ib, p, i

    n = 0
    do ib = 1, nblocks
       if (selected(blocks(ib)%material)) n = n + blocks(ib)%count
    end do
    allocate (x(n, nd), vol(n), f(n), avg(n), group(n))
    i = 0
    do ib = 1, nblocks
       associate (b => blocks(ib))
         if (.not. selected(b%material)) cycle
         do p = 1, b%count
            i = i + 1
            x(i, :) = b%x(p, 1:nd)
            vol(i) = b%vol0(p) * det_f(b%f, p, nd)
            f(i) = fields(ib)%v(p, column)
            group(i) = b%material
         end do
       end associate
    end do
    call nonlocal_average(n, nd, x, vol, f, group, radius, avg)
    i = 0
    do ib = 1, nblocks
       if (.not. selected(blocks(ib)%material)) cycle
       do p = 1, blocks(ib)%count
          i = i + 1
          fields(ib)%v(p, column) = avg(i)
       end do
    end do
  end subroutine nonlocal_blocks

  !> The stress update of every block with *NONLOCAL: the VUSDFLD of the blocks whose material
  !> takes part (timed with the material: it runs without the option too), the average (its own effect), then each block's
  !> stress update with the averaged fields as the VUMAT's fieldNew. Blocks of other materials
  !> are updated as without the option.
  subroutine nonlocal_stress_update(m, st, fx)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(effects_t), intent(inout) :: fx
    type(block_field_t), allocatable :: fields(:)
    logical :: selected(m%n_materials)
    integer :: ib, k

    associate (nl => m%mpm%nonlocal)
      do k = 1, m%n_materials
         selected(k) = m%materials(k)%user_field .and. (nl%material == 0 .or. nl%material == k)
      end do
      allocate (fields(st%nblocks))
      do ib = 1, st%nblocks
         associate (b => st%blocks(ib))
           if (.not. selected(b%material)) cycle
           allocate (fields(ib)%v(b%count, size(b%field, 2)))
           call fx%start(fx_material)
           call field_update(m, st, b, fields(ib)%v)
           call fx%stop(fx_material)
         end associate
      end do
      call fx%start(fx_nonlocal)
      call nonlocal_blocks(st%blocks, st%nblocks, st%nd, selected, nl%field, nl%length, fields)
      call fx%stop(fx_nonlocal)
      do ib = 1, st%nblocks
         if (selected(st%blocks(ib)%material)) then
            call stress_update(m, st, fx, st%blocks(ib), fields(ib)%v)
         else
            call stress_update(m, st, fx, st%blocks(ib))
         end if
      end do
    end associate
  end subroutine nonlocal_stress_update
end module mpm_nonlocal
