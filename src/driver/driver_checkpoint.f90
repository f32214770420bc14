!> Checkpoint and restart of the solver state: everything that changes during a run and is not
!> rebuilt identically from the model by the set-up (nodal motion, element state, rigid bodies,
!> energies, time, output counters). A restarted run continues bit for bit as the uninterrupted
!> one would have. One file per rank (output_checkpoint), so a restart needs the same number of
!> ranks. The checkpoint also holds the scene's digest (model_digest): a restart of an edited
!> scene is refused at the first line that differs.
!>
!> Every failure of a restart (no checkpoint, another rank count, an edited scene, a file that
!> does not match) is found alike on every rank (output_checkpoint agrees its errors) and comes
!> back in err with what was expected; the caller ends the run cleanly (stop_agreed_error).
module driver_checkpoint
  use base_kinds, only: dp
  use error_report, only: error_t
  use model, only: model_t
  use checkpoint_scene, only: put_scene_digest, check_saved_scene
  use output_checkpoint, only: checkpoint_t, checkpoint_header_t, checkpoint_begin_write, checkpoint_put, &
       checkpoint_end_write, restart_begin_read, checkpoint_get, checkpoint_end_read
  use output_hdf5, only: field_writer_frame_count
  use output_history, only: history_row_count
  use driver_solver, only: solver_t, element_block_t
  use driver_output, only: run_output_t
  implicit none
  private

  public :: save_checkpoint, load_checkpoint

contains

  subroutine save_checkpoint(m, base, solver, out)
    type(model_t), intent(in) :: m
    character(len=*), intent(in) :: base
    type(solver_t), intent(in) :: solver
    type(run_output_t), intent(in) :: out
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: header
    integer :: ib
    character(len=16) :: tag

    header%step = solver%step
    header%increment = solver%increment
    header%step_time = solver%step_time
    header%total_time = solver%total_time
    header%dt = solver%dt
    header%frame_count = 0
    if (out%fields_open) header%frame_count = field_writer_frame_count(out%fields)
    header%history_rows = history_row_count(out%history)
    call checkpoint_begin_write(ck, base, solver%part%comm, header)
    ! The scene first: a restart of another scene must say so, not fail on an array's shape.
    call put_scene_digest(ck, m%digest)
    call checkpoint_put(ck, 'u', solver%u)
    call checkpoint_put(ck, 'v', solver%v)
    call checkpoint_put(ck, 'a', solver%a)
    call checkpoint_put(ck, 'f_int', solver%f_int)
    call checkpoint_put(ck, 'f_ext', solver%f_ext)
    call checkpoint_put(ck, 'reaction', solver%reaction)
    ! the walls' forces of this increment: a step's first history row reports them
    call checkpoint_put(ck, 'wall_force', solver%wall_force)
    call checkpoint_put(ck, 'rigid_u', rigid_array(solver, .true.))
    call checkpoint_put(ck, 'rigid_v', rigid_array(solver, .false.))
    call checkpoint_put(ck, 'scalars', [solver%e_viscous, solver%e_artificial, solver%e_friction, &
         solver%e_external, solver%step_start, solver%dt_prev, solver%dt_stable, out%energy_reference, &
         out%energy_peak])
    call checkpoint_put(ck, 'counters', [solver%step_increment, solver%dt_element])
    ! Mass scaling and the step stop condition (driver_mass_scaling, driver_stop_condition).
    call checkpoint_put(ck, 'mass', solver%mass)
    if (allocated(solver%u_step_start)) then
       call checkpoint_put(ck, 'u_step_start', solver%u_step_start)
    else
       call checkpoint_put(ck, 'u_step_start', solver%u)
    end if
    call checkpoint_put(ck, 'stop_scalars', [solver%stop_umax, solver%stop_ke, solver%stop_ke_peak, &
         solver%stop_quiet_since, solver%stop_window_start, solver%stop_window_umax])
    call checkpoint_put(ck, 'stop_outcome', solver%stop_outcome)
    do ib = 1, solver%n_blocks
       write (tag, '(a,i0,a)') 'b', ib, '_'
       associate (b => solver%blocks(ib))
         call checkpoint_put(ck, trim(tag) // 'rotation', b%rotation)
         call checkpoint_put(ck, trim(tag) // 'hourglass', b%hourglass)
         call checkpoint_put(ck, trim(tag) // 'stress', b%stress)
         call checkpoint_put(ck, trim(tag) // 'state', b%state)
         call checkpoint_put(ck, trim(tag) // 'field', b%field)
         call checkpoint_put(ck, trim(tag) // 'e_int', b%e_int)
         call checkpoint_put(ck, trim(tag) // 'e_inel', b%e_inel)
         call checkpoint_put(ck, trim(tag) // 'log_strain', b%log_strain)
         call checkpoint_put(ck, trim(tag) // 'plastic_strain', b%plastic_strain)
         call checkpoint_put(ck, trim(tag) // 'sigma_bv', b%sigma_bv)
         call checkpoint_put(ck, trim(tag) // 'force_hg', b%force_hg)
         call checkpoint_put(ck, trim(tag) // 'mass_scale', block_mass_scale(b))
       end associate
    end do
    call checkpoint_end_write(ck)
  end subroutine save_checkpoint

  !> Read the state back into a freshly set-up solver. Returns the step to continue in and the
  !> output counters (frames, history rows) the output files are truncated to.
  !> On failure err says why and what was expected, alike on every rank, and the solver state
  !> is incomplete (the run must stop).
  subroutine load_checkpoint(m, base, solver, step, frames, rows, err)
    type(model_t), intent(in) :: m
    character(len=*), intent(in) :: base
    type(solver_t), intent(inout) :: solver
    integer, intent(out) :: step, frames, rows
    type(error_t), intent(inout) :: err
    type(checkpoint_t) :: ck
    type(checkpoint_header_t) :: header
    real(dp) :: scalars(9)
    real(dp), allocatable :: rigid_u(:, :), rigid_v(:, :)
    integer :: counters(2), ib, i
    real(dp) :: stop_scalars(6)
    character(len=16) :: tag

    step = 0
    frames = 0
    rows = 0
    ! after a failed read the rest of the reads do nothing: these keep their values defined
    scalars = 0
    stop_scalars = 0
    counters = 0
    call restart_begin_read(ck, base, solver%part%comm, header, err)
    if (err%raised) return
    call check_saved_scene(ck, m%digest, err)
    if (err%raised) return
    solver%step = header%step
    solver%increment = header%increment
    solver%step_time = header%step_time
    solver%total_time = header%total_time
    solver%dt = header%dt
    step = header%step
    frames = header%frame_count
    rows = header%history_rows
    call checkpoint_get(ck, 'u', solver%u, err)
    call checkpoint_get(ck, 'v', solver%v, err)
    call checkpoint_get(ck, 'a', solver%a, err)
    call checkpoint_get(ck, 'f_int', solver%f_int, err)
    call checkpoint_get(ck, 'f_ext', solver%f_ext, err)
    call checkpoint_get(ck, 'reaction', solver%reaction, err)
    call checkpoint_get(ck, 'wall_force', solver%wall_force, err)
    allocate(rigid_u(3, size(solver%rigid)), rigid_v(3, size(solver%rigid)))
    call checkpoint_get(ck, 'rigid_u', rigid_u, err)
    call checkpoint_get(ck, 'rigid_v', rigid_v, err)
    do i = 1, size(solver%rigid)
       solver%rigid(i)%u = rigid_u(:, i)
       solver%rigid(i)%v = rigid_v(:, i)
    end do
    call checkpoint_get(ck, 'scalars', scalars, err)
    solver%e_viscous = scalars(1)
    solver%e_artificial = scalars(2)
    solver%e_friction = scalars(3)
    solver%e_external = scalars(4)
    solver%step_start = scalars(5)
    solver%dt_prev = scalars(6)
    solver%dt_stable = scalars(7)
    call checkpoint_get(ck, 'counters', counters, err)
    solver%step_increment = counters(1)
    solver%dt_element = counters(2)
    call checkpoint_get(ck, 'mass', solver%mass, err)
    if (.not. allocated(solver%u_step_start)) allocate(solver%u_step_start, mold=solver%u)
    call checkpoint_get(ck, 'u_step_start', solver%u_step_start, err)
    call checkpoint_get(ck, 'stop_scalars', stop_scalars, err)
    solver%stop_umax = stop_scalars(1)
    solver%stop_ke = stop_scalars(2)
    solver%stop_ke_peak = stop_scalars(3)
    solver%stop_quiet_since = stop_scalars(4)
    solver%stop_window_start = stop_scalars(5)
    solver%stop_window_umax = stop_scalars(6)
    call checkpoint_get(ck, 'stop_outcome', solver%stop_outcome, err)
    do ib = 1, solver%n_blocks
       write (tag, '(a,i0,a)') 'b', ib, '_'
       associate (b => solver%blocks(ib))
         call checkpoint_get(ck, trim(tag) // 'rotation', b%rotation, err)
         call checkpoint_get(ck, trim(tag) // 'hourglass', b%hourglass, err)
         call checkpoint_get(ck, trim(tag) // 'stress', b%stress, err)
         call checkpoint_get(ck, trim(tag) // 'state', b%state, err)
         call checkpoint_get(ck, trim(tag) // 'field', b%field, err)
         call checkpoint_get(ck, trim(tag) // 'e_int', b%e_int, err)
         call checkpoint_get(ck, trim(tag) // 'e_inel', b%e_inel, err)
         call checkpoint_get(ck, trim(tag) // 'log_strain', b%log_strain, err)
         call checkpoint_get(ck, trim(tag) // 'plastic_strain', b%plastic_strain, err)
         call checkpoint_get(ck, trim(tag) // 'sigma_bv', b%sigma_bv, err)
         call checkpoint_get(ck, trim(tag) // 'force_hg', b%force_hg, err)
         if (.not. allocated(b%mass_scale)) allocate(b%mass_scale(b%count))
         call checkpoint_get(ck, trim(tag) // 'mass_scale', b%mass_scale, err)
         if (.not. err%raised) b%mass_scaled = maxval(abs(b%mass_scale - 1)) > 0
       end associate
    end do
    call checkpoint_end_read(ck, err)
    if (err%raised) return
    ! (the output schedule is rebuilt from the step time and increment: output_schedule)
    solver%restart_energy_reference = scalars(8)
    solver%restart_energy_peak = scalars(9)
  end subroutine load_checkpoint

  !> The digest's hashes as pairs of 32-bit words (the checkpoint stores 32-bit integers).

  !> The block's mass-scaling factors (ones before any scaling).
  function block_mass_scale(b) result(values)
    type(element_block_t), intent(in) :: b
    real(dp) :: values(b%count)

    values = 1
    if (allocated(b%mass_scale)) values = b%mass_scale
  end function block_mass_scale

  function rigid_array(solver, displacement) result(values)
    type(solver_t), intent(in) :: solver
    logical, intent(in) :: displacement
    real(dp) :: values(3, size(solver%rigid))
    integer :: i

    do i = 1, size(solver%rigid)
       values(:, i) = merge(solver%rigid(i)%u, solver%rigid(i)%v, displacement)
    end do
  end function rigid_array
end module driver_checkpoint
