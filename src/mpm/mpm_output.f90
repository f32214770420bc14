!> Field output of a material-point run: what a frame holds, written through the shared point
!> writer (src/output/output_points.f90, the element writer's rows, HDF5 primitives and XDMF).
!> Every rank passes its own particles; the file is the same on any number of ranks.
!>
!>   BASE.h5   /particles/NNNNNN   one group per frame, attributes step (int), increment (int),
!>                                 step_time, total_time, count (int); datasets (rows = particles,
!>                                 shapes as h5py shows them): coordinates (n, 3) (z = 0 in 2D),
!>                                 V (n, 3), S (n, ncomp) global Cauchy stress in VUMAT order,
!>                                 LE (n, ncomp), density (n), mass (n), volume (n), id (n) int32,
!>                                 material (n) int32 (1-based *MATERIAL order), SDV (n, nsdv);
!>                                 when a field request's *ELEMENT OUTPUT names them (the element
!>                                 driver's names): FV1..FVn (n) every field variable of the scene
!>                                 (*INITIAL CONDITIONS, TYPE=FIELD or VUSDFLD-written), TEMP (n)
!>                                 the particle's temperature at the frame
!>             /grid               attributes ndim, n (3), lo (3), h
!>             /grid/NNNNNN        mass (nz, ny, nx), V (nz, ny, nx, 3) of the frame's increment
!>                                 (nz = 1 in 2D), after the walls
!>   BASE.xmf       particles: one Polyvertex grid per frame (temporal collection)
!>   BASE_grid.xmf  background grid: CoRectMesh with nodal mass and V
!>
!> Restart (mpm_checkpoint): mpm_writer_open(..., restart_frames=n) reopens BASE.h5, checks its
!> grid against the scene's, keeps frames 0..n-1, deletes later ones (written by the
!> interrupted run after its checkpoint) and rewrites the XDMF files from what it kept.
module mpm_output
  use mpi_f08, only: MPI_Comm
  use base_kinds, only: dp
  use error_report, only: error_t
  use output_points, only: point_writer_t, point_writer_open, point_writer_frame, point_writer_field, &
       point_writer_scalar, point_writer_ints, point_writer_grid_field, point_writer_end_frame, &
       point_writer_close, point_writer_frame_count
  use output_files, only: int_to_str
  use model, only: model_t
  use model_particle_fields, only: particle_temperature
  use mpm_particles, only: particle_block_t
  use mpm_grid, only: grid_t
  implicit none
  private

  !> What the frames hold beyond the fields every frame has.
  type, public :: mpm_field_request_t
     integer :: nsdv = 0              !< SDV columns (the largest *DEPVAR), 0: no SDV dataset
     integer :: nfv = 0               !< FV1..FVnfv (*ELEMENT OUTPUT FV in a field request), 0: none
     logical :: temp = .false.        !< TEMP (*ELEMENT OUTPUT TEMP in a field request)
  end type mpm_field_request_t

  type, public :: mpm_writer_t
     private
     type(point_writer_t) :: points
     integer :: ndim = 0, ncomp = 0
     type(mpm_field_request_t) :: req
  end type mpm_writer_t

  public :: mpm_field_requests, mpm_writer_open, mpm_writer_frame, mpm_writer_close, mpm_writer_frame_count

contains

  !> The scene's requests: SDV always (when a material has state variables), FV and TEMP when
  !> any step's field request names them (written in every frame then, as SDV is).
  function mpm_field_requests(m) result(req)
    type(model_t), intent(in) :: m
    type(mpm_field_request_t) :: req
    integer :: k

    do k = 1, m%n_materials
       req%nsdv = max(req%nsdv, m%materials(k)%nstatev)
    end do
    if (requested('FV')) then
       req%nfv = 1
       do k = 1, m%n_materials
          req%nfv = max(req%nfv, m%materials(k)%nfieldv)
       end do
    end if
    req%temp = requested('TEMP')
  contains
    logical function requested(name)
      character(len=*), intent(in) :: name
      integer :: s, j

      requested = .false.
      do s = 1, m%n_steps
         if (.not. allocated(m%steps(s)%field_outputs)) cycle
         do j = 1, size(m%steps(s)%field_outputs)
            if (.not. allocated(m%steps(s)%field_outputs(j)%element_variables)) cycle
            if (any(m%steps(s)%field_outputs(j)%element_variables == name)) requested = .true.
         end do
      end do
    end function requested
  end function mpm_field_requests

  !> Create BASE.h5 (or, with restart_frames, reopen it keeping that many frames; a problem
  !> then goes to err when given, else stops). Collective over comm.
  subroutine mpm_writer_open(wr, base, comm, g, ncomp, req, restart_frames, err)
    type(mpm_writer_t), intent(out) :: wr
    character(len=*), intent(in) :: base
    type(MPI_Comm), intent(in) :: comm
    type(grid_t), intent(in) :: g
    integer, intent(in) :: ncomp
    type(mpm_field_request_t), intent(in) :: req
    integer, intent(in), optional :: restart_frames
    type(error_t), intent(inout), optional :: err
    character(len=8), allocatable :: shown(:)
    integer :: j

    wr%ndim = g%ndim
    wr%ncomp = ncomp
    wr%req = req
    shown = [character(len=8) :: 'V', 'density', 'mass', 'S']
    do j = 1, req%nfv
       shown = [character(len=8) :: shown, 'FV' // int_to_str(j)]
    end do
    if (req%temp) shown = [character(len=8) :: shown, 'TEMP']
    call point_writer_open(wr%points, base, comm, 'bulkflow-mpm', g%ndim, g%n, g%lo, g%h, &
         shown, [3, 1, 1, ncomp, (1, j = 5, size(shown))], &
         [character(len=4) :: 'mass', 'V'], [1, 3], restart_frames, err)
  end subroutine mpm_writer_open

  !> One frame: every particle of this rank's blocks (in block order) and the grid. Collective.
  subroutine mpm_writer_frame(wr, m, blocks, nblocks, g, step, increment, step_time, total_time, owned_lo, owned_hi)
    type(mpm_writer_t), intent(inout) :: wr
    type(model_t), intent(in) :: m
    type(particle_block_t), intent(in) :: blocks(:)
    integer, intent(in) :: nblocks
    type(grid_t), intent(in) :: g
    integer, intent(in) :: step, increment
    real(dp), intent(in) :: step_time, total_time
    !> a decomposed grid: g is the rank's held box and these its owned nodes (whole-grid node
    !> indices, 0-based, inclusive; hi < lo: none), which this rank writes (mpm_domain)
    integer, intent(in), optional :: owned_lo(3), owned_hi(3)
    integer :: n, ib, p, r, nd, nsv, nfv, j
    real(dp), allocatable :: xyz(:, :), vel(:, :), s(:, :), le(:, :), dens(:), mass(:), vol(:), sdv(:, :)
    real(dp), allocatable :: fv(:, :), temp(:)
    real(dp), allocatable :: gv(:, :)
    integer, allocatable :: id(:), mat(:)
    real(dp) :: detf

    nd = wr%ndim
    n = sum(blocks(1:nblocks)%count)
    allocate (xyz(3, n), vel(3, n), s(wr%ncomp, n), le(wr%ncomp, n), dens(n), mass(n), vol(n), &
         sdv(max(1, wr%req%nsdv), n), id(n), mat(n), fv(n, wr%req%nfv), temp(n))
    xyz = 0
    vel = 0
    sdv = 0
    fv = 0
    r = 0
    do ib = 1, nblocks
       associate (b => blocks(ib))
         nsv = min(size(b%state, 2), wr%req%nsdv)
         nfv = min(size(b%field, 2), wr%req%nfv)
         if (wr%req%temp) temp(r + 1:r + b%count) = particle_temperature(m, step, b%material, step_time, total_time)
         do p = 1, b%count
            r = r + 1
            xyz(1:nd, r) = b%x(p, :)
            vel(1:nd, r) = b%v(p, :)
            s(:, r) = b%stress_global(p, :)
            le(:, r) = b%log_strain(p, :)
            if (nd == 2) then
               detf = b%f(p, 1, 1) * b%f(p, 2, 2) - b%f(p, 1, 2) * b%f(p, 2, 1)
            else
               detf = b%f(p, 1, 1) * (b%f(p, 2, 2) * b%f(p, 3, 3) - b%f(p, 2, 3) * b%f(p, 3, 2)) &
                    - b%f(p, 1, 2) * (b%f(p, 2, 1) * b%f(p, 3, 3) - b%f(p, 2, 3) * b%f(p, 3, 1)) &
                    + b%f(p, 1, 3) * (b%f(p, 2, 1) * b%f(p, 3, 2) - b%f(p, 2, 2) * b%f(p, 3, 1))
            end if
            vol(r) = b%vol0(p) * detf
            mass(r) = b%mass(p)
            dens(r) = b%mass(p) / vol(r)
            if (nsv > 0) sdv(1:nsv, r) = b%state(p, 1:nsv)
            if (nfv > 0) fv(r, 1:nfv) = b%field(p, 1:nfv)
            id(r) = b%number(p)
            mat(r) = b%material
         end do
       end associate
    end do
    call point_writer_frame(wr%points, step, increment, step_time, total_time, n)
    call point_writer_field(wr%points, 'coordinates', xyz)
    call point_writer_field(wr%points, 'V', vel)
    call point_writer_field(wr%points, 'S', s)
    call point_writer_field(wr%points, 'LE', le)
    call point_writer_scalar(wr%points, 'density', dens)
    call point_writer_scalar(wr%points, 'mass', mass)
    call point_writer_scalar(wr%points, 'volume', vol)
    if (wr%req%nsdv > 0) call point_writer_field(wr%points, 'SDV', sdv)
    call point_writer_ints(wr%points, 'id', id)
    call point_writer_ints(wr%points, 'material', mat)
    do j = 1, wr%req%nfv
       call point_writer_scalar(wr%points, 'FV' // int_to_str(j), fv(:, j))
    end do
    if (wr%req%temp) call point_writer_scalar(wr%points, 'TEMP', temp)
    if (present(owned_lo) .and. present(owned_hi)) then
       call write_owned_grid(wr, g, owned_lo, owned_hi)
    else
       allocate (gv(3, g%nn))
       gv = 0
       gv(1:nd, :) = g%v_new
       call point_writer_grid_field(wr%points, 'mass', g%mass, 1)
       call point_writer_grid_field(wr%points, 'V', reshape(gv, [3 * g%nn]), 3)
    end if
    call point_writer_end_frame(wr%points)
  end subroutine mpm_writer_frame

  !> The grid part of a frame of a decomposed grid: each rank writes the mass and V of the
  !> nodes it owns (the owner's values: the halo sums made them whole there), a box of the
  !> whole grid's datasets. Collective.
  subroutine write_owned_grid(wr, g, owned_lo, owned_hi)
    type(mpm_writer_t), intent(inout) :: wr
    type(grid_t), intent(in) :: g
    integer, intent(in) :: owned_lo(3), owned_hi(3)
    real(dp), allocatable :: mass(:), v(:, :)
    integer :: count(3), i, j, k, r, node, nd

    nd = wr%ndim
    count = max(0, owned_hi - owned_lo + 1)
    allocate (mass(product(count)), v(3, product(count)))
    v = 0
    r = 0
    do k = owned_lo(3), owned_hi(3)
       do j = owned_lo(2), owned_hi(2)
          do i = owned_lo(1), owned_hi(1)
             r = r + 1
             node = 1 + (i - g%offset(1)) + g%n(1) * ((j - g%offset(2)) + g%n(2) * (k - g%offset(3)))
             mass(r) = g%mass(node)
             v(1:nd, r) = g%v_new(:, node)
          end do
       end do
    end do
    call point_writer_grid_field(wr%points, 'mass', mass, 1, owned_lo, count)
    call point_writer_grid_field(wr%points, 'V', reshape(v, [3 * size(mass)]), 3, owned_lo, count)
  end subroutine write_owned_grid

  !> Frames written so far (what a checkpoint records).
  pure integer function mpm_writer_frame_count(wr)
    type(mpm_writer_t), intent(in) :: wr
    mpm_writer_frame_count = point_writer_frame_count(wr%points)
  end function mpm_writer_frame_count

  subroutine mpm_writer_close(wr)
    type(mpm_writer_t), intent(inout) :: wr
    call point_writer_close(wr%points)
  end subroutine mpm_writer_close
end module mpm_output
