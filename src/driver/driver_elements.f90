!> The element phase of an increment, block by block: kinematics on the mid-increment
!> configuration, corotational strain increment, [VUSDFLD] + VUMAT, stress back to the global
!> frame, bulk viscosity, internal and hourglass forces, element stable increment and energies.
!> Each block's element forces are assembled into solver%f_int as soon as the block is done
!> (parallel_assembly's block form: the same sums as the one-call assembly, in cache).
module driver_elements
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use, intrinsic :: iso_fortran_env, only: int64
  use base_kinds, only: dp
  use error_report, only: raise_error
  use model, only: model_t
  use model_mesh, only: element_cpe4r, element_cax4r
  use driver_solver, only: solver_t, element_block_t
  use driver_effects, only: effect_elements, effect_material, effect_hourglass, &
       effect_bulk_viscosity, effect_user_field, effect_assembly
  use output_effects, only: effects_t
  use driver_temperature, only: element_temperatures
  use material_door, only: vumat_work_t, call_material, vumat_work_init
  use fem_cpe4r, only: cpe4r_increment_kinematics, cpe4r_internal_force, cpe4r_internal_force_bv, &
       cpe4r_hourglass_update
  use fem_c3d8r, only: c3d8r_kinematics, c3d8r_internal_force, c3d8r_hourglass
  use fem_cax4r, only: cax4r_increment_kinematics, cax4r_internal_force, cax4r_hourglass_update, &
       cax4r_hoop_stretch
  use fem_corotation, only: corotational_increment, deformation_gradient, to_global, rotation_matrix, &
       vumat_defgrad, vumat_stretch
  use fem_bulk_viscosity, only: bulk_viscosity
  use driver_plastic_strain, only: add_elastic_compliance
  use parallel_partition, only: partition_t
  use parallel_assembly, only: block_assembly_t, block_assembly_init, assembly_start, &
       assembly_add_block, assembly_finish
  use fem_stable_dt, only: element_stable_dt
  use fem_inversion, only: check_inversion, inversion_reason_text, default_min_volume_ratio
  use fem_hourglass, only: hourglass_viscous, default_hourglass_viscous_coefficient, &
       default_hourglass_stiffness_coefficient
  implicit none
  private

  !> Per-block work arrays of the element phase, sized once for the largest block.
  type, public :: element_work_t
     real(dp), allocatable :: xe_old(:, :, :), du(:, :, :), xe_mid(:, :, :), xe_new(:, :, :)
     real(dp), allocatable :: xe_ref(:, :, :)         !< CPE4R: X of the nodes (B0, V0 formed again)
     real(dp), allocatable :: bmat_mid(:, :, :), bmat_new(:, :, :), fe(:, :, :), fe_hg(:, :, :)
     real(dp), allocatable :: volume_mid(:), volume_new(:), char_length(:), density(:), modulus(:)
     real(dp), allocatable :: volume_abs(:)           !< |volume_mid| (no temporary per call)
     real(dp), allocatable :: gamma(:, :), bsq(:)     !< CPE4R: hourglass γ, Σ B² of B_{n+½}
     real(dp), allocatable :: bhoop_new(:, :), area_mid(:)  !< CAX4R: hoop row of B̄_{n+1}, |A| of x_{n+½}
     real(dp), allocatable :: hoop_stretch(:)         !< CAX4R: F33 = U33 for the VUMAT
     real(dp), allocatable :: e_hg_kernel(:)          !< the hourglass kernel's own ΔE (not booked)
     real(dp), allocatable :: wave_speed(:), sigma_bv(:), xi(:), e_bv(:), e_hg(:), dt_el(:)
     real(dp), allocatable :: strain_inc(:, :), spin_inc(:, :), strain_corot(:, :), rel_spin(:, :)
     real(dp), allocatable :: r_mid(:, :, :), r_new(:, :, :), f_old(:, :, :), f_new(:, :, :)
     real(dp), allocatable :: r_plane(:, :, :)        !< CPE4R: R_{n+1} in the stored plane form (nb, 2, 1)
     real(dp), allocatable :: r_old(:, :, :)          !< CPE4R: R_n as a matrix, for vumat_stretch
     real(dp), allocatable :: sigma_bv_swap(:)        !< unallocated: holder for the σ_bv exchange
     real(dp), allocatable :: stretch_old(:, :), stretch_new(:, :), defgrad_old(:, :), defgrad_new(:, :)
     real(dp), allocatable :: stress_force(:, :), stress_global(:, :)
     integer, allocatable :: reason(:)
     type(vumat_work_t) :: vumat
  end type element_work_t

  !> Work arrays for every block size met so far: each block works in a set of exactly its own
  !> size, so the (1:nb, ...) sections passed to the kernels are contiguous and never copied.
  !> (One set sized for the largest block made every smaller block — the last of each section —
  !> copy some forty arrays in and out of the kernels, every increment.) A rank meets few sizes:
  !> block_size and the remainders of its sections.
  type, public :: element_workspace_t
     integer :: ndim = 0, nen = 0, ncomp = 0, nshr = 0, nstatev = 1, nfieldv = 1
     type(element_work_t), allocatable :: sets(:)
     type(block_assembly_t) :: assembly               !< f_int block by block
     integer(int64) :: touch_checksum = 0             !< keeps touch_block's loads (not used)
  end type element_workspace_t

  public :: element_work_init, element_workspace_init, element_phase

contains

  subroutine element_work_init(w, nmax, ndim, nen, ncomp, nshr)
    type(element_work_t), intent(inout) :: w
    integer, intent(in) :: nmax, ndim, nen, ncomp, nshr

    allocate(w%xe_old(nmax, ndim, nen), w%du(nmax, ndim, nen), w%xe_mid(nmax, ndim, nen))
    allocate(w%xe_new(nmax, ndim, nen), w%bmat_mid(nmax, ndim, nen), w%bmat_new(nmax, ndim, nen))
    allocate(w%xe_ref(nmax, ndim, nen))
    allocate(w%fe(nmax, ndim, nen), w%fe_hg(nmax, ndim, nen))
    allocate(w%volume_mid(nmax), w%volume_new(nmax), w%char_length(nmax), w%density(nmax))
    allocate(w%modulus(nmax), w%wave_speed(nmax), w%sigma_bv(nmax), w%xi(nmax), w%e_bv(nmax))
    allocate(w%e_hg(nmax), w%dt_el(nmax), w%reason(nmax), w%volume_abs(nmax), w%e_hg_kernel(nmax))
    allocate(w%gamma(nmax, nen), w%bsq(nmax))
    allocate(w%bhoop_new(nmax, nen), w%area_mid(nmax), w%hoop_stretch(nmax))
    allocate(w%strain_inc(nmax, ncomp), w%spin_inc(nmax, nshr), w%strain_corot(nmax, ncomp))
    allocate(w%rel_spin(nmax, nshr), w%stress_force(nmax, ncomp), w%stress_global(nmax, ncomp))
    allocate(w%r_mid(nmax, ndim, ndim), w%r_new(nmax, ndim, ndim), w%f_old(nmax, ndim, ndim))
    allocate(w%f_new(nmax, ndim, ndim), w%r_old(nmax, ndim, ndim), w%r_plane(nmax, 2, 1))
    allocate(w%stretch_old(nmax, ncomp), w%stretch_new(nmax, ncomp))
    allocate(w%defgrad_old(nmax, ncomp + nshr), w%defgrad_new(nmax, ncomp + nshr))
    ! Identity F and U for blocks whose VUMAT does not read them (they are not recomputed).
    w%defgrad_old = 0
    w%defgrad_old(:, 1:3) = 1
    w%defgrad_new = w%defgrad_old
    w%stretch_old = 0
    w%stretch_old(:, 1:3) = 1
    w%stretch_new = w%stretch_old
    w%e_bv = 0
    w%e_hg = 0
  end subroutine element_work_init

  subroutine element_workspace_init(ws, part, ndim, nen, ncomp, nshr, nstatev, nfieldv)
    type(element_workspace_t), intent(out) :: ws
    type(partition_t), intent(in) :: part
    integer, intent(in) :: ndim, nen, ncomp, nshr, nstatev, nfieldv

    ws%ndim = ndim
    ws%nen = nen
    ws%ncomp = ncomp
    ws%nshr = nshr
    ws%nstatev = nstatev
    ws%nfieldv = nfieldv
    allocate(ws%sets(0))
    call block_assembly_init(part, ndim, ws%assembly)
  end subroutine element_workspace_init

  !> Index of the work set of exactly nb elements, made when first needed.
  integer function work_set(ws, nb) result(k)
    type(element_workspace_t), intent(inout) :: ws
    integer, intent(in) :: nb
    type(element_work_t), allocatable :: grown(:)

    do k = 1, size(ws%sets)
       if (size(ws%sets(k)%xe_old, 1) == nb) return
    end do
    allocate(grown(size(ws%sets) + 1))
    grown(1:size(ws%sets)) = ws%sets
    call move_alloc(grown, ws%sets)
    k = size(ws%sets)
    call element_work_init(ws%sets(k), nb, ws%ndim, ws%nen, ws%ncomp, ws%nshr)
    call vumat_work_init(ws%sets(k)%vumat, nb, ws%ncomp, ws%nshr, ws%nstatev, ws%nfieldv)
  end function work_set

  !> All blocks of this rank for one increment, from the nodal x_old = x0 + u_n and
  !> du = dt v_{n+1/2} (formed per gathered node, as finish_nodes forms it: no nodal array). Sets solver%f_int (assembled; collective over the
  !> neighbouring ranks), the element energies, and returns the smallest
  !> element stable increment (unscaled) with the user number of its element. Stops with the
  !> element number, the time and the reason when an element inverts or collapses.
  !> x0 + u is formed per gathered node (the same sum as the nodal array x0 + u it replaces:
  !> that actual argument cost a node-sized temporary, allocated and freed every increment).
  subroutine element_phase(m, solver, effects, ws, dt, b1, b2, dt_min, dt_elem)
    type(model_t), intent(in) :: m
    type(solver_t), intent(inout) :: solver
    type(effects_t), intent(inout) :: effects
    type(element_workspace_t), intent(inout) :: ws
    real(dp), intent(in) :: dt, b1, b2
    real(dp), intent(out) :: dt_min
    integer, intent(out) :: dt_elem
    integer :: ib, nb, e, nd, ne, iw

    dt_min = huge(1.0_dp)
    dt_elem = 0
    nd = solver%ndim
    ne = solver%nen
    ! The 'elements' timer runs except while a nested effect (material, hourglass, ...) has its
    ! own, so the shares in the report add up to the wall time.
    call assembly_start(solver%f_int)
    call effects%start(effect_elements)
    do ib = 1, solver%n_blocks
       iw = work_set(ws, solver%blocks(ib)%count)
       associate (blk => solver%blocks(ib), w => ws%sets(iw))
         nb = blk%count
         call touch_block(blk, m%mesh%element_type == element_cpe4r, &
              m%sections(blk%section)%hourglass /= hourglass_viscous, ws%touch_checksum)
         if (nd == 2) then
            call gather_block_2d(nb, ne, solver%part%conn(:, blk%first:blk%first + nb - 1), solver%x0, &
                 solver%u, dt, solver%v, w%xe_ref, w%xe_old, w%du)
         else
            call gather_block(nb, nd, ne, solver%part%conn(:, blk%first:blk%first + nb - 1), solver%x0, &
                 solver%u, dt, solver%v, w%xe_old, w%du, w%xe_mid, w%xe_new)
         end if
         call block_increment(m, solver, blk, effects, w, nb, nd, ne, dt, b1, b2)
         do e = 1, nb
            if (w%dt_el(e) < dt_min) then
               dt_min = w%dt_el(e)
               dt_elem = blk%elem_number(e)
            end if
         end do
         call effects%stop(effect_elements)
         call effects%start(effect_assembly)
         call assembly_add_block(solver%part, ws%assembly, blk%first, nb, w%fe, solver%f_int)
         call effects%stop(effect_assembly)
         call effects%start(effect_elements)
       end associate
    end do
    call effects%stop(effect_elements)
    call effects%start(effect_assembly)
    call assembly_finish(solver%part, ws%assembly, solver%f_int)
    call effects%stop(effect_assembly)
  end subroutine element_phase

  !> One load per cache line of every array of the block that the increment reads, before its
  !> kernels run. The kernels interleave those loads with long chains of arithmetic, so a
  !> block whose arrays had left the cache (a 20 000-element model does not fit in a shared L3)
  !> waited for them a few lines at a time; these loads are independent of each other and of
  !> any arithmetic, so the misses overlap and the lines arrive at the memory's bandwidth.
  !> 15 % off the CPE4R Mohr-Coulomb loop of the benchmark hopper (median of 5 alternated runs);
  !> results unchanged (nothing is written). `plane`: CPE4R forms B0 and V0 again from the
  !> reference coordinates (and the mass from them), so volume_ref, bmat_ref and mass are not
  !> read; `hourglass_state`: the stiffness form reads its hourglass state (the viscous form has
  !> none).
  subroutine touch_block(blk, plane, hourglass_state, checksum)
    type(element_block_t), intent(in) :: blk
    logical, intent(in) :: plane, hourglass_state
    integer(int64), intent(inout) :: checksum

    call touch_lines(size(blk%rotation), blk%rotation, checksum)
    call touch_lines(size(blk%stress), blk%stress, checksum)
    call touch_lines(size(blk%state), blk%state, checksum)
    call touch_lines(size(blk%e_int), blk%e_int, checksum)
    call touch_lines(size(blk%e_inel), blk%e_inel, checksum)
    call touch_lines(size(blk%sigma_bv), blk%sigma_bv, checksum)
    if (hourglass_state) call touch_lines(size(blk%hourglass), blk%hourglass, checksum)
    call touch_lines(size(blk%force_hg), blk%force_hg, checksum)
    call touch_lines(size(blk%log_strain), blk%log_strain, checksum)
    call touch_lines(size(blk%plastic_strain), blk%plastic_strain, checksum)
    if (.not. plane) then
       call touch_lines(size(blk%mass), blk%mass, checksum)
       call touch_lines(size(blk%volume_ref), blk%volume_ref, checksum)
       if (blk%vumat_needs_kinematics) call touch_lines(size(blk%bmat_ref), blk%bmat_ref, checksum)
    end if
    if (blk%mass_scaled) call touch_lines(size(blk%mass_scale), blk%mass_scale, checksum)
  end subroutine touch_block

  !> Loads a(1), a(9), ... and a(n): every 64-byte line of a once. Their bits go into an
  !> integer checksum the workspace keeps, so the loads stay (integer operations: no
  !> floating-point exception whatever the values).
  pure subroutine touch_lines(n, a, checksum)
    integer, intent(in) :: n
    real(dp), intent(in) :: a(n)
    integer(int64), intent(inout) :: checksum
    integer :: i

    if (n == 0) return
    do i = 1, n, 8
       checksum = ieor(checksum, transfer(a(i), checksum))
    end do
    checksum = ieor(checksum, transfer(a(n), checksum))
  end subroutine touch_lines

  !> Element coordinates x_n = x0 + u_n, x_{n+½}, x_{n+1} and du of a block from the nodal arrays,
  !> in one pass. A subroutine with explicit-shape dummies: written in place on the work set's
  !> allocatable components, the loop reloaded their descriptors at every store.
  subroutine gather_block(nb, nd, ne, conn, x0, u, dt, v, xe_old, du, xe_mid, xe_new)
    integer, intent(in) :: nb, nd, ne
    integer, intent(in) :: conn(ne, nb)
    real(dp), intent(in) :: x0(nd, *), u(nd, *), dt, v(nd, *)
    real(dp), intent(out) :: xe_old(nb, nd, ne), du(nb, nd, ne), xe_mid(nb, nd, ne), xe_new(nb, nd, ne)
    integer :: e, i, a, k
    real(dp) :: xo, d

    ! The node index once per (node, element), all components from it (they are adjacent in
    ! the nodal arrays). gather_block_2d: the same with a literal component count.
    do a = 1, ne
       do e = 1, nb
          k = conn(a, e)
          do i = 1, nd
             xo = x0(i, k) + u(i, k)
             d = dt * v(i, k)
             xe_old(e, i, a) = xo
             du(e, i, a) = d
             xe_mid(e, i, a) = xo + 0.5_dp * d
             xe_new(e, i, a) = xo + d
          end do
       end do
    end do
  end subroutine gather_block

  !> gather_block for two components (CPE4R): X, x_n and du. cpe4r_increment_kinematics forms
  !> x_{n+½} and x_{n+1} from them in registers, with the expressions of gather_block (writing
  !> and reading back two more (nb, 2, 4) arrays per block cost more than the additions).
  subroutine gather_block_2d(nb, ne, conn, x0, u, dt, v, xe_ref, xe_old, du)
    integer, intent(in) :: nb, ne
    integer, intent(in) :: conn(ne, nb)
    real(dp), intent(in) :: x0(2, *), u(2, *), dt, v(2, *)
    real(dp), intent(out) :: xe_ref(nb, 2, ne), xe_old(nb, 2, ne), du(nb, 2, ne)
    integer :: e, a, k
    real(dp) :: xr1, xr2, xo1, xo2, d1, d2

    do a = 1, ne
       do e = 1, nb
          k = conn(a, e)
          xr1 = x0(1, k)
          xr2 = x0(2, k)
          xo1 = xr1 + u(1, k)
          xo2 = xr2 + u(2, k)
          d1 = dt * v(1, k)
          d2 = dt * v(2, k)
          xe_ref(e, 1, a) = xr1
          xe_ref(e, 2, a) = xr2
          xe_old(e, 1, a) = xo1
          xe_old(e, 2, a) = xo2
          du(e, 1, a) = d1
          du(e, 2, a) = d2
       end do
    end do
  end subroutine gather_block_2d

  !> One block's increment; the element forces end in w%fe.
  subroutine block_increment(m, solver, blk, effects, w, nb, nd, ne, dt, b1, b2)
    type(model_t), intent(in) :: m
    type(solver_t), intent(inout) :: solver
    type(element_block_t), intent(inout) :: blk
    type(effects_t), intent(inout) :: effects
    type(element_work_t), intent(inout) :: w
    integer, intent(in) :: nb, nd, ne
    real(dp), intent(in) :: dt, b1, b2
    integer :: nc, ns
    logical :: plane, bulk, axisym

    nc = solver%ncomp
    ns = solver%nshr
    ! plane: the 2D paths (plane rotation, fused kernels); axisym: CAX4R's own kernels among them
    axisym = m%mesh%element_type == element_cax4r
    plane = m%mesh%element_type == element_cpe4r .or. axisym
    call block_kinematics(m, solver, blk, w, nb, nd, ne, dt, plane, axisym)
    if (blk%vumat_needs_kinematics) then
       call deformation_gradient(nb, nd, ne, blk%bmat_ref, w%xe_old(1:nb, :, :), w%f_old(1:nb, :, :))
       call vumat_defgrad(nb, nd, w%f_old(1:nb, :, :), w%defgrad_old(1:nb, :))
       call vumat_defgrad(nb, nd, w%f_new(1:nb, :, :), w%defgrad_new(1:nb, :))
       if (plane) then
          call rotation_matrix(nb, nd, 1, blk%rotation, w%r_old)
          call vumat_stretch(nb, nd, w%r_old, w%f_old(1:nb, :, :), w%stretch_old(1:nb, :))
       else
          call vumat_stretch(nb, nd, blk%rotation, w%f_old(1:nb, :, :), w%stretch_old(1:nb, :))
       end if
       call vumat_stretch(nb, nd, w%r_new(1:nb, :, :), w%f_new(1:nb, :, :), w%stretch_new(1:nb, :))
       if (axisym) then
          ! the hoop stretch r̄/R̄ is F33 = U33 (θ is a principal direction)
          call cax4r_hoop_stretch(nb, w%xe_ref, w%xe_old, w%hoop_stretch)
          w%defgrad_old(1:nb, 3) = w%hoop_stretch
          w%stretch_old(1:nb, 3) = w%hoop_stretch
          w%xe_new(1:nb, :, :) = w%xe_old(1:nb, :, :) + w%du(1:nb, :, :)
          call cax4r_hoop_stretch(nb, w%xe_ref, w%xe_new, w%hoop_stretch)
          w%defgrad_new(1:nb, 3) = w%hoop_stretch
          w%stretch_new(1:nb, 3) = w%hoop_stretch
       end if
       call centroids(nb, nd, ne, w%xe_old, w%du, w%vumat%coord)
    end if
    ! *INITIAL CONDITIONS, TYPE=TEMPERATURE and the step's *TEMPERATURE at t_n and t_n+1, for a
    ! user's VUMAT (tempOld, tempNew) and a user's VUSDFLD (vgetvrm('TEMP')); ours ignore it.
    if (blk%vumat_needs_kinematics .or. m%materials(blk%material)%user_field_code) then
       call element_temperatures(m, solver, blk, solver%step_time, solver%total_time, w%vumat%temp(1:nb))
       call element_temperatures(m, solver, blk, solver%step_time + dt, solver%total_time + dt, &
            w%vumat%temp_new(1:nb))
    end if

    ! PE (only when written): Δε^p = Δε − C⁻¹(σ_new − σ_old); the σ_old part before the call.
    if (size(blk%plastic_strain, 1) == nb) then
       associate (props => m%materials(blk%material)%props)
         call add_elastic_compliance(nb, nc, props(1), props(2), 1.0_dp, blk%stress, blk%plastic_strain)
       end associate
       blk%plastic_strain = blk%plastic_strain + w%strain_corot(1:nb, :)
    end if
    call effects%stop(effect_elements)
    call effects%start(effect_material)
    call call_material(m%materials(blk%material), nb, nc, ns, blk%elem_number, solver%step_time + dt, &
         solver%total_time + dt, dt, w%char_length(1:nb), w%density(1:nb), w%strain_corot(1:nb, :), &
         w%rel_spin(1:nb, :), w%stretch_old(1:nb, :), w%stretch_new(1:nb, :), w%defgrad_old(1:nb, :), &
         w%defgrad_new(1:nb, :), blk%log_strain, blk%stress, blk%state, blk%field, blk%e_int, &
         blk%e_inel, w%vumat)
    call effects%stop(effect_material)
    if (m%materials(blk%material)%user_field) then
       ! LE for vgetvrm: VUSDFLD has just seen the start-of-increment value.
       call effects%start(effect_user_field)
       blk%log_strain = blk%log_strain + w%strain_corot(1:nb, :)
       call effects%stop(effect_user_field)
    else if (size(blk%log_strain, 1) == nb) then
       ! LE kept for the field output only.
       blk%log_strain = blk%log_strain + w%strain_corot(1:nb, :)
    end if
    call effects%start(effect_elements)
    if (size(blk%plastic_strain, 1) == nb) then
       associate (props => m%materials(blk%material)%props)
         call add_elastic_compliance(nb, nc, props(1), props(2), -1.0_dp, blk%stress, blk%plastic_strain)
       end associate
    end if
    ! The global stress of t_{n+1} lives in the work set only (the output forms it again from
    ! the same R and σ: the same bits); a block array of it was written to memory every increment.
    ! R_{n+1} is w%r_new for the rest of the increment; the block takes it at the end.
    call to_global(nb, nd, nc, w%r_new, blk%stress, w%stress_global)

    ! Mass scaling (driver_mass_scaling): wave speed, stable increment, bulk viscosity and
    ! hourglass see the scaled inertia; the VUMAT above got the physical density.
    if (blk%mass_scaled) w%density(1:nb) = w%density(1:nb) * blk%mass_scale
    w%wave_speed(1:nb) = sqrt(blk%wave_modulus / w%density(1:nb))
    ! CPE4R: the internal-force kernel adds σ_bv itself (no stress copy, no three passes adding it).
    if (.not. plane) w%stress_force(1:nb, :) = w%stress_global
    bulk = effects%active(effect_bulk_viscosity)
    if (.not. bulk) w%xi(1:nb) = 0
    if (bulk) then
       call effects%stop(effect_elements)
       call effects%start(effect_bulk_viscosity)
       call block_bulk_viscosity(blk, w, nb, nc, dt, b1, b2, plane, solver%e_viscous)
       call effects%stop(effect_bulk_viscosity)
       call effects%start(effect_elements)
    end if
    if (axisym) then
       ! w%xi is zero without bulk viscosity: no σ_bv then
       call cax4r_internal_force(nb, w%volume_new, w%bmat_new, w%bhoop_new, w%stress_global, &
            merge(blk%sigma_bv, w%xi, bulk), w%fe)
    else if (plane .and. bulk) then
       call cpe4r_internal_force_bv(nb, w%volume_new, w%bmat_new, w%stress_global, blk%sigma_bv, w%fe)
    else if (plane) then
       call cpe4r_internal_force(nb, w%volume_new, w%bmat_new, w%stress_global, w%fe)
    else
       call c3d8r_internal_force(nb, w%volume_new(1:nb), w%bmat_new(1:nb, :, :), w%stress_force(1:nb, :), &
            w%fe(1:nb, :, :))
    end if

    if (effects%active(effect_hourglass)) then
       call effects%stop(effect_elements)
       call effects%start(effect_hourglass)
       call block_hourglass(m, blk, w, nb, nd, ne, dt, plane, axisym, solver%e_artificial)
       call effects%stop(effect_hourglass)
       call effects%start(effect_elements)
    end if
    ! The next increment's stable time uses the current geometry and the damping just found.
    call element_stable_dt(nb, w%char_length(1:nb), w%wave_speed(1:nb), w%xi(1:nb), w%dt_el(1:nb))

    ! R_{n+1} becomes the block's rotation by exchanging the arrays (the work set has exactly nb
    ! rows); the old R_n is overwritten by the next corotational step. CPE4R keeps the plane form.
    if (plane) then
       call exchange_rotations(blk%rotation, w%r_plane)
    else
       call exchange_rotations(blk%rotation, w%r_new)
    end if
  end subroutine block_increment

  !> The block's kinematics of the increment: strain increment, rotations, the inversion check
  !> (a stop naming the element), corotational strain and spin, density at mid-increment.
  subroutine block_kinematics(m, solver, blk, w, nb, nd, ne, dt, plane, axisym)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    type(element_block_t), intent(inout) :: blk
    type(element_work_t), intent(inout) :: w
    integer, intent(in) :: nb, nd, ne
    real(dp), intent(in) :: dt
    logical, intent(in) :: plane, axisym
    integer :: e
    character(len=64) :: text

    if (axisym) then
       call cax4r_increment_kinematics(nb, w%xe_old, w%du, blk%bmat_ref, blk%volume_ref, &
            default_min_volume_ratio, m%materials(blk%material)%density, blk%rotation, w%volume_mid, &
            w%volume_abs, w%area_mid, w%density, w%gamma, w%bsq, w%strain_inc, w%volume_new, w%bmat_new, &
            w%bhoop_new, w%char_length, w%reason, w%r_mid, w%r_new, w%r_plane, w%f_new, w%strain_corot, &
            w%rel_spin)
    else if (plane) then
       ! Kinematics, inversion check, corotational step and density in one pass.
       ! The section's thickness and the material's density, from which the set-up formed V0 and
       ! blk%mass = ρ0 V0 (kinematics forms ρ0 V0 again: the same bits).
       call cpe4r_increment_kinematics(nb, m%sections(blk%section)%thickness, w%xe_old, w%du, w%xe_ref, &
            default_min_volume_ratio, m%materials(blk%material)%density, blk%rotation, w%volume_mid, &
            w%volume_abs, w%density, &
            w%gamma, w%bsq, w%strain_inc, w%volume_new, w%bmat_new, w%char_length, w%reason, &
            w%r_mid, w%r_new, w%r_plane, w%f_new, w%strain_corot, w%rel_spin)
    else
       call c3d8r_kinematics(nb, w%xe_mid(1:nb, :, :), w%du(1:nb, :, :), w%xe_new(1:nb, :, :), &
            w%volume_mid(1:nb), w%bmat_mid(1:nb, :, :), w%strain_inc(1:nb, :), w%spin_inc(1:nb, :), &
            w%volume_new(1:nb), w%bmat_new(1:nb, :, :), w%char_length(1:nb))
       call check_inversion(nb, nd, ne, w%xe_new(1:nb, :, :), w%volume_new(1:nb), blk%volume_ref, &
            default_min_volume_ratio, w%reason(1:nb))
    end if
    if (any(w%reason(1:nb) /= 0)) then
       e = findloc(w%reason(1:nb) /= 0, .true., dim=1)
       ! The reason text is long: numbers go through a small buffer, the message is built by
       ! concatenation (an internal write of the whole message overflowed its buffer).
       write (text, '(a,i0,a,es12.5)') 'element ', blk%elem_number(e), ' at total time ', &
            solver%total_time + dt
       if (.not. ieee_is_finite(w%volume_new(e))) then
          ! not an inversion: the motion became NaN or Inf (loads or masses far out of scale)
          call raise_error(trim(m%input_file), 0, trim(text) // ': its node coordinates became infinite or not a number; ' // &
               'expected finite motion (look for loads, masses or material constants far out of scale)')
       end if
       call raise_error(trim(m%input_file), 0, trim(text) // ': ' // inversion_reason_text(w%reason(e)) // &
            ' (increment too large, mesh too coarse for the deformation, or material too soft)')
    end if

    if (.not. plane) then
       call corotational_increment(nb, nd, ne, blk%bmat_ref, w%xe_mid(1:nb, :, :), w%xe_new(1:nb, :, :), &
            w%strain_inc(1:nb, :), w%spin_inc(1:nb, :), blk%rotation, w%r_mid(1:nb, :, :), &
            w%r_new(1:nb, :, :), w%f_new(1:nb, :, :), w%strain_corot(1:nb, :), w%rel_spin(1:nb, :))
       ! Current density at mid-increment, as Abaqus passes it (mass is conserved per element).
       w%volume_abs(1:nb) = abs(w%volume_mid(1:nb))
       w%density(1:nb) = blk%mass / w%volume_abs(1:nb)
    end if
  end subroutine block_kinematics

  !> Bulk viscosity of the block: σ_bv of the increment (the block keeps it) and ALLVD.
  subroutine block_bulk_viscosity(blk, w, nb, nc, dt, b1, b2, plane, e_viscous)
    type(element_block_t), intent(inout) :: blk
    type(element_work_t), intent(inout) :: w
    integer, intent(in) :: nb, nc
    real(dp), intent(in) :: dt, b1, b2
    logical, intent(in) :: plane
    real(dp), intent(inout) :: e_viscous
    integer :: e

    call bulk_viscosity(nb, nc, w%strain_inc(1:nb, :), dt, w%density(1:nb), w%wave_speed(1:nb), &
         w%char_length(1:nb), w%volume_abs(1:nb), b1, b2, w%sigma_bv(1:nb), w%xi(1:nb), &
         w%e_bv(1:nb))
    if (.not. plane) then
       do e = 1, 3
          w%stress_force(1:nb, e) = w%stress_force(1:nb, e) + w%sigma_bv(1:nb)
       end do
    end if
    ! ALLVD with the trapezoidal rule, like the material's stress power: the pressure found now
    ! acts in the forces at t_{n+1}, the previous one in those at t_n, and the balance charges
    ! the work of the forces as ½ (f_n + f_{n+1})·Δu. The kernel's σ_bv^{n+½} tr Δε V alone
    ! overstates ALLVD where the rate jumps (a wave front: 0.3 % of the energies).
    do e = 1, nb
       w%e_bv(e) = 0.5_dp * (blk%sigma_bv(e) + w%sigma_bv(e)) * (w%strain_inc(e, 1) + w%strain_inc(e, 2) &
            + w%strain_inc(e, 3)) * abs(w%volume_mid(e))
    end do
    ! σ_bv becomes the block's by exchanging the arrays (both have exactly nb elements).
    call move_alloc(blk%sigma_bv, w%sigma_bv_swap)
    call move_alloc(w%sigma_bv, blk%sigma_bv)
    call move_alloc(w%sigma_bv_swap, w%sigma_bv)
    e_viscous = e_viscous + sum(w%e_bv(1:nb))
  end subroutine block_bulk_viscosity

  !> Hourglass forces of the block (its section's form and coefficient), added to w%fe, and ALLAE.
  subroutine block_hourglass(m, blk, w, nb, nd, ne, dt, plane, axisym, e_artificial)
    type(model_t), intent(in) :: m
    type(element_block_t), intent(inout) :: blk
    type(element_work_t), intent(inout) :: w
    integer, intent(in) :: nb, nd, ne
    real(dp), intent(in) :: dt
    logical, intent(in) :: plane, axisym
    real(dp), intent(inout) :: e_artificial
    integer :: a, i, hourglass_kind
    real(dp) :: hourglass_coefficient

    ! The hourglass form and coefficient of this block's section (a block has one section).
    ! Before, every element used the first section's, whatever its own *SECTION CONTROLS said.
    hourglass_kind = m%sections(blk%section)%hourglass
    hourglass_coefficient = m%sections(blk%section)%hourglass_coefficient
    if (hourglass_coefficient <= 0) hourglass_coefficient = merge(default_hourglass_viscous_coefficient, &
         default_hourglass_stiffness_coefficient, hourglass_kind == hourglass_viscous)
    w%modulus(1:nb) = blk%wave_modulus
    ! ALLAE as the work of the hourglass forces with the trapezoidal rule, ½ (f_n + f_{n+1})·Δu,
    ! as the balance charges it (the kernels' C q²/Δt of the viscous form pairs the force of
    ! t_{n+1} with this increment alone; where the rates change fast — a block released from
    ! its initial stress — that lag put 1 % of the energies into ETOTAL). For the stiffness form
    ! the two agree up to the rotation of the increment. blk%force_hg keeps f_{n+1} for the
    ! next increment: C3D8R the change of fe the hourglass forces make, CPE4R its generalised
    ! force (cpe4r_hourglass_update).
    if (axisym) then
       call cax4r_hourglass_update(nb, w%gamma, w%bsq, w%volume_mid, w%area_mid, w%du, dt, w%density, &
            w%modulus, hourglass_kind, hourglass_coefficient, w%r_mid, w%r_new, blk%hourglass, w%fe, &
            blk%force_hg, w%e_hg_kernel, w%e_hg)
    else if (plane) then
       ! One fused kernel: forces, force change and work in one pass over the block.
       call cpe4r_hourglass_update(nb, m%sections(blk%section)%thickness, w%gamma, w%bsq, w%volume_mid, &
            w%du, dt, w%density, w%modulus, hourglass_kind, hourglass_coefficient, w%r_mid, w%r_new, &
            blk%hourglass, w%fe, blk%force_hg, w%e_hg_kernel, w%e_hg)
    else
       w%fe_hg(1:nb, :, :) = w%fe(1:nb, :, :)
       call c3d8r_hourglass(nb, w%xe_mid(1:nb, :, :), w%volume_mid(1:nb), w%bmat_mid(1:nb, :, :), &
            w%du(1:nb, :, :), dt, w%density(1:nb), w%modulus(1:nb), hourglass_kind, &
            hourglass_coefficient, w%r_mid(1:nb, :, :), w%r_new, blk%hourglass, w%fe(1:nb, :, :), &
            w%e_hg(1:nb))
       w%fe_hg(1:nb, :, :) = w%fe(1:nb, :, :) - w%fe_hg(1:nb, :, :)
       w%e_hg(1:nb) = 0
       do a = 1, ne
          do i = 1, nd
             w%e_hg(1:nb) = w%e_hg(1:nb) + 0.5_dp * (blk%force_hg(:, i, a) + w%fe_hg(1:nb, i, a)) &
                  * w%du(1:nb, i, a)
          end do
       end do
       blk%force_hg = w%fe_hg(1:nb, :, :)
    end if
    e_artificial = e_artificial + sum(w%e_hg(1:nb))
  end subroutine block_hourglass

  !> coordMp: the element's integration point (its centroid) at the end of the increment,
  !> x_n + Δu averaged over the nodes; the third column stays 0 in plane strain.
  subroutine centroids(nb, nd, ne, xe_old, du, coord)
    integer, intent(in) :: nb, nd, ne
    real(dp), intent(in) :: xe_old(:, :, :), du(:, :, :)
    real(dp), intent(inout) :: coord(:, :)
    integer :: i, a

    do i = 1, nd
       coord(1:nb, i) = 0
       do a = 1, ne
          coord(1:nb, i) = coord(1:nb, i) + (xe_old(1:nb, i, a) + du(1:nb, i, a))
       end do
       coord(1:nb, i) = coord(1:nb, i) / ne
    end do
  end subroutine centroids

  !> a ↔ b by their allocations (no copy).
  subroutine exchange_rotations(a, b)
    real(dp), allocatable, intent(inout) :: a(:, :, :), b(:, :, :)
    real(dp), allocatable :: held(:, :, :)

    call move_alloc(a, held)
    call move_alloc(b, a)
    call move_alloc(held, b)
  end subroutine exchange_rotations
end module driver_elements
