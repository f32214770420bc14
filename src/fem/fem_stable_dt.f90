!> Element stable time increment of the central-difference scheme, Abaqus element-by-element
!> estimate with the bulk-viscosity damping correction:
!>   Δt_e = (L_e / c_d) (√(1 + ξ²) − ξ),   c_d = √((λ+2μ)/ρ)
!> L_e from fem_cpe4r/fem_c3d8r char_length (= h for a square/cube of side h), ξ the damping
!> ratio from fem_bulk_viscosity (b1 alone: ξ = 0.06 → factor 0.9417). λ+2μ is the effective
!> p-wave modulus the driver gets from the material's packaging call, ρ the current density.
!> The driver takes scale · min_e Δt_e over all ranks.
module fem_stable_dt
  use base_kinds, only: dp
  implicit none
  private

  public :: dilatational_wave_speed, element_stable_dt

contains

  !> c_d = √(M/ρ), M = λ + 2μ (0 for M ≤ 0).
  elemental real(dp) function dilatational_wave_speed(modulus, density) result(c)
    real(dp), intent(in) :: modulus, density

    c = sqrt(max(modulus, 0.0_dp) / max(density, tiny(1.0_dp)))
  end function dilatational_wave_speed

  !> dt_el(nb): stable increment per element. √(1+ξ²) − ξ is evaluated as 1/(√(1+ξ²) + ξ),
  !> free of cancellation for large ξ. An element without stiffness (c_d = 0) gets ~1e300.
  pure subroutine element_stable_dt(nb, char_length, wave_speed, damping_ratio, dt_el)
    integer, intent(in) :: nb
    real(dp), intent(in) :: char_length(nb), wave_speed(nb), damping_ratio(nb)
    real(dp), intent(out) :: dt_el(nb)
    real(dp) :: xi
    integer :: e

    do e = 1, nb
       xi = max(damping_ratio(e), 0.0_dp)
       ! c_d = 0 gives L_e/(1e-300 L_e) = 1e300: no overflow, no trap
       dt_el(e) = char_length(e) / max(wave_speed(e), 1.0e-300_dp * char_length(e), tiny(1.0_dp)) &
                  / (sqrt(1.0_dp + xi * xi) + xi)
    end do
  end subroutine element_stable_dt
end module fem_stable_dt
