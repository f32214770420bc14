!> Abaqus/Explicit bulk viscosity: linear (always on) and quadratic (compression only) terms,
!> an isotropic stress added to the element's nodal forces only, never to the material stress.
!>
!> With ε̇_v = tr Δε / Δt (dilation positive), ρ the current density, c_d the dilatational wave
!> speed and L_e the characteristic length, Abaqus defines the pressures
!>   p1 = b1 ρ c_d L_e ε̇_v,   p2 = ρ (b2 L_e)² ε̇_v min(0, ε̇_v)      (b1 = 0.06, b2 = 1.2)
!> as resisting the volume change. In bulkflow's tension-positive convention the added stress
!> is isotropic, σ_bv I, with
!>   σ_bv = ρ c_d L_e ξ ε̇_v,   ξ = b1 − b2² (L_e/c_d) min(0, ε̇_v)  (≥ b1)
!> i.e. σ_bv = b1 ρ c_d L_e ε̇_v + ρ (b2 L_e)² ε̇_v |min(0, ε̇_v)|: negative (compressive) when
!> the element is compressed (ε̇_v < 0), positive in expansion (linear term only). The
!> corresponding pressure is p_bv = −σ_bv. ξ is the fraction of critical damping of the
!> highest mode, which reduces the stable increment (fem_stable_dt).
!> Its work, σ_bv tr Δε V = ρ c_d L_e ξ ε̇_v² Δt V ≥ 0, is dissipated (ALLVD).
module fem_bulk_viscosity
  use base_kinds, only: dp
  implicit none
  private

  public :: bulk_viscosity, bulk_viscosity_force

  real(dp), parameter, public :: default_bulk_linear = 0.06_dp
  real(dp), parameter, public :: default_bulk_quadratic = 1.2_dp

contains

  !> strain_inc (nb, ncomp): strain increment of the increment (global or corotational: only
  !> the trace is used, components 1..3); dt > 0; density, wave_speed, char_length, volume
  !> (nb) per element; b1, b2 the linear and quadratic coefficients.
  !> sigma_bv: isotropic bulk-viscosity stress (tension positive, add to 11, 22, 33);
  !> damping_ratio: ξ; energy_inc: dissipated energy σ_bv tr Δε V (≥ 0).
  pure subroutine bulk_viscosity(nb, ncomp, strain_inc, dt, density, wave_speed, char_length, &
                                 volume, b1, b2, sigma_bv, damping_ratio, energy_inc)
    integer, intent(in) :: nb, ncomp
    real(dp), intent(in) :: strain_inc(nb, ncomp)
    real(dp), intent(in) :: dt
    real(dp), intent(in) :: density(nb), wave_speed(nb), char_length(nb), volume(nb)
    real(dp), intent(in) :: b1, b2
    real(dp), intent(out) :: sigma_bv(nb), damping_ratio(nb), energy_inc(nb)
    real(dp) :: dvol, rate
    integer :: e

    do e = 1, nb
       dvol = strain_inc(e, 1) + strain_inc(e, 2) + strain_inc(e, 3)
       rate = dvol / max(dt, tiny(1.0_dp))
       damping_ratio(e) = b1 - b2 * b2 * char_length(e) * min(0.0_dp, rate) &
                          / max(wave_speed(e), tiny(1.0_dp))
       sigma_bv(e) = density(e) * char_length(e) * rate &
                     * (b1 * wave_speed(e) - b2 * b2 * char_length(e) * min(0.0_dp, rate))
       energy_inc(e) = sigma_bv(e) * dvol * volume(e)
    end do
  end subroutine bulk_viscosity

  !> Adds the nodal forces of the isotropic stress σ_bv: f_iI += V σ_bv B_iI (internal-force
  !> sign, like fem_cpe4r/fem_c3d8r internal_force). Alternatively add σ_bv to the direct
  !> components of the global stress passed to <el>_internal_force (same result).
  pure subroutine bulk_viscosity_force(nb, ndim, nen, volume, bmat, sigma_bv, fe)
    integer, intent(in) :: nb, ndim, nen
    real(dp), intent(in) :: volume(nb)
    real(dp), intent(in) :: bmat(nb, ndim, nen)
    real(dp), intent(in) :: sigma_bv(nb)
    real(dp), intent(inout) :: fe(nb, ndim, nen)
    integer :: i, n

    do n = 1, nen
       do i = 1, ndim
          fe(:, i, n) = fe(:, i, n) + volume * sigma_bv * bmat(:, i, n)
       end do
    end do
  end subroutine bulk_viscosity_force
end module fem_bulk_viscosity
