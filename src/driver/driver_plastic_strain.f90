!> PE, the plastic strain field, for blocks of our materials (all of which are linear isotropic
!> elastic with E = props(1), ν = props(2) — umat/README.md). Our VUMATs keep PEEQ and the
!> volumetric plastic strain, not the tensor, so the driver integrates it from what the VUMAT
!> sees: Δε^p = Δε − C⁻¹(σ_new − σ_old), in the corotational frame like LE, tensor shears.
!> It is kept (and costs anything) only when a step writes PE (driver_setup).
module driver_plastic_strain
  use base_kinds, only: dp
  implicit none
  private

  public :: add_elastic_compliance

contains

  !> pe ← pe + factor · C⁻¹ σ for a block of ncomp-component stresses (11, 22, 33, 12[, 23, 31]):
  !> ε_ii = (σ_ii − ν(σ_jj + σ_kk))/E, ε_ij = (1 + ν)/E σ_ij (tensor shear).
  pure subroutine add_elastic_compliance(nb, ncomp, young, poisson, factor, stress, pe)
    integer, intent(in) :: nb, ncomp
    real(dp), intent(in) :: young, poisson, factor
    real(dp), intent(in) :: stress(nb, ncomp)
    real(dp), intent(inout) :: pe(nb, ncomp)
    real(dp) :: a, b, c, trace
    integer :: e, k

    a = factor / young
    b = factor * poisson / young
    c = factor * (1 + poisson) / young
    do e = 1, nb
       trace = stress(e, 1) + stress(e, 2) + stress(e, 3)
       pe(e, 1) = pe(e, 1) + (a + b) * stress(e, 1) - b * trace
       pe(e, 2) = pe(e, 2) + (a + b) * stress(e, 2) - b * trace
       pe(e, 3) = pe(e, 3) + (a + b) * stress(e, 3) - b * trace
    end do
    do k = 4, ncomp
       pe(:, k) = pe(:, k) + c * stress(:, k)
    end do
  end subroutine add_elastic_compliance
end module driver_plastic_strain
