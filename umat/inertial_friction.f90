!> Rate-dependent friction μ(I) of Jop, Forterre & Pouliquen (2006, Nature 441:727), an option
!> of the Mohr-Coulomb VUMAT (umat/README.md, docs/mu_of_i.md).
!>
!>   μ(I) = μs + (μ2 − μs) / (I0/I + 1),   I = γ̇ d / sqrt(p/ρs)
!>
!> γ̇ = sqrt(2 dev(D):dev(D)) is Jop et al.'s |γ̇| = sqrt(½ γ̇_ij γ̇_ij) with γ̇_ij = 2 D_ij of the
!> deviatoric part (their flow is incompressible; the volumetric rate of a compressible solid
!> is not shear). In simple shear at engineering rate γ̇ it is γ̇ itself. μ is mapped to the
!> Mohr-Coulomb angle by sin φ = μ: in steady simple shear with ψ = 0 the stress ratio on the
!> shear plane of a Mohr-Coulomb solid is sin φ (Davis 1968), and that ratio is what μ(I) is.
!>
!> The increment's rate is Δε/dt and p the start-of-increment pressure; the fraction
!> I/(I0 + I) is formed as a/(a + b) with a = |Δγ| d sqrt(ρs), b = I0 sqrt(p) dt, so that
!> neither dt → 0 nor p → 0 divides by zero: p ≤ 0 (no confinement) or dt = 0 with shear gives
!> the fraction 1 (μ2), no shear gives exactly 0 (μs, bit for bit the static material).
module inertial_friction
  use material_kinds, only: dp
  implicit none
  private

  public :: shear_increment, inertial_fraction, inertial_friction_chunk

contains

  !> |Δγ| = sqrt(2 dev(Δε):dev(Δε)) of one increment (tensor shear components 4..ncomp).
  pure real(dp) function shear_increment(ncomp, deps) result(dgamma)
    integer, intent(in) :: ncomp
    ! Assumed shape: a row of a (nblock, ncomp) block is passed without a copy.
    real(dp), intent(in) :: deps(:)
    real(dp) :: third_trace, sum2

    third_trace = (deps(1) + deps(2) + deps(3)) / 3.0_dp
    sum2 = (deps(1) - third_trace)**2 + (deps(2) - third_trace)**2 + (deps(3) - third_trace)**2 &
         + 2.0_dp * sum(deps(4:ncomp)**2)
    dgamma = sqrt(2.0_dp * sum2)
  end function shear_increment

  !> I/(I0 + I) of an increment with shear |Δγ| over dt at pressure p (compression positive);
  !> d_sqrt_rho = d sqrt(ρs). In [0, 1]; 0 exactly when |Δγ| = 0.
  pure elemental real(dp) function inertial_fraction(dgamma, dt, pressure, i0, d_sqrt_rho) result(f)
    real(dp), intent(in) :: dgamma, dt, pressure, i0, d_sqrt_rho
    real(dp) :: a, b

    a = dgamma * d_sqrt_rho
    b = i0 * sqrt(max(pressure, 0.0_dp)) * max(dt, 0.0_dp)
    if (a > 0) then
       f = a / (a + b)
    else
       f = 0
    end if
  end function inertial_fraction

  !> Rate-dependent sin φ and φ of the points k0+1..k0+n of a VUMAT block, from their static
  !> sin φs (sin_phi, phi: the angle the static model uses) and sin φ2. Where the fraction is
  !> 0 the static values are kept bit for bit (sin φs + 0 = sin φs; φ not recomputed).
  !> Explicit in the rate: I of this increment's Δε/dt at the start-of-increment pressure.
  pure subroutine inertial_friction_chunk(n, k0, nblock, ncomp, strain_inc, stress_old, dt, &
       sin_phi2, i0, d_sqrt_rho, phi, sin_phi, phi_rate, sin_phi_rate)
    integer, intent(in) :: n, k0, nblock, ncomp
    real(dp), intent(in) :: strain_inc(nblock, ncomp), stress_old(nblock, ncomp)
    real(dp), intent(in) :: dt, sin_phi2, i0, d_sqrt_rho
    real(dp), intent(in) :: phi(n), sin_phi(n)
    real(dp), intent(out) :: phi_rate(n), sin_phi_rate(n)
    integer :: i, k
    real(dp) :: tr, sum2, dgamma(n), pressure(n)

    ! One loop per step with unit stride in the point index (vectorised, as material_update's
    ! loops); the first two are the operations of shear_increment.
    if (ncomp == 4) then
       do i = 1, n
          k = k0 + i
          tr = (strain_inc(k, 1) + strain_inc(k, 2) + strain_inc(k, 3)) / 3.0_dp
          sum2 = (strain_inc(k, 1) - tr)**2 + (strain_inc(k, 2) - tr)**2 + (strain_inc(k, 3) - tr)**2 &
               + 2.0_dp * strain_inc(k, 4)**2
          dgamma(i) = sqrt(2.0_dp * sum2)
       end do
    else
       do i = 1, n
          k = k0 + i
          tr = (strain_inc(k, 1) + strain_inc(k, 2) + strain_inc(k, 3)) / 3.0_dp
          sum2 = (strain_inc(k, 1) - tr)**2 + (strain_inc(k, 2) - tr)**2 + (strain_inc(k, 3) - tr)**2 &
               + 2.0_dp * (strain_inc(k, 4)**2 + strain_inc(k, 5)**2 + strain_inc(k, 6)**2)
          dgamma(i) = sqrt(2.0_dp * sum2)
       end do
    end if
    do i = 1, n
       k = k0 + i
       pressure(i) = -(stress_old(k, 1) + stress_old(k, 2) + stress_old(k, 3)) / 3.0_dp
    end do
    do i = 1, n
       sin_phi_rate(i) = sin_phi(i) + (sin_phi2 - sin_phi(i)) &
            * inertial_fraction(dgamma(i), dt, pressure(i), i0, d_sqrt_rho)
    end do
    ! Where the rate does not move sin φ (f = 0, or below its last bit) φ stays the static
    ! angle bit for bit (asin(sin φ) need not be φ to the last bit). sin φ2 ≥ sin φ (checked
    ! by the decoder), so the rate can only raise it.
    do i = 1, n
       if (sin_phi_rate(i) > sin_phi(i)) then
          phi_rate(i) = asin(sin_phi_rate(i))
       else
          phi_rate(i) = phi(i)
       end if
    end do
  end subroutine inertial_friction_chunk
end module inertial_friction
