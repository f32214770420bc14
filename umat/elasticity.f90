!> Linear isotropic elasticity for the material kernels: elastic constants from (E, ν), the
!> stiffness increment D:Δε on Abaqus-ordered component vectors, and the compliance on
!> principal values.
!>
!> Component order (Abaqus/Explicit): ncomp = 4 → (11, 22, 33, 12) for plane strain and
!> axisymmetry (σ33 is carried, ε33 is whatever the host passes, 0 for plane strain);
!> ncomp = 6 → (11, 22, 33, 12, 23, 31). Shear strains are TENSOR components (ε12, not γ12),
!> so the shear stiffness is 2G, exactly like the direct components. Tension positive.
!>
!> Everything here is tiny and pure so the compiler can inline it into the per-point loops.
module elasticity
  use material_kinds, only: dp
  implicit none
  private

  public :: lame_constants
  public :: bulk_modulus
  public :: p_wave_modulus
  public :: elastic_increment
  public :: principal_compliance

contains

  !> Lamé's first constant λ and the shear modulus G (= μ) from Young's modulus and Poisson's ratio.
  pure subroutine lame_constants(young, poisson, lam, shear)
    real(dp), intent(in)  :: young
    real(dp), intent(in)  :: poisson
    real(dp), intent(out) :: lam
    real(dp), intent(out) :: shear

    shear = young / (2.0_dp * (1.0_dp + poisson))
    lam = young * poisson / ((1.0_dp + poisson) * (1.0_dp - 2.0_dp * poisson))
  end subroutine lame_constants

  !> Bulk modulus K = E / (3(1 − 2ν)).
  pure function bulk_modulus(young, poisson) result(bulk)
    real(dp), intent(in) :: young
    real(dp), intent(in) :: poisson
    real(dp) :: bulk

    bulk = young / (3.0_dp * (1.0_dp - 2.0_dp * poisson))
  end function bulk_modulus

  !> P-wave (constrained, oedometric) modulus M = λ + 2G = E(1 − ν)/((1 + ν)(1 − 2ν)).
  !> It sets the dilatational wave speed √(M/ρ) and hence the explicit stable time step.
  pure function p_wave_modulus(young, poisson) result(modulus)
    real(dp), intent(in) :: young
    real(dp), intent(in) :: poisson
    real(dp) :: modulus

    modulus = young * (1.0_dp - poisson) / ((1.0_dp + poisson) * (1.0_dp - 2.0_dp * poisson))
  end function p_wave_modulus

  !> stress ← stress + D:Δε.
  !> Components 1..3 are direct, components 4..ncomp are tensor shears (Δσij = 2G Δεij), so the
  !> same loop serves ncomp = 4 and ncomp = 6. The arrays are assumed-shape (only their first
  !> ncomp entries are used) so that a row of an Abaqus (nblock, ncomp) block, a strided section,
  !> is passed without a copy-in/copy-out temporary.
  pure subroutine elastic_increment(ncomp, lam, shear, strain_inc, stress)
    integer, intent(in)     :: ncomp
    real(dp), intent(in)    :: lam
    real(dp), intent(in)    :: shear
    real(dp), intent(in)    :: strain_inc(:)
    real(dp), intent(inout) :: stress(:)

    real(dp) :: lam_tr, two_g
    integer :: i

    two_g = 2.0_dp * shear
    lam_tr = lam * (strain_inc(1) + strain_inc(2) + strain_inc(3))
    do i = 1, 3
      stress(i) = stress(i) + lam_tr + two_g * strain_inc(i)
    end do
    do i = 4, ncomp
      stress(i) = stress(i) + two_g * strain_inc(i)
    end do
  end subroutine elastic_increment

  !> Δε = D⁻¹ Δσ for principal (or any direct) values:
  !> Δε_i = (Δσ_i − λ/(3λ + 2G) tr Δσ) / (2G)
  !> (from tr Δσ = (3λ + 2G) tr Δε, then solving Δσ = λ tr Δε I + 2G Δε for Δε).
  pure subroutine principal_compliance(lam, shear, dsig, deps)
    real(dp), intent(in)  :: lam
    real(dp), intent(in)  :: shear
    real(dp), intent(in)  :: dsig(3)
    real(dp), intent(out) :: deps(3)

    real(dp) :: vol_part

    vol_part = lam / (3.0_dp * lam + 2.0_dp * shear) * (dsig(1) + dsig(2) + dsig(3))
    deps = (dsig - vol_part) / (2.0_dp * shear)
  end subroutine principal_compliance

end module elasticity
