!> Flow functions of cohesive powders: the unconfined yield strength fc as a function of the major
!> principal consolidation stress σ1 (COMPRESSION positive, Jenike's convention), and the link
!> between fc and the Mohr–Coulomb cohesion c (thesis eq. 6.9).
!>
!> Kinds (props 8 of the MC model, umat/README.md):
!>   none     (0): no flow function; fc = 0 is returned and the caller uses another cohesion source;
!>   linear   (1): fc = fc0 + k σ1                                           (thesis eq. 6.1);
!>   bilinear (2): thesis §6.5.4 — fc(0) = fc0/2, a straight line from there to the point where the
!>                 linear flow function crosses fc = σ1, i.e. σ1* = fc0/(1 − k) (needs k < 1), and
!>                 the linear flow function beyond. Through (0, fc0/2) and (σ1*, σ1*) the first
!>                 leg has slope (1 + k)/2, so below σ1* it lies under the linear one and
!>                 fc = min(fc0/2 + (1 + k)/2 σ1, fc0 + k σ1) for σ1 ≥ 0 (no division by 1 − k;
!>                 with k ≥ 1, which material_props rejects, the halved leg would apply throughout);
!>   table    (3): piecewise-linear (σ1_i, fc_i) table, end values held (property_table).
!> A tensile σ1 (< 0) is treated as zero consolidation: a flow function is measured for
!> compressive consolidation only, a powder pulled apart is not consolidated any further than an
!> unloaded one, and extrapolating the line into tension would lower fc below fc0 (even below 0).
module flow_function
  use material_kinds, only: dp
  use property_table, only: interpolate_table
  implicit none
  private

  integer, parameter, public :: flow_function_none = 0
  integer, parameter, public :: flow_function_linear = 1
  integer, parameter, public :: flow_function_bilinear = 2
  integer, parameter, public :: flow_function_table = 3

  public :: unconfined_yield_strength
  public :: cohesion_from_unconfined_strength
  public :: unconfined_strength_from_cohesion

contains

  !> fc(σ1) for the given kind. fc0, slope: linear and bilinear kinds; tab_sigma1, tab_fc: table
  !> kind (σ1 ascending; pass zero-size arrays otherwise). Unknown kinds give 0 like kind none.
  pure function unconfined_yield_strength(kind, fc0, slope, sigma1, tab_sigma1, tab_fc) result(fc)
    integer, intent(in)  :: kind
    real(dp), intent(in) :: fc0
    real(dp), intent(in) :: slope
    real(dp), intent(in) :: sigma1
    real(dp), intent(in) :: tab_sigma1(:)
    real(dp), intent(in) :: tab_fc(:)
    real(dp) :: fc

    real(dp) :: consolidation

    consolidation = max(sigma1, 0.0_dp)
    select case (kind)
    case (flow_function_linear)
      fc = fc0 + slope * consolidation
    case (flow_function_bilinear)
      fc = min(0.5_dp * fc0 + 0.5_dp * (1.0_dp + slope) * consolidation, &
               fc0 + slope * consolidation)
    case (flow_function_table)
      fc = interpolate_table(tab_sigma1, tab_fc, consolidation)
    case default
      fc = 0.0_dp
    end select
  end function unconfined_yield_strength

  !> Mohr–Coulomb cohesion from the unconfined yield strength (thesis eq. 6.9 inverted):
  !> c = fc (1 − sinφ)/(2 cosφ), evaluated as fc cosφ/(2(1 + sinφ)) — the same number, since
  !> (1 − sinφ)(1 + sinφ) = cos²φ, without the cancellation in 1 − sinφ at large φ.
  pure function cohesion_from_unconfined_strength(fc, sin_phi) result(c)
    real(dp), intent(in) :: fc
    real(dp), intent(in) :: sin_phi
    real(dp) :: c

    c = fc * sqrt(1.0_dp - sin_phi**2) / (2.0_dp * (1.0_dp + sin_phi))
  end function cohesion_from_unconfined_strength

  !> Unconfined yield strength from the cohesion (thesis eq. 6.9): fc = 2c cosφ/(1 − sinφ),
  !> evaluated as 2c(1 + sinφ)/cosφ (equal, see above). fc is the diameter of the Mohr circle
  !> through σ3 = 0 that touches the line τ = c + σn tanφ (compression positive).
  pure function unconfined_strength_from_cohesion(c, sin_phi) result(fc)
    real(dp), intent(in) :: c
    real(dp), intent(in) :: sin_phi
    real(dp) :: fc

    fc = 2.0_dp * c * (1.0_dp + sin_phi) / sqrt(1.0_dp - sin_phi**2)
  end function unconfined_strength_from_cohesion

end module flow_function
