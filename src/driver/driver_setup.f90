!> Everything done once before the first increment: local nodes and element blocks from the
!> partition, reference geometry, lumped masses, material moduli from the packaging call,
!> initial conditions, and the internal forces of the initial stresses.
module driver_setup
  use base_kinds, only: dp
  use model, only: model_t
  use model_mesh, only: element_cpe4r, element_cax4r
  use parallel_partition, only: partition_t, local_node_index, local_elem_index
  use parallel_assembly, only: assemble_element_vectors, block_assembly_t, block_assembly_init, &
       assembly_start, assembly_add_block, assembly_finish
  use driver_solver, only: solver_t, element_block_t, build_blocks
  use material_door, only: checked_packaging_modulus
  use fem_cpe4r, only: cpe4r_geometry, cpe4r_internal_force
  use fem_cax4r, only: cax4r_geometry, cax4r_internal_force
  use fem_c3d8r, only: c3d8r_geometry, c3d8r_internal_force
  use fem_corotation, only: identity_rotation, stored_to_global
  use fem_mass, only: lumped_mass
  use material_props, only: model_from_name, model_unknown
  implicit none
  private

  public :: setup_solver, initial_internal_forces, shared_node_mass

contains

  subroutine setup_solver(m, part, solver, user_field_active)
    type(model_t), intent(in) :: m
    type(partition_t), intent(in) :: part
    type(solver_t), intent(inout) :: solver
    logical, intent(in) :: user_field_active
    integer :: nd, nn, i, j, k, ib, nb, e, g, le
    real(dp), allocatable :: moduli(:), mass_e(:, :, :), mass2(:, :), mass_b(:, :)
    logical, allocatable :: known(:)

    solver%part = part
    call build_blocks(m, part, solver)
    nd = solver%ndim
    nn = part%n_local_nodes
    solver%n_nodes = nn
    allocate(solver%x0(nd, nn), solver%u(nd, nn), solver%v(nd, nn), solver%a(nd, nn))
    allocate(solver%mass(nn), solver%f_int(nd, nn), solver%f_ext(nd, nn), solver%f_contact(nd, nn))
    allocate(solver%reaction(nd, nn), solver%fixed(nd, nn))
    allocate(solver%f_ext_old(nd, nn), solver%v_old(nd, 0))
    do i = 1, nn
       solver%x0(:, i) = m%mesh%x0(:, part%node_global(i))
    end do
    solver%u = 0
    solver%v = 0
    solver%a = 0
    solver%f_int = 0
    solver%f_ext = 0
    solver%f_contact = 0
    solver%reaction = 0
    solver%fixed = .false.
    allocate(solver%rigid(max(1, m%n_rigid_surfaces)))
    allocate(solver%wall_force(nd, max(1, m%n_rigid_surfaces)))
    solver%wall_force = 0

    ! P-wave modulus of each material from Abaqus's packaging call, once per material.
    allocate(moduli(m%n_materials), known(m%n_materials))
    known = .false.
    do ib = 1, solver%n_blocks
       k = solver%blocks(ib)%material
       if (.not. known(k)) then
          moduli(k) = checked_packaging_modulus(m%materials(k), solver%ncomp, solver%nshr, m%input_file)
          known(k) = .true.
       end if
    end do

    allocate(mass_e(part%n_local_elems, 1, solver%nen))
    do ib = 1, solver%n_blocks
       call setup_block(m, part, solver, solver%blocks(ib), moduli(solver%blocks(ib)%material), &
            user_field_active)
       nb = solver%blocks(ib)%count
       associate (blk => solver%blocks(ib))
         ! Through a block-sized array: a section of mass_e would be copied in and out.
         allocate(mass_b(nb, solver%nen))
         call lumped_mass(nb, solver%nen, blk%mass / blk%volume_ref, blk%volume_ref, mass_b)
         if (allocated(blk%mass_share)) call shared_node_mass(nb, solver%nen, blk%mass, blk%mass_share, mass_b)
         mass_e(blk%first:blk%first + nb - 1, 1, :) = mass_b
         deallocate(mass_b)
       end associate
    end do
    allocate(mass2(1, nn))
    call assemble_element_vectors(part, 1, mass_e, mass2)
    solver%mass = mass2(1, :)

    ! Initial conditions given on global nodes and elements; keep what is local.
    if (allocated(m%initial_velocities)) then
       do j = 1, size(m%initial_velocities)
          associate (ic => m%initial_velocities(j))
            do i = 1, size(ic%nodes)
               k = local_node_index(part, ic%nodes(i))
               if (k > 0 .and. ic%dof <= nd) solver%v(ic%dof, k) = ic%value
            end do
          end associate
       end do
    end if
    if (allocated(m%initial_stresses)) then
       do j = 1, size(m%initial_stresses)
          associate (ic => m%initial_stresses(j))
            do i = 1, size(ic%elems)
               le = local_elem_index(part, ic%elems(i))
               if (le == 0) cycle
               call locate(solver, le, ib, e)
               solver%blocks(ib)%stress(e, :) = ic%stress(1:solver%ncomp)
            end do
          end associate
       end do
    end if
    if (allocated(m%initial_fields)) then
       ! Element value = mean of its nodes' values (nodes without a value count as 0). Our models
       ! read field 1 with our user field only; a user's VUMAT gets every field and the
       ! temperature, a user's VUSDFLD every field and the temperature (vgetvrm).
       do ib = 1, solver%n_blocks
          associate (blk => solver%blocks(ib), mat => m%materials(solver%blocks(ib)%material))
            do e = 1, blk%count
               g = part%elem_global(blk%first + e - 1)
               if (mat%user_code) then
                  blk%temp(e) = mean_initial_field(m, g, 0)
                  do k = 1, mat%nfieldv
                     blk%field(e, k) = mean_initial_field(m, g, k)
                  end do
               else if (mat%user_field_code) then
                  ! a user's VUSDFLD on one of our models: every field it is given, and the
                  ! temperature for vgetvrm('TEMP')
                  blk%temp(e) = mean_initial_field(m, g, 0)
                  do k = 1, mat%nfieldv
                     blk%field(e, k) = mean_initial_field(m, g, k)
                  end do
               else if (blk%nfieldv >= 1 .and. mat%user_field) then
                  blk%field(e, 1) = mean_initial_field(m, g, 1)
               end if
            end do
          end associate
       end do
    end if
  end subroutine setup_solver

  subroutine setup_block(m, part, solver, blk, modulus, user_field_active)
    type(model_t), intent(in) :: m
    type(partition_t), intent(in) :: part
    type(solver_t), intent(in) :: solver
    type(element_block_t), intent(inout) :: blk
    real(dp), intent(in) :: modulus
    logical, intent(in) :: user_field_active
    integer :: nb, nd, ne, e, a, i
    real(dp), allocatable :: xe(:, :, :)

    nb = blk%count
    nd = solver%ndim
    ne = solver%nen
    associate (mat => m%materials(blk%material))
      blk%nstatev = max(1, mat%nstatev)
      blk%nfieldv = max(1, mat%nfieldv)
      allocate(blk%elem_number(nb), blk%volume_ref(nb), blk%bmat_ref(nb, nd, ne))
      allocate(blk%mass(nb), blk%hourglass(nb, nd, solver%nmode))
      if (m%mesh%element_type == element_cpe4r .or. m%mesh%element_type == element_cax4r) then
         allocate(blk%rotation(nb, 2, 1))
      else
         allocate(blk%rotation(nb, nd, nd))
      end if
      allocate(blk%stress(nb, solver%ncomp))
      allocate(blk%state(nb, blk%nstatev), blk%field(nb, blk%nfieldv), blk%e_int(nb), blk%e_inel(nb))
      allocate(blk%temp(nb))
      blk%temp = 0
      ! Hourglass forces of t_n for the ALLAE work: CPE4R keeps the generalised force Q (nb, 2, 1)
      ! of its one mode (cpe4r_hourglass_update), C3D8R the nodal forces (nb, 3, 8).
      if (m%mesh%element_type == element_cpe4r .or. m%mesh%element_type == element_cax4r) then
         allocate(blk%sigma_bv(nb), blk%force_hg(nb, nd, 1))
      else
         allocate(blk%sigma_bv(nb), blk%force_hg(nb, nd, ne))
      end if
      blk%sigma_bv = 0
      blk%force_hg = 0
      ! LE is kept where a VUSDFLD will ask for it, and everywhere when a step writes it (before,
      ! only the former: a requested LE field of any other material was silently all zeros).
      if ((user_field_active .and. mat%user_field) .or. element_variable_requested(m, 'LE')) then
         allocate(blk%log_strain(nb, solver%ncomp))
      else
         allocate(blk%log_strain(0, solver%ncomp))
      end if
      blk%log_strain = 0
      ! PE is integrated only when a step writes it (driver_plastic_strain).
      if (element_variable_requested(m, 'PE')) then
         allocate(blk%plastic_strain(nb, solver%ncomp))
      else
         allocate(blk%plastic_strain(0, solver%ncomp))
      end if
      blk%plastic_strain = 0
      allocate(xe(nb, nd, ne))
      do e = 1, nb
         blk%elem_number(e) = m%mesh%elem_id(part%elem_global(blk%first + e - 1))
      end do
      do a = 1, ne
         do i = 1, nd
            do e = 1, nb
               xe(e, i, a) = solver%x0(i, part%conn(a, blk%first + e - 1))
            end do
         end do
      end do
      if (m%mesh%element_type == element_cpe4r) then
         call cpe4r_geometry(nb, xe, m%sections(blk%section)%thickness, blk%volume_ref, blk%bmat_ref)
      else if (m%mesh%element_type == element_cax4r) then
         ! the full ring: the section thickness does not apply (Abaqus ignores it too)
         allocate(blk%mass_share(nb, 4), blk%bhoop_ref(nb, 4))
         call cax4r_geometry(nb, xe, blk%volume_ref, blk%bmat_ref, blk%bhoop_ref, blk%mass_share)
      else
         call c3d8r_geometry(nb, xe, blk%volume_ref, blk%bmat_ref)
      end if
      blk%mass = mat%density * blk%volume_ref
      call identity_rotation(nb, nd, size(blk%rotation, 3), blk%rotation)
      blk%hourglass = 0
      blk%stress = 0
      blk%state = 0
      blk%field = 0
      blk%e_int = 0
      blk%e_inel = 0
      blk%wave_modulus = modulus
      blk%vumat_needs_kinematics = mat%user_code .or. model_from_name(mat%vumat_name) == model_unknown
    end associate
  end subroutine setup_block

  !> CAX4R nodal masses: element mass × its nodal share (fem_cax4r: ∫ N_I r dA / ∫ r dA), in
  !> place of lumped_mass's equal quarters.
  pure subroutine shared_node_mass(nb, nen, element_mass, share, mass_b)
    integer, intent(in) :: nb, nen
    real(dp), intent(in) :: element_mass(nb), share(nb, nen)
    real(dp), intent(out) :: mass_b(nb, nen)
    integer :: a

    do a = 1, nen
       mass_b(:, a) = element_mass * share(:, a)
    end do
  end subroutine shared_node_mass

  !> Internal forces of the current global stresses on the reference configuration: the
  !> forces at t = 0 (initial stresses), before any increment.
  subroutine initial_internal_forces(m, solver)
    type(model_t), intent(in) :: m
    type(solver_t), intent(inout) :: solver
    integer :: ib, nb, e
    real(dp), allocatable :: fe(:, :, :), stress_global(:, :)
    type(block_assembly_t) :: ba

    call block_assembly_init(solver%part, solver%ndim, ba)
    call assembly_start(solver%f_int)
    do ib = 1, solver%n_blocks
       associate (blk => solver%blocks(ib))
         nb = blk%count
         allocate(fe(nb, solver%ndim, solver%nen), stress_global(nb, solver%ncomp))
         call stored_to_global(nb, solver%ndim, size(blk%rotation, 3), solver%ncomp, blk%rotation, blk%stress, &
              stress_global)
         if (m%mesh%element_type == element_cpe4r) then
            call cpe4r_internal_force(nb, blk%volume_ref, blk%bmat_ref, stress_global, fe)
         else if (m%mesh%element_type == element_cax4r) then
            call cax4r_internal_force(nb, blk%volume_ref, blk%bmat_ref, blk%bhoop_ref, stress_global, &
                 [(0.0_dp, e = 1, nb)], fe)
         else
            call c3d8r_internal_force(nb, blk%volume_ref, blk%bmat_ref, stress_global, fe)
         end if
         call assembly_add_block(solver%part, ba, blk%first, nb, fe, solver%f_int)
         deallocate(fe, stress_global)
       end associate
    end do
    call assembly_finish(solver%part, ba, solver%f_int)
  end subroutine initial_internal_forces

  !> Does any step write the element field `name` (LE, PE)?
  pure logical function element_variable_requested(m, name) result(requested)
    type(model_t), intent(in) :: m
    character(len=*), intent(in) :: name
    integer :: i, j

    requested = .false.
    do i = 1, m%n_steps
       if (.not. allocated(m%steps(i)%field_outputs)) cycle
       do j = 1, size(m%steps(i)%field_outputs)
          if (.not. allocated(m%steps(i)%field_outputs(j)%element_variables)) cycle
          if (any(m%steps(i)%field_outputs(j)%element_variables == name)) requested = .true.
       end do
    end do
  end function element_variable_requested

  !> Block and position of local element le.
  pure subroutine locate(solver, le, ib, e)
    type(solver_t), intent(in) :: solver
    integer, intent(in) :: le
    integer, intent(out) :: ib, e

    do ib = 1, solver%n_blocks
       if (le >= solver%blocks(ib)%first .and. le < solver%blocks(ib)%first + solver%blocks(ib)%count) then
          e = le - solver%blocks(ib)%first + 1
          return
       end if
    end do
    ib = 1
    e = 1
  end subroutine locate

  !> Field `variable` (0: the temperature) of global element g: the mean of its nodes' values.
  real(dp) function mean_initial_field(m, g, variable)
    type(model_t), intent(in) :: m
    integer, intent(in) :: g, variable
    integer :: a, j, i
    real(dp) :: total

    total = 0
    do a = 1, m%mesh%nen
       do j = 1, size(m%initial_fields)
          if (m%initial_fields(j)%variable /= variable) cycle
          do i = 1, size(m%initial_fields(j)%nodes)
             if (m%initial_fields(j)%nodes(i) == m%mesh%conn(a, g)) total = total + m%initial_fields(j)%value
          end do
       end do
    end do
    mean_initial_field = total / m%mesh%nen
  end function mean_initial_field
end module driver_setup
