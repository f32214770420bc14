!> The explicit time integration of a whole scene: steps in sequence, each increment as the named
!> phases of the central-difference scheme (docs/solver_interfaces.md §0), with output,
!> progress, checkpoints and restart. The increment reads like a table of contents; each phase
!> lives in its own module.
module driver_run
  use, intrinsic :: iso_fortran_env, only: output_unit
  use mpi_f08, only: MPI_Comm
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use model, only: model_t
  use model_mesh, only: element_cpe4r, element_cax4r
  use parallel_partition, only: partition_t, partition_model
  use parallel_assembly, only: global_min, global_sum
  use driver_solver, only: solver_t
  use driver_effects, only: effects_t, effect_gravity, effect_pressure, effect_rigid_walls, effect_boundary, &
       effect_assembly, effect_output, effect_checkpoint, effect_user_field
  use driver_setup, only: setup_solver, initial_internal_forces
  use driver_elements, only: element_workspace_t, element_workspace_init, element_phase
  use driver_loads, only: step_loads_t, prepare_step, apply_prescribed_velocities, &
       apply_rigid_body_velocities, gravity_forces, apply_contact, gravity_varies_in_step
  use driver_output, only: run_output_t, open_run_output, close_run_output, step_output_start, &
       write_frame, write_history, energy_values, progress_line, sum_over_ranks, next_time_point
  use driver_checkpoint, only: save_checkpoint, load_checkpoint
  use driver_mass_scaling, only: apply_step_mass_scaling
  use driver_pressure, only: step_pressures_t, prepare_pressures, add_pressure_forces
  use driver_finite, only: energies_finite, stop_non_finite, non_finite_flag
  use driver_stop_condition, only: stop_step_start, check_stop_condition, report_stop_condition
  use fem_cpe4r, only: cpe4r_char_length
  use fem_cax4r, only: cax4r_char_length
  use fem_c3d8r, only: c3d8r_char_length
  use fem_stable_dt, only: element_stable_dt
  use output_timer, only: timer_report
  use output_schedule, only: schedule_due, schedule_advance
  use output_collective, only: stop_agreed_error
  implicit none
  private

  !> Nodes per chunk of finish_nodes_2d: its arrays, 1024 nodes × 10 values, stay in L2.
  integer, parameter :: node_chunk = 1024

  type, public :: run_options_t
     character(len=:), allocatable :: output_base     !< path of the outputs without extension
     logical :: restart = .false.                     !< continue from the checkpoint
     integer :: stop_after = 0                        !< > 0: stop after this increment (tests)
     logical :: progress = .true.
  end type run_options_t

  !> Margin on the element estimate L_e/c_d. Our L_e (area/longest edge, volume/largest face)
  !> equals the exact limit for regular meshes of many elements, but measured critical
  !> increments of free 2x2 and 2x2x2 blocks are 0.97 and 0.94 L_e/c_d (ν = 0.3), before the
  !> bulk-viscosity correction; 0.9 keeps every mesh we tried stable at SCALE FACTOR = 1.
  !> Lone free elements are stiffer still (0.84 / 0.73): scenes with them need SCALE FACTOR.
  real(dp), parameter :: stable_dt_safety = 0.9_dp

  !> A *STOP CONDITION is evaluated every this many increments of its step (and at the step
  !> end): its exact global sum costs about a tenth of an increment of a small 2D model.
  integer, parameter :: stop_check_stride = 10

  public :: run_scene

contains

  subroutine run_scene(m, comm, opts)
    type(model_t), intent(in) :: m
    type(MPI_Comm), intent(in) :: comm
    type(run_options_t), intent(in) :: opts
    type(partition_t) :: part
    type(solver_t) :: solver
    type(effects_t) :: effects
    type(element_workspace_t) :: ew
    type(step_loads_t) :: loads
    type(step_pressures_t) :: pressures
    type(run_output_t) :: out
    integer :: istep, first_step, max_state, max_field, i, frames, rows
    real(dp) :: dt_min, energies(6)
    logical :: resumed, stop_now, condition_met
    real(dp) :: period
    type(error_t) :: err

    call partition_model(m, comm, part)
    call effects%decide(m)
    call setup_solver(m, part, solver, effects%active(effect_user_field))
    max_state = 1
    max_field = 1
    do i = 1, m%n_materials
       max_state = max(max_state, m%materials(i)%nstatev)
       max_field = max(max_field, m%materials(i)%nfieldv)
    end do
    call element_workspace_init(ew, solver%part, solver%ndim, solver%nen, solver%ncomp, solver%nshr, max_state, max_field)

    first_step = 1
    resumed = .false.
    if (opts%restart) then
       call load_checkpoint(m, opts%output_base, solver, first_step, frames, rows, err)
       if (err%raised) call stop_agreed_error(part%comm, err)
       resumed = .true.
       call open_run_output(m, solver, out, opts%output_base, frames, rows, solver%total_time)
       call step_output_start(m, first_step, out, solver%step_time)
       out%energy_reference = solver%restart_energy_reference
       out%energy_peak = solver%restart_energy_peak
    else
       call open_run_output(m, solver, out, opts%output_base)
    end if
    out%progress = opts%progress
    out%energy_floor = 1.0e-12_dp * strain_energy_scale(solver)
    if (part%rank == 0) call print_header(m, part, solver, effects, opts)

    stop_now = .false.
    condition_met = .false.
    do istep = first_step, m%n_steps
       call prepare_step(m, istep, solver, loads)
       call prepare_pressures(m, istep, solver, pressures)
       period = m%steps(istep)%period
       if (.not. resumed) then
          solver%step = istep
          solver%step_time = 0
          solver%step_start = solver%total_time
          solver%step_increment = 0
          call step_output_start(m, istep, out)
          call stop_step_start(solver)
          call apply_step_mass_scaling(m, istep, solver, solver%dt_stable)
          if (istep == 1) then
             call initial_internal_forces(m, solver)
             call gravity_forces(m, loads, solver, 0.0_dp, solver%f_ext)
             if (effects%active(effect_pressure)) &
                  call add_pressure_forces(m, pressures, solver, 0.0_dp, 0.0_dp, solver%f_ext)
             call update_accelerations(solver)
             solver%dt_stable = initial_stable_dt(m, solver, m%steps(1)%bulk_linear)
             call energy_values(solver, energies)
             out%energy_reference = energies(1) + energies(2) + energies(3) + energies(4) - energies(5)
          else
             ! The step's loads and constraints from its first increment on: gravity at step time
             ! 0 of this step, and accelerations/reactions with this step's prescribed dofs (a dof
             ! released now must accelerate in the first increment, not keep a = 0).
             if (effects%active(effect_gravity)) call gravity_forces(m, loads, solver, 0.0_dp, solver%f_ext)
             if (effects%active(effect_pressure)) then
                if (.not. effects%active(effect_gravity)) solver%f_ext = 0
                call add_pressure_forces(m, pressures, solver, 0.0_dp, 0.0_dp, solver%f_ext)
             end if
             call update_accelerations(solver)
          end if
          call write_outputs(m, solver, out, effects, istep)
       end if
       resumed = .false.

       do while (solver%step_time < period * (1 - 1.0e-12_dp))
          call one_increment(m, solver, effects, ew, loads, pressures, istep, dt_min)
          call write_outputs(m, solver, out, effects, istep)
          call progress_line(m, solver, out, istep, .false.)
          if (effects%active(effect_checkpoint)) then
             if (checkpoint_due(m, solver, istep) .or. solver%increment == opts%stop_after) then
                call effects%start(effect_checkpoint)
                call save_checkpoint(m, opts%output_base, solver, out)
                call effects%stop(effect_checkpoint)
             end if
          else if (solver%increment == opts%stop_after) then
             ! --stop-after always leaves a checkpoint to continue from, *RESTART or not (before,
             ! a scene without *RESTART stopped, said "continue with --restart" and had none).
             call save_checkpoint(m, opts%output_base, solver, out)
          end if
          if (solver%increment == opts%stop_after) then
             stop_now = .true.
             exit
          end if
          if (m%steps(istep)%stop%active) then
             if (mod(solver%step_increment, stop_check_stride) == 0 .or. &
                  solver%step_time >= period * (1 - 1.0e-12_dp)) then
                if (check_stop_condition(m, istep, solver)) then
                   ! The last row and frame at the moment of the decision.
                   call write_history(m, solver, out, istep)
                   call write_frame(m, solver, out, istep)
                   condition_met = .true.
                   exit
                end if
             end if
          end if
       end do
       call progress_line(m, solver, out, istep, .true.)
       if (.not. stop_now) call report_stop_condition(m, istep, solver)
       if (stop_now .or. condition_met) exit
    end do

    call close_run_output(out)
    if (m%n_rigid_surfaces > 0) call sum_over_ranks(solver, solver%wall_force)
    if (part%rank == 0) then
       if (stop_now) write (output_unit, '(a,i0,a)') 'bulkflow: stopped after increment ', solver%increment, &
            ' as asked (--stop-after); continue with --restart'
       call print_summary(m, solver)
    end if
    call timer_report(effects%timers, output_unit, comm)
  end subroutine run_scene

  !> One central-difference increment, t_n → t_{n+1}.
  subroutine one_increment(m, solver, effects, ew, loads, pressures, istep, dt_min)
    type(model_t), intent(in) :: m
    type(solver_t), intent(inout) :: solver
    type(effects_t), intent(inout) :: effects
    type(element_workspace_t), intent(inout) :: ew
    type(step_loads_t), intent(in) :: loads
    type(step_pressures_t), intent(in) :: pressures
    integer, intent(in) :: istep
    real(dp), intent(out) :: dt_min
    real(dp) :: dt, dt_avg, t_mid, t_new, t_point, work, free_sum
    integer :: i, dt_elem
    logical :: gravity_varies

    associate (s => m%steps(istep))
      ! Time increment: the stable one (scaled), or the user's; never past the end of the step.
      if (s%dt_fixed > 0) then
         dt = s%dt_fixed
      else
         dt = s%dt_scale * stable_dt_safety * solver%dt_stable
      end if
      dt = min(dt, s%period - solver%step_time)
      ! TIME POINTS= output: the increment is cut to end exactly on the next listed time.
      t_point = next_time_point(m, istep, solver%step_time, 1.0e-9_dp * s%period)
      t_new = solver%step_time + dt
      if (t_point - solver%step_time <= dt) then
         dt = t_point - solver%step_time
         t_new = t_point
      end if
      solver%dt = dt
      t_mid = solver%step_time + 0.5_dp * dt

      ! Velocities at mid-increment (the first increment of the run starts from v_0 with dt/2).
      dt_avg = merge(0.5_dp * dt, 0.5_dp * (solver%dt_prev + dt), solver%increment == 0)
      call keep_constrained_velocities(solver, loads%constrained)
      if (solver%ndim == 2) then
         ! A literal component count: the compiler keeps the per-node sum in registers.
         call update_velocities(2, solver%n_nodes, solver%part%node_owned, solver%mass, dt_avg, solver%a, &
              solver%v, free_sum)
      else
         call update_velocities(solver%ndim, solver%n_nodes, solver%part%node_owned, solver%mass, dt_avg, &
              solver%a, solver%v, free_sum)
      end if

      if (effects%active(effect_boundary)) then
         call effects%start(effect_boundary)
         call apply_prescribed_velocities(m, loads, solver, t_mid, t_new, dt)
         call apply_rigid_body_velocities(m, loads, solver, t_mid, t_new, dt)
         call effects%stop(effect_boundary)
      end if
      work = 0
      if (effects%active(effect_rigid_walls)) then
         call effects%start(effect_rigid_walls)
         call apply_contact(m, loads, solver, dt, dt_avg, work)
         solver%e_friction = solver%e_friction + work
         ! A prescribed dof wins over contact, as in Abaqus.
         call apply_prescribed_velocities(m, loads, solver, t_mid, t_new, dt)
         call effects%stop(effect_rigid_walls)
      end if
      call constraint_work(solver, loads%constrained, dt, dt_avg, free_sum, work)

      call element_phase(m, solver, effects, ew, dt, s%bulk_linear, s%bulk_quadratic, dt_min, dt_elem)
      do i = 1, size(solver%rigid)
         solver%rigid(i)%u = solver%rigid(i)%u + dt * solver%rigid(i)%v
      end do

      ! Gravity without an amplitude is the same at every time of the step: f_ext (set at the
      ! step start, or read from the checkpoint) stays, and f_ext_old is f_ext. Recomputing it
      ! gave the same numbers at the cost of two passes over the nodes. (Code that changes the
      ! gravity loads within a step must call gravity_forces itself.)
      gravity_varies = effects%active(effect_gravity) .and. gravity_varies_in_step(loads)
      if (gravity_varies) then
         solver%f_ext_old = solver%f_ext
         call effects%start(effect_gravity)
         call gravity_forces(m, loads, solver, t_new, solver%f_ext)
         call effects%stop(effect_gravity)
         if (effects%active(effect_pressure)) then
            call effects%start(effect_pressure)
            call add_pressure_forces(m, pressures, solver, t_new, dt, solver%f_ext)
            call effects%stop(effect_pressure)
         end if
         call finish_nodes(solver, solver%f_ext_old)
      else if (effects%active(effect_pressure)) then
         ! follower pressure on the geometry of t_{n+1} (+ gravity, constant here)
         solver%f_ext_old = solver%f_ext
         call effects%start(effect_pressure)
         call gravity_forces(m, loads, solver, t_new, solver%f_ext)
         call add_pressure_forces(m, pressures, solver, t_new, dt, solver%f_ext)
         call effects%stop(effect_pressure)
         call finish_nodes(solver, solver%f_ext_old)
      else
         call finish_nodes(solver, solver%f_ext)
      end if

      solver%step_time = t_new
      solver%total_time = solver%step_start + t_new
      solver%increment = solver%increment + 1
      solver%step_increment = solver%step_increment + 1
      solver%dt_prev = dt
      ! NaN or Inf stops the run now, on every rank (driver_finite: tested on the energy sums,
      ! agreed through the minimum the increment takes anyway)
      if (.not. energies_finite(solver)) dt_min = non_finite_flag
      call global_min(solver%part, dt_min)
      if (dt_min <= non_finite_flag) call stop_non_finite(m, solver)
      solver%dt_stable = dt_min
      solver%dt_element = dt_elem
    end associate
  end subroutine one_increment

  !> External work of the kinematic constraints at t_n — prescribed velocities/displacements
  !> (supports) and rigid walls — added to ALLWK on this rank's owned nodes.
  !>
  !> The constraints act as impulses: with the force balance of the central-difference step,
  !> m (v_{n+1/2} − v_{n-1/2}) = h_n m a_n + I_n (h_n = Δt_avg, a_n the unconstrained acceleration
  !> (f_ext − f_int)/m, also on prescribed dofs, where the driver keeps a = 0 and the static
  !> reaction R = f_int − f_ext), the impulse of a node is I_n = m (v_{n+1/2} − v_free) + h_n R_n
  !> with v_free = v_{n-1/2} + h_n a. Its work is
  !>     I_n·½(v_{n-1/2} + v_{n+1/2}) + ¼ (Δt_{n-1/2} − Δt_{n+1/2}) (h_n m |a_n|² + a_n·I_n),
  !> which makes the balance exact for a linear system — with the kinetic energy
  !> ½ m v_{n+1/2}·(v_{n+1/2} + Δt a_{n+1}) and the pending support work ½ Δt v·R of energy_values,
  !> and the trapezoidal internal and gravity work — whatever the constraints do and however Δt
  !> varies. The second term matters where Δt changes: at a step end (the last increment is
  !> shortened) a support that changes speed there left ¼ ΔΔt R·Δv in ETOTAL for good (1.4 %
  !> in rotation_2d). On the first increment Δt_{-1/2} = 0 and h_0 = Δt/2: the same formula is then
  !> the start-up term of a suddenly applied load. (Before: ½(R_n + R_{n+1})·Δu with the static
  !> reactions only — the inertia of a driven node was missing, a sudden velocity cost ½ m v²
  !> unaccounted — and the contact forces times Δu, which counted friction twice, once in ALLFD
  !> and once as negative work.)
  !>
  !> For a wall the impulse work is the work of the wall (Σ F·v_wall Δt) minus the frictional
  !> dissipation minus the kinetic energy a perfectly plastic landing removes. ALLFD reports the
  !> friction (the contact kernel's friction_work) separately, so it is added back here: ALLWK
  !> holds the wall's work and the landing losses (Abaqus books the latter as ALLPW, which we do
  !> not have). A fixed wall with steady sliding contributes nothing, as in Abaqus.
  !>
  !> Only the constrained nodes have an impulse: on every other node v_{n+1/2} is v_free to the
  !> bit (update_velocities forms it with constraint_work_nodes' expression) and R = 0, so its
  !> impulse is exactly 0 and its work is the Δt-change term ¼ (Δt_{n-1/2} − Δt_{n+1/2}) h_n m |a_n|²
  !> alone. update_velocities sums m |a_n|² over the owned nodes in its pass (free_sum: a = 0 on a
  !> prescribed dof, whose −R/m the constrained pass adds); the constrained pass (a prescribed
  !> dof or a contact slave node, loads%constrained) adds the rest. Before, a pass over every node
  !> formed all the terms (and du = Δt v, now formed where it is read): the same work up to the
  !> order of the sums, a tenth of the CPE4R loop's instructions.
  subroutine constraint_work(solver, constrained, dt, dt_avg, free_sum, friction_work)
    type(solver_t), intent(inout) :: solver
    integer, intent(in) :: constrained(:)
    real(dp), intent(in) :: dt, dt_avg, free_sum, friction_work
    real(dp) :: work, ddt

    ddt = 0.25_dp * (solver%dt_prev - dt)
    work = 0
    call constraint_work_nodes(solver%ndim, solver%n_nodes, size(constrained), constrained, solver%mass, &
         solver%a, solver%reaction, solver%v, solver%v_old, ddt, dt_avg, work)
    work = work + ddt * dt_avg * free_sum
    solver%e_external = solver%e_external + work + friction_work
  end subroutine constraint_work

  !> The constrained nodes' terms of constraint_work, in node order: ½ I·(v_{n-1/2} + v_{n+1/2})
  !> + ¼ ΔΔt (h_n m |R/m|² + a_n·I), a_n = a − R/m (R ≠ 0 on prescribed dofs only, where a = 0).
  pure subroutine constraint_work_nodes(nd, nn, nc, constrained, mass, a, reaction, v, v_old, &
       ddt, dt_avg, work)
    ! v_old(:, k): v_{n-1/2} of node constrained(k) (keep_constrained_velocities)
    integer, intent(in) :: nd, nn, nc
    integer, intent(in) :: constrained(nc)
    real(dp), intent(in) :: mass(nn), a(nd, nn), reaction(nd, nn), v(nd, nn)
    real(dp), intent(in) :: v_old(nd, nc), ddt, dt_avg
    real(dp), intent(inout) :: work
    integer :: i, j, k
    real(dp) :: aj, rm, impulse, s_v, s_r2, s_ai, v_free

    do k = 1, nc
       i = constrained(k)
       if (mass(i) <= 0) cycle
       s_v = 0
       s_r2 = 0
       s_ai = 0
       do j = 1, nd
          rm = reaction(j, i) / mass(i)
          aj = a(j, i) - rm
          v_free = v_old(j, k) + dt_avg * a(j, i)
          impulse = mass(i) * (v(j, i) - v_free) + dt_avg * reaction(j, i)
          s_v = s_v + impulse * (v_old(j, k) + v(j, i))
          s_r2 = s_r2 + rm**2
          s_ai = s_ai + aj * impulse
       end do
       work = work + 0.5_dp * s_v + ddt * (dt_avg * mass(i) * s_r2 + s_ai)
    end do
  end subroutine constraint_work_nodes

  !> v_{n-1/2} of the constrained nodes (solver%v_old, in the order of `constrained`), before the
  !> velocity update: constraint_work needs it there only. (A copy of every node's velocity,
  !> kept before, was a node array written to memory every increment.)
  subroutine keep_constrained_velocities(solver, constrained)
    type(solver_t), intent(inout) :: solver
    integer, intent(in) :: constrained(:)
    integer :: k

    if (size(solver%v_old, 2) /= size(constrained)) then
       deallocate(solver%v_old)
       allocate(solver%v_old(solver%ndim, size(constrained)))
    end if
    do k = 1, size(constrained)
       solver%v_old(:, k) = solver%v(:, constrained(k))
    end do
  end subroutine keep_constrained_velocities

  !> v_{n+1/2} = v_{n-1/2} + Δt_avg a_n; free_sum = Σ m |a_n|² over the owned nodes with mass,
  !> in node order (constraint_work).
  pure subroutine update_velocities(nd, nn, owned, mass, dt_avg, a, v, free_sum)
    integer, intent(in) :: nd, nn
    logical, intent(in) :: owned(nn)
    real(dp), intent(in) :: mass(nn), dt_avg, a(nd, nn)
    real(dp), intent(inout) :: v(nd, nn)
    real(dp), intent(out) :: free_sum
    integer :: i, j
    real(dp) :: s

    free_sum = 0
    do i = 1, nn
       s = 0
       do j = 1, nd
          v(j, i) = v(j, i) + dt_avg * a(j, i)
          s = s + a(j, i)**2
       end do
       if (owned(i) .and. mass(i) > 0) free_sum = free_sum + mass(i) * s
    end do
  end subroutine update_velocities

  !> The node pass that closes an increment, after the assembly and gravity: u_{n+1} = u_n + du
  !> (du = Δt v_{n+1/2}, formed here as the element gather forms it),
  !> accelerations and reactions (update_accelerations), and the work of gravity on this rank's
  !> owned nodes with the trapezoidal rule, ½ (f_ext,n + f_ext,n+1)·du, in node order.
  !> f_ext_old: f_ext at t_n (solver%f_ext itself when it did not change).
  subroutine finish_nodes(solver, f_ext_old)
    type(solver_t), intent(inout) :: solver
    real(dp), intent(in) :: f_ext_old(:, :)

    if (solver%ndim == 2) then
       call finish_nodes_2d(solver%n_nodes, solver%part%node_owned, solver%fixed, solver%mass, &
            solver%f_int, solver%f_ext, f_ext_old, solver%dt, solver%v, solver%u, solver%a, solver%reaction, &
            solver%e_external)
    else
       call finish_nodes_kernel(solver%ndim, solver%n_nodes, solver%part%node_owned, solver%fixed, &
            solver%mass, solver%f_int, solver%f_ext, f_ext_old, solver%dt, solver%v, solver%u, solver%a, &
            solver%reaction, solver%e_external)
    end if
  end subroutine finish_nodes

  !> finish_nodes on explicit-shape arrays (the compiler then keeps the loop tight; on the
  !> solver's allocatable components it reloaded their descriptors at every store).
  pure subroutine finish_nodes_kernel(nd, nn, owned, fixed, mass, f_int, f_ext, f_ext_old, dt, v, u, a, &
       reaction, e_external)
    integer, intent(in) :: nd, nn
    logical, intent(in) :: owned(nn), fixed(nd, nn)
    real(dp), intent(in) :: mass(nn), f_int(nd, nn), f_ext(nd, nn), f_ext_old(nd, nn), dt, v(nd, nn)
    real(dp), intent(inout) :: u(nd, nn), e_external
    real(dp), intent(out) :: a(nd, nn), reaction(nd, nn)
    integer :: i, j
    real(dp) :: w

    do i = 1, nn
       do j = 1, nd
          u(j, i) = u(j, i) + dt * v(j, i)
          call dof_acceleration(fixed(j, i), mass(i), f_int(j, i), f_ext(j, i), a(j, i), reaction(j, i))
       end do
       if (.not. owned(i)) cycle
       w = 0
       do j = 1, nd
          w = w + 0.5_dp * (f_ext_old(j, i) + f_ext(j, i)) * (dt * v(j, i))
       end do
       e_external = e_external + w
    end do
  end subroutine finish_nodes_kernel

  !> finish_nodes_kernel for two components, with the same operations in the same order. The
  !> extent 2 literal, so the arrays' stride is known and the update of u, a and the reactions
  !> vectorises (-fno-trapping-math on this file, src/CMakeLists.txt: with nd a variable it
  !> stayed scalar and branching). The work's ordered sum would keep that loop scalar: it has a
  !> loop of its own, chunk by chunk, so it reads f_ext and v from the cache.
  pure subroutine finish_nodes_2d(nn, owned, fixed, mass, f_int, f_ext, f_ext_old, dt, v, u, a, reaction, &
       e_external)
    integer, intent(in) :: nn
    logical, intent(in) :: owned(nn), fixed(2, nn)
    real(dp), intent(in) :: mass(nn), f_int(2, nn), f_ext(2, nn), f_ext_old(2, nn), dt, v(2, nn)
    real(dp), intent(inout) :: u(2, nn), e_external
    real(dp), intent(out) :: a(2, nn), reaction(2, nn)
    integer :: i, j, i0, i1
    real(dp) :: w

    do i0 = 1, nn, node_chunk
       i1 = min(nn, i0 + node_chunk - 1)
       do i = i0, i1
          do j = 1, 2
             u(j, i) = u(j, i) + dt * v(j, i)
             call dof_acceleration(fixed(j, i), mass(i), f_int(j, i), f_ext(j, i), a(j, i), reaction(j, i))
          end do
       end do
       do i = i0, i1
          if (.not. owned(i)) cycle
          w = 0
          do j = 1, 2
             w = w + 0.5_dp * (f_ext_old(j, i) + f_ext(j, i)) * (dt * v(j, i))
          end do
          e_external = e_external + w
       end do
    end do
  end subroutine finish_nodes_2d

  !> ½ Σ_e M_e V_e (M the P-wave modulus): the strain energy of the whole model at unit strain,
  !> equal to ½ Σ m c_d², the kinetic energy at the wave speed. Scale of "significant" energies.
  real(dp) function strain_energy_scale(solver)
    type(solver_t), intent(in) :: solver
    integer :: ib

    strain_energy_scale = 0
    do ib = 1, solver%n_blocks
       strain_energy_scale = strain_energy_scale + 0.5_dp * solver%blocks(ib)%wave_modulus &
            * sum(solver%blocks(ib)%volume_ref)
    end do
    call global_sum(solver%part, strain_energy_scale)
  end function strain_energy_scale

  !> a = (f_ext − f_int)/m on free dofs; reactions f_int − f_ext on prescribed ones.
  subroutine update_accelerations(solver)
    type(solver_t), intent(inout) :: solver
    integer :: i, j

    do i = 1, solver%n_nodes
       do j = 1, solver%ndim
          call dof_acceleration(solver%fixed(j, i), solver%mass(i), solver%f_int(j, i), solver%f_ext(j, i), &
               solver%a(j, i), solver%reaction(j, i))
       end do
    end do
  end subroutine update_accelerations

  !> Acceleration and reaction of one dof (update_accelerations, finish_nodes_kernel, finish_nodes_2d).
  !> A node no element uses (a rigid body's reference node, held by rank 0) has no mass and no
  !> forces: it does not move unless prescribed.
  elemental subroutine dof_acceleration(fixed, mass, f_int, f_ext, a, reaction)
    logical, intent(in) :: fixed
    real(dp), intent(in) :: mass, f_int, f_ext
    real(dp), intent(out) :: a, reaction
    real(dp) :: quotient

    ! Selections, not branches, so finish_nodes_2d vectorises: the quotient is formed
    ! everywhere, with the divisor 1 where the mass is 0 (no division by zero), and not used there.
    quotient = (f_ext - f_int) / merge(mass, 1.0_dp, mass > 0)
    a = merge(quotient, 0.0_dp, mass > 0 .and. .not. fixed)
    reaction = merge(f_int - f_ext, 0.0_dp, fixed)
  end subroutine dof_acceleration

  subroutine write_outputs(m, solver, out, effects, istep)
    type(model_t), intent(in) :: m
    type(solver_t), intent(inout) :: solver
    type(run_output_t), intent(inout) :: out
    type(effects_t), intent(inout) :: effects
    integer, intent(in) :: istep
    call effects%start(effect_output)
    if (schedule_due(out%field_schedule, solver%step_time, solver%step_increment, solver%dt)) then
       call write_frame(m, solver, out, istep)
       call schedule_advance(out%field_schedule, solver%step_time)
    end if
    if (schedule_due(out%history_schedule, solver%step_time, solver%step_increment, solver%dt)) then
       call write_history(m, solver, out, istep)
       call schedule_advance(out%history_schedule, solver%step_time)
    end if
    call effects%stop(effect_output)
  end subroutine write_outputs

  logical function checkpoint_due(m, solver, istep)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    integer, intent(in) :: istep
    real(dp) :: interval, before

    checkpoint_due = .false.
    if (.not. m%steps(istep)%restart_write) return
    interval = m%steps(istep)%restart_interval
    if (interval <= 0) then
       checkpoint_due = solver%step_time >= m%steps(istep)%period * (1 - 1.0e-12_dp)
       return
    end if
    before = solver%step_time - solver%dt
    checkpoint_due = floor(solver%step_time / interval + 1.0e-9_dp) > floor(before / interval + 1.0e-9_dp)
  end function checkpoint_due

  !> Stable increment of the undeformed mesh: L_e / c_d with the linear bulk-viscosity damping.
  real(dp) function initial_stable_dt(m, solver, b1)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    real(dp), intent(in) :: b1
    integer :: ib, nb, e, a, i
    real(dp), allocatable :: xe(:, :, :), lc(:), c(:), xi(:), dte(:)

    initial_stable_dt = huge(1.0_dp)
    do ib = 1, solver%n_blocks
       associate (blk => solver%blocks(ib))
         nb = blk%count
         allocate(xe(nb, solver%ndim, solver%nen), lc(nb), c(nb), xi(nb), dte(nb))
         do a = 1, solver%nen
            do i = 1, solver%ndim
               do e = 1, nb
                  xe(e, i, a) = solver%x0(i, solver%part%conn(a, blk%first + e - 1))
               end do
            end do
         end do
         if (m%mesh%element_type == element_cpe4r) then
            call cpe4r_char_length(nb, xe, lc)
         else if (m%mesh%element_type == element_cax4r) then
            call cax4r_char_length(nb, xe, lc)
         else
            call c3d8r_char_length(nb, xe, blk%volume_ref, lc)
         end if
         c = sqrt(blk%wave_modulus / (blk%mass / blk%volume_ref))
         if (blk%mass_scaled) c = c / sqrt(blk%mass_scale)
         xi = b1
         call element_stable_dt(nb, lc, c, xi, dte)
         initial_stable_dt = min(initial_stable_dt, minval(dte))
         deallocate(xe, lc, c, xi, dte)
       end associate
    end do
    call global_min(solver%part, initial_stable_dt)
  end function initial_stable_dt

  subroutine print_header(m, part, solver, effects, opts)
    type(model_t), intent(in) :: m
    type(partition_t), intent(in) :: part
    type(solver_t), intent(in) :: solver
    type(effects_t), intent(in) :: effects
    type(run_options_t), intent(in) :: opts

    write (output_unit, '(a)') 'bulkflow: ' // trim(m%heading)
    write (output_unit, '(a,i0,a,i0,a,i0,a,i0,a)') '  model     ', m%mesh%n_nodes, ' nodes, ', m%mesh%n_elems, &
         ' elements, ', m%n_steps, ' step(s), ', part%nranks, ' rank(s)'
    write (output_unit, '(a)') '  effects   ' // effects%active_list()
    write (output_unit, '(a)') '  output    ' // opts%output_base // '.h5/.xmf, ' // opts%output_base // &
         '_history.csv'
    if (opts%restart) write (output_unit, '(a,i0,a,es12.5)') '  restart   from increment ', solver%increment, &
         ' at t = ', solver%total_time
    flush (output_unit)
  end subroutine print_header

  subroutine print_summary(m, solver)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    integer :: i
    real(dp) :: wall(solver%ndim, max(1, m%n_rigid_surfaces))

    write (output_unit, '(a,i0,a,es12.5)') 'bulkflow: done, ', solver%increment, ' increments, t = ', &
         solver%total_time
    associate (e => solver%energies)
      write (output_unit, '(a,6es12.4)') '  energies  ALLKE ALLIE ALLVD ALLFD ALLWK ALLAE:', e%kinetic, &
           e%internal, e%viscous, e%friction, e%external, e%artificial
    end associate
    wall = solver%wall_force
    do i = 1, m%n_rigid_surfaces
       write (output_unit, '(a,3es13.5)') '  wall ' // trim(m%rigid_surfaces(i)%name) // ' force:', wall(:, i)
    end do
  end subroutine print_summary
end module driver_run
