!> Element inversion / collapse detection for CPE4R and C3D8R blocks.
!>
!> The one-point volume alone does not catch every tangled element: a bow-tie quadrilateral
!> can keep a positive centre area. So every corner Jacobian is checked too (the Jacobian of
!> the bilinear/trilinear map at a node is the determinant of the edge vectors to its
!> neighbours along ξ, η (and ζ), with the sign of the node's natural coordinates), and the
!> volume ratio V/V0 against a collapse limit. The driver stops the run with the element
!> number, the time and inversion_reason_text(reason).
!>
!> Node numbering: CPE4R 1–4 counter-clockwise; C3D8R 1–4 bottom face, counter-clockwise seen
!> from the top, 5–8 above them (Abaqus order).
module fem_inversion
  use base_kinds, only: dp
  implicit none
  private

  public :: check_inversion, inversion_reason_text

  integer, parameter, public :: inversion_none = 0      !< element is fine
  integer, parameter, public :: inversion_centre = 1    !< volume (centre Jacobian) ≤ 0
  integer, parameter, public :: inversion_corner = 2    !< a corner Jacobian ≤ 0 (tangled/bow-tie)
  integer, parameter, public :: inversion_collapse = 3  !< V/V0 below the collapse limit
  integer, parameter, public :: inversion_axis = 4      !< CAX4R: a node crossed the axis (r < 0)
  !> Suggested collapse limit for V/V0 (granular compaction stays far above it).
  real(dp), parameter, public :: default_min_volume_ratio = 1.0e-2_dp

  ! Natural coordinates of the nodes and their neighbours along ξ, η, ζ.
  real(dp), parameter :: xi2(4) = [-1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp]
  real(dp), parameter :: eta2(4) = [-1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp]
  integer, parameter :: nxi2(4) = [2, 1, 4, 3], neta2(4) = [4, 3, 2, 1]
  real(dp), parameter :: xi3(8) = [-1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp]
  real(dp), parameter :: eta3(8) = [-1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp]
  real(dp), parameter :: zeta3(8) = [-1.0_dp, -1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp]
  integer, parameter :: nxi3(8) = [2, 1, 4, 3, 6, 5, 8, 7]
  integer, parameter :: neta3(8) = [4, 3, 2, 1, 8, 7, 6, 5]
  integer, parameter :: nzeta3(8) = [5, 6, 7, 8, 1, 2, 3, 4]

contains

  !> reason(e) for every element of the block (inversion_* codes, first failing test in the
  !> order centre, corner, collapse). volume: current one-point volume (fem_cpe4r/fem_c3d8r
  !> geometry, thickness included in 2D); volume_ref: reference volume (same convention).
  pure subroutine check_inversion(nb, ndim, nen, xe, volume, volume_ref, min_volume_ratio, reason)
    integer, intent(in) :: nb, ndim, nen
    real(dp), intent(in) :: xe(nb, ndim, nen)
    real(dp), intent(in) :: volume(nb), volume_ref(nb)
    real(dp), intent(in) :: min_volume_ratio
    integer, intent(out) :: reason(nb)
    real(dp), allocatable :: jmin(:)

    if (ndim == 2) then
       call check_inversion_2d(nb, xe, volume, volume_ref, min_volume_ratio, reason)
       return
    end if
    allocate(jmin(nb))
    call min_corner_jacobian_3d(nb, xe, jmin)
    reason = merge(inversion_centre, &
                   merge(inversion_corner, &
                         merge(inversion_collapse, inversion_none, &
                               volume < min_volume_ratio * volume_ref), &
                         jmin <= 0.0_dp), &
                   volume <= 0.0_dp)
  end subroutine check_inversion

  !> check_inversion for CPE4R as one element loop on scalars (no block-sized temporary, which
  !> gfortran would allocate on the heap at every call). Corner values ξ_I η_I ·
  !> (x_nξ − x_I) × (x_nη − x_I) (4 × the corner Jacobian), their minimum, then the tests in the
  !> order of the 3D path.
  pure subroutine check_inversion_2d(nb, xe, volume, volume_ref, min_volume_ratio, reason)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 2, 4)
    real(dp), intent(in) :: volume(nb), volume_ref(nb)
    real(dp), intent(in) :: min_volume_ratio
    integer, intent(out) :: reason(nb)
    integer :: n, a, b, e, r
    real(dp) :: s, j, jmin

    !GCC$ ivdep
    do e = 1, nb
       jmin = huge(1.0_dp)
       do n = 1, 4
          a = nxi2(n)
          b = neta2(n)
          s = xi2(n) * eta2(n)
          j = s * ((xe(e, 1, a) - xe(e, 1, n)) * (xe(e, 2, b) - xe(e, 2, n)) &
                   - (xe(e, 2, a) - xe(e, 2, n)) * (xe(e, 1, b) - xe(e, 1, n)))
          jmin = min(jmin, j)
       end do
       r = inversion_none
       if (volume(e) < min_volume_ratio * volume_ref(e)) r = inversion_collapse
       if (jmin <= 0.0_dp) r = inversion_corner
       if (volume(e) <= 0.0_dp) r = inversion_centre
       reason(e) = r
    end do
  end subroutine check_inversion_2d

  !> Smallest corner value −ξ_I η_I ζ_I · det[x_nξ − x_I, x_nη − x_I, x_nζ − x_I]
  !> (8 × the corner Jacobian of the trilinear map).
  pure subroutine min_corner_jacobian_3d(nb, xe, jmin)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 3, 8)
    real(dp), intent(out) :: jmin(nb)
    integer :: n, a, b, c, e
    real(dp) :: s, j, u(3), v(3), w(3)

    jmin = huge(1.0_dp)
    do n = 1, 8
       a = nxi3(n)
       b = neta3(n)
       c = nzeta3(n)
       s = -xi3(n) * eta3(n) * zeta3(n)
       do e = 1, nb
          u = xe(e, :, a) - xe(e, :, n)
          v = xe(e, :, b) - xe(e, :, n)
          w = xe(e, :, c) - xe(e, :, n)
          j = s * (u(1) * (v(2) * w(3) - v(3) * w(2)) + u(2) * (v(3) * w(1) - v(1) * w(3)) &
                   + u(3) * (v(1) * w(2) - v(2) * w(1)))
          jmin(e) = min(jmin(e), j)
       end do
    end do
  end subroutine min_corner_jacobian_3d

  !> One-line reason for the driver's stop message.
  pure function inversion_reason_text(reason) result(text)
    integer, intent(in) :: reason
    character(len=:), allocatable :: text

    select case (reason)
    case (inversion_none)
       text = 'element is valid'
    case (inversion_centre)
       text = 'element inverted: volume (centre Jacobian) <= 0'
    case (inversion_corner)
       text = 'element tangled: a corner Jacobian <= 0 (bow-tie or folded element)'
    case (inversion_collapse)
       text = 'element collapsed: volume ratio V/V0 below the limit'
    case (inversion_axis)
       text = 'axisymmetric element crossed the symmetry axis: a node has r < 0'
    case default
       text = 'unknown inversion reason'
    end select
  end function inversion_reason_text
end module fem_inversion
