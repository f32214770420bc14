!> Plane-strain matching between Mohr–Coulomb (φ, ψ, c) and linear Drucker–Prager in the Abaqus
!> q-form (F = q − p tanβ − d, G = q − p tanψ_DP, K = 1), and its inverse. Angles in radians.
!>
!> The match (docs/theory/return_mapping.md §2.2; the Abaqus manual's relation): in plane strain at steady plastic
!> flow the elastic strain rate vanishes, so ε̇zz^p = 0, i.e. ∂G/∂σzz = 0 ⇒ szz = −(2/9) q tanψ_DP.
!> With the in-plane radius τ = (σ1 − σ3)/2 and centre σ̄ = (σ1 + σ3)/2 this gives
!>   q = 3√3 τ / √(9 − tan²ψ_DP),  p = −σ̄ + q tanψ_DP/9,
!> and F = 0 becomes the Mohr–Coulomb line τ = c cosφ − σ̄ sinφ with
!>   sinφ   = tanβ S/(9 − tanβ tanψ_DP),   c cosφ = d S/(9 − tanβ tanψ_DP),   S = √(3(9 − tan²ψ_DP)),
!> while the in-plane dilation produced by the DP flow rule is sinψ = √3 tanψ_DP/√(9 − tan²ψ_DP).
!> The two special cases follow by setting ψ_DP = 0 or ψ_DP = β.
!>
!> Valid ranges: 0 ≤ ψ ≤ φ < π/2, c ≥ 0 (forward); tanψ_DP < 3, tanβ tanψ_DP < 9 and a resulting
!> sinφ < 1 (inverse). Inputs are not checked here; material_props validates props.
module drucker_prager_match
  use material_kinds, only: dp
  implicit none
  private

  public :: match_plane_strain
  public :: match_plane_strain_nondilatant
  public :: match_plane_strain_associated
  public :: mohr_coulomb_from_drucker_prager

contains

  !> General non-associated match: the DP material reproduces, in plane strain, the Mohr–Coulomb
  !> strength (φ, c) and the Mohr–Coulomb in-plane dilation angle ψ.
  pure subroutine match_plane_strain(phi, psi, cohesion, tan_beta, tan_psi_dp, d)
    real(dp), intent(in)  :: phi
    real(dp), intent(in)  :: psi
    real(dp), intent(in)  :: cohesion
    real(dp), intent(out) :: tan_beta
    real(dp), intent(out) :: tan_psi_dp
    real(dp), intent(out) :: d

    real(dp) :: sin_phi, sin_psi, s_fac

    sin_phi = sin(phi)
    sin_psi = sin(psi)
    ! Inverse of sinψ = √3 tanψ_DP/√(9 − tan²ψ_DP).
    tan_psi_dp = 3.0_dp * sin_psi / sqrt(3.0_dp + sin_psi**2)
    s_fac = sqrt(3.0_dp * (9.0_dp - tan_psi_dp**2))
    ! sinφ (9 − tanβ tanψ_DP) = tanβ S solved for tanβ.
    tan_beta = 9.0_dp * sin_phi / (s_fac + tan_psi_dp * sin_phi)
    d = cohesion * cos(phi) * (9.0_dp - tan_beta * tan_psi_dp) / s_fac
  end subroutine match_plane_strain

  !> ψ_DP = 0 (isochoric DP flow): tanβ = √3 sinφ, d = √3 c cosφ.
  !> NOTE: thesis eq. 3.2 prints d = c cosφ. That is the intercept of the √J2 form
  !> (√J2 + sinφ σm − c cosφ = 0); in the Abaqus q-form used here (q = √3 √J2) the intercept is
  !> √3 c cosφ. With d = c cosφ the DP material would be weaker than the MC one by a factor √3 in
  !> cohesion. The thesis's MC/DP comparison (§4.5.3) is cohesionless (c = 0), where the two agree.
  pure subroutine match_plane_strain_nondilatant(phi, cohesion, tan_beta, d)
    real(dp), intent(in)  :: phi
    real(dp), intent(in)  :: cohesion
    real(dp), intent(out) :: tan_beta
    real(dp), intent(out) :: d

    tan_beta = sqrt(3.0_dp) * sin(phi)
    d = sqrt(3.0_dp) * cohesion * cos(phi)
  end subroutine match_plane_strain_nondilatant

  !> Associated DP flow (ψ_DP = β): tanβ = 3 sinφ/√(3 + sin²φ), d = 3c cosφ/√(3 + sin²φ).
  !> The matching MC dilation angle is then ψ = φ.
  pure subroutine match_plane_strain_associated(phi, cohesion, tan_beta, d)
    real(dp), intent(in)  :: phi
    real(dp), intent(in)  :: cohesion
    real(dp), intent(out) :: tan_beta
    real(dp), intent(out) :: d

    real(dp) :: sin_phi, root

    sin_phi = sin(phi)
    root = sqrt(3.0_dp + sin_phi**2)
    tan_beta = 3.0_dp * sin_phi / root
    d = 3.0_dp * cohesion * cos(phi) / root
  end subroutine match_plane_strain_associated

  !> Inverse of match_plane_strain: the Mohr–Coulomb (φ, ψ, c) that a DP material reproduces in
  !> plane strain.
  pure subroutine mohr_coulomb_from_drucker_prager(tan_beta, tan_psi_dp, d, phi, psi, cohesion)
    real(dp), intent(in)  :: tan_beta
    real(dp), intent(in)  :: tan_psi_dp
    real(dp), intent(in)  :: d
    real(dp), intent(out) :: phi
    real(dp), intent(out) :: psi
    real(dp), intent(out) :: cohesion

    real(dp) :: s_fac, denom, sin_phi, root

    root = sqrt(9.0_dp - tan_psi_dp**2)
    s_fac = sqrt(3.0_dp) * root
    denom = 9.0_dp - tan_beta * tan_psi_dp
    sin_phi = tan_beta * s_fac / denom
    phi = asin(sin_phi)
    psi = asin(sqrt(3.0_dp) * tan_psi_dp / root)
    ! c cosφ = d S/(9 − tanβ tanψ_DP)
    cohesion = d * s_fac / (denom * cos(phi))
  end subroutine mohr_coulomb_from_drucker_prager

end module drucker_prager_match
