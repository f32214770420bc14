!> Stress update of a block of material points for each model, in the VUMAT array layout.
!>
!> This is the hot path: one routine per model, each looping over the `nblock` points of a
!> VUMAT call with the component index outside the point index (`(nblock, ncomp)` arrays).
!> Per-point parameters (friction and dilation angles from tables, cohesion from the flow
!> function or the hardening table) are evaluated with the start-of-increment state, i.e.
!> lagged by one increment, which is consistent for an explicit code with small increments.
module material_update
  use material_kinds, only: dp, rad_to_deg
  use material_state, only: sdv_peeq, sdv_evp, sdv_ev, sdv_sigma1_consolidation, sdv_yield, &
       sdv_cohesion, sdv_phi, sdv_psi, n_state_plastic
  use material_props, only: mohr_coulomb_props_t, drucker_prager_props_t
  use elasticity, only: elastic_increment, principal_compliance
  use principal_stress, only: principal_plane, rebuild_plane, principal_3d, rebuild_3d
  use mohr_coulomb_return, only: mohr_coulomb_principal_return
  use drucker_prager_return, only: drucker_prager_stress_return
  use property_table, only: interpolate_table
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
  pure subroutine update_mohr_coulomb_block(nblock, ncomp, nstatev, nfieldv, nprops, props, mc, &
       total_time, density, strain_inc, field_new, stress_old, state_old, stress_new, state_new, &
       e_int_old, e_int_new, e_inel_old, e_inel_new)
    integer, intent(in) :: nblock, ncomp, nstatev, nfieldv, nprops
    real(dp), intent(in) :: props(nprops)
    type(mohr_coulomb_props_t), intent(in) :: mc
    real(dp), intent(in) :: total_time
    real(dp), intent(in) :: density(nblock), strain_inc(nblock, ncomp), field_new(nblock, nfieldv)
    real(dp), intent(in) :: stress_old(nblock, ncomp), state_old(nblock, nstatev)
    real(dp), intent(out) :: stress_new(nblock, ncomp), state_new(nblock, nstatev)
    real(dp), intent(in) :: e_int_old(nblock), e_inel_old(nblock)
    real(dp), intent(out) :: e_int_new(nblock), e_inel_new(nblock)
    integer :: k, region, izz, ang_end, coh_end, ff_end
    real(dp) :: s(ncomp), sig_trial(3), sig(3), vec(3, 3), c2, s2
    real(dp) :: phi, psi, sin_phi, sin_psi, cohesion, fc, x, plastic_work
    logical :: record

    ang_end = mc%coh_start - 1
    coh_end = mc%ff_start - 1
    ff_end = mc%ff_start + 2 * mc%n_ff - 1
    record = mc%t_freeze <= 0 .or. total_time <= mc%t_freeze
    phi = mc%phi
    psi = mc%psi
    sin_phi = sin(phi)
    sin_psi = sin(psi)
    cohesion = mc%cohesion

    state_new = state_old
    do k = 1, nblock
       if (mc%n_ang > 0) then
          x = field_new(k, mc%ang_field)
          phi = interpolate_table(props(mc%ang_start + 2:ang_end:3), props(mc%ang_start:ang_end:3), x) &
               / rad_to_deg
          psi = interpolate_table(props(mc%ang_start + 2:ang_end:3), props(mc%ang_start + 1:ang_end:3), x) &
               / rad_to_deg
          sin_phi = sin(phi)
          sin_psi = sin(psi)
       end if
       if (mc%flow_kind /= flow_function_none) then
          fc = unconfined_yield_strength(mc%flow_kind, mc%fc0, mc%slope, &
               state_old(k, sdv_sigma1_consolidation), props(mc%ff_start:ff_end:2), &
               props(mc%ff_start + 1:ff_end:2))
          cohesion = cohesion_from_unconfined_strength(fc, sin_phi)
       else if (mc%n_coh > 0) then
          cohesion = interpolate_table(props(mc%coh_start + 1:coh_end:2), props(mc%coh_start:coh_end:2), &
               state_old(k, sdv_peeq))
       end if

       s = stress_old(k, :)
       call elastic_increment(ncomp, mc%lam, mc%shear, strain_inc(k, :), s)
       if (ncomp == 4) then
          call principal_plane(s, sig_trial, c2, s2, izz)
       else
          call principal_3d(s, sig_trial, vec)
       end if
       call mohr_coulomb_principal_return(sig_trial, sin_phi, sin_psi, cohesion, mc%lam, mc%shear, &
            mc%tension_cutoff, mc%sigma_t, sig, region)
       if (region /= 0) then
          if (ncomp == 4) then
             call rebuild_plane(sig, c2, s2, izz, s)
          else
             call rebuild_3d(sig, vec, s)
          end if
       end if
       stress_new(k, :) = s
       call record_plastic_state(mc%lam, mc%shear, sig_trial, sig, region, state_new(k, :), plastic_work)

       state_new(k, sdv_ev) = state_old(k, sdv_ev) + sum(strain_inc(k, 1:3))
       if (record) then
          if (mc%record_maximum) then
             state_new(k, sdv_sigma1_consolidation) = max(state_old(k, sdv_sigma1_consolidation), -sig(3))
          else
             state_new(k, sdv_sigma1_consolidation) = max(0.0_dp, -sig(3))
          end if
       end if
       state_new(k, sdv_cohesion) = cohesion
       state_new(k, sdv_phi) = phi * rad_to_deg
       state_new(k, sdv_psi) = psi * rad_to_deg
       e_inel_new(k) = e_inel_old(k) + plastic_work / density(k)
    end do
    do k = 1, nblock
       e_int_new(k) = e_int_old(k) + stress_power(ncomp, stress_old(k, :), stress_new(k, :), &
            strain_inc(k, :)) / density(k)
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

  !> PEEQ, EVP and YIELD from the principal plastic corrector; returns σ:Δε^p.
  pure subroutine record_plastic_state(lam, shear, sig_trial, sig, region, state, plastic_work)
    real(dp), intent(in) :: lam, shear, sig_trial(3), sig(3)
    integer, intent(in) :: region
    real(dp), intent(inout) :: state(:)
    real(dp), intent(out) :: plastic_work
    real(dp) :: deps_p(3), trace

    state(sdv_yield) = real(region, dp)
    plastic_work = 0
    if (region == 0) return
    call principal_compliance(lam, shear, sig_trial - sig, deps_p)
    trace = sum(deps_p)
    state(sdv_peeq) = state(sdv_peeq) + sqrt(2 * sum((deps_p - trace / 3)**2) / 3)
    state(sdv_evp) = state(sdv_evp) + trace
    plastic_work = sum(sig * deps_p)
  end subroutine record_plastic_state

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
end module material_update
