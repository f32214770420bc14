!> Loads and constraints of the current step on this rank's nodes: prescribed velocities and
!> displacements (with amplitudes), rigid-body reference nodes, gravity, and rigid-wall contact.
!> prepare_step turns the step's global, user-facing lists into local index lists once, so the
!> increment loop touches only arrays.
module driver_loads
  use base_kinds, only: dp
  use model, only: model_t
  use model_steps, only: bc_velocity
  use model_time_variation, only: time_variation_t, variation_factor, variation_is_constant
  use model_sets, only: sorted_position
  use parallel_partition, only: partition_t, local_node_index, local_elem_index
  use parallel_assembly, only: assemble_element_vectors
  use driver_solver, only: solver_t
  use contact_rigid_wall, only: rigid_wall_contact
  implicit none
  private

  type :: prescribed_t
     integer :: node = 0, dof = 0            !< local node (or rigid surface for rigid lists)
     integer :: kind = 0
     type(time_variation_t) :: variation
     real(dp) :: value = 0
  end type prescribed_t

  type :: gravity_local_t
     real(dp) :: g(3) = 0
     type(time_variation_t) :: variation
     real(dp), allocatable :: mass(:)         !< (n_local_nodes) lumped mass of the loaded elements
  end type gravity_local_t

  type :: contact_local_t
     integer :: wall = 0
     real(dp) :: mu = 0
     integer, allocatable :: owned(:), others(:)   !< local slave nodes this rank owns / does not
  end type contact_local_t

  type, public :: step_loads_t
     integer :: n_prescribed = 0, n_rigid = 0
     type(prescribed_t), allocatable :: prescribed(:), rigid(:)
     type(gravity_local_t), allocatable :: gravity(:)
     type(contact_local_t), allocatable :: contact(:)
     !> Owned nodes whose velocity a constraint of the step may change after the free update
     !> (a prescribed dof, or a slave node of a contact pair), ascending: the only nodes with a
     !> constraint impulse (driver_run's constraint_work).
     integer, allocatable :: constrained(:)
  end type step_loads_t

  public :: prepare_step, apply_prescribed_velocities, apply_rigid_body_velocities, gravity_forces, &
       apply_contact, gravity_varies_in_step

contains

  subroutine prepare_step(m, istep, solver, loads)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(solver_t), intent(inout) :: solver
    type(step_loads_t), intent(out) :: loads
    integer :: ib, i, j, k, dof, n, nr, r, g, le, a, e
    real(dp), allocatable :: fe(:, :, :), gm(:, :)
    logical :: found

    associate (s => m%steps(istep), part => solver%part)
      ! Prescribed dofs: nodes of the deformable mesh, and reference nodes of rigid surfaces.
      n = 0
      nr = 0
      if (allocated(s%boundaries)) then
         do ib = 1, size(s%boundaries)
            associate (b => s%boundaries(ib))
              n = n + size(b%nodes) * (b%last_dof - b%first_dof + 1)
            end associate
         end do
      end if
      allocate(loads%prescribed(max(1, n)), loads%rigid(max(1, n)))
      n = 0
      solver%fixed = .false.
      if (allocated(s%boundaries)) then
         do ib = 1, size(s%boundaries)
            associate (b => s%boundaries(ib))
              do i = 1, size(b%nodes)
                 do dof = b%first_dof, min(b%last_dof, solver%ndim)
                    found = .false.
                    do r = 1, m%n_rigid_surfaces
                       if (m%rigid_surfaces(r)%ref_node == b%nodes(i)) then
                          nr = nr + 1
                          loads%rigid(nr) = prescribed_t(r, dof, b%kind, b%variation, b%value)
                          found = .true.
                       end if
                    end do
                    if (found) cycle
                    k = local_node_index(part, b%nodes(i))
                    if (k == 0) cycle
                    n = n + 1
                    loads%prescribed(n) = prescribed_t(k, dof, b%kind, b%variation, b%value)
                    solver%fixed(dof, k) = .true.
                 end do
              end do
            end associate
         end do
      end if
      loads%n_prescribed = n
      loads%n_rigid = nr

      ! Gravity: the lumped mass of the loaded elements at each node, assembled like the mass.
      if (allocated(s%gravity)) then
         allocate(loads%gravity(size(s%gravity)))
         allocate(fe(part%n_local_elems, 1, solver%nen), gm(1, solver%n_nodes))
         do g = 1, size(s%gravity)
            fe = 0
            do ib = 1, solver%n_blocks
               associate (blk => solver%blocks(ib))
                 do e = 1, blk%count
                    le = blk%first + e - 1
                    if (s%gravity(g)%elset > 0) then
                       if (sorted_position(m%elsets(s%gravity(g)%elset)%members, part%elem_global(le)) == 0) cycle
                    end if
                    do a = 1, solver%nen
                       fe(le, 1, a) = blk%mass(e) / solver%nen
                       ! CAX4R: the ring's nodal shares (the nodal masses' own, fem_cax4r)
                       if (allocated(blk%mass_share)) fe(le, 1, a) = blk%mass(e) * blk%mass_share(e, a)
                    end do
                 end do
               end associate
            end do
            call assemble_element_vectors(part, 1, fe, gm)
            loads%gravity(g)%mass = gm(1, :)
            loads%gravity(g)%g = s%gravity(g)%magnitude * s%gravity(g)%direction
            loads%gravity(g)%variation = s%gravity(g)%variation
         end do
      else
         allocate(loads%gravity(0))
      end if

      ! Contact pairs: the slave nodes present on this rank, owned ones apart (they alone count
      ! in forces and frictional work, so shared nodes are not counted twice across ranks).
      if (allocated(s%contact_pairs)) then
         allocate(loads%contact(size(s%contact_pairs)))
         do j = 1, size(s%contact_pairs)
            associate (cp => s%contact_pairs(j), c => loads%contact(j))
              c%wall = cp%rigid_surface
              c%mu = 0
              if (cp%interaction > 0) c%mu = m%interactions(cp%interaction)%friction
              call split_slaves(part, m%element_surfaces(cp%slave_surface)%nodes, c%owned, c%others)
            end associate
         end do
      else
         allocate(loads%contact(0))
      end if
      ! Contact forces are zero except at this step's slave nodes (apply_contact resets only those).
      solver%f_contact = 0
      call constrained_nodes(part, solver%fixed, loads%contact, loads%constrained)
    end associate
  end subroutine prepare_step

  !> The owned nodes with a prescribed dof or in a contact pair's slave set, ascending, once each.
  subroutine constrained_nodes(part, fixed, contact, nodes)
    type(partition_t), intent(in) :: part
    logical, intent(in) :: fixed(:, :)
    type(contact_local_t), intent(in) :: contact(:)
    integer, allocatable, intent(out) :: nodes(:)
    logical, allocatable :: mark(:)
    integer :: j, k

    allocate(mark(size(fixed, 2)))
    mark = any(fixed, dim=1)
    do j = 1, size(contact)
       mark(contact(j)%owned) = .true.
    end do
    mark = mark .and. part%node_owned
    nodes = pack([(k, k = 1, size(mark))], mark)
  end subroutine constrained_nodes

  subroutine split_slaves(part, nodes, owned, others)
    type(partition_t), intent(in) :: part
    integer, intent(in) :: nodes(:)
    integer, allocatable, intent(out) :: owned(:), others(:)
    integer :: i, k, no, nt

    allocate(owned(size(nodes)), others(size(nodes)))
    no = 0
    nt = 0
    do i = 1, size(nodes)
       k = local_node_index(part, nodes(i))
       if (k == 0) cycle
       if (part%node_owned(k)) then
          no = no + 1
          owned(no) = k
       else
          nt = nt + 1
          others(nt) = k
       end if
    end do
    owned = owned(1:no)
    others = others(1:nt)
  end subroutine split_slaves

  !> Overwrite v_{n+1/2} on prescribed dofs: a velocity BC gives value·A(t_{n+1/2}); a
  !> displacement BC the velocity that reaches value·A(t_{n+1}) at the end of the increment.
  subroutine apply_prescribed_velocities(m, loads, solver, step_time_mid, step_time_new, dt)
    type(model_t), intent(in) :: m
    type(step_loads_t), intent(in) :: loads
    type(solver_t), intent(inout) :: solver
    real(dp), intent(in) :: step_time_mid, step_time_new, dt
    integer :: i
    real(dp) :: amp_mid, amp_new

    do i = 1, loads%n_prescribed
       associate (p => loads%prescribed(i))
         call amplitudes(m, p%variation, solver%step_start, step_time_mid, step_time_new, amp_mid, amp_new)
         if (p%kind == bc_velocity) then
            solver%v(p%dof, p%node) = p%value * amp_mid
         else
            solver%v(p%dof, p%node) = (p%value * amp_new - solver%u(p%dof, p%node)) / dt
         end if
       end associate
    end do
  end subroutine apply_prescribed_velocities

  !> Velocities of the rigid surfaces' reference nodes over the increment (unconstrained dofs
  !> of a reference node do not move: walls are driven, not free bodies).
  subroutine apply_rigid_body_velocities(m, loads, solver, step_time_mid, step_time_new, dt)
    type(model_t), intent(in) :: m
    type(step_loads_t), intent(in) :: loads
    type(solver_t), intent(inout) :: solver
    real(dp), intent(in) :: step_time_mid, step_time_new, dt
    integer :: i
    real(dp) :: amp_mid, amp_new

    do i = 1, size(solver%rigid)
       solver%rigid(i)%v = 0
    end do
    do i = 1, loads%n_rigid
       associate (p => loads%rigid(i), body => solver%rigid(loads%rigid(i)%node))
         call amplitudes(m, p%variation, solver%step_start, step_time_mid, step_time_new, amp_mid, amp_new)
         if (p%kind == bc_velocity) then
            body%v(p%dof) = p%value * amp_mid
         else
            body%v(p%dof) = (p%value * amp_new - body%u(p%dof)) / dt
         end if
       end associate
    end do
  end subroutine apply_rigid_body_velocities

  !> Factors at the middle and the end of the increment (model_time_variation: no amplitude
  !> gives 1, Abaqus's step variation in Explicit; a condition carried over with a step-time
  !> amplitude its held value).
  subroutine amplitudes(m, variation, step_start, t_mid, t_new, a_mid, a_new)
    type(model_t), intent(in) :: m
    type(time_variation_t), intent(in) :: variation
    real(dp), intent(in) :: step_start, t_mid, t_new
    real(dp), intent(out) :: a_mid, a_new

    a_mid = variation_factor(variation, m%amplitudes, t_mid, step_start + t_mid)
    a_new = variation_factor(variation, m%amplitudes, t_new, step_start + t_new)
  end subroutine amplitudes

  !> f_ext = Σ gravity loads at the given step time.
  subroutine gravity_forces(m, loads, solver, step_time, f_ext)
    type(model_t), intent(in) :: m
    type(step_loads_t), intent(in) :: loads
    type(solver_t), intent(in) :: solver
    real(dp), intent(in) :: step_time
    real(dp), intent(out) :: f_ext(:, :)
    integer :: g, i
    real(dp) :: amp

    f_ext = 0
    do g = 1, size(loads%gravity)
       amp = variation_factor(loads%gravity(g)%variation, m%amplitudes, step_time, solver%step_start + step_time)
       do i = 1, solver%n_nodes
          f_ext(:, i) = f_ext(:, i) + loads%gravity(g)%mass(i) * amp * loads%gravity(g)%g(1:solver%ndim)
       end do
    end do
  end subroutine gravity_forces

  !> Does a gravity load of the step change within the step (f_ext must be formed anew)?
  pure logical function gravity_varies_in_step(loads)
    type(step_loads_t), intent(in) :: loads
    integer :: g

    gravity_varies_in_step = .false.
    if (.not. allocated(loads%gravity)) return
    do g = 1, size(loads%gravity)
       if (.not. variation_is_constant(loads%gravity(g)%variation)) gravity_varies_in_step = .true.
    end do
  end function gravity_varies_in_step

  !> Kinematic contact of every active pair on v_{n+1/2}. Two passes settle nodes held by two
  !> walls (a concave corner: hopper wall and outlet plate). Returns the frictional work of this
  !> rank's owned slaves; f_contact gets the contact forces of owned slaves and wall_force the
  !> force on each wall (minus the force on the material).
  !> The kernel's force is m Δv/Δt; the impulse of the step belongs to t_n, whose velocity change
  !> spans Δt_avg = ½(Δt_{n-1/2} + Δt_{n+1/2}), so the force is m Δv/Δt_avg: scaled here by
  !> Δt/Δt_avg (before, the wall force of a block at rest was 2.6 times its weight on the
  !> shortened last increment of a step, and twice it on the first increment of the run).
  subroutine apply_contact(m, loads, solver, dt, dt_avg, friction_work)
    type(model_t), intent(in) :: m
    type(step_loads_t), intent(in) :: loads
    type(solver_t), intent(inout) :: solver
    real(dp), intent(in) :: dt, dt_avg
    real(dp), intent(out) :: friction_work
    integer :: j, pass, npass, i, nd, k
    real(dp), allocatable :: x(:, :), force(:, :)
    logical, allocatable :: touching(:)
    real(dp) :: work, scale

    nd = solver%ndim
    friction_work = 0
    solver%wall_force = 0
    if (size(loads%contact) == 0) return
    scale = dt / dt_avg
    ! x_n = x0 + u, and the reset of f_contact, at the slave nodes only: the kernel reads no other
    ! node, and f_contact is zero elsewhere (prepare_step). Two passes over every node were most
    ! of the time of this routine.
    allocate(x(nd, solver%n_nodes))
    do j = 1, size(loads%contact)
       associate (c => loads%contact(j))
         do i = 1, size(c%owned)
            k = c%owned(i)
            x(:, k) = solver%x0(:, k) + solver%u(:, k)
            solver%f_contact(:, k) = 0
         end do
         do i = 1, size(c%others)
            k = c%others(i)
            x(:, k) = solver%x0(:, k) + solver%u(:, k)
         end do
       end associate
    end do
    npass = merge(2, 1, size(loads%contact) > 1)
    do pass = 1, npass
       do j = 1, size(loads%contact)
          associate (c => loads%contact(j), wall => m%rigid_surfaces(loads%contact(j)%wall), &
               body => solver%rigid(loads%contact(j)%wall))
            allocate(force(nd, size(c%owned)), touching(size(c%owned)))
            call rigid_wall_contact(nd, solver%n_nodes, x, solver%v, solver%mass, c%owned, dt, wall, &
                 body%u(1:nd), body%v(1:nd), c%mu, force, work, touching)
            friction_work = friction_work + work
            do i = 1, size(c%owned)
               solver%f_contact(:, c%owned(i)) = solver%f_contact(:, c%owned(i)) + scale * force(:, i)
               solver%wall_force(:, c%wall) = solver%wall_force(:, c%wall) - scale * force(:, i)
            end do
            deallocate(force, touching)
            allocate(force(nd, size(c%others)), touching(size(c%others)))
            call rigid_wall_contact(nd, solver%n_nodes, x, solver%v, solver%mass, c%others, dt, wall, &
                 body%u(1:nd), body%v(1:nd), c%mu, force, work, touching)
            deallocate(force, touching)
          end associate
       end do
    end do
  end subroutine apply_contact
end module driver_loads
