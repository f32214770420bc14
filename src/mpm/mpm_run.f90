!> The explicit material-point solver (MUSL with a PIC/FLIP blend; docs/theory/mpm.md §4), one rank.
!>
!> One increment (velocities at integer times, Δt from the grid size and the wave speed):
!>   stencils     uGIMP or linear weights S_Ip and gradients ∇S_Ip at x_p^n       (mpm_shape)
!>   P2G          m_I, p_I = Σ S m v, f_I = −Σ V σ·∇S + Σ S m g                     [p2g]
!>   grid         [local damping] p_I += Δt f_I; v_I^n, v_I^{n+1}; walls on v^{n+1} [grid, walls]
!>   G2P          v_p ← α(v_p + Σ S Δv_I) + (1−α) Σ S v_I^{n+1}; x_p += Δt Σ S v_I^{n+1}   [g2p]
!>   MUSL remap   p_I = Σ S m v_p, v_I = p_I/m_I, walls again; L_p = Σ v_I ⊗ ∇S         [g2p, walls]
!>   stress       F ← (I + LΔt) F; Green–Naghdi frame R from F (fem_corotation, as elements);
!>                strainInc = R_{n+½}ᵀ sym(L)Δt R_{n+½}, relSpinInc; VUSDFLD/VUMAT on the
!>                block exactly as for element blocks (material_door)             [kinematics, material]
!>   outflow      particles below the outflow level leave (mass, time counted)     [outflow]
!>   inflow       layers of particles at the top keep the free surface level      [inflow]
!>
!> Why Green–Naghdi and not Jaumann/Hughes–Winget: the VUMAT contract (and our elements) hand
!> the material stresses in the frame R of F = RU; a particle carries F, so the same frame, the
!> same relSpinInc and the same code serve both (a user VUMAT sees one convention).
!> MPI: particle decomposition with a replicated grid. Every rank generates all particles and
!> keeps every nranks-th block; P2G sums (mass, momentum, forces) and the MUSL remap are summed
!> over ranks (one MPI_Allreduce each), so every rank holds the whole grid and does the grid
!> update and the walls itself; particles never migrate. Inflow particles are made by rank 0.
!> Sums over ranks are in rank order (MPI_Allreduce): results are deterministic for a given
!> number of ranks and differ from 1 rank by round-off only. Output: rank 0 gathers the blocks.
!> Checkpoint and restart: src/mpm/mpm_checkpoint.f90 (the hooks at the end of this module copy
!> the run state in and out).
module mpm_run
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Allreduce, MPI_IN_PLACE, &
       MPI_DOUBLE_PRECISION, MPI_INTEGER, MPI_INTEGER8, MPI_LOGICAL, MPI_SUM, MPI_MAX, MPI_LOR, MPI_MAXLOC, &
       MPI_2DOUBLE_PRECISION, MPI_Send, MPI_Recv, MPI_STATUS_IGNORE
  use material_kinds, only: dp
  use error_report, only: error_t, raise_error
  use material_props, only: model_from_name, model_unknown
  use model, only: model_t
  use model_time_variation, only: variation_factor
  use mpm_scene, only: mpm_scene_t, particle_region_t, mpm_inflow_t, region_box, region_polygon
  use mpm_grid, only: grid_t, grid_init, grid_reset_sums, grid_clear
  use mpm_particles, only: particle_block_t, particle_block_size, block_allocate, block_keep, block_grow
  use mpm_shape, only: stencil_nodes_per_direction, block_stencil
  use mpm_transfer, only: scatter_p2g, gather_velocity, scatter_momentum, gather_gradient
  use mpm_walls, only: wall_nodes_t, wall_find_nodes, wall_project, wall_contains, wall_distance, wall_rows_behind, &
       wall_slide_velocity
  use mpm_mirror, only: mirror_plane_t, mirror_plane_setup, mirror_fold, mirror_fold_momentum
  use mpm_output, only: mpm_writer_t, mpm_writer_open, mpm_writer_frame, mpm_writer_close, mpm_writer_frame_count
  use mpm_checkpoint, only: mpm_saved_t, mpm_checkpoint_due, mpm_checkpoint_save, mpm_checkpoint_load, &
       mpm_restart_outputs
  use material_door, only: vumat_work_t, vumat_work_init, call_material, checked_packaging_modulus
  use fem_corotation, only: polar_rotation, to_corotational, to_global, relative_spin, vumat_defgrad, &
       vumat_stretch
  use output_timer, only: timer_set_t, timer_init, timer_register, timer_start, timer_stop, timer_report, &
       clock_text
  use output_collective, only: stop_agreed_error
  use output_history, only: history_t, history_open, history_row, history_close, history_row_count
  implicit none
  private

  ! The MPM effects: the same registry idea as driver_effects (one switch from the scene, a
  ! timer only for what is active, shares in the report); MPM's own list keeps the FEM one intact.
  integer, parameter :: fx_p2g = 1, fx_grid = 2, fx_g2p = 3, fx_kinematics = 4, fx_material = 5, &
       fx_user_field = 6, fx_gravity = 7, fx_damping = 8, fx_walls = 9, fx_outflow = 10, fx_inflow = 11, &
       fx_output = 12, n_fx = 12
  character(len=16), parameter :: fx_names(n_fx) = [character(len=16) :: 'p2g', 'grid update', 'g2p', &
       'kinematics', 'material', 'user field', 'gravity', 'damping', 'walls', 'outflow', 'inflow', 'output']

  type :: mpm_effects_t
     logical :: active(n_fx) = .false.
     integer :: id(n_fx) = 0
     type(timer_set_t) :: timers
  end type mpm_effects_t

  !> Everything the run keeps. Per-rank partial values (sum over ranks when reported) are
  !> marked "rank"; the rest is the same on every rank.
  type :: mpm_state_t
     type(MPI_Comm) :: comm
     integer :: rank = 0, nranks = 1
     integer :: nd = 0, nc = 0, nshr = 0, nsup = 0
     type(grid_t) :: g
     integer :: nblocks = 0
     type(particle_block_t), allocatable :: blocks(:)
     type(wall_nodes_t), allocatable :: wall_nodes(:)
     !> per wall: a symmetry plane on a node plane is done by mirroring the grid (mpm_mirror)
     type(mirror_plane_t), allocatable :: mirror(:)
     logical, allocatable :: mirrored(:)
     real(dp), allocatable :: modulus(:)             !< per material: λ + 2G (packaging call)
     logical, allocatable :: needs_kinematics(:)     !< per material: user VUMAT reads F, U
     !> VUMAT work sets: work(1) has particle_block_size rows (full blocks), work(2) the rows of
     !> the last partial block (made again when a block of another count comes). Why: with
     !> exactly nb rows every (1:nb, ...) section the door passes is the whole, contiguous array
     !> (no pack/unpack copies) and the new stress and state are swapped in, not copied.
     type(vumat_work_t) :: work(2)
     integer :: work_statev = 1, work_fieldv = 1     !< columns of the work sets (largest of the materials)
     integer :: next_number = 0
     ! mass bookkeeping (exact: particle masses never change)
     real(dp) :: mass_initial = 0, mass_in = 0, mass_out = 0   !< mass_out: rank
     integer :: n_initial = 0, n_in = 0, n_out = 0, n_guarded = 0  !< n_out, n_guarded: rank
     real(dp) :: mass_cutoff = 0
     ! energies (global sums; 2D per unit thickness)
     real(dp) :: e_kinetic = 0, e_internal = 0, w_external = 0, e_walls = 0, e_damping = 0
     real(dp) :: e_out = 0, e_in = 0                 !< w_external, e_out: rank (e_kinetic, e_internal: global after measure)
     real(dp), allocatable :: wall_force(:, :)       !< (3, n_walls) force of the material on each wall
     !> Impulse of the material on each wall since the last history row, and the time it took.
     !> The history reports impulse / time: the force of one increment, m Δv/Δt at the wall
     !> nodes, also removes the normal velocity the nodes brought into the increment, so it
     !> scales with 1/Δt; a short final increment made it 2-3.5 times too large.
     real(dp), allocatable :: wall_impulse(:, :)
     real(dp), allocatable :: wall_force_row(:, :)   !< the last history row's (mean) wall forces
     real(dp) :: impulse_time = 0
     logical, allocatable :: on_wall(:)              !< grid nodes of the walls active in this step
     ! time
     integer :: step = 0, increment = 0
     integer(int64) :: particle_steps = 0           !< Σ over increments of the particle count
     real(dp) :: loop_seconds = 0                    !< wall time of the time loop
     real(dp) :: total_time = 0, step_time = 0, dt = 0, dt_stable = 0
     real(dp) :: gravity(3) = 0
  end type mpm_state_t

  public :: mpm_run_scene

contains

  !> Run a material-point scene: base = output path without extension. stop_after > 0: stop
  !> (with a checkpoint) after that increment; restart: continue from the checkpoint of base.
  subroutine mpm_run_scene(m, base, progress, stop_after, comm, restart)
    type(model_t), intent(in) :: m
    character(len=*), intent(in) :: base
    logical, intent(in) :: progress
    integer, intent(in) :: stop_after
    type(MPI_Comm), intent(in) :: comm
    logical, intent(in), optional :: restart
    type(mpm_state_t) :: st
    type(mpm_effects_t) :: fx
    type(mpm_writer_t) :: wr
    type(history_t) :: hist
    character(len=32), allocatable :: columns(:)
    real(dp) :: next_field, next_history, field_dt, history_dt, last_row_time, last_row_out
    real(dp) :: period, eps, sim_start
    integer :: s, k, nsdv, first_step
    integer(int64) :: clock_last, clock_now, clock_rate, clock_start
    logical :: stop_now, resumed, history_due, field_due

    st%comm = comm
    call MPI_Comm_rank(comm, st%rank)
    call MPI_Comm_size(comm, st%nranks)
    call setup(m, st, fx)
    nsdv = 0
    do k = 1, m%n_materials
       nsdv = max(nsdv, m%materials(k)%nstatev)
    end do
    if (st%rank == 0) call header(m, st, fx, base)
    call history_columns(m, columns)
    resumed = .false.
    if (present(restart)) resumed = restart
    first_step = 1
    if (resumed) then
       call resume(m, st, base, nsdv, columns, wr, hist, next_field, next_history, last_row_time, last_row_out)
       first_step = st%step
    else
       if (st%rank == 0) call mpm_writer_open(wr, base, st%g, st%nc, nsdv)
       call history_open(hist, base // '_history.csv', columns, comm)
       call measure(st)
       call write_frame(st, wr, 1, 0.0_dp)
       last_row_time = 0
       last_row_out = 0
       call write_history(m, st, hist, last_row_time, last_row_out)
    end if
    call system_clock(clock_last, clock_rate)
    clock_start = clock_last
    sim_start = st%total_time
    stop_now = .false.
    do s = first_step, m%n_steps
       ! a resumed step continues at the checkpoint's step time and output schedule
       if (.not. resumed) then
          st%step = s
          st%step_time = 0
       end if
       period = m%steps(s)%period
       eps = 1.0e-12_dp * period
       call output_intervals(m, s, field_dt, history_dt)
       if (.not. resumed) then
          next_field = field_dt
          next_history = history_dt
       end if
       resumed = .false.
       call mark_wall_nodes(m, st)
       do while (st%step_time < period - eps)
          call stable_increment(m, st)
          st%dt = min(st%dt_stable, period - st%step_time)
          if (m%steps(s)%dt_fixed > 0) st%dt = min(m%steps(s)%dt_fixed, period - st%step_time)
          st%particle_steps = st%particle_steps + sum(st%blocks(1:st%nblocks)%count)
          call increment(m, st, fx)
          st%step_time = st%step_time + st%dt
          st%total_time = st%total_time + st%dt
          st%increment = st%increment + 1
          stop_now = stop_after > 0 .and. st%increment >= stop_after
          call timer_start(fx%timers, fx%id(fx_output))
          history_due = st%step_time >= next_history - eps .or. st%step_time >= period - eps
          field_due = st%step_time >= next_field - eps .or. (st%step_time >= period - eps .and. field_dt < huge(1.0_dp))
          if (history_due) then
             call measure(st)
             call write_history(m, st, hist, last_row_time, last_row_out)
             do while (next_history <= st%step_time + eps)
                next_history = next_history + history_dt
             end do
          end if
          if (field_due) then
             call write_frame(st, wr, s, st%step_time)
             do while (next_field <= st%step_time + eps)
                next_field = next_field + field_dt
             end do
          end if
          ! The checkpoint (timed as output) follows the increment's own output and precedes the
          ! extra row and frame of a stop: the uninterrupted run has none there, so a restart
          ! drops them (it keeps the frames and rows the checkpoint counted).
          if (stop_now .or. mpm_checkpoint_due(m, s, st%step_time, st%dt)) &
               call save_checkpoint(m, st, base, wr, hist, next_field, next_history, last_row_time, last_row_out)
          if (stop_now .and. .not. history_due) then
             call measure(st)
             call write_history(m, st, hist, last_row_time, last_row_out)
          end if
          if (stop_now .and. .not. field_due) call write_frame(st, wr, s, st%step_time)
          if (progress .and. st%rank == 0) then
             ! rank 0's own clock decides: no collective here (the ranks' clocks differ)
             call system_clock(clock_now)
             if (real(clock_now - clock_last, dp) / real(clock_rate, dp) > 2.0_dp) then
                clock_last = clock_now
                call progress_line(m, st, s, real(clock_now - clock_start, dp) / real(clock_rate, dp), &
                     sim_start)
             end if
          end if
          call timer_stop(fx%timers, fx%id(fx_output))
          if (stop_now) exit
       end do
       if (progress .and. st%rank == 0 .and. .not. stop_now) then
          ! one line per finished step: its end and the wall time so far (benchmarks split a
          ! fill from the discharge with it)
          call system_clock(clock_now)
          write (output_unit, '(a,i0,a,i0,1x,a,a,es11.4,a,i0,a,f10.1,a)') '  step ', s, '/', m%n_steps, &
               trim(m%steps(s)%name), ' done  t = ', st%total_time, '  inc ', st%increment, '  wall ', &
               real(clock_now - clock_start, dp) / real(clock_rate, dp), ' s'
          flush (output_unit)
       end if
       if (stop_now) exit
    end do
    call system_clock(clock_now)
    st%loop_seconds = real(clock_now - clock_start, dp) / real(clock_rate, dp)
    if (st%rank == 0) call mpm_writer_close(wr)
    call history_close(hist)
    call summary(m, st, fx, stop_now)
  end subroutine mpm_run_scene

  !> "  step 2/2 DISCHARGE  t = 1.2345E+00  inc 12345  dt 1.234E-04  out kg (rank 0) 12.3  ETA 0:04:10":
  !> the ETA from this run's wall time per simulated second so far (since the restart, if any).
  subroutine progress_line(m, st, s, elapsed, sim_start)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(in) :: st
    integer, intent(in) :: s
    real(dp), intent(in) :: elapsed, sim_start
    real(dp) :: remaining, eta

    remaining = m%steps(s)%period - st%step_time
    if (s < m%n_steps) remaining = remaining + sum(m%steps(s + 1:m%n_steps)%period)
    eta = 0
    if (st%total_time > sim_start) eta = elapsed / (st%total_time - sim_start) * remaining
    write (output_unit, '(a,i0,a,i0,1x,a,a,es11.4,a,i0,a,es10.3,a,es11.4,a,a)') '  step ', s, '/', m%n_steps, &
         trim(m%steps(s)%name), '  t = ', st%total_time, '  inc ', st%increment, '  dt ', st%dt, &
         '  out kg (rank 0) ', st%mass_out, '  ETA ', clock_text(eta)
    flush (output_unit)
  end subroutine progress_line

  ! ------------------------------------------------------------------------------ ranks

  subroutine sum_real(st, x)
    type(mpm_state_t), intent(in) :: st
    real(dp), intent(inout) :: x(:)
    if (st%nranks > 1) call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_DOUBLE_PRECISION, MPI_SUM, st%comm)
  end subroutine sum_real

  subroutine max_real(st, x)
    type(mpm_state_t), intent(in) :: st
    real(dp), intent(inout) :: x(:)
    if (st%nranks > 1) call MPI_Allreduce(MPI_IN_PLACE, x, size(x), MPI_DOUBLE_PRECISION, MPI_MAX, st%comm)
  end subroutine max_real

  integer function global_count(st)
    type(mpm_state_t), intent(in) :: st
    integer :: n(1)
    n(1) = sum(st%blocks(1:st%nblocks)%count)
    if (st%nranks > 1) call MPI_Allreduce(MPI_IN_PLACE, n, 1, MPI_INTEGER, MPI_SUM, st%comm)
    global_count = n(1)
  end function global_count

  !> A field frame: rank 0 gathers every rank's blocks (in rank order) and writes them.
  subroutine write_frame(st, wr, step, step_time)
    type(mpm_state_t), intent(inout) :: st
    type(mpm_writer_t), intent(inout) :: wr
    integer, intent(in) :: step
    real(dp), intent(in) :: step_time
    type(particle_block_t), allocatable :: all(:)
    integer :: nall

    if (st%nranks == 1) then
       call mpm_writer_frame(wr, st%blocks, st%nblocks, st%g, step, st%increment, step_time, st%total_time)
       return
    end if
    allocate (all(st%nblocks + 16))
    call gather_blocks(st, all, nall)
    if (st%rank == 0) call mpm_writer_frame(wr, all, nall, st%g, step, st%increment, step_time, st%total_time)
  end subroutine write_frame

  !> Rank 0 receives copies of the other ranks' blocks (what the writer reads of them).
  subroutine gather_blocks(st, all, nall)
    type(mpm_state_t), intent(in) :: st
    type(particle_block_t), allocatable, intent(inout) :: all(:)   !< allocated by the caller
    integer, intent(out) :: nall
    integer :: r, k, nb(1), head(5), c, nd, nc, nsv, nfv, nreal, off
    real(dp), allocatable :: buf(:)

    nd = st%nd
    nc = st%nc
    nall = 0
    if (st%rank /= 0) then
       nb(1) = st%nblocks
       call MPI_Send(nb, 1, MPI_INTEGER, 0, 1, st%comm)
       do k = 1, st%nblocks
          associate (b => st%blocks(k))
            c = b%count
            head = [c, b%material, size(b%state, 2), size(b%field, 2), 0]
            call MPI_Send(head, 5, MPI_INTEGER, 0, 2, st%comm)
            call MPI_Send(b%number, c, MPI_INTEGER, 0, 3, st%comm)
            nsv = size(b%state, 2)
            if (allocated(buf)) deallocate (buf)
            allocate (buf(c * (2 * nd + 2 * nc + nd * nd + 2 + nsv) + 1))
            off = 0
            buf(off + 1:off + c * nd) = reshape(b%x, [c * nd]); off = off + c * nd
            buf(off + 1:off + c * nd) = reshape(b%v, [c * nd]); off = off + c * nd
            buf(off + 1:off + c * nc) = reshape(b%stress_global, [c * nc]); off = off + c * nc
            buf(off + 1:off + c * nc) = reshape(b%log_strain, [c * nc]); off = off + c * nc
            buf(off + 1:off + c * nd * nd) = reshape(b%f, [c * nd * nd]); off = off + c * nd * nd
            buf(off + 1:off + c) = b%vol0; off = off + c
            buf(off + 1:off + c) = b%mass; off = off + c
            buf(off + 1:off + c * nsv) = reshape(b%state, [c * nsv]); off = off + c * nsv
            buf(off + 1) = b%half
            call MPI_Send(buf, size(buf), MPI_DOUBLE_PRECISION, 0, 4, st%comm)
          end associate
       end do
       return
    end if
    all(1:st%nblocks) = st%blocks(1:st%nblocks)
    nall = st%nblocks
    do r = 1, st%nranks - 1
       call MPI_Recv(nb, 1, MPI_INTEGER, r, 1, st%comm, MPI_STATUS_IGNORE)
       do k = 1, nb(1)
          call MPI_Recv(head, 5, MPI_INTEGER, r, 2, st%comm, MPI_STATUS_IGNORE)
          c = head(1)
          nsv = head(3)
          nfv = head(4)
          if (nall == size(all)) call grow_list(all, nall)
          nall = nall + 1
          call block_allocate(all(nall), c, nd, nc, nsv, nfv, 1)
          all(nall)%material = head(2)
          call MPI_Recv(all(nall)%number, c, MPI_INTEGER, r, 3, st%comm, MPI_STATUS_IGNORE)
          nreal = c * (2 * nd + 2 * nc + nd * nd + 2 + nsv) + 1
          if (allocated(buf)) deallocate (buf)
          allocate (buf(nreal))
          call MPI_Recv(buf, nreal, MPI_DOUBLE_PRECISION, r, 4, st%comm, MPI_STATUS_IGNORE)
          off = 0
          all(nall)%x = reshape(buf(off + 1:off + c * nd), [c, nd]); off = off + c * nd
          all(nall)%v = reshape(buf(off + 1:off + c * nd), [c, nd]); off = off + c * nd
          all(nall)%stress_global = reshape(buf(off + 1:off + c * nc), [c, nc]); off = off + c * nc
          all(nall)%log_strain = reshape(buf(off + 1:off + c * nc), [c, nc]); off = off + c * nc
          all(nall)%f = reshape(buf(off + 1:off + c * nd * nd), [c, nd, nd]); off = off + c * nd * nd
          all(nall)%vol0 = buf(off + 1:off + c); off = off + c
          all(nall)%mass = buf(off + 1:off + c); off = off + c
          all(nall)%state = reshape(buf(off + 1:off + c * nsv), [c, nsv]); off = off + c * nsv
          all(nall)%half = buf(off + 1)
       end do
    end do
  end subroutine gather_blocks

  subroutine grow_list(list, n)
    type(particle_block_t), allocatable, intent(inout) :: list(:)
    integer, intent(in) :: n
    type(particle_block_t), allocatable :: grown(:)
    allocate (grown(2 * n + 16))
    grown(1:n) = list(1:n)
    call move_alloc(grown, list)
  end subroutine grow_list

  ! ------------------------------------------------------------------------------ set-up

  subroutine setup(m, st, fx)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(mpm_effects_t), intent(inout) :: fx
    integer :: k, s, nsv, nfv
    logical :: any_user_field

    associate (mpm => m%mpm)
      st%nd = mpm%ndim
      if (st%nd == 2) then
         st%nc = 4
         st%nshr = 1
      else
         st%nc = 6
         st%nshr = 3
      end if
      st%nsup = stencil_nodes_per_direction(mpm%shape)
      call grid_init(st%g, st%nd, mpm%lo, mpm%hi, mpm%cell)
      allocate (st%modulus(m%n_materials), st%needs_kinematics(m%n_materials))
      nsv = 1
      nfv = 1
      any_user_field = .false.
      do k = 1, m%n_materials
         st%modulus(k) = checked_packaging_modulus(m%materials(k), st%nc, st%nshr, m%input_file)
         st%needs_kinematics(k) = m%materials(k)%user_code .or. &
              model_from_name(m%materials(k)%vumat_name) == model_unknown
         nsv = max(nsv, m%materials(k)%nstatev)
         nfv = max(nfv, m%materials(k)%nfieldv)
         if (m%materials(k)%user_field) any_user_field = .true.
      end do
      st%work_statev = nsv
      st%work_fieldv = nfv
      call material_work_init(st, st%work(1), particle_block_size)
      allocate (st%blocks(16))
      st%nblocks = 0
      do k = 1, size(mpm%regions)
         call generate_region(m, st, mpm%regions(k))
      end do
      if (st%nblocks == 0) call raise_error(trim(m%input_file), 0, 'the *PARTICLES regions hold no ' // &
           'particle centre; expected regions at least one particle spacing (CELL/PPC) wide')
      st%mass_initial = 0
      do k = 1, st%nblocks
         st%mass_initial = st%mass_initial + sum(st%blocks(k)%mass)
      end do
      st%mass_cutoff = 1.0e-9_dp * maxval([(maxval(st%blocks(k)%mass), k = 1, st%nblocks)])
      st%n_initial = sum(st%blocks(1:st%nblocks)%count)
      ! every rank made all blocks (same order); each keeps every nranks-th one
      if (st%nranks > 1) then
         s = 0
         do k = 1, st%nblocks
            if (mod(k - 1, st%nranks) /= st%rank) cycle
            s = s + 1
            if (s /= k) st%blocks(s) = st%blocks(k)
         end do
         st%nblocks = s
      end if
      allocate (st%wall_nodes(size(mpm%walls)), st%wall_force(3, size(mpm%walls)))
      allocate (st%wall_impulse(3, size(mpm%walls)), st%wall_force_row(3, size(mpm%walls)))
      st%wall_force = 0
      st%wall_impulse = 0
      st%wall_force_row = 0
      allocate (st%mirror(size(mpm%walls)), st%mirrored(size(mpm%walls)))
      do k = 1, size(mpm%walls)
         call wall_find_nodes(mpm%walls(k), st%g, st%wall_nodes(k))
         call mirror_plane_setup(mpm%walls(k), st%g, st%mirror(k), st%mirrored(k))
         ! a mirrored plane is no wall to the grid: its nodes and images are damped as the full
         ! model's would be (the fold leaves them symmetric)
         if (st%mirrored(k)) st%wall_nodes(k)%nodes = [integer ::]
      end do

      fx%active = .false.
      fx%active([fx_p2g, fx_grid, fx_g2p, fx_kinematics, fx_material, fx_output]) = .true.
      fx%active(fx_user_field) = any_user_field
      fx%active(fx_walls) = size(mpm%walls) > 0
      fx%active(fx_outflow) = mpm%outflow
      do s = 1, m%n_steps
         if (mpm%steps(s)%inflow%on) fx%active(fx_inflow) = .true.
         if (mpm%steps(s)%damping > 0) fx%active(fx_damping) = .true.
         if (allocated(m%steps(s)%gravity)) then
            if (size(m%steps(s)%gravity) > 0) fx%active(fx_gravity) = .true.
         end if
      end do
      call timer_init(fx%timers)
      do k = 1, n_fx
         ! gravity and damping act inside the P2G/grid loops, VUSDFLD inside the material call:
         ! listed, not timed apart
         if (fx%active(k) .and. k /= fx_gravity .and. k /= fx_damping .and. k /= fx_user_field) &
              call timer_register(fx%timers, trim(fx_names(k)), fx%id(k))
      end do
    end associate
  end subroutine setup

  !> A regular lattice of ppc particles per cell and direction (aligned with the grid), kept
  !> where the particle centre lies in the region.
  subroutine generate_region(m, st, r)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(particle_region_t), intent(in) :: r
    real(dp) :: dx, x(3), lo(3)
    integer :: i0(3), i1(3), i, j, k, n, nd
    real(dp), allocatable :: pts(:, :)

    nd = st%nd
    dx = m%mpm%cell / r%ppc
    lo = m%mpm%lo
    i0 = 0
    i1 = 0
    do k = 1, nd
       i0(k) = floor((r%lo(k) - lo(k)) / dx)
       i1(k) = ceiling((r%hi(k) - lo(k)) / dx)
    end do
    allocate (pts(3, product(i1(1:nd) - i0(1:nd) + 1)))
    n = 0
    do k = i0(3), i1(3)
       do j = i0(2), i1(2)
          do i = i0(1), i1(1)
             x = lo + ([real(dp) :: i, j, k] + 0.5_dp) * dx
             if (nd == 2) x(3) = 0
             if (.not. inside(r, nd, x)) cycle
             n = n + 1
             pts(:, n) = x
          end do
       end do
    end do
    call add_particles(m, st, r%material, r%ppc, pts(:, 1:n), r%velocity)
  end subroutine generate_region

  logical function inside(r, nd, x)
    type(particle_region_t), intent(in) :: r
    integer, intent(in) :: nd
    real(dp), intent(in) :: x(3)
    integer :: i, j, nv

    if (r%kind == region_box) then
       inside = all(x(1:nd) >= r%lo(1:nd)) .and. all(x(1:nd) < r%hi(1:nd))
       return
    end if
    ! polygon (x, y) by ray casting; in 3D also the z range
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
  end function inside

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
    integer :: n, done, ib, first, add, p, nd

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
       end associate
       done = done + add
    end do
  end subroutine add_particles

  ! ------------------------------------------------------------------------------ increment

  subroutine stable_increment(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    real(dp) :: vmax, v1(1)
    integer :: ib

    vmax = 0
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         call block_max_speed(b%count, st%nd, st%modulus(b%material), b%mass, b%vol0, b%f, b%v, vmax)
       end associate
    end do
    v1(1) = vmax
    call max_real(st, v1)
    st%dt_stable = m%mpm%steps(st%step)%cfl * m%mpm%cell / max(v1(1), tiny(1.0_dp))
  end subroutine stable_increment

  !> vmax ← max(vmax, c_p + |v_p|) over the particles of a block, in order; c_p from the current
  !> density m/(V0 det F). Explicit-shape dummies, as the other per-block loops (on the block's
  !> allocatable components every access goes through the descriptor); the same expressions
  !> in the same order as the loop it replaces.
  pure subroutine block_max_speed(nb, nd, modulus, mass, vol0, f, v, vmax)
    integer, intent(in) :: nb, nd
    real(dp), intent(in) :: modulus, mass(nb), vol0(nb), f(nb, nd, nd), v(nb, nd)
    real(dp), intent(inout) :: vmax
    real(dp) :: speed, rho, detf
    integer :: p

    do p = 1, nb
       detf = det_f(f, p, nd)
       rho = mass(p) / (vol0(p) * detf)
       speed = sqrt(modulus / rho) + norm2(v(p, :))
       vmax = max(vmax, speed)
    end do
  end subroutine block_max_speed

  !> The nodes the active walls constrain: local damping leaves them alone, so that it does not
  !> change the reactions (the wall forces) of a body at rest.
  subroutine mark_wall_nodes(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer :: k

    if (.not. allocated(st%on_wall)) allocate (st%on_wall(st%g%nn))
    st%on_wall = .false.
    do k = 1, size(m%mpm%walls)
       if (m%mpm%walls(k)%active(st%step)) st%on_wall(st%wall_nodes(k)%nodes) = .true.
    end do
  end subroutine mark_wall_nodes

  !> det F of particle p (p2g's volume and block_max_speed's density use the one formula).
  pure real(dp) function det_f(f, p, nd)
    real(dp), intent(in) :: f(:, :, :)   !< a block's F, (count, nd, nd)
    integer, intent(in) :: p, nd
    if (nd == 2) then
       det_f = f(p, 1, 1) * f(p, 2, 2) - f(p, 1, 2) * f(p, 2, 1)
    else
       det_f = f(p, 1, 1) * (f(p, 2, 2) * f(p, 3, 3) - f(p, 2, 3) * f(p, 3, 2)) &
            - f(p, 1, 2) * (f(p, 2, 1) * f(p, 3, 3) - f(p, 2, 3) * f(p, 3, 1)) &
            + f(p, 1, 3) * (f(p, 2, 1) * f(p, 3, 2) - f(p, 2, 2) * f(p, 3, 1))
    end if
  end function det_f

  subroutine increment(m, st, fx)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(mpm_effects_t), intent(inout) :: fx
    integer :: ib, k, i, s
    real(dp) :: t_new

    s = st%step
    t_new = st%step_time + st%dt
    ! gravity of the step at the end of the increment (as the element driver takes loads; a
    ! load carried over from an earlier step keeps its value: model_time_variation)
    st%gravity = 0
    if (allocated(m%steps(s)%gravity)) then
       do k = 1, size(m%steps(s)%gravity)
          associate (gl => m%steps(s)%gravity(k))
            st%gravity = st%gravity + gl%magnitude * gl%direction * &
                 variation_factor(gl%variation, m%amplitudes, t_new, st%total_time + st%dt)
          end associate
       end do
    end if

    ! stencils and P2G
    call timer_start(fx%timers, fx%id(fx_p2g))
    call grid_reset_sums(st%g)
    do ib = 1, st%nblocks
       call stencil(m, st, st%blocks(ib))
       call p2g(st, st%blocks(ib))
    end do
    if (st%nranks > 1) call reduce_grid(st, .true.)
    st%g%mass_own = st%g%mass
    st%wall_force = 0
    do k = 1, size(m%mpm%walls)
       if (st%mirrored(k) .and. m%mpm%walls(k)%active(s)) &
            call mirror_fold(st%mirror(k), st%g, st%dt, st%wall_force(:, k))
    end do
    call timer_stop(fx%timers, fx%id(fx_p2g))

    ! grid update
    call timer_start(fx%timers, fx%id(fx_grid))
    call grid_update(m, st)
    call timer_stop(fx%timers, fx%id(fx_grid))
    if (fx%active(fx_walls)) then
       call timer_start(fx%timers, fx%id(fx_walls))
       do k = 1, size(m%mpm%walls)
          if (.not. m%mpm%walls(k)%active(s) .or. st%mirrored(k)) cycle
          call wall_project(m%mpm%walls(k), st%wall_nodes(k), st%nd, st%g%mass_own, st%g%active, st%g%v_new, &
               st%dt, st%wall_force(:, k), st%e_walls)
       end do
       st%wall_impulse = st%wall_impulse + st%dt * st%wall_force
       st%impulse_time = st%impulse_time + st%dt
       call timer_stop(fx%timers, fx%id(fx_walls))
    end if

    ! G2P and the MUSL remap
    call timer_start(fx%timers, fx%id(fx_g2p))
    call grid_clear(st%nd * st%g%nn, st%g%mom)
    do ib = 1, st%nblocks
       call g2p(m, st, st%blocks(ib))
    end do
    if (st%nranks > 1) call reduce_grid(st, .false.)
    do k = 1, size(m%mpm%walls)
       if (st%mirrored(k) .and. m%mpm%walls(k)%active(s)) call mirror_fold_momentum(st%mirror(k), st%g)
    end do
    ! Inactive nodes: v_new is still grid_update's zero (the walls project active nodes only).
    do i = 1, st%g%nn
       if (st%g%active(i)) st%g%v_new(:, i) = st%g%mom(:, i) / st%g%mass(i)
    end do
    call timer_stop(fx%timers, fx%id(fx_g2p))
    if (fx%active(fx_walls)) then
       call timer_start(fx%timers, fx%id(fx_walls))
       do k = 1, size(m%mpm%walls)
          if (.not. m%mpm%walls(k)%active(s) .or. st%mirrored(k)) cycle
          call wall_project(m%mpm%walls(k), st%wall_nodes(k), st%nd, st%g%mass, st%g%active, st%g%v_new, st%dt)
       end do
       call timer_stop(fx%timers, fx%id(fx_walls))
    end if

    ! stresses
    do ib = 1, st%nblocks
       call stress_update(m, st, fx, st%blocks(ib))
    end do

    if (fx%active(fx_walls)) then
       call timer_start(fx%timers, fx%id(fx_walls))
       call guard_particles(m, st)
       call timer_stop(fx%timers, fx%id(fx_walls))
    end if
    if (fx%active(fx_outflow)) then
       call timer_start(fx%timers, fx%id(fx_outflow))
       call outflow(m, st)
       call timer_stop(fx%timers, fx%id(fx_outflow))
    end if
    if (fx%active(fx_inflow)) then
       if (m%mpm%steps(s)%inflow%on) then
          call timer_start(fx%timers, fx%id(fx_inflow))
          call inflow(m, st, m%mpm%steps(s)%inflow)
          call timer_stop(fx%timers, fx%id(fx_inflow))
       end if
    end if
  end subroutine increment

  !> Sum the grid arrays over ranks: after P2G mass, momentum and force, after the remap momentum.
  subroutine reduce_grid(st, all_fields)
    type(mpm_state_t), intent(inout) :: st
    logical, intent(in) :: all_fields
    real(dp), allocatable :: buf(:)
    integer :: nn, nd

    nn = st%g%nn
    nd = st%nd
    if (all_fields) then
       allocate (buf(nn * (1 + 2 * nd)))
       buf(1:nn) = st%g%mass
       buf(nn + 1:nn + nd * nn) = reshape(st%g%mom, [nd * nn])
       buf(nn + nd * nn + 1:) = reshape(st%g%force, [nd * nn])
       call MPI_Allreduce(MPI_IN_PLACE, buf, size(buf), MPI_DOUBLE_PRECISION, MPI_SUM, st%comm)
       st%g%mass = buf(1:nn)
       st%g%mom = reshape(buf(nn + 1:nn + nd * nn), [nd, nn])
       st%g%force = reshape(buf(nn + nd * nn + 1:), [nd, nn])
    else
       call MPI_Allreduce(MPI_IN_PLACE, st%g%mom, nd * nn, MPI_DOUBLE_PRECISION, MPI_SUM, st%comm)
    end if
  end subroutine reduce_grid

  subroutine stencil(m, st, b)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), intent(inout) :: b
    integer :: outside
    character(len=160) :: text

    call block_stencil(b%count, st%nd, st%nsup, m%mpm%shape, st%g%lo, st%g%h, st%g%n, b%half, b%x, b%corner, &
         b%w1, b%dw1, outside)
    if (outside /= 0) then
       write (text, '(a,i0,a,3es12.4,a,es12.5)') 'particle ', b%number(outside), ' at ', b%x(outside, :), &
            ' left the background grid at t = ', st%total_time
       call raise_error(trim(m%input_file), 0, trim(text) // '; expected a *MPM GRID that covers the flow ' // &
            '(enlarge it, add walls or an *OUTFLOW)')
    end if
  end subroutine stencil

  !> Particle to grid: mass, momentum, internal and gravity forces. The particle factors
  !> (m v, V σ, m g) are formed first in block loops that vectorize; the scatter then does one
  !> multiply-add per value and node.
  subroutine p2g(st, b)
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), intent(in) :: b
    integer :: p, k, nd, nb
    real(dp) :: vol(b%count)
    real(dp) :: mv(b%count, st%nd), vs(b%count, st%nc), mg(b%count, st%nd)

    nd = st%nd
    nb = b%count
    ! column by column (particle index innermost): the row-wise form was a quarter of p2g
    do p = 1, nb
       vol(p) = b%vol0(p) * det_f(b%f, p, nd)
    end do
    do k = 1, st%nc
       vs(:, k) = vol * b%stress_global(:, k)
    end do
    do k = 1, nd
       mv(:, k) = b%mass * b%v(:, k)
       mg(:, k) = b%mass * st%gravity(k)
    end do
    call scatter_p2g(nb, st%nsup, nd, st%nc, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, b%dw1, &
         b%mass, mv, vs, mg, st%g%mass, st%g%mom, st%g%force)
  end subroutine p2g

  !> v_I^n = p_I/m_I; [local damping f ← f − a|f| sgn v]; v_I^{n+1} = v_I^n + Δt f_I/m_I.
  subroutine grid_update(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer :: i, k
    real(dp) :: a, f, dt, damp

    a = m%mpm%steps(st%step)%damping
    dt = st%dt
    ! Inactive nodes keep zero velocities: both arrays are cleared in one go first (per node,
    ! `v(:, i) = 0` was a memset call each, two for every inactive node).
    call grid_clear(st%nd * st%g%nn, st%g%v_old)
    call grid_clear(st%nd * st%g%nn, st%g%v_new)
    do i = 1, st%g%nn
       st%g%active(i) = st%g%mass(i) > st%mass_cutoff
       if (.not. st%g%active(i)) cycle
       do k = 1, st%nd
          st%g%v_old(k, i) = st%g%mom(k, i) / st%g%mass(i)
          f = st%g%force(k, i)
          if (a > 0 .and. abs(st%g%v_old(k, i)) > 0 .and. .not. st%on_wall(i)) then
             ! Cundall's local non-viscous damping: opposes the motion, proportional to |f|
             damp = a * abs(f)
             f = f - sign(damp, st%g%v_old(k, i))
             ! the real material's share of the node (image mass folded in: mpm_mirror)
             st%e_damping = st%e_damping + damp * abs(st%g%v_old(k, i)) * dt * st%g%mass_own(i) / st%g%mass(i)
          end if
          st%g%v_new(k, i) = st%g%v_old(k, i) + dt * f / st%g%mass(i)
       end do
    end do
  end subroutine grid_update

  !> Grid to particles: PIC/FLIP blend of the velocity, position from the new grid velocity;
  !> then (MUSL) the block's new momentum goes back to the grid (st%g%mom, zeroed by the caller)
  !> while its stencil is at hand.
  subroutine g2p(m, st, b)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), intent(inout) :: b
    integer :: p, k, nd, nb
    real(dp) :: alpha, vpic(b%count, st%nd), dv(b%count, st%nd), dt, wk

    nd = st%nd
    nb = b%count
    alpha = m%mpm%steps(st%step)%flip
    dt = st%dt
    call gather_velocity(nb, st%nsup, nd, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, st%g%v_new, &
         st%g%v_old, vpic, dv)
    wk = 0
    do k = 1, nd
       do p = 1, nb
          b%v(p, k) = alpha * (b%v(p, k) + dv(p, k)) + (1 - alpha) * vpic(p, k)
          b%x(p, k) = b%x(p, k) + dt * vpic(p, k)
          wk = wk + b%mass(p) * st%gravity(k) * dt * vpic(p, k)
          ! from here on dv holds the particle momentum for the remap
          dv(p, k) = b%mass(p) * b%v(p, k)
       end do
    end do
    st%w_external = st%w_external + wk
    call scatter_momentum(nb, st%nsup, nd, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, dv, st%g%mom)
  end subroutine g2p

  !> Velocity gradient from the remapped grid velocities, F, the corotational increments, and
  !> the material call on the block (the element blocks' door).
  subroutine stress_update(m, st, fx, b)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(mpm_effects_t), intent(inout) :: fx
    type(particle_block_t), intent(inout) :: b
    integer :: nb, nd, p, a, c, k, iw
    real(dp) :: dt
    real(dp) :: l(b%count, st%nd, st%nd), f_mid(b%count, st%nd, st%nd), f_new(b%count, st%nd, st%nd)
    real(dp) :: r_mid(b%count, st%nd, st%nd), r_new(b%count, st%nd, st%nd)
    real(dp) :: strain(b%count, st%nc), spin(b%count, st%nshr), strain_corot(b%count, st%nc)
    real(dp) :: rel_spin(b%count, st%nshr), density(b%count), char_length(b%count)

    call timer_start(fx%timers, fx%id(fx_kinematics))
    nb = b%count
    nd = st%nd
    dt = st%dt
    call gather_gradient(nb, st%nsup, nd, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, b%dw1, &
         st%g%v_new, l)
    ! F_{n+1} = (I + L Δt) F_n, F_{n+½} = (I + ½ L Δt) F_n
    f_new = b%f
    f_mid = b%f
    do c = 1, nd
       do a = 1, nd
          do k = 1, nd
             f_new(:, a, c) = f_new(:, a, c) + dt * l(:, a, k) * b%f(:, k, c)
             f_mid(:, a, c) = f_mid(:, a, c) + 0.5_dp * dt * l(:, a, k) * b%f(:, k, c)
          end do
       end do
    end do
    strain(:, 1) = dt * l(:, 1, 1)
    strain(:, 2) = dt * l(:, 2, 2)
    if (nd == 2) then
       strain(:, 3) = 0
       strain(:, 4) = 0.5_dp * dt * (l(:, 1, 2) + l(:, 2, 1))
       spin(:, 1) = 0.5_dp * dt * (l(:, 2, 1) - l(:, 1, 2))
    else
       strain(:, 3) = dt * l(:, 3, 3)
       strain(:, 4) = 0.5_dp * dt * (l(:, 1, 2) + l(:, 2, 1))
       strain(:, 5) = 0.5_dp * dt * (l(:, 2, 3) + l(:, 3, 2))
       strain(:, 6) = 0.5_dp * dt * (l(:, 3, 1) + l(:, 1, 3))
       spin(:, 1) = 0.5_dp * dt * (l(:, 3, 2) - l(:, 2, 3))
       spin(:, 2) = 0.5_dp * dt * (l(:, 1, 3) - l(:, 3, 1))
       spin(:, 3) = 0.5_dp * dt * (l(:, 2, 1) - l(:, 1, 2))
    end if
    call polar_rotation(nb, nd, f_mid, r_mid)
    call polar_rotation(nb, nd, f_new, r_new)
    call to_corotational(nb, nd, st%nc, r_mid, strain, strain_corot)
    call relative_spin(nb, nd, spin, b%rot, r_new, r_mid, rel_spin)
    ! the work set with exactly nb rows (material_work_init)
    iw = 1
    if (nb /= particle_block_size) then
       iw = 2
       if (.not. allocated(st%work(2)%temp)) then
          call material_work_init(st, st%work(2), nb)
       else if (size(st%work(2)%temp) /= nb) then
          call material_work_init(st, st%work(2), nb)
       end if
    end if
    if (st%needs_kinematics(b%material)) then
       call vumat_defgrad(nb, nd, b%f, st%work(iw)%defgrad_old)
       call vumat_defgrad(nb, nd, f_new, st%work(iw)%defgrad_new)
       call vumat_stretch(nb, nd, b%rot, b%f, st%work(iw)%stretch_old)
       call vumat_stretch(nb, nd, r_new, f_new, st%work(iw)%stretch_new)
       ! coordMp: the particle's position (the third column stays 0 in 2D)
       st%work(iw)%coord(1:nb, 1:nd) = b%x(1:nb, 1:nd)
    end if
    do p = 1, nb
       if (nd == 2) then
          density(p) = f_mid(p, 1, 1) * f_mid(p, 2, 2) - f_mid(p, 1, 2) * f_mid(p, 2, 1)
       else
          density(p) = f_mid(p, 1, 1) * (f_mid(p, 2, 2) * f_mid(p, 3, 3) - f_mid(p, 2, 3) * f_mid(p, 3, 2)) &
               - f_mid(p, 1, 2) * (f_mid(p, 2, 1) * f_mid(p, 3, 3) - f_mid(p, 2, 3) * f_mid(p, 3, 1)) &
               + f_mid(p, 1, 3) * (f_mid(p, 2, 1) * f_mid(p, 3, 2) - f_mid(p, 2, 2) * f_mid(p, 3, 1))
       end if
       if (.not. (density(p) > 0)) call inverted(m, st, b, p)
       density(p) = b%mass(p) / (b%vol0(p) * density(p))
    end do
    ! the particle size: CELL/PPC
    char_length = 2 * b%half
    call timer_stop(fx%timers, fx%id(fx_kinematics))

    call timer_start(fx%timers, fx%id(fx_material))
    call call_material(m%materials(b%material), nb, st%nc, st%nshr, b%number, st%step_time + dt, &
         st%total_time + dt, dt, char_length, density, strain_corot, rel_spin, st%work(iw)%stretch_old, &
         st%work(iw)%stretch_new, st%work(iw)%defgrad_old, st%work(iw)%defgrad_new, &
         b%log_strain, b%stress, b%state, b%field, b%e_int, b%e_inel, st%work(iw))
    call timer_stop(fx%timers, fx%id(fx_material))

    call timer_start(fx%timers, fx%id(fx_kinematics))
    ! LE: what vgetvrm hands the next VUSDFLD and what the output shows
    b%log_strain = b%log_strain + strain_corot
    b%f = f_new
    b%rot = r_new
    call to_global(nb, nd, st%nc, r_new, b%stress, b%stress_global)
    call timer_stop(fx%timers, fx%id(fx_kinematics))
  end subroutine stress_update

  !> A VUMAT work set of `rows` rows; U = F = I, which stay for the materials that do not read
  !> them (needs_kinematics false: stress_update does not write them).
  subroutine material_work_init(st, w, rows)
    type(mpm_state_t), intent(in) :: st
    type(vumat_work_t), intent(inout) :: w
    integer, intent(in) :: rows

    call vumat_work_init(w, rows, st%nc, st%nshr, st%work_statev, st%work_fieldv)
    w%point_kind = 'particle'
    w%stretch_old = 0
    w%stretch_old(:, 1:3) = 1
    w%defgrad_old = 0
    w%defgrad_old(:, 1:3) = 1
    w%stretch_new = w%stretch_old
    w%defgrad_new = w%defgrad_old
  end subroutine material_work_init

  subroutine inverted(m, st, b, p)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(in) :: st
    type(particle_block_t), intent(in) :: b
    integer, intent(in) :: p
    character(len=160) :: text

    write (text, '(a,i0,a,3es12.4,a,es12.5)') 'particle ', b%number(p), ' at ', b%x(p, :), &
         ' inverted (det F <= 0) at t = ', st%total_time
    call raise_error(trim(m%input_file), 0, trim(text) // '; expected a smaller CFL or a finer grid')
  end subroutine inverted

  !> Particles behind an active wall (within its extent) go back onto it, without their normal
  !> velocity into the wall.
  subroutine guard_particles(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer :: k, ib, p, nd, j, nrows, rows(particle_block_size)
    real(dp) :: x(3), d, n(3), dist(particle_block_size)

    nd = st%nd
    do k = 1, size(m%mpm%walls)
       associate (w => m%mpm%walls(k))
         if (.not. w%active(st%step)) cycle
         n = w%normal
         do ib = 1, st%nblocks
            associate (b => st%blocks(ib))
              ! the few particles behind the wall first, then each of them as before
              call wall_rows_behind(w, b%count, nd, b%x, dist, nrows, rows)
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

  !> Remove the particles below the outflow level; count their mass and energy. Blocks that
  !> become empty leave the list (the others keep their order).
  subroutine outflow(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    integer :: ib, p, nk, j
    integer, allocatable :: keep(:)
    real(dp) :: level

    level = m%mpm%outflow_level
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
    j = 0
    do ib = 1, st%nblocks
       if (st%blocks(ib)%count == 0) cycle
       j = j + 1
       if (j /= ib) st%blocks(j) = st%blocks(ib)
    end do
    st%nblocks = j
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
  !> rank wins a tie, so exactly one rank supplies it).
  subroutine global_tops(st, ncol, seen, top, vtop)
    type(mpm_state_t), intent(in) :: st
    integer, intent(in) :: ncol
    logical, intent(inout) :: seen(ncol)
    real(dp), intent(inout) :: top(ncol), vtop(3, ncol)
    real(dp) :: pair(2, ncol)
    integer :: c

    do c = 1, ncol
       pair(1, c) = -huge(1.0_dp)
       if (seen(c)) pair(1, c) = top(c)
       pair(2, c) = real(st%rank, dp)
    end do
    call MPI_Allreduce(MPI_IN_PLACE, pair, ncol, MPI_2DOUBLE_PRECISION, MPI_MAXLOC, st%comm)
    call MPI_Allreduce(MPI_IN_PLACE, seen, ncol, MPI_LOGICAL, MPI_LOR, st%comm)
    do c = 1, ncol
       if (nint(pair(2, c)) /= st%rank) vtop(:, c) = 0
       top(c) = pair(1, c)
    end do
    call MPI_Allreduce(MPI_IN_PLACE, vtop, 3 * ncol, MPI_DOUBLE_PRECISION, MPI_SUM, st%comm)
  end subroutine global_tops

  ! ------------------------------------------------------------------------------ output

  subroutine output_intervals(m, s, field_dt, history_dt)
    type(model_t), intent(in) :: m
    integer, intent(in) :: s
    real(dp), intent(out) :: field_dt, history_dt
    integer :: j

    field_dt = huge(1.0_dp)
    history_dt = m%steps(s)%period / 200
    if (allocated(m%steps(s)%field_outputs)) then
       do j = 1, size(m%steps(s)%field_outputs)
          associate (f => m%steps(s)%field_outputs(j))
            if (f%time_interval > 0) field_dt = min(field_dt, f%time_interval)
            if (f%number_interval > 0) field_dt = min(field_dt, m%steps(s)%period / f%number_interval)
          end associate
       end do
    end if
    if (allocated(m%steps(s)%history_outputs)) then
       if (size(m%steps(s)%history_outputs) > 0) history_dt = huge(1.0_dp)
       do j = 1, size(m%steps(s)%history_outputs)
          associate (h => m%steps(s)%history_outputs(j))
            if (h%time_interval > 0) then
               history_dt = min(history_dt, h%time_interval)
            else if (h%number_interval > 0) then
               history_dt = min(history_dt, m%steps(s)%period / h%number_interval)
            else
               history_dt = 0
            end if
          end associate
       end do
    end if
  end subroutine output_intervals

  subroutine history_columns(m, columns)
    type(model_t), intent(in) :: m
    character(len=32), allocatable, intent(out) :: columns(:)
    character(len=*), parameter :: fixed(*) = [character(len=32) :: 'time', 'step', 'step_time', 'increment', &
         'particles', 'MASS', 'MASS_IN', 'MASS_OUT', 'MDR', 'MASS_ERROR', 'ALLKE', 'ALLIE', 'ALLWK', 'ALLFD', &
         'ALLDMD', 'ETOTAL', 'XCM1', 'XCM2', 'XCM3', 'VCM1', 'VCM2', 'VCM3', 'YTOP', 'GUARDED']
    integer :: k, n, j

    n = size(m%mpm%walls)
    allocate (columns(size(fixed) + 3 * n))
    columns(1:size(fixed)) = fixed
    j = size(fixed)
    do k = 1, n
       columns(j + 1) = 'WALLF1_' // trim(m%mpm%walls(k)%name)
       columns(j + 2) = 'WALLF2_' // trim(m%mpm%walls(k)%name)
       columns(j + 3) = 'WALLF3_' // trim(m%mpm%walls(k)%name)
       j = j + 3
    end do
  end subroutine history_columns

  !> Kinetic and internal energy (global sums) of the particles.
  subroutine measure(st)
    type(mpm_state_t), intent(inout) :: st
    integer :: ib
    real(dp) :: e(2)
    st%e_kinetic = 0
    st%e_internal = 0
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         st%e_kinetic = st%e_kinetic + 0.5_dp * sum(b%mass * sum(b%v**2, dim=2))
         st%e_internal = st%e_internal + sum(b%mass * b%e_int)
       end associate
    end do
    e = [st%e_kinetic, st%e_internal]
    call sum_real(st, e)
    st%e_kinetic = e(1)
    st%e_internal = e(2)
  end subroutine measure

  !> One history row: global values (sums over ranks in rank order; collective).
  subroutine write_history(m, st, hist, last_time, last_out)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(history_t), intent(inout) :: hist
    real(dp), intent(inout) :: last_time, last_out
    real(dp), allocatable :: row(:)
    real(dp) :: g(12), top(1), mass, xcm(3), vcm(3), mdr, etotal, mass_out
    integer :: ib, k, j

    g = 0
    top = -huge(1.0_dp)
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         g(1) = g(1) + sum(b%mass)
         do k = 1, st%nd
            g(1 + k) = g(1 + k) + sum(b%mass * b%x(:, k))
            g(4 + k) = g(4 + k) + sum(b%mass * b%v(:, k))
         end do
         top(1) = max(top(1), maxval(b%x(:, 2)))
         g(8) = g(8) + b%count
       end associate
    end do
    g(9) = st%mass_out
    g(10) = st%w_external
    g(11) = st%e_out
    g(12) = st%n_guarded
    call sum_real(st, g)
    call max_real(st, top)
    mass = g(1)
    xcm = g(2:4) / mass
    vcm = g(5:7) / mass
    mass_out = g(9)
    mdr = 0
    if (st%total_time > last_time) mdr = (mass_out - last_out) / (st%total_time - last_time)
    etotal = st%e_kinetic + st%e_internal + st%e_walls + st%e_damping + g(11) - st%e_in - g(10)
    allocate (row(24 + 3 * size(m%mpm%walls)))
    row(1:24) = [st%total_time, real(st%step, dp), st%step_time, real(st%increment, dp), g(8), mass, &
         st%mass_in, mass_out, mdr, st%mass_initial + st%mass_in - mass_out - mass, st%e_kinetic, &
         st%e_internal, g(10), st%e_walls, st%e_damping, etotal, xcm, vcm, top(1), g(12)]
    j = 24
    do k = 1, size(m%mpm%walls)
       if (st%impulse_time > 0) then
          st%wall_force_row(:, k) = st%wall_impulse(:, k) / st%impulse_time
       else
          st%wall_force_row(:, k) = st%wall_force(:, k)
       end if
       row(j + 1:j + 3) = st%wall_force_row(:, k)
       j = j + 3
    end do
    if (allocated(st%wall_impulse)) st%wall_impulse = 0
    st%impulse_time = 0
    call history_row(hist, row)
    last_time = st%total_time
    last_out = mass_out
  end subroutine write_history

  subroutine header(m, st, fx, base)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(in) :: st
    type(mpm_effects_t), intent(in) :: fx
    character(len=*), intent(in) :: base
    character(len=:), allocatable :: list
    integer :: k

    list = ''
    do k = 1, n_fx
       if (.not. fx%active(k)) cycle
       if (len(list) > 0) list = list // ', '
       list = list // trim(fx_names(k))
    end do
    write (output_unit, '(a)') 'bulkflow: ' // trim(m%heading)
    write (output_unit, '(a,i0,a,i0,a,i0,a,es10.3,a,a,a,i0,a)') '  mpm       ', st%nd, 'D, ', &
         st%n_initial, ' particles, ', st%g%nn, ' grid nodes, cell ', m%mpm%cell, &
         ', shape ', trim(merge('uGIMP ', 'linear', st%nsup == 3)), ', ', st%nranks, ' rank(s)'
    write (output_unit, '(a)') '  effects   ' // list
    write (output_unit, '(a)') '  output    ' // base // '.h5/.xmf (particles), ' // base // '_grid.xmf, ' // &
         base // '_history.csv'
    flush (output_unit)
  end subroutine header

  subroutine summary(m, st, fx, stopped)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(mpm_effects_t), intent(in) :: fx
    logical, intent(in) :: stopped
    real(dp) :: g(8), rate
    integer :: ib, k

    call measure(st)
    g = 0
    do ib = 1, st%nblocks
       g(1) = g(1) + sum(st%blocks(ib)%mass)
       g(2) = g(2) + st%blocks(ib)%count
    end do
    g(3:8) = [st%mass_out, real(st%n_out, dp), st%w_external, real(st%n_guarded, dp), &
         real(st%particle_steps, dp), 0.0_dp]
    call sum_real(st, g)
    call timer_report(fx%timers, output_unit, st%comm)
    if (st%rank /= 0) return
    if (stopped) write (output_unit, '(a,i0,a)') 'bulkflow: stopped after increment ', st%increment, &
         ' as asked (--stop-after); continue with --restart'
    write (output_unit, '(a,i0,a,es12.5)') 'bulkflow: done, ', st%increment, ' increments, t = ', st%total_time
    write (output_unit, '(a,i0,a,i0,a,i0,a)') '  particles ', nint(g(2)), ' (', st%n_in, ' in, ', nint(g(4)), ' out)'
    write (output_unit, '(a,4es14.6,a,es10.2)') '  mass      initial, in, out, now:', st%mass_initial, st%mass_in, &
         g(3), g(1), '  balance error', st%mass_initial + st%mass_in - g(3) - g(1)
    write (output_unit, '(a,5es12.4)') '  energies  ALLKE ALLIE ALLWK ALLFD ALLDMD:', st%e_kinetic, st%e_internal, &
         g(5), st%e_walls, st%e_damping
    do k = 1, size(m%mpm%walls)
       write (output_unit, '(a,3es13.5)') '  wall ' // trim(m%mpm%walls(k)%name) // ' force:', st%wall_force_row(:, k)
    end do
    if (g(6) > 0) write (output_unit, '(a,i0)') '  particles put back onto walls: ', nint(g(6))
    rate = g(7) / max(st%loop_seconds, 1.0e-9_dp)
    write (output_unit, '(a,i0,a,es11.4,a,f10.3,a,i0,a,es11.4,a)') '  throughput ', nint(g(7), int64), &
         ' particle-steps, ', rate, ' per second (time loop ', st%loop_seconds, ' s, ', st%nranks, &
         ' ranks: ', rate / st%nranks, ' per rank)'
  end subroutine summary

  ! ------------------------------------------------------------------------------ checkpoint hooks

  !> Write a checkpoint of the run (mpm_checkpoint; collective). The loop's own variables (the
  !> step's output schedule, the MDR reference of the last history row) go with the state.
  subroutine save_checkpoint(m, st, base, wr, hist, next_field, next_history, last_row_time, last_row_out)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(in) :: st
    character(len=*), intent(in) :: base
    type(mpm_writer_t), intent(in) :: wr
    type(history_t), intent(in) :: hist
    real(dp), intent(in) :: next_field, next_history, last_row_time, last_row_out
    type(mpm_saved_t) :: sv

    sv%step = st%step
    sv%increment = st%increment
    sv%step_time = st%step_time
    sv%total_time = st%total_time
    sv%dt = st%dt
    sv%dt_stable = st%dt_stable
    sv%next_number = st%next_number
    sv%n_initial = st%n_initial
    sv%n_in = st%n_in
    sv%n_out = st%n_out
    sv%n_guarded = st%n_guarded
    sv%mass_initial = st%mass_initial
    sv%mass_in = st%mass_in
    sv%mass_out = st%mass_out
    sv%mass_cutoff = st%mass_cutoff
    sv%e_kinetic = st%e_kinetic
    sv%e_internal = st%e_internal
    sv%w_external = st%w_external
    sv%e_walls = st%e_walls
    sv%e_damping = st%e_damping
    sv%e_out = st%e_out
    sv%e_in = st%e_in
    sv%gravity = st%gravity
    sv%impulse_time = st%impulse_time
    sv%wall_force = st%wall_force
    sv%wall_impulse = st%wall_impulse
    sv%wall_force_row = st%wall_force_row
    sv%next_field = next_field
    sv%next_history = next_history
    sv%last_row_time = last_row_time
    sv%last_row_out = last_row_out
    sv%frames = 0
    if (st%rank == 0) sv%frames = mpm_writer_frame_count(wr)
    sv%rows = history_row_count(hist)
    call mpm_checkpoint_save(base, st%comm, m, st%blocks, st%nblocks, sv)
  end subroutine save_checkpoint

  !> Continue from the checkpoint of base: the set-up's particles are replaced by the
  !> checkpoint's, the outputs are reopened at it. A restart that cannot continue stops here on
  !> every rank with the reason (stop_agreed_error). particle_steps is not restored: the
  !> throughput report is this run's.
  subroutine resume(m, st, base, nsdv, columns, wr, hist, next_field, next_history, last_row_time, last_row_out)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    character(len=*), intent(in) :: base
    integer, intent(in) :: nsdv
    character(len=*), intent(in) :: columns(:)
    type(mpm_writer_t), intent(inout) :: wr
    type(history_t), intent(inout) :: hist
    real(dp), intent(out) :: next_field, next_history, last_row_time, last_row_out
    type(mpm_saved_t) :: sv
    type(error_t) :: err

    call mpm_checkpoint_load(base, st%comm, m, st%nd, st%nc, st%nsup, st%blocks, st%nblocks, sv, err)
    if (.not. err%raised) call mpm_restart_outputs(base, st%comm, st%g, st%nc, nsdv, columns, sv%frames, &
         sv%rows, wr, hist, err)
    if (err%raised) call stop_agreed_error(st%comm, err)
    st%step = sv%step
    st%increment = sv%increment
    st%step_time = sv%step_time
    st%total_time = sv%total_time
    st%dt = sv%dt
    st%dt_stable = sv%dt_stable
    st%next_number = sv%next_number
    st%n_initial = sv%n_initial
    st%n_in = sv%n_in
    st%n_out = sv%n_out
    st%n_guarded = sv%n_guarded
    st%mass_initial = sv%mass_initial
    st%mass_in = sv%mass_in
    st%mass_out = sv%mass_out
    st%mass_cutoff = sv%mass_cutoff
    st%e_kinetic = sv%e_kinetic
    st%e_internal = sv%e_internal
    st%w_external = sv%w_external
    st%e_walls = sv%e_walls
    st%e_damping = sv%e_damping
    st%e_out = sv%e_out
    st%e_in = sv%e_in
    st%gravity = sv%gravity
    st%impulse_time = sv%impulse_time
    st%wall_force = sv%wall_force
    st%wall_impulse = sv%wall_impulse
    st%wall_force_row = sv%wall_force_row
    next_field = sv%next_field
    next_history = sv%next_history
    last_row_time = sv%last_row_time
    last_row_out = sv%last_row_out
    if (st%rank == 0) then
       write (output_unit, '(a,i0,a,es12.5)') '  restart   from increment ', st%increment, ' at t = ', st%total_time
       flush (output_unit)
    end if
  end subroutine resume
end module mpm_run
