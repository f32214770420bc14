!> The element solver's increment: each increment as the named phases of the central-difference
!> scheme (docs/solver_interfaces.md §0), the start of a step (its loads, the initial forces and
!> accelerations), and the increment the solver proposes. The step loop, outputs, progress and
!> checkpoints are the run skeleton's (src/run: run_loop drives element_technique_t of
!> run_element, which calls these). The increment reads like a table of contents; each phase
!> lives in its own module.
module driver_run
  use, intrinsic :: iso_fortran_env, only: output_unit
  use base_kinds, only: dp
  use model, only: model_t
  use model_mesh, only: element_cpe4r, element_cax4r
  use parallel_partition, only: partition_t
  use parallel_assembly, only: global_min, global_sum
  use driver_solver, only: solver_t
  use driver_effects, only: effect_gravity, effect_pressure, effect_rigid_walls, effect_boundary
  use output_effects, only: effects_t
  use driver_setup, only: initial_internal_forces
  use driver_elements, only: element_workspace_t, element_phase
  use driver_loads, only: step_loads_t, prepare_step, apply_prescribed_velocities, &
       apply_rigid_body_velocities, gravity_forces, apply_contact, gravity_varies_in_step
  use driver_output, only: run_output_t, energy_values
  use driver_mass_scaling, only: apply_step_mass_scaling
  use driver_pressure, only: step_pressures_t, prepare_pressures, add_pressure_forces
  use driver_finite, only: energies_finite, stop_non_finite, non_finite_flag
  use driver_stop_condition, only: stop_step_start
  use fem_cpe4r, only: cpe4r_char_length
  use fem_cax4r, only: cax4r_char_length
  use fem_c3d8r, only: c3d8r_char_length
  use fem_stable_dt, only: element_stable_dt
  implicit none
  private

  !> Nodes per chunk of finish_nodes_2d: its arrays, 1024 nodes × 10 values, stay in L2.
  integer, parameter :: node_chunk = 1024

  !> Margin on the element estimate L_e/c_d. Our L_e (area/longest edge, volume/largest face)
  !> equals the exact limit for regular meshes of many elements, but measured critical
  !> increments of free 2x2 and 2x2x2 blocks are 0.97 and 0.94 L_e/c_d (ν = 0.3), before the
  !> bulk-viscosity correction; 0.9 keeps every mesh we tried stable at SCALE FACTOR = 1.
  !> Lone free elements are stiffer still (0.84 / 0.73): scenes with them need SCALE FACTOR.
  real(dp), parameter :: stable_dt_safety = 0.9_dp

  public :: start_step, proposed_increment, one_increment, strain_energy_scale, print_header, print_summary

contains

  !> The start of step istep: its loads and pressures on this rank's nodes; unless resumed (a
  !> restart continuing the step), the clock at the step's start, the step's mass scaling and
  !> stop condition, and the forces and accelerations of its first increment (in step 1 the
  !> initial internal forces, the first stable increment and the energy reference too).
  subroutine start_step(m, istep, resumed, solver, effects, loads, pressures, out)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    logical, intent(in) :: resumed
    type(solver_t), intent(inout) :: solver
    type(effects_t), intent(in) :: effects
    type(step_loads_t), intent(inout) :: loads
    type(step_pressures_t), intent(inout) :: pressures
    type(run_output_t), intent(inout) :: out
    real(dp) :: energies(6)

    call prepare_step(m, istep, solver, loads)
    call prepare_pressures(m, istep, solver, pressures)
    if (resumed) return
    solver%step = istep
    solver%step_time = 0
    solver%step_start = solver%total_time
    solver%step_increment = 0
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
  end subroutine start_step

  !> The increment the solver takes next, before the step's end and TIME POINTS cut it: the
  !> stable one (scaled, with the safety margin) or the step's fixed one.
  real(dp) function proposed_increment(m, istep, solver) result(dt)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(solver_t), intent(in) :: solver

    associate (s => m%steps(istep))
      if (s%dt_fixed > 0) then
         dt = s%dt_fixed
      else
         dt = s%dt_scale * stable_dt_safety * solver%dt_stable
      end if
    end associate
  end function proposed_increment

  !> One central-difference increment, t_n → t_{n+1}: Δt = dt, ending at step time t_new (the
  !> run skeleton's cut of proposed_increment: src/run/run_loop.f90).
  subroutine one_increment(m, solver, effects, ew, loads, pressures, istep, dt, t_new, dt_min)
    type(model_t), intent(in) :: m
    type(solver_t), intent(inout) :: solver
    type(effects_t), intent(inout) :: effects
    type(element_workspace_t), intent(inout) :: ew
    type(step_loads_t), intent(in) :: loads
    type(step_pressures_t), intent(in) :: pressures
    integer, intent(in) :: istep
    real(dp), intent(in) :: dt, t_new
    real(dp), intent(out) :: dt_min
    real(dp) :: dt_avg, t_mid, work, free_sum
    integer :: i, dt_elem
    logical :: gravity_varies

    associate (s => m%steps(istep))
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

  !> The run's header (rank 0): heading, model, active effects, output files.
  subroutine print_header(m, part, effects, output_base)
    type(model_t), intent(in) :: m
    type(partition_t), intent(in) :: part
    type(effects_t), intent(in) :: effects
    character(len=*), intent(in) :: output_base

    write (output_unit, '(a)') 'bulkflow: ' // trim(m%heading)
    write (output_unit, '(a,i0,a,i0,a,i0,a,i0,a)') '  model     ', m%mesh%n_nodes, ' nodes, ', m%mesh%n_elems, &
         ' elements, ', m%n_steps, ' step(s), ', part%nranks, ' rank(s)'
    write (output_unit, '(a)') effects%header_line()
    write (output_unit, '(a)') '  output    ' // output_base // '.h5/.xmf, ' // output_base // &
         '_history.csv'
    flush (output_unit)
  end subroutine print_header

  !> The element solver's lines of the end report (rank 0): final energies, wall forces (summed
  !> over the ranks before).
  subroutine print_summary(m, solver)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    integer :: i
    real(dp) :: wall(solver%ndim, max(1, m%n_rigid_surfaces))

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
