!> Stress update of a block of material points for each model, in the VUMAT array layout.
!>
!> This is the hot path: one routine per model, each looping over the `nblock` points of a
!> VUMAT call with the component index outside the point index (`(nblock, ncomp)` arrays).
!> Mohr-Coulomb runs in chunks of block_points points through the block kernels
!> (principal_*_block, mohr_coulomb_return_block), one vectorised loop per step, and gives
!> the results of the point-by-point scalar kernels bit for bit.
!> Per-point parameters (friction and dilation angles from tables, cohesion from the flow
!> function or the hardening table) are evaluated with the start-of-increment state, i.e.
!> lagged by one increment, which is consistent for an explicit code with small increments.
module material_update
  use, intrinsic :: iso_fortran_env, only: int64
  use material_kinds, only: dp, rad_to_deg
  use material_state, only: sdv_peeq, sdv_evp, sdv_ev, sdv_sigma1_consolidation, sdv_yield, &
       sdv_cohesion, sdv_phi, sdv_psi, n_state_plastic
  use material_props, only: mohr_coulomb_props_t, drucker_prager_props_t
  use elasticity, only: elastic_increment
  use principal_stress, only: principal_plane, principal_3d, block_points, principal_plane_block, &
       rebuild_plane_block, principal_3d_block, rebuild_3d_block
  use mohr_coulomb_return, only: mohr_coulomb_return_block
  use drucker_prager_return, only: drucker_prager_stress_return
  use inertial_friction, only: inertial_friction_chunk
  use property_table, only: interpolate_table, interpolate_table_field
  use flow_function, only: flow_function_none, unconfined_yield_strength, &
       cohesion_from_unconfined_strength
  implicit none
  private

  public :: update_elastic_block, update_mohr_coulomb_block, update_drucker_prager_block
  public :: stress_power

contains

  !> Linear elasticity; also the packaging-call response of every model.
  pure subroutine update_elastic_block(nblock, ncomp, lam, shear, density, strain_inc, &
       stress_old, stress_new, e_int_old, e_int_new)
    integer, intent(in) :: nblock, ncomp
    real(dp), intent(in) :: lam, shear
    real(dp), intent(in) :: density(nblock), strain_inc(nblock, ncomp), stress_old(nblock, ncomp)
    real(dp), intent(out) :: stress_new(nblock, ncomp)
    real(dp), intent(in) :: e_int_old(nblock)
    real(dp), intent(out) :: e_int_new(nblock)
    integer :: k
    real(dp) :: s(ncomp)

    do k = 1, nblock
       s = stress_old(k, :)
       call elastic_increment(ncomp, lam, shear, strain_inc(k, :), s)
       stress_new(k, :) = s
    end do
    do k = 1, nblock
       e_int_new(k) = e_int_old(k) + stress_power(ncomp, stress_old(k, :), stress_new(k, :), &
            strain_inc(k, :)) / density(k)
    end do
  end subroutine update_elastic_block

  !> Non-associated Mohr-Coulomb with exact principal-space return (plane, edges, apex,
  !> optional tension cut-off), tabulated angles and flow-function cohesion.
  !>
  !> The block is processed in chunks of block_points points. Each step of the update is one
  !> loop over the points of a chunk with unit stride in the point index, which gfortran -O3
  !> vectorises: the elastic trial, the principal decomposition (principal_plane_block /
  !> principal_3d_block), the return (mohr_coulomb_return_block), the rotation back and the
  !> state and energy bookkeeping. Only the strength parameters from tables (angles, flow
  !> function, hardening) are evaluated point by point. The chunk's work arrays have a fixed
  !> size (no allocation) and stay in the L1 cache.
  !> With the μ(I) option (mc%mu_of_i) the friction angle of each point is raised with the
  !> inertial number of this increment (strain_inc/dt, start-of-increment pressure) before the
  !> return; without it dt is not used and the update is the static one.
  pure subroutine update_mohr_coulomb_block(nblock, ncomp, nstatev, nfieldv, nprops, props, mc, &
       total_time, dt, density, strain_inc, field_new, stress_old, state_old, stress_new, state_new, &
       e_int_old, e_int_new, e_inel_old, e_inel_new)
    integer, intent(in) :: nblock, ncomp, nstatev, nfieldv, nprops
    real(dp), intent(in) :: props(nprops)
    type(mohr_coulomb_props_t), intent(in) :: mc
    real(dp), intent(in) :: total_time, dt
    real(dp), intent(in) :: density(nblock), strain_inc(nblock, ncomp), field_new(nblock, nfieldv)
    real(dp), intent(in) :: stress_old(nblock, ncomp), state_old(nblock, nstatev)
    real(dp), intent(out) :: stress_new(nblock, ncomp), state_new(nblock, nstatev)
    real(dp), intent(in) :: e_int_old(nblock), e_inel_old(nblock)
    real(dp), intent(out) :: e_int_new(nblock), e_inel_new(nblock)
    ! Work arrays of one chunk (point index first).
    real(dp) :: s_trial(block_points, 6), s_back(block_points, 6)
    real(dp) :: sig_trial(block_points, 3), sig(block_points, 3), vec(block_points, 3, 3)
    real(dp) :: c2(block_points), s2(block_points)
    real(dp) :: phi(block_points), psi(block_points), sin_phi(block_points), sin_psi(block_points)
    real(dp) :: cohesion(block_points)
    real(dp) :: phi_rate(block_points), sin_phi_rate(block_points)   ! μ(I) option only
    integer :: izz(block_points), region(block_points)
    integer :: k0, n, i, j, k, ang_end, coh_end, ff_end
    real(dp) :: lam, two_g, lam_tr, vol_factor, fc, x, d1, d2, d3, dp1, dp2, dp3, trace, third_trace
    real(dp) :: plastic_work, power, a, b
    logical :: record, record_maximum, tables

    ang_end = mc%coh_start - 1
    coh_end = mc%ff_start - 1
    ff_end = mc%ff_start + 2 * mc%n_ff - 1
    record = mc%t_freeze <= 0 .or. total_time <= mc%t_freeze
    record_maximum = mc%record_maximum
    tables = mc%n_ang > 0 .or. mc%flow_kind /= flow_function_none .or. mc%n_coh > 0
    lam = mc%lam
    two_g = 2.0_dp * mc%shear
    vol_factor = lam / (3.0_dp * lam + 2.0_dp * mc%shear)
    ! Constant strength: filled once for every chunk.
    n = min(nblock, block_points)
    phi(1:n) = mc%phi
    psi(1:n) = mc%psi
    sin_phi(1:n) = sin(mc%phi)
    sin_psi(1:n) = sin(mc%psi)
    cohesion(1:n) = mc%cohesion

    if (nstatev > n_state_plastic) state_new(:, n_state_plastic + 1:) = state_old(:, n_state_plastic + 1:)
    do k0 = 0, nblock - 1, block_points
       n = min(block_points, nblock - k0)

       ! Strength of each point from the tables, with the start-of-increment state.
       if (tables) then
          do i = 1, n
             k = k0 + i
             if (mc%n_ang > 0) then
                x = field_new(k, mc%ang_field)
                phi(i) = interpolate_table(props(mc%ang_start + 2:ang_end:3), &
                     props(mc%ang_start:ang_end:3), x) / rad_to_deg
                psi(i) = interpolate_table(props(mc%ang_start + 2:ang_end:3), &
                     props(mc%ang_start + 1:ang_end:3), x) / rad_to_deg
                ! sin again only where the angle differs from the previous point's (bit for bit:
                ! the same argument gives the same sine). A constant φ column, or ψ held at a
                ! table end, was two libm sines per point and increment (7 % of an MPM hopper).
                j = max(1, i - 1)
                sin_phi(i) = sine_reused(phi(i), i > 1, phi(j), sin_phi(j))
                sin_psi(i) = sine_reused(psi(i), i > 1, psi(j), sin_psi(j))
             end if
             if (mc%flow_kind /= flow_function_none) then
                fc = unconfined_yield_strength(mc%flow_kind, mc%fc0, mc%slope, &
                     state_old(k, sdv_sigma1_consolidation), props(mc%ff_start:ff_end:2), &
                     props(mc%ff_start + 1:ff_end:2))
                cohesion(i) = cohesion_from_unconfined_strength(fc, sin_phi(i))
             else if (mc%coh_on_field) then
                cohesion(i) = interpolate_table_field(props(mc%coh_start + 1:coh_end:3), &
                     props(mc%coh_start + 2:coh_end:3), props(mc%coh_start:coh_end:3), &
                     state_old(k, sdv_peeq), field_new(k, mc%ang_field))
             else if (mc%n_coh > 0) then
                cohesion(i) = interpolate_table(props(mc%coh_start + 1:coh_end:2), &
                     props(mc%coh_start:coh_end:2), state_old(k, sdv_peeq))
             end if
          end do
       end if

       ! Elastic trial σ_old + D:Δε (the operations of elastic_increment).
       do i = 1, n
          k = k0 + i
          lam_tr = lam * (strain_inc(k, 1) + strain_inc(k, 2) + strain_inc(k, 3))
          s_trial(i, 1) = stress_old(k, 1) + lam_tr + two_g * strain_inc(k, 1)
          s_trial(i, 2) = stress_old(k, 2) + lam_tr + two_g * strain_inc(k, 2)
          s_trial(i, 3) = stress_old(k, 3) + lam_tr + two_g * strain_inc(k, 3)
          s_trial(i, 4) = stress_old(k, 4) + two_g * strain_inc(k, 4)
       end do
       if (ncomp == 6) then
          do i = 1, n
             k = k0 + i
             s_trial(i, 5) = stress_old(k, 5) + two_g * strain_inc(k, 5)
             s_trial(i, 6) = stress_old(k, 6) + two_g * strain_inc(k, 6)
          end do
       end if

       ! Principal trial stresses, return, rotation back.
       if (ncomp == 4) then
          call principal_plane_block(n, s_trial, sig_trial, c2, s2, izz)
       else
          call principal_3d_block(n, s_trial, sig_trial, vec)
       end if
       if (mc%mu_of_i) then
          ! Rate-dependent angle; the cohesion above keeps the static φ (a material property).
          call inertial_friction_chunk(n, k0, nblock, ncomp, strain_inc, stress_old, dt, mc%sin_phi2, &
               mc%i0, mc%d_sqrt_rho, phi, sin_phi, phi_rate, sin_phi_rate)
          call mohr_coulomb_return_block(n, sig_trial, sin_phi_rate, sin_psi, cohesion, lam, mc%shear, &
               mc%tension_cutoff, mc%sigma_t, sig, region)
       else
          call mohr_coulomb_return_block(n, sig_trial, sin_phi, sin_psi, cohesion, lam, mc%shear, &
               mc%tension_cutoff, mc%sigma_t, sig, region)
       end if
       if (ncomp == 4) then
          call rebuild_plane_block(n, sig, c2, s2, izz, s_back)
       else
          call rebuild_3d_block(n, sig, vec, s_back)
       end if

       ! New stress: the trial one where the point stayed elastic.
       do j = 1, ncomp
          do i = 1, n
             a = s_back(i, j)
             b = s_trial(i, j)
             stress_new(k0 + i, j) = merge(a, b, region(i) /= 0)
          end do
       end do

       ! Plastic strain increment D⁻¹(σ_trial − σ) in principal values (zero, exactly, for
       ! elastic points, whose σ is σ_trial), with the operations of principal_compliance and
       ! of the PEEQ, EVP and plastic work sums; the other state variables.
       do i = 1, n
          k = k0 + i
          d1 = sig_trial(i, 1) - sig(i, 1)
          d2 = sig_trial(i, 2) - sig(i, 2)
          d3 = sig_trial(i, 3) - sig(i, 3)
          x = vol_factor * (d1 + d2 + d3)
          dp1 = (d1 - x) / two_g
          dp2 = (d2 - x) / two_g
          dp3 = (d3 - x) / two_g
          trace = dp1 + dp2 + dp3
          third_trace = trace / 3.0_dp
          state_new(k, sdv_peeq) = state_old(k, sdv_peeq) + sqrt(2.0_dp * ((dp1 - third_trace)**2 &
               + (dp2 - third_trace)**2 + (dp3 - third_trace)**2) / 3.0_dp)
          state_new(k, sdv_evp) = state_old(k, sdv_evp) + trace
          state_new(k, sdv_ev) = state_old(k, sdv_ev) + (strain_inc(k, 1) + strain_inc(k, 2) &
               + strain_inc(k, 3))
          state_new(k, sdv_yield) = real(region(i), dp)
          plastic_work = sig(i, 1) * dp1 + sig(i, 2) * dp2 + sig(i, 3) * dp3
          e_inel_new(k) = e_inel_old(k) + plastic_work / density(k)
       end do
       ! (A loop of its own: the compiler checks at run time that the columns of state_new
       ! written in one loop do not overlap, and gives up beyond a few of them.)
       do i = 1, n
          state_new(k0 + i, sdv_cohesion) = cohesion(i)
          state_new(k0 + i, sdv_phi) = phi(i) * rad_to_deg
          state_new(k0 + i, sdv_psi) = psi(i) * rad_to_deg
       end do
       if (mc%mu_of_i) state_new(k0 + 1:k0 + n, sdv_phi) = phi_rate(1:n) * rad_to_deg

       ! Internal energy: ½(σ_old + σ_new):Δε, tensor shears counted twice (stress_power).
       if (ncomp == 4) then
          do k = k0 + 1, k0 + n
             power = (stress_old(k, 1) + stress_new(k, 1)) * strain_inc(k, 1) &
                  + (stress_old(k, 2) + stress_new(k, 2)) * strain_inc(k, 2) &
                  + (stress_old(k, 3) + stress_new(k, 3)) * strain_inc(k, 3)
             power = 0.5_dp * (power + 2.0_dp * ((stress_old(k, 4) + stress_new(k, 4)) * strain_inc(k, 4)))
             e_int_new(k) = e_int_old(k) + power / density(k)
          end do
       else
          do k = k0 + 1, k0 + n
             power = (stress_old(k, 1) + stress_new(k, 1)) * strain_inc(k, 1) &
                  + (stress_old(k, 2) + stress_new(k, 2)) * strain_inc(k, 2) &
                  + (stress_old(k, 3) + stress_new(k, 3)) * strain_inc(k, 3)
             power = 0.5_dp * (power + 2.0_dp * ((stress_old(k, 4) + stress_new(k, 4)) * strain_inc(k, 4) &
                  + (stress_old(k, 5) + stress_new(k, 5)) * strain_inc(k, 5) &
                  + (stress_old(k, 6) + stress_new(k, 6)) * strain_inc(k, 6)))
             e_int_new(k) = e_int_old(k) + power / density(k)
          end do
       end if

       ! Recorded consolidation stress σ1 = −σ3 (compression positive).
       if (.not. record) then
          state_new(k0 + 1:k0 + n, sdv_sigma1_consolidation) = &
               state_old(k0 + 1:k0 + n, sdv_sigma1_consolidation)
       else if (record_maximum) then
          do i = 1, n
             state_new(k0 + i, sdv_sigma1_consolidation) = &
                  max(state_old(k0 + i, sdv_sigma1_consolidation), -sig(i, 3))
          end do
       else
          do i = 1, n
             state_new(k0 + i, sdv_sigma1_consolidation) = max(0.0_dp, -sig(i, 3))
          end do
       end if
    end do
  end subroutine update_mohr_coulomb_block

  !> Linear Drucker-Prager (Abaqus q-form, K = 1) with cone and apex return.
  pure subroutine update_drucker_prager_block(nblock, ncomp, nstatev, dpp, density, strain_inc, &
       stress_old, state_old, stress_new, state_new, e_int_old, e_int_new, e_inel_old, e_inel_new)
    integer, intent(in) :: nblock, ncomp, nstatev
    type(drucker_prager_props_t), intent(in) :: dpp
    real(dp), intent(in) :: density(nblock), strain_inc(nblock, ncomp)
    real(dp), intent(in) :: stress_old(nblock, ncomp), state_old(nblock, nstatev)
    real(dp), intent(out) :: stress_new(nblock, ncomp), state_new(nblock, nstatev)
    real(dp), intent(in) :: e_int_old(nblock), e_inel_old(nblock)
    real(dp), intent(out) :: e_int_new(nblock), e_inel_new(nblock)
    integer :: k, region
    real(dp) :: s_trial(ncomp), s(ncomp), deps_p(ncomp), trace, dev_norm2

    state_new = state_old
    do k = 1, nblock
       s_trial = stress_old(k, :)
       call elastic_increment(ncomp, dpp%lam, dpp%shear, strain_inc(k, :), s_trial)
       call drucker_prager_stress_return(ncomp, s_trial, dpp%tan_beta, dpp%tan_psi, dpp%d, dpp%bulk, &
            dpp%shear, s, deps_p, region)
       stress_new(k, :) = s
       trace = sum(deps_p(1:3))
       dev_norm2 = sum((deps_p(1:3) - trace / 3)**2) + 2 * sum(deps_p(4:ncomp)**2)
       state_new(k, sdv_peeq) = state_old(k, sdv_peeq) + sqrt(2 * dev_norm2 / 3)
       state_new(k, sdv_evp) = state_old(k, sdv_evp) + trace
       state_new(k, sdv_ev) = state_old(k, sdv_ev) + sum(strain_inc(k, 1:3))
       state_new(k, sdv_yield) = real(region, dp)
       state_new(k, sdv_sigma1_consolidation) = max(0.0_dp, -minval_principal(ncomp, s))
       e_inel_new(k) = e_inel_old(k) + (sum(s(1:3) * deps_p(1:3)) + 2 * sum(s(4:ncomp) * deps_p(4:ncomp))) &
            / density(k)
    end do
    state_new(:, sdv_cohesion) = dpp%d
    state_new(:, sdv_phi) = atan(dpp%tan_beta) * rad_to_deg
    state_new(:, sdv_psi) = atan(dpp%tan_psi) * rad_to_deg
    do k = 1, nblock
       e_int_new(k) = e_int_old(k) + stress_power(ncomp, stress_old(k, :), stress_new(k, :), &
            strain_inc(k, :)) / density(k)
    end do
  end subroutine update_drucker_prager_block

  !> Most compressive principal stress, for the consolidation record of Drucker-Prager points.
  pure real(dp) function minval_principal(ncomp, s)
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: s(ncomp)
    real(dp) :: sig(3), vec(3, 3), c2, s2
    integer :: izz

    if (ncomp == 4) then
       call principal_plane(s, sig, c2, s2, izz)
    else
       call principal_3d(s, sig, vec)
    end if
    minval_principal = sig(3)
  end function minval_principal

  !> ½(σ_old + σ_new):Δε with tensor shear components counted twice.
  pure real(dp) function stress_power(ncomp, s_old, s_new, deps)
    integer, intent(in) :: ncomp
    ! Assumed shape: callers pass rows of (nblock, ncomp) blocks without a copy.
    real(dp), intent(in) :: s_old(:), s_new(:), deps(:)

    stress_power = 0.5_dp * (sum((s_old(1:3) + s_new(1:3)) * deps(1:3)) &
         + 2 * sum((s_old(4:ncomp) + s_new(4:ncomp)) * deps(4:ncomp)))
  end function stress_power

  !> sin(x), or sin_prev when there is a previous point (have_prev) whose angle x_prev is the
  !> same double as x bit for bit (+0 and −0 differ).
  pure real(dp) function sine_reused(x, have_prev, x_prev, sin_prev) result(s)
    real(dp), intent(in) :: x, x_prev, sin_prev
    logical, intent(in) :: have_prev

    if (have_prev) then
       if (transfer(x, 0_int64) == transfer(x_prev, 0_int64)) then
          s = sin_prev
          return
       end if
    end if
    s = sin(x)
  end function sine_reused
end module material_update
