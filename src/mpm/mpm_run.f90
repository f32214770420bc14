!> The explicit material-point solver's increment (MUSL with a PIC/FLIP blend;
!> docs/theory/mpm.md §4) as a sequence of phases, and the checkpoint hooks that copy the run
!> state in and out. The step loop, the output schedule, the progress line and the calls of
!> these hooks are the run skeleton's (src/run: run_loop drives mpm_technique_t of run_mpm).
!> The phases live in modules of their own:
!>   set-up       grid, particles, walls, effects                                  (mpm_setup)
!>   transfer     Δt; stencils, P2G, grid update, walls, G2P, MUSL remap           (mpm_musl)
!>   stress       F, Green–Naghdi frame, VUSDFLD/VUMAT on the block                (mpm_stress_update)
!>                with *NONLOCAL: VUSDFLD on all blocks, the average, then the VUMAT (mpm_nonlocal)
!>   flow         particles behind walls put back, outflow, inflow                 (mpm_flow)
!>   report       header, history rows, frames, summary                            (mpm_report)
!> and the state they share is mpm_state.
!> MPI: particle decomposition with a replicated grid. Every rank generates all particles and
!> keeps every nranks-th block; P2G sums (mass, momentum, forces) and the MUSL remap are summed
!> over ranks (one all-reduction each, src/parallel), so every rank holds the whole grid and
!> does the grid update and the walls itself; particles never migrate. Inflow particles are
!> made by rank 0. Sums over ranks are in rank order: results are deterministic for a given
!> number of ranks and differ from 1 rank by round-off only. Output: every rank writes its own blocks.
!> With *MPM CONTROLS, DECOMPOSITION=SPATIAL the grid is decomposed instead (mpm_domain: boxes,
!> halo sums in mpm_halo, particle migration and re-partition at the increment's end in mpm_migrate).
!> Checkpoint and restart: src/mpm/mpm_checkpoint.f90.
module mpm_run
  use base_kinds, only: dp
  use error_report, only: error_t
  use model, only: model_t
  use mpm_state, only: mpm_state_t, fx_walls, fx_outflow, fx_inflow, fx_migration, fx_nonlocal
  use mpm_musl, only: step_gravity, musl_transfer
  use mpm_stress_update, only: stress_update
  use mpm_nonlocal, only: nonlocal_stress_update
  use mpm_flow, only: guard_particles, outflow, inflow
  use mpm_migrate, only: domain_increment_end
  use mpm_domain, only: domain_build
  use mpm_halo, only: domain_regrid, whole_grid_shape
  use mpm_setup, only: setup_walls, mark_wall_nodes
  use mpm_output, only: mpm_writer_t, mpm_writer_frame_count, mpm_field_request_t
  use mpm_checkpoint, only: mpm_saved_t, mpm_checkpoint_save, mpm_checkpoint_load, mpm_restart_outputs
  use output_effects, only: effects_t
  use output_collective, only: stop_agreed_error
  use output_history, only: history_t, history_row_count
  implicit none
  private

  public :: mpm_increment, mpm_save, mpm_resume

contains

  !> One increment: the transfer phase, the stress update of every block, then particles in
  !> and out.
  subroutine mpm_increment(m, st, fx)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(effects_t), intent(inout) :: fx
    integer :: ib, s
    logical :: regridded

    s = st%step
    call step_gravity(m, st)
    call musl_transfer(m, st, fx)
    if (fx%active(fx_nonlocal)) then
       call nonlocal_stress_update(m, st, fx)
    else
       do ib = 1, st%nblocks
          call stress_update(m, st, fx, st%blocks(ib))
       end do
    end if
    if (fx%active(fx_walls)) then
       call fx%start(fx_walls)
       call guard_particles(m%mpm%walls, st)
       call fx%stop(fx_walls)
    end if
    if (fx%active(fx_outflow)) then
       call fx%start(fx_outflow)
       call outflow(st, m%mpm%outflow_level)
       call fx%stop(fx_outflow)
    end if
    if (fx%active(fx_inflow)) then
       if (m%mpm%steps(s)%inflow%on) then
          call fx%start(fx_inflow)
          call inflow(m, st, m%mpm%steps(s)%inflow)
          call fx%stop(fx_inflow)
       end if
    end if
    ! spatial decomposition: particles to the rank of their new position, re-partition if due
    if (st%dom%on) then
       call fx%start(fx_migration)
       call domain_increment_end(m, st, regridded)
       call fx%stop(fx_migration)
       if (regridded) then
          call setup_walls(m, st)
          call mark_wall_nodes(m, st)
       end if
    end if
  end subroutine mpm_increment

  ! ------------------------------------------------------------------------------ checkpoint hooks

  !> Write a checkpoint of the run (mpm_checkpoint; collective). The MDR reference of the last
  !> history row goes with the state (the step's output schedule is rebuilt from the step time).
  subroutine mpm_save(m, st, base, wr, hist, last_row_time, last_row_out)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(in) :: st
    character(len=*), intent(in) :: base
    type(mpm_writer_t), intent(in) :: wr
    type(history_t), intent(in) :: hist
    real(dp), intent(in) :: last_row_time, last_row_out
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
    sv%last_row_time = last_row_time
    sv%last_row_out = last_row_out
    sv%frames = 0
    if (st%rank == 0) sv%frames = mpm_writer_frame_count(wr)
    sv%rows = history_row_count(hist)
    if (st%dom%on) allocate (sv%domain(1 + 6 * st%nranks), source=[st%dom%rebalances, &
         reshape(st%dom%box, [6 * st%nranks])])
    allocate (sv%grid_mass(size(st%g%mass)), source=st%g%mass)
    allocate (sv%grid_v(size(st%g%v_new, 1), size(st%g%v_new, 2)), source=st%g%v_new)
    call mpm_checkpoint_save(base, st%comm, m, st%blocks, st%nblocks, sv)
  end subroutine mpm_save

  !> Continue from the checkpoint of base: the set-up's particles are replaced by the
  !> checkpoint's, the outputs are reopened at it (the run skeleton says where it continues). A restart that cannot continue stops here on
  !> every rank with the reason (stop_agreed_error). particle_steps is not restored: the
  !> throughput report is this run's.
  subroutine mpm_resume(m, st, base, fields, columns, wr, hist, last_row_time, last_row_out)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    character(len=*), intent(in) :: base
    type(mpm_field_request_t), intent(in) :: fields
    character(len=*), intent(in) :: columns(:)
    type(mpm_writer_t), intent(inout) :: wr
    type(history_t), intent(inout) :: hist
    real(dp), intent(out) :: last_row_time, last_row_out
    type(mpm_saved_t) :: sv
    type(error_t) :: err

    call mpm_checkpoint_load(base, st%comm, m, st%nd, st%nc, st%nsup, st%blocks, st%nblocks, sv, err)
    if (.not. err%raised) then
       if (st%dom%on) then
          call mpm_restart_outputs(base, st%comm, whole_grid_shape(st), st%nc, fields, columns, sv%frames, &
               sv%rows, wr, hist, err)
       else
          call mpm_restart_outputs(base, st%comm, st%g, st%nc, fields, columns, sv%frames, sv%rows, wr, hist, err)
       end if
    end if
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
    last_row_time = sv%last_row_time
    last_row_out = sv%last_row_out
    ! the boxes the checkpointed particles were in (a re-partition may have moved them)
    if (st%dom%on) then
       st%dom%rebalances = sv%domain(1)
       call domain_build(st%dom, reshape(sv%domain(2:), [2, 3, st%nranks]))
       call domain_regrid(st)
       call setup_walls(m, st)
       call mark_wall_nodes(m, st)
    end if
    ! the last increment's grid, which a frame at the next step's start shows
    if (size(sv%grid_mass) == size(st%g%mass) .and. size(sv%grid_v) == size(st%g%v_new)) then
       st%g%mass = sv%grid_mass
       st%g%v_new = sv%grid_v
    end if
  end subroutine mpm_resume
end module mpm_run
