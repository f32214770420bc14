!> Closed-form stress return for linear Drucker–Prager perfect plasticity in the Abaqus q-form
!> (K = 1, no deviatoric-plane shape factor):
!>
!>   F = q − p tanβ − d,   G = q − p tanψ,   p = −tr σ/3 (compression positive),  q = √(3/2 s:s).
!>
!> Owns: the elastic / cone / apex decision and the backward-Euler return for one material point,
!> on Abaqus-ordered component vectors (ncomp = 4: 11, 22, 33, 12 with σ33 carried, plane strain or
!> axisymmetry; ncomp = 6: 11, 22, 33, 12, 23, 31), tension positive, tensor shear strains.
!>
!> Derivation (q-form; docs/theory/return_mapping.md §2.3 gives the same algorithm in the √J2 form: with q = √3 √J2,
!> f = F/√3, η = tanβ/√3, η̄ = tanψ/√3, ξc = d/√3 and Δγ = √3 Δλ, its Δγ = f*/(G + K η η̄) is
!> exactly the Δλ below, and its apex σm = ξc/η is the σ_a below):
!>   ∂G/∂σ = (3/2) s/q + (tanψ/3) I, so Δε^p = Δλ ∂G/∂σ has
!>   Δe^p = (3/2) Δλ s/q   (equivalent shear strain √(2/3 Δe^p:Δe^p) = Δλ) and tr Δε^p = Δλ tanψ.
!>   Elastic predictor/corrector: q = q* − 3G Δλ, p = p* + K Δλ tanψ, s ∥ s* (radial return).
!>   F(q, p) = 0  ⇒  Δλ = F* / (3G + K tanβ tanψ).
!>   The cone return is valid while q* − 3G Δλ ≥ 0; otherwise the trial lies beyond the apex.
!> Apex: σ = σ_a I with q = 0 and F = 0 ⇒ −p tanβ − d = 0 ⇒ p_a = −d/tanβ, i.e. the tension-positive
!>   mean stress σ_a = d/tanβ (the cone's tip lies in hydrostatic tension; σ_a = 0 when d = 0).
!>   tanβ = 0 is the von Mises limit: the yield surface is a cylinder and has no apex.
!>   The apex plastic strain is Δε^p = D⁻¹(σ* − σ_a I): Δe^p = s*/(2G), tr Δε^p = (σm* − σ_a)/K.
!>
!> Nothing divides by tanψ, so ψ = 0 (isochoric flow on the cone) is exact. Requirements:
!> tanβ ≥ 0, tanψ ≥ 0, d ≥ 0, bulk > 0, shear > 0.
module drucker_prager_return
  use material_kinds, only: dp
  implicit none
  private

  public :: drucker_prager_stress_return

  ! Return regions, numbered like the Mohr–Coulomb ones (SDV5 YIELD in umat/README.md).
  ! Kept private here: mohr_coulomb_return owns the public names.
  integer, parameter :: region_elastic = 0
  integer, parameter :: region_cone = 1
  integer, parameter :: region_apex = 4

  ! A trial stress with F* ≤ yield_tol·(q* + |p*| + d) is treated as elastic. The band is a few
  ! hundred ulps wide: it absorbs the rounding left by a previous return (so that returning a
  ! returned stress changes nothing) and is far below any physically meaningful violation.
  real(dp), parameter :: yield_tol = 64.0_dp * epsilon(1.0_dp)

contains

  !> Return the trial stress s_trial to the linear Drucker–Prager surface.
  !> s, dstrain_p: returned stress and plastic strain increment (tensor components, same order);
  !> region: 0 elastic, 1 cone, 4 apex.
  pure subroutine drucker_prager_stress_return(ncomp, s_trial, tan_beta, tan_psi, d, bulk, shear, &
                                               s, dstrain_p, region)
    integer, intent(in)   :: ncomp
    real(dp), intent(in)  :: s_trial(ncomp)
    real(dp), intent(in)  :: tan_beta
    real(dp), intent(in)  :: tan_psi
    real(dp), intent(in)  :: d
    real(dp), intent(in)  :: bulk
    real(dp), intent(in)  :: shear
    real(dp), intent(out) :: s(ncomp)
    real(dp), intent(out) :: dstrain_p(ncomp)
    integer, intent(out)  :: region

    ! Fixed-size scratch (ncomp ≤ 6): no automatic array on the per-point path.
    real(dp) :: dev(6)
    real(dp) :: mean_trial, p_trial, q_trial, f_trial, dlam, p_new, q_new, ratio, sigma_apex, vol_third

    ! Trial invariants; dev holds the trial deviator s* (shear entries are deviatoric as given).
    mean_trial = (s_trial(1) + s_trial(2) + s_trial(3)) / 3.0_dp
    p_trial = -mean_trial
    dev(1:ncomp) = s_trial
    dev(1:3) = dev(1:3) - mean_trial
    q_trial = equivalent_stress(ncomp, dev(1:ncomp))

    f_trial = q_trial - p_trial * tan_beta - d
    if (f_trial <= yield_tol * (q_trial + abs(p_trial) + d)) then
      region = region_elastic
      s = s_trial
      dstrain_p = 0.0_dp
      return
    end if

    dlam = f_trial / (3.0_dp * shear + bulk * tan_beta * tan_psi)

    ! The cone/apex decision compares two accurately computed positive numbers (no cancellation).
    ! With tanβ = 0 there is no apex: mathematically q* − 3GΔλ = d ≥ 0 then, and the guard keeps
    ! a rounding-level violation of that from dividing by tanβ below.
    if (q_trial >= 3.0_dp * shear * dlam .or. tan_beta <= 0.0_dp) then
      region = region_cone
      p_new = p_trial + bulk * dlam * tan_psi
      ! Take the returned q from F = 0 itself rather than from q* − 3GΔλ: the two are equal in
      ! exact arithmetic, but q* − 3GΔλ loses all digits when q* ≫ q, whereas this form leaves
      ! the returned stress on the surface to rounding of its own size. Clamped at 0 against
      ! rounding at the cone/apex boundary. q_trial > 0 here because Δλ > 0 (F* > 0).
      q_new = max(p_new * tan_beta + d, 0.0_dp)
      ratio = q_new / q_trial
      s = ratio * dev(1:ncomp)
      s(1:3) = s(1:3) - p_new
      ! Δε^p = Δλ ((3/2) s*/q* + (tanψ/3) I); s/q = s*/q* on the cone (radial return).
      dstrain_p = (1.5_dp * dlam / q_trial) * dev(1:ncomp)
      dstrain_p(1:3) = dstrain_p(1:3) + dlam * tan_psi / 3.0_dp
    else
      region = region_apex
      sigma_apex = d / tan_beta
      s(1:3) = sigma_apex
      s(4:ncomp) = 0.0_dp
      ! Δε^p = D⁻¹(σ* − σ_a I): the whole trial deviator and the volumetric excess are plastic.
      ! This is the usual closed-form apex return for any ψ (de Souza Neto et al.; Abaqus): a
      ! stress beyond the tip can only go to the tip. It dilates even for ψ = 0, as it must,
      ! since the trial lies in hydrostatic tension beyond what the material can carry.
      vol_third = (mean_trial - sigma_apex) / (3.0_dp * bulk)
      dstrain_p = dev(1:ncomp) / (2.0_dp * shear)
      dstrain_p(1:3) = dstrain_p(1:3) + vol_third
    end if
  end subroutine drucker_prager_stress_return

  !> q = √(3/2 s:s) of a deviator in Abaqus component order; entries 4..ncomp are the off-diagonal
  !> tensor components and appear twice in s:s.
  pure function equivalent_stress(ncomp, dev) result(q)
    integer, intent(in)  :: ncomp
    real(dp), intent(in) :: dev(ncomp)
    real(dp) :: q

    q = sqrt(1.5_dp * (dev(1)**2 + dev(2)**2 + dev(3)**2 + 2.0_dp * sum(dev(4:ncomp)**2)))
  end function equivalent_stress

end module drucker_prager_return
