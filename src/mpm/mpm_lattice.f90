!> The particle factory of a material-point run: the regular lattice of a *PARTICLES region
!> (ppc particles per cell and direction, aligned with the grid), the test of a point against a
!> region, the append of new particles to the blocks (set-up and inflow), and the tally of a
!> region's lattice without making it (particles per cell, and the block sums the set-up's
!> totals need).
!>
!> Why a tally: a spatially decomposed run (mpm_domain) cuts the grid by the particle counts per
!> cell before any particle exists, so each rank then makes only the particles of its own box and
!> no rank ever holds the whole set (memory per rank falls with the rank count; docs/scaling.md).
!> The tally walks the lattice in the set-up's order and follows the blocks the full set would
!> fill, so the initial mass, count and cut-off are the same doubles as when every particle was
!> made; a rank's particles keep the numbers they have in the full set.
module mpm_lattice
  use base_kinds, only: dp
  use model, only: model_t
  use mpm_scene, only: particle_region_t, region_box, region_polygon
  use mpm_state, only: mpm_state_t
  use mpm_particles, only: particle_block_t, particle_block_size, block_allocate, block_grow
  use mpm_domain, only: cell_of, rank_of_cell
  use model_particle_fields, only: particle_initial_field
  implicit none
  private

  !> What the set-up needs of the whole particle set: counts per cell and the sums over the
  !> blocks the set fills (in their order), and the last of those blocks (material, half, count).
  type, public :: lattice_tally_t
     integer, allocatable :: counts(:, :, :)   !< particles per grid cell (c1, c2, c3), 1-based
     integer :: particles = 0
     real(dp) :: mass = 0, largest_mass = 0
     integer :: block_material = 0, block_count = 0
     real(dp) :: block_half = 0, block_sum = 0
  end type lattice_tally_t

  public :: generate_region, region_contains, add_particles, tally_region, tally_close

contains

  !> The lattice of region r (rows along x, in the order k, j, i), appended with add_particles.
  !> With owner_only, only the points of cells in this rank's box (st%dom, on the whole grid)
  !> are made; the skipped points still take their particle numbers.
  subroutine generate_region(m, st, r, owner_only)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(particle_region_t), intent(in) :: r
    logical, intent(in), optional :: owner_only
    real(dp) :: x(3)
    integer :: i0(3), i1(3), i, j, k, n
    logical :: filter
    real(dp), allocatable :: pts(:, :)

    filter = .false.
    if (present(owner_only)) filter = owner_only
    call lattice_range(m, st%nd, r, i0, i1)
    allocate (pts(3, i1(1) - i0(1) + 1))
    do k = i0(3), i1(3)
       do j = i0(2), i1(2)
          n = 0
          do i = i0(1), i1(1)
             x = lattice_point(m, st%nd, r, i, j, k)
             if (.not. region_contains(r, st%nd, x)) cycle
             if (filter) then
                if (rank_of_cell(st%dom, cell_of(st%dom, st%g%lo, st%g%h, x)) /= st%rank) then
                   ! another rank's particle: the pending run goes in first, then its number
                   ! is taken
                   if (n > 0) call add_particles(m, st, r%material, r%ppc, pts(:, 1:n), r%velocity)
                   n = 0
                   st%next_number = st%next_number + 1
                   cycle
                end if
             end if
             n = n + 1
             pts(:, n) = x
          end do
          if (n > 0) call add_particles(m, st, r%material, r%ppc, pts(:, 1:n), r%velocity)
       end do
    end do
  end subroutine generate_region

  !> Add region r's lattice to the tally: counts per cell of the whole grid (st%g, st%dom%ncell)
  !> and the blocks add_particles would fill with it after the earlier regions.
  subroutine tally_region(m, st, r, t)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(in) :: st
    type(particle_region_t), intent(in) :: r
    type(lattice_tally_t), intent(inout) :: t
    real(dp) :: x(3), half, mass
    integer :: i0(3), i1(3), i, j, k, c(3)

    if (.not. allocated(t%counts)) then
       allocate (t%counts(st%dom%ncell(1), st%dom%ncell(2), st%dom%ncell(3)))
       t%counts = 0
    end if
    half = 0.5_dp * particle_spacing(m, r%ppc)
    mass = particle_mass(m, st%nd, r%material, r%ppc)
    call lattice_range(m, st%nd, r, i0, i1)
    do k = i0(3), i1(3)
       do j = i0(2), i1(2)
          do i = i0(1), i1(1)
             x = lattice_point(m, st%nd, r, i, j, k)
             if (.not. region_contains(r, st%nd, x)) cycle
             c = cell_of(st%dom, st%g%lo, st%g%h, x)
             t%counts(c(1) + 1, c(2) + 1, c(3) + 1) = t%counts(c(1) + 1, c(2) + 1, c(3) + 1) + 1
             ! add_particles' rule: the last block takes it if of the same kind and not full
             if (t%block_count == 0 .or. t%block_material /= r%material .or. &
                  abs(t%block_half - half) > 1.0e-12_dp * half .or. t%block_count >= particle_block_size) then
                call tally_close(t)
                t%block_material = r%material
                t%block_half = half
             end if
             t%block_count = t%block_count + 1
             ! sum(b%mass) of the block: its masses in order from zero
             t%block_sum = t%block_sum + mass
             t%particles = t%particles + 1
             t%largest_mass = max(t%largest_mass, mass)
          end do
       end do
    end do
  end subroutine tally_region

  !> The open block's sum joins the total (the set-up's sum over the blocks, in block order).
  subroutine tally_close(t)
    type(lattice_tally_t), intent(inout) :: t
    if (t%block_count > 0) t%mass = t%mass + t%block_sum
    t%block_count = 0
    t%block_sum = 0
  end subroutine tally_close

  !> Lattice indices covering region r's bounding box (points at lo + (i + ½) CELL/ppc).
  subroutine lattice_range(m, nd, r, i0, i1)
    type(model_t), intent(in) :: m
    integer, intent(in) :: nd
    type(particle_region_t), intent(in) :: r
    integer, intent(out) :: i0(3), i1(3)
    real(dp) :: dx
    integer :: k

    dx = particle_spacing(m, r%ppc)
    i0 = 0
    i1 = 0
    do k = 1, nd
       i0(k) = floor((r%lo(k) - m%mpm%lo(k)) / dx)
       i1(k) = ceiling((r%hi(k) - m%mpm%lo(k)) / dx)
    end do
  end subroutine lattice_range

  pure function lattice_point(m, nd, r, i, j, k) result(x)
    type(model_t), intent(in) :: m
    integer, intent(in) :: nd, i, j, k
    type(particle_region_t), intent(in) :: r
    real(dp) :: x(3)
    x = m%mpm%lo + ([real(dp) :: i, j, k] + 0.5_dp) * particle_spacing(m, r%ppc)
    if (nd == 2) x(3) = 0
  end function lattice_point

  pure real(dp) function particle_spacing(m, ppc)
    type(model_t), intent(in) :: m
    integer, intent(in) :: ppc
    particle_spacing = m%mpm%cell / ppc
  end function particle_spacing

  pure real(dp) function particle_mass(m, nd, material, ppc)
    type(model_t), intent(in) :: m
    integer, intent(in) :: nd, material, ppc
    particle_mass = m%materials(material)%density * particle_spacing(m, ppc)**nd
  end function particle_mass

  !> Is x inside the region (a box: lo ≤ x < hi; a polygon by ray casting, in 3D also z)?
  logical function region_contains(r, nd, x) result(inside)
    type(particle_region_t), intent(in) :: r
    integer, intent(in) :: nd
    real(dp), intent(in) :: x(3)
    integer :: i, j, nv

    if (r%kind == region_box) then
       inside = all(x(1:nd) >= r%lo(1:nd)) .and. all(x(1:nd) < r%hi(1:nd))
       return
    end if
    inside = .false.
    if (nd == 3) then
       if (x(3) < r%lo(3) .or. x(3) >= r%hi(3)) return
    end if
    nv = size(r%polygon, 2)
    j = nv
    do i = 1, nv
       if ((r%polygon(2, i) > x(2)) .neqv. (r%polygon(2, j) > x(2))) then
          if (x(1) < (r%polygon(1, j) - r%polygon(1, i)) * (x(2) - r%polygon(2, i)) / &
               (r%polygon(2, j) - r%polygon(2, i)) + r%polygon(1, i)) inside = .not. inside
       end if
       j = i
    end do
    if (r%kind /= region_polygon) inside = .false.
  end function region_contains

  !> Append particles of one material and spacing CELL/ppc at pts(3, n) (zero stress, F = I):
  !> first into the last block of that material and spacing, then into new blocks.
  subroutine add_particles(m, st, material, ppc, pts, velocity)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer, intent(in) :: material, ppc
    real(dp), intent(in) :: pts(:, :)
    real(dp), intent(in) :: velocity(:)
    type(particle_block_t), allocatable :: grown(:)
    real(dp) :: dx, vol, half
    integer :: n, done, ib, first, add, p, nd, k

    nd = st%nd
    n = size(pts, 2)
    dx = m%mpm%cell / ppc
    vol = dx**nd
    half = 0.5_dp * dx
    done = 0
    do while (done < n)
       ib = 0
       if (st%nblocks > 0) then
          if (st%blocks(st%nblocks)%material == material .and. abs(st%blocks(st%nblocks)%half - half) <= &
               1.0e-12_dp * half .and. st%blocks(st%nblocks)%count < particle_block_size) ib = st%nblocks
       end if
       if (ib == 0) then
          if (.not. allocated(st%blocks)) allocate (st%blocks(16))
          if (st%nblocks == size(st%blocks)) then
             allocate (grown(2 * st%nblocks))
             grown(1:st%nblocks) = st%blocks(1:st%nblocks)
             call move_alloc(grown, st%blocks)
          end if
          st%nblocks = st%nblocks + 1
          ib = st%nblocks
          call block_allocate(st%blocks(ib), 0, nd, st%nc, max(1, m%materials(material)%nstatev), &
               max(1, m%materials(material)%nfieldv), st%nsup)
          st%blocks(ib)%material = material
          st%blocks(ib)%half = half
       end if
       associate (b => st%blocks(ib))
         first = b%count + 1
         add = min(n - done, particle_block_size - b%count)
         call block_grow(b, b%count + add, nd)
         do p = 1, add
            st%next_number = st%next_number + 1
            b%number(first + p - 1) = st%next_number
            b%x(first + p - 1, :) = pts(1:nd, done + p)
            b%v(first + p - 1, :) = velocity(1:nd)
         end do
         b%vol0(first:) = vol
         b%mass(first:) = m%materials(material)%density * vol
         ! *INITIAL CONDITIONS, TYPE=FIELD of the material's particles (for a user's VUMAT or
         ! VUSDFLD, as in elements; inflow particles start with them too)
         if (m%materials(material)%user_code .or. m%materials(material)%user_field_code) then
            do k = 1, size(b%field, 2)
               b%field(first:, k) = particle_initial_field(m, material, k)
            end do
         end if
       end associate
       done = done + add
    end do
  end subroutine add_particles
end module mpm_lattice
