!> The explicit material-point solver (MUSL with a PIC/FLIP blend; docs/theory/mpm.md §4): the
!> time loop, one increment as a sequence of phases, the output schedule and the checkpoint
!> hooks. The phases live in modules of their own:
!>   set-up       grid, particles, walls, effects                                  (mpm_setup)
!>   transfer     Δt; stencils, P2G, grid update, walls, G2P, MUSL remap           (mpm_musl)
!>   stress       F, Green–Naghdi frame, VUSDFLD/VUMAT on the block                (mpm_stress_update)
!>   flow         particles behind walls put back, outflow, inflow                 (mpm_flow)
!>   report       header, history rows, frames, progress, summary                  (mpm_report)
!> and the state they share is mpm_state.
!> MPI: particle decomposition with a replicated grid. Every rank generates all particles and
!> keeps every nranks-th block; P2G sums (mass, momentum, forces) and the MUSL remap are summed
!> over ranks (one all-reduction each, src/parallel), so every rank holds the whole grid and
!> does the grid update and the walls itself; particles never migrate. Inflow particles are
!> made by rank 0. Sums over ranks are in rank order: results are deterministic for a given
!> number of ranks and differ from 1 rank by round-off only. Output: rank 0 gathers the blocks.
!> Checkpoint and restart: src/mpm/mpm_checkpoint.f90 (the hooks at the end of this module copy
!> the run state in and out).
module mpm_run
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use mpi_f08, only: MPI_Comm
  use base_kinds, only: dp
  use error_report, only: error_t
  use model, only: model_t
  use mpm_state, only: mpm_state_t, mpm_effects_t, fx_walls, fx_outflow, fx_inflow, fx_output
  use mpm_setup, only: mpm_setup_run, mark_wall_nodes
  use mpm_musl, only: stable_increment, step_gravity, musl_transfer
  use mpm_stress_update, only: stress_update
  use mpm_flow, only: guard_particles, outflow, inflow
  use mpm_report, only: header, summary, progress_line, history_columns, measure, write_history, write_frame
  use mpm_output, only: mpm_writer_t, mpm_writer_open, mpm_writer_close, mpm_writer_frame_count
  use mpm_checkpoint, only: mpm_saved_t, mpm_checkpoint_due, mpm_checkpoint_save, mpm_checkpoint_load, &
       mpm_restart_outputs
  use output_timer, only: timer_start, timer_stop
  use output_collective, only: stop_agreed_error
  use output_history, only: history_t, history_open, history_close, history_row_count
  use output_schedule, only: output_schedule_t, field_schedule, history_schedule, schedule_due, schedule_advance, &
       schedule_resume
  use parallel_comm, only: comm_rank, comm_size
  implicit none
  private

  !> The output schedules of the running step (output_schedule: the element driver's rule) and
  !> the MDR reference of the last history row.
  type :: schedule_t
     type(output_schedule_t) :: field, history
     real(dp) :: last_row_time = 0, last_row_out = 0
  end type schedule_t

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
    type(schedule_t) :: sch
    character(len=32), allocatable :: columns(:)
    real(dp) :: period, eps, sim_start
    integer :: s, k, nsdv, first_step
    integer(int64) :: clock_last, clock_now, clock_rate, clock_start
    logical :: stop_now, resumed

    st%comm = comm
    st%rank = comm_rank(comm)
    st%nranks = comm_size(comm)
    call mpm_setup_run(m, st, fx)
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
       call resume(m, st, base, nsdv, columns, wr, hist, sch)
       first_step = st%step
    else
       if (st%rank == 0) call mpm_writer_open(wr, base, st%g, st%nc, nsdv)
       call history_open(hist, base // '_history.csv', columns, comm)
       sch%last_row_time = 0
       sch%last_row_out = 0
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
       call field_schedule(m%steps(s), sch%field)
       call history_schedule(m%steps(s), sch%history)
       if (resumed) then
          call schedule_resume(sch%field, st%step_time)
          call schedule_resume(sch%history, st%step_time)
       else
          ! the step's first row and frame: its initial state
          st%step_increment = 0
          call increment_outputs(m, st, base, wr, hist, sch, .false.)
       end if
       resumed = .false.
       call mark_wall_nodes(m, st)
       do while (st%step_time < period - eps)
          call stable_increment(st, m%mpm%steps(st%step)%cfl, m%mpm%cell)
          st%dt = min(st%dt_stable, period - st%step_time)
          if (m%steps(s)%dt_fixed > 0) st%dt = min(m%steps(s)%dt_fixed, period - st%step_time)
          st%particle_steps = st%particle_steps + sum(st%blocks(1:st%nblocks)%count)
          call increment(m, st, fx)
          st%step_time = st%step_time + st%dt
          st%total_time = st%total_time + st%dt
          st%increment = st%increment + 1
          st%step_increment = st%step_increment + 1
          stop_now = stop_after > 0 .and. st%increment >= stop_after
          call timer_start(fx%timers, fx%id(fx_output))
          call increment_outputs(m, st, base, wr, hist, sch, stop_now)
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

  !> One increment: the transfer phase, the stress update of every block, then particles in
  !> and out.
  subroutine increment(m, st, fx)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(mpm_effects_t), intent(inout) :: fx
    integer :: ib, s

    s = st%step
    call step_gravity(m, st)
    call musl_transfer(m, st, fx)
    do ib = 1, st%nblocks
       call stress_update(m, st, fx, st%blocks(ib))
    end do
    if (fx%active(fx_walls)) then
       call timer_start(fx%timers, fx%id(fx_walls))
       call guard_particles(m%mpm%walls, st)
       call timer_stop(fx%timers, fx%id(fx_walls))
    end if
    if (fx%active(fx_outflow)) then
       call timer_start(fx%timers, fx%id(fx_outflow))
       call outflow(st, m%mpm%outflow_level)
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

  !> The history row and frame due after an increment (or at the step's start, step_increment
  !> 0), the checkpoint, and the extra row and frame of a --stop-after stop.
  subroutine increment_outputs(m, st, base, wr, hist, sch, stop_now)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    character(len=*), intent(in) :: base
    type(mpm_writer_t), intent(inout) :: wr
    type(history_t), intent(inout) :: hist
    type(schedule_t), intent(inout) :: sch
    logical, intent(in) :: stop_now
    logical :: history_due, field_due

    history_due = schedule_due(sch%history, st%step_time, st%step_increment, st%dt)
    field_due = schedule_due(sch%field, st%step_time, st%step_increment, st%dt)
    if (history_due) then
       call measure(st)
       call write_history(m, st, hist, sch%last_row_time, sch%last_row_out)
       call schedule_advance(sch%history, st%step_time)
    end if
    if (field_due) then
       call write_frame(st, wr, st%step, st%step_time)
       call schedule_advance(sch%field, st%step_time)
    end if
    if (st%step_increment == 0) return
    ! The checkpoint (timed as output) follows the increment's own output and precedes the
    ! extra row and frame of a stop: the uninterrupted run has none there, so a restart
    ! drops them (it keeps the frames and rows the checkpoint counted).
    if (stop_now .or. mpm_checkpoint_due(m, st%step, st%step_time, st%dt)) &
         call save_checkpoint(m, st, base, wr, hist, sch)
    if (stop_now .and. .not. history_due) then
       call measure(st)
       call write_history(m, st, hist, sch%last_row_time, sch%last_row_out)
    end if
    if (stop_now .and. .not. field_due) call write_frame(st, wr, st%step, st%step_time)
  end subroutine increment_outputs

  ! ------------------------------------------------------------------------------ checkpoint hooks

  !> Write a checkpoint of the run (mpm_checkpoint; collective). The loop's own variables (the
  !> step's output schedule, the MDR reference of the last history row) go with the state.
  subroutine save_checkpoint(m, st, base, wr, hist, sch)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(in) :: st
    character(len=*), intent(in) :: base
    type(mpm_writer_t), intent(in) :: wr
    type(history_t), intent(in) :: hist
    type(schedule_t), intent(in) :: sch
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
    sv%rigid_u = st%rigid_u
    sv%step_increment = st%step_increment
    sv%last_row_time = sch%last_row_time
    sv%last_row_out = sch%last_row_out
    sv%frames = 0
    if (st%rank == 0) sv%frames = mpm_writer_frame_count(wr)
    sv%rows = history_row_count(hist)
    call mpm_checkpoint_save(base, st%comm, m, st%blocks, st%nblocks, sv)
  end subroutine save_checkpoint

  !> Continue from the checkpoint of base: the set-up's particles are replaced by the
  !> checkpoint's, the outputs are reopened at it. A restart that cannot continue stops here on
  !> every rank with the reason (stop_agreed_error). particle_steps is not restored: the
  !> throughput report is this run's.
  subroutine resume(m, st, base, nsdv, columns, wr, hist, sch)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    character(len=*), intent(in) :: base
    integer, intent(in) :: nsdv
    character(len=*), intent(in) :: columns(:)
    type(mpm_writer_t), intent(inout) :: wr
    type(history_t), intent(inout) :: hist
    type(schedule_t), intent(inout) :: sch
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
    st%rigid_u = sv%rigid_u
    st%step_increment = sv%step_increment
    sch%last_row_time = sv%last_row_time
    sch%last_row_out = sv%last_row_out
    if (st%rank == 0) then
       write (output_unit, '(a,i0,a,es12.5)') '  restart   from increment ', st%increment, ' at t = ', st%total_time
       flush (output_unit)
    end if
  end subroutine resume
end module mpm_run
