!> Checkpoint and restart of a material-point run (the time loop is src/mpm/mpm_run.f90).
!>
!> Owns what a checkpoint of an MPM run holds and how a restart checks and restores it:
!>   * this rank's particle blocks; their number and sizes change with outflow and inflow, so
!>     the block table (count, material, state and field columns, half-length) comes first,
!>     then one flat array per particle field holding every block's values in block order.
!>     Flat arrays, not one record per block: reading is collective record by record
!>     (output_checkpoint agrees on errors), and the ranks hold different numbers of blocks;
!>   * the run's counters and sums (mpm_saved_t): time, step, increment, Δt, particle
!>     numbering, mass and particle counts in/out, energies, wall impulses and forces, the
!>     step's increment count (the output schedule is rebuilt from it and the step time), the MDR reference of the last history row, and the number of
!>     field frames and history rows written so far;
!>   * the scene's digest (model_digest: a hash per keyword and data line), so that a restart
!>     of an edited scene is refused at the first line that differs (file:line).
!>   * this rank's grid mass and velocity of the last increment: the grid carries no history
!>     (mpm_grid: every increment starts from zero), but the frame written at the start of the
!>     next step shows the last increment's grid, so a restart at a step's end needs it.
!> Everything else (wall node lists, mirror planes, material moduli) is rebuilt by the set-up
!> from the scene, so a restarted run repeats the uninterrupted one bit for bit.
!>
!> Files: one per rank, `<base>.rst.<rank>`, in the element driver's format (output_checkpoint:
!> atomic replacement, rank count, names, kinds and shapes checked), so a restart needs the
!> number of ranks that wrote the checkpoint; another number is refused. On restart BASE.h5
!> keeps the frames and BASE_history.csv the rows the checkpoint counted; what the interrupted
!> run wrote after its checkpoint is replaced.
!>
!> Every failure of a restart (no checkpoint, another rank count, a changed scene, outputs that
!> do not match) is agreed between the ranks and ends the run cleanly: rank 0 prints
!> `bulkflow: error: file: what is wrong; expected ...`, exit status 2, no MPI_Abort.
module mpm_checkpoint
  use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Bcast, MPI_INTEGER
  use mpm_scene, only: decomposition_spatial
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error, add_expectation
  use model, only: model_t
  use checkpoint_scene, only: put_scene_digest, check_saved_scene
  use mpm_particles, only: particle_block_t, particle_block_size, block_allocate
  use mpm_grid, only: grid_t
  use mpm_output, only: mpm_writer_t, mpm_writer_open, mpm_field_request_t
  use output_checkpoint, only: checkpoint_t, checkpoint_header_t, checkpoint_begin_write, checkpoint_put, &
       checkpoint_end_write, restart_begin_read, checkpoint_get, checkpoint_end_read, checkpoint_file_name
  use output_collective, only: agree_on_error
  use output_history, only: history_t, history_open
  use output_files, only: int_to_str
  implicit none
  private

  !> The run state a checkpoint holds besides the particle blocks; mpm_run copies its own
  !> state in and out (values marked "rank" in mpm_run are this rank's part).
  type, public :: mpm_saved_t
     integer :: step = 0, increment = 0
     real(dp) :: step_time = 0, total_time = 0, dt = 0, dt_stable = 0
     integer :: next_number = 0                       !< last particle number given
     integer :: n_initial = 0, n_in = 0, n_out = 0, n_guarded = 0
     real(dp) :: mass_initial = 0, mass_in = 0, mass_out = 0, mass_cutoff = 0
     real(dp) :: e_kinetic = 0, e_internal = 0, w_external = 0, e_walls = 0, e_damping = 0
     real(dp) :: e_out = 0, e_in = 0
     real(dp) :: gravity(3) = 0
     real(dp) :: impulse_time = 0                     !< time the wall impulses were summed over
     real(dp), allocatable :: wall_force(:, :)        !< (3, n_walls)
     real(dp), allocatable :: wall_impulse(:, :)      !< (3, n_walls) since the last history row
     real(dp), allocatable :: wall_force_row(:, :)    !< (3, n_walls) of the last history row
     real(dp), allocatable :: rigid_u(:, :)           !< (3, n_rigid_surfaces) reference node displacements
     !> increments of the running step: the FREQUENCY= output requests count them (the
     !> requests' next times are rebuilt from the step time, output_schedule)
     integer :: step_increment = 0
     real(dp) :: last_row_time = 0, last_row_out = 0  !< time and MASS_OUT of the last row (MDR)
     integer :: frames = 0                            !< field frames written (rank 0's writer)
     integer :: rows = 0                              !< history rows written
     !> a spatially decomposed run (mpm_domain): re-partitions done, then the boxes (2, 3, nranks)
     integer, allocatable :: domain(:)
     !> this rank's grid mass and velocity v_n+1 of the last increment: the frame at the start of
     !> the next step shows them (a restart at a step's end writes that frame)
     real(dp), allocatable :: grid_mass(:), grid_v(:, :)
  end type mpm_saved_t

  public :: mpm_checkpoint_save, mpm_checkpoint_load, mpm_restart_outputs

  integer, parameter :: n_scalars = 18
  integer, parameter :: n_counters = 7
  !> The per-particle real arrays of a block that a checkpoint holds (the stencil arrays node,
  !> w, dw are recomputed at the start of every increment).
  character(len=13), parameter :: block_fields(13) = [character(len=13) :: 'x', 'v', 'mass', 'vol0', 'f', &
       'rot', 'stress', 'stress_global', 'state', 'field', 'e_int', 'e_inel', 'log_strain']

contains

  ! ------------------------------------------------------------------------------ writing

  !> Write this rank's checkpoint (collective: every rank writes its file, then all replace the
  !> previous checkpoint together). `sv%frames` is read on rank 0, whose writer counts them.
  subroutine mpm_checkpoint_save(base, comm, m, blocks, nblocks, sv)
    character(len=*), intent(in) :: base
    type(MPI_Comm), intent(in) :: comm
    type(model_t), intent(in) :: m
    type(particle_block_t), intent(in) :: blocks(:)
    integer, intent(in) :: nblocks
    type(mpm_saved_t), intent(in) :: sv
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: header
    integer :: frames(1), ib, j, info(4, nblocks)
    real(dp), allocatable :: flat(:)

    frames(1) = sv%frames
    call MPI_Bcast(frames, 1, MPI_INTEGER, 0, comm)
    header%step = sv%step
    header%increment = sv%increment
    header%step_time = sv%step_time
    header%total_time = sv%total_time
    header%dt = sv%dt
    header%frame_count = frames(1)
    header%history_rows = sv%rows
    call checkpoint_begin_write(ck, base, comm, header)
    call put_scene_digest(ck, m%digest)
    call checkpoint_put(ck, 'counters', [sv%next_number, sv%n_initial, sv%n_in, sv%n_out, sv%n_guarded, nblocks, &
         sv%step_increment])
    call checkpoint_put(ck, 'scalars', pack_scalars(sv))
    call checkpoint_put(ck, 'wall_force', sv%wall_force)
    call checkpoint_put(ck, 'wall_impulse', sv%wall_impulse)
    call checkpoint_put(ck, 'wall_force_row', sv%wall_force_row)
    ! only scenes with rigid surfaces (checkpoints of the others stay as they were)
    if (m%n_rigid_surfaces > 0) call checkpoint_put(ck, 'rigid_u', sv%rigid_u)
    if (allocated(sv%domain)) call checkpoint_put(ck, 'domain', sv%domain)
    call checkpoint_put(ck, 'grid_size', [size(sv%grid_mass)])
    call checkpoint_put(ck, 'grid_mass', sv%grid_mass)
    call checkpoint_put(ck, 'grid_v', sv%grid_v)
    do ib = 1, nblocks
       info(:, ib) = [blocks(ib)%count, blocks(ib)%material, size(blocks(ib)%state, 2), size(blocks(ib)%field, 2)]
    end do
    call checkpoint_put(ck, 'block_info', info)
    call checkpoint_put(ck, 'block_half', [real(dp) :: (blocks(ib)%half, ib = 1, nblocks)])
    call checkpoint_put(ck, 'number', [integer :: (blocks(ib)%number, ib = 1, nblocks)])
    do j = 1, size(block_fields)
       call collect(blocks, nblocks, trim(block_fields(j)), flat)
       call checkpoint_put(ck, trim(block_fields(j)), flat)
    end do
    call checkpoint_end_write(ck)
  end subroutine mpm_checkpoint_save

  ! ------------------------------------------------------------------------------ reading

  !> Read this rank's checkpoint into `blocks` (replacing what the set-up generated) and `sv`.
  !> The grid, walls and materials must be set up already (nd, nc, nsup: dimensions, stress
  !> components, stencil nodes per direction). Collective; on a problem `err` is raised on every
  !> rank.
  subroutine mpm_checkpoint_load(base, comm, m, nd, nc, nsup, blocks, nblocks, sv, err)
    character(len=*), intent(in) :: base
    type(MPI_Comm), intent(in) :: comm
    type(model_t), intent(in) :: m
    integer, intent(in) :: nd, nc, nsup
    type(particle_block_t), allocatable, intent(inout) :: blocks(:)
    integer, intent(out) :: nblocks
    type(mpm_saved_t), intent(out) :: sv
    type(error_t), intent(inout) :: err
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: header
    real(dp), allocatable :: scalars(:), half(:), flat(:)
    integer, allocatable :: info(:, :), number(:)
    integer :: counters(n_counters), ib, j, rank, nw, off, nranks, grid_size(1)
    character(len=:), allocatable :: msg, file
    logical :: any_failed

    call MPI_Comm_rank(comm, rank)
    nblocks = 0
    file = checkpoint_file_name(base, rank)
    call restart_begin_read(ck, base, comm, header, err)
    if (err%raised) return
    sv%step = header%step
    sv%increment = header%increment
    sv%step_time = header%step_time
    sv%total_time = header%total_time
    sv%dt = header%dt
    sv%frames = header%frame_count
    sv%rows = header%history_rows

    ! The scene first: a changed scene must say so, not fail on some array's shape later.
    call check_saved_scene(ck, m%digest, err)
    if (err%raised) return

    counters = 0
    call checkpoint_get(ck, 'counters', counters, err)
    allocate (scalars(n_scalars))
    scalars = 0
    call checkpoint_get(ck, 'scalars', scalars, err)
    nw = size(m%mpm%walls)
    allocate (sv%wall_force(3, nw), sv%wall_impulse(3, nw), sv%wall_force_row(3, nw))
    sv%wall_force = 0
    sv%wall_impulse = 0
    sv%wall_force_row = 0
    call checkpoint_get(ck, 'wall_force', sv%wall_force, err)
    call checkpoint_get(ck, 'wall_impulse', sv%wall_impulse, err)
    call checkpoint_get(ck, 'wall_force_row', sv%wall_force_row, err)
    allocate (sv%rigid_u(3, m%n_rigid_surfaces))
    sv%rigid_u = 0
    if (m%n_rigid_surfaces > 0) call checkpoint_get(ck, 'rigid_u', sv%rigid_u, err)
    call MPI_Comm_size(comm, nranks)
    if (m%mpm%decomposition == decomposition_spatial .and. nranks > 1) then
       allocate (sv%domain(1 + 6 * nranks), source=0)
       call checkpoint_get(ck, 'domain', sv%domain, err)
    end if
    grid_size = 0
    call checkpoint_get(ck, 'grid_size', grid_size, err)
    allocate (sv%grid_mass(max(grid_size(1), 0)), source=0.0_dp)
    allocate (sv%grid_v(nd, max(grid_size(1), 0)), source=0.0_dp)
    call checkpoint_get(ck, 'grid_mass', sv%grid_mass, err)
    call checkpoint_get(ck, 'grid_v', sv%grid_v, err)
    if (err%raised) return
    call unpack_scalars(scalars, sv)
    sv%next_number = counters(1)
    sv%n_initial = counters(2)
    sv%n_in = counters(3)
    sv%n_out = counters(4)
    sv%n_guarded = counters(5)
    nblocks = counters(6)
    sv%step_increment = counters(7)

    ! The block table, checked before anything is allocated from it (a damaged file must not
    ! make this rank allocate nonsense while the others wait).
    if (nblocks < 0) msg = 'damaged file: ' // int_to_str(nblocks) // ' particle blocks'
    call agree_on_error(comm, allocated(msg), msg, any_failed, file)
    if (any_failed) then
       call raise_error(file, 0, msg, err)
       nblocks = 0
       return
    end if
    allocate (info(4, nblocks), half(nblocks))
    info = 0
    half = 0
    call checkpoint_get(ck, 'block_info', info, err)
    call checkpoint_get(ck, 'block_half', half, err)
    if (err%raised) then
       nblocks = 0
       return
    end if
    do ib = 1, nblocks
       if (info(1, ib) < 1 .or. info(1, ib) > particle_block_size .or. info(2, ib) < 1 .or. &
            info(2, ib) > m%n_materials .or. info(3, ib) < 1 .or. info(4, ib) < 1) then
          msg = 'damaged file: block ' // int_to_str(ib) // ' has ' // int_to_str(info(1, ib)) // &
               ' particles of material ' // int_to_str(info(2, ib)) // '; expected 1 to ' // &
               int_to_str(particle_block_size) // ' particles of a material 1 to ' // int_to_str(m%n_materials)
          exit
       end if
    end do
    call agree_on_error(comm, allocated(msg), msg, any_failed, file)
    if (any_failed) then
       call raise_error(file, 0, msg, err)
       nblocks = 0
       return
    end if

    if (allocated(blocks)) deallocate (blocks)
    ! room to grow: inflow appends blocks (mpm_run doubles the list when it is full)
    allocate (blocks(max(16, 2 * nblocks)))
    do ib = 1, nblocks
       call block_allocate(blocks(ib), info(1, ib), nd, nc, info(3, ib), info(4, ib), nsup)
       blocks(ib)%material = info(2, ib)
       blocks(ib)%half = half(ib)
    end do
    ! every field's flat array has the length the allocated blocks give it (checked by the read)
    allocate (number(sum(info(1, :))))
    number = 0
    call checkpoint_get(ck, 'number', number, err)
    off = 0
    do ib = 1, nblocks
       blocks(ib)%number = number(off + 1:off + blocks(ib)%count)
       off = off + blocks(ib)%count
    end do
    do j = 1, size(block_fields)
       call collect(blocks, nblocks, trim(block_fields(j)), flat)
       call checkpoint_get(ck, trim(block_fields(j)), flat, err)
       if (err%raised) exit
       call distribute(flat, trim(block_fields(j)), blocks, nblocks)
    end do
    if (.not. err%raised) call checkpoint_end_read(ck, err)
  end subroutine mpm_checkpoint_load

  !> Reopen the outputs of the interrupted run at the checkpoint: BASE.h5 keeps its first
  !> `frames` frames, BASE_history.csv its first `rows` rows. Collective.
  subroutine mpm_restart_outputs(base, comm, g, ncomp, fields, columns, frames, rows, wr, hist, err)
    character(len=*), intent(in) :: base
    type(MPI_Comm), intent(in) :: comm
    type(grid_t), intent(in) :: g
    integer, intent(in) :: ncomp
    type(mpm_field_request_t), intent(in) :: fields
    character(len=*), intent(in) :: columns(:)
    integer, intent(in) :: frames, rows
    type(mpm_writer_t), intent(inout) :: wr
    type(history_t), intent(inout) :: hist
    type(error_t), intent(inout) :: err

    call mpm_writer_open(wr, base, comm, g, ncomp, fields, restart_frames=frames, err=err)
    if (err%raised) then
       call add_expectation(err, 'the field output of the run that wrote the checkpoint')
       return
    end if
    call history_open(hist, base // '_history.csv', columns, comm, restart_rows=rows, err=err)
    if (err%raised) call add_expectation(err, 'the history of the run that wrote the checkpoint')
  end subroutine mpm_restart_outputs

  ! ------------------------------------------------------------------------------ block fields

  !> One particle field of every block, flattened in block order (each block's array in
  !> Fortran element order).
  subroutine collect(blocks, nblocks, name, flat)
    type(particle_block_t), intent(in) :: blocks(:)
    integer, intent(in) :: nblocks
    character(len=*), intent(in) :: name
    real(dp), allocatable, intent(inout) :: flat(:)
    integer :: ib, off, n

    n = 0
    do ib = 1, nblocks
       n = n + field_size(blocks(ib), name)
    end do
    if (allocated(flat)) deallocate (flat)
    allocate (flat(n))
    off = 0
    do ib = 1, nblocks
       associate (b => blocks(ib))
         n = field_size(b, name)
         select case (name)
         case ('x')
            flat(off + 1:off + n) = reshape(b%x, [n])
         case ('v')
            flat(off + 1:off + n) = reshape(b%v, [n])
         case ('mass')
            flat(off + 1:off + n) = b%mass
         case ('vol0')
            flat(off + 1:off + n) = b%vol0
         case ('f')
            flat(off + 1:off + n) = reshape(b%f, [n])
         case ('rot')
            flat(off + 1:off + n) = reshape(b%rot, [n])
         case ('stress')
            flat(off + 1:off + n) = reshape(b%stress, [n])
         case ('stress_global')
            flat(off + 1:off + n) = reshape(b%stress_global, [n])
         case ('state')
            flat(off + 1:off + n) = reshape(b%state, [n])
         case ('field')
            flat(off + 1:off + n) = reshape(b%field, [n])
         case ('e_int')
            flat(off + 1:off + n) = b%e_int
         case ('e_inel')
            flat(off + 1:off + n) = b%e_inel
         case ('log_strain')
            flat(off + 1:off + n) = reshape(b%log_strain, [n])
         end select
       end associate
       off = off + n
    end do
  end subroutine collect

  !> The inverse of collect: the blocks are allocated with their shapes already.
  subroutine distribute(flat, name, blocks, nblocks)
    real(dp), intent(in) :: flat(:)
    character(len=*), intent(in) :: name
    type(particle_block_t), intent(inout) :: blocks(:)
    integer, intent(in) :: nblocks
    integer :: ib, off, n

    off = 0
    do ib = 1, nblocks
       associate (b => blocks(ib))
         n = field_size(b, name)
         select case (name)
         case ('x')
            b%x = reshape(flat(off + 1:off + n), shape(b%x))
         case ('v')
            b%v = reshape(flat(off + 1:off + n), shape(b%v))
         case ('mass')
            b%mass = flat(off + 1:off + n)
         case ('vol0')
            b%vol0 = flat(off + 1:off + n)
         case ('f')
            b%f = reshape(flat(off + 1:off + n), shape(b%f))
         case ('rot')
            b%rot = reshape(flat(off + 1:off + n), shape(b%rot))
         case ('stress')
            b%stress = reshape(flat(off + 1:off + n), shape(b%stress))
         case ('stress_global')
            b%stress_global = reshape(flat(off + 1:off + n), shape(b%stress_global))
         case ('state')
            b%state = reshape(flat(off + 1:off + n), shape(b%state))
         case ('field')
            b%field = reshape(flat(off + 1:off + n), shape(b%field))
         case ('e_int')
            b%e_int = flat(off + 1:off + n)
         case ('e_inel')
            b%e_inel = flat(off + 1:off + n)
         case ('log_strain')
            b%log_strain = reshape(flat(off + 1:off + n), shape(b%log_strain))
         end select
       end associate
       off = off + n
    end do
  end subroutine distribute

  pure integer function field_size(b, name) result(n)
    type(particle_block_t), intent(in) :: b
    character(len=*), intent(in) :: name

    select case (name)
    case ('x')
       n = size(b%x)
    case ('v')
       n = size(b%v)
    case ('f')
       n = size(b%f)
    case ('rot')
       n = size(b%rot)
    case ('stress')
       n = size(b%stress)
    case ('stress_global')
       n = size(b%stress_global)
    case ('state')
       n = size(b%state)
    case ('field')
       n = size(b%field)
    case ('log_strain')
       n = size(b%log_strain)
    case default
       ! mass, vol0, e_int, e_inel: one value per particle
       n = b%count
    end select
  end function field_size

  ! ------------------------------------------------------------------------------ scalars

  pure function pack_scalars(sv) result(r)
    type(mpm_saved_t), intent(in) :: sv
    real(dp) :: r(n_scalars)

    r = [sv%dt_stable, sv%mass_initial, sv%mass_in, sv%mass_out, sv%mass_cutoff, sv%e_kinetic, &
         sv%e_internal, sv%w_external, sv%e_walls, sv%e_damping, sv%e_out, sv%e_in, sv%gravity, &
         sv%impulse_time, sv%last_row_time, sv%last_row_out]
  end function pack_scalars

  !> The inverse of pack_scalars (time, step time and Δt are in the header).
  pure subroutine unpack_scalars(r, sv)
    real(dp), intent(in) :: r(n_scalars)
    type(mpm_saved_t), intent(inout) :: sv

    sv%dt_stable = r(1)
    sv%mass_initial = r(2)
    sv%mass_in = r(3)
    sv%mass_out = r(4)
    sv%mass_cutoff = r(5)
    sv%e_kinetic = r(6)
    sv%e_internal = r(7)
    sv%w_external = r(8)
    sv%e_walls = r(9)
    sv%e_damping = r(10)
    sv%e_out = r(11)
    sv%e_in = r(12)
    sv%gravity = r(13:15)
    sv%impulse_time = r(16)
    sv%last_row_time = r(17)
    sv%last_row_out = r(18)
  end subroutine unpack_scalars

end module mpm_checkpoint
