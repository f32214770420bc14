!> Kinematic arrays handed to a VUMAT besides the strain increment, for a material point
!> driven by prescribed corotational strain increments and no rotation: the material-point
!> driver's path and the door's two-point packaging probe (material_door).
!>
!> relSpinInc = 0, R = I. The accumulated logarithmic strain E (sum of the increments, tensor
!> shear) gives the stretch U = exp(E) and F = U. This is exact for coaxial paths (triaxial,
!> biaxial, oedometer, isotropic); for simple shear it is the usual material-point idealisation
!> (strain increments without spin), which is what the closed-form checks assume. Our VUMATs do
!> not use U or F; user VUMATs that do get a consistent, symmetric pair.
module material_kinematics
  use base_kinds, only: dp
  use lapack_interfaces, only: dsyev
  implicit none
  private

  public :: stretch_from_log_strain, defgrad_from_stretch, volumetric_strain

contains

  !> tr E (dilation positive).
  pure real(dp) function volumetric_strain(ncomp, e)
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: e(ncomp)

    volumetric_strain = e(1) + e(2) + e(3)
  end function volumetric_strain

  !> U = exp(E) in VUMAT layout (11,22,33,12[,23,31]).
  subroutine stretch_from_log_strain(ncomp, e, u)
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: e(ncomp)
    real(dp), intent(out) :: u(ncomp)
    real(dp) :: a(3, 3), v(3, 3), w(3), m(3, 3)
    integer :: k

    a = 0.0_dp
    a(1, 1) = e(1); a(2, 2) = e(2); a(3, 3) = e(3)
    a(1, 2) = e(4); a(2, 1) = e(4)
    if (ncomp == 6) then
       a(2, 3) = e(5); a(3, 2) = e(5)
       a(3, 1) = e(6); a(1, 3) = e(6)
    end if
    call symmetric_eigen(a, w, v)
    m = 0.0_dp
    do k = 1, 3
       m = m + exp(w(k)) * outer(v(:, k), v(:, k))
    end do
    u(1) = m(1, 1); u(2) = m(2, 2); u(3) = m(3, 3); u(4) = m(1, 2)
    if (ncomp == 6) then
       u(5) = m(2, 3); u(6) = m(3, 1)
    end if
  end subroutine stretch_from_log_strain

  !> F = U (no rotation) in VUMAT layout: 2D F11,F22,F33,F12,F21;
  !> 3D F11,F22,F33,F12,F23,F31,F21,F32,F13.
  pure subroutine defgrad_from_stretch(ncomp, u, f)
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: u(ncomp)
    real(dp), intent(out) :: f(:)

    f(1:ncomp) = u
    if (ncomp == 4) then
       f(5) = u(4)
    else
       f(7) = u(4); f(8) = u(5); f(9) = u(6)
    end if
  end subroutine defgrad_from_stretch

  pure function outer(x, y) result(m)
    real(dp), intent(in) :: x(3), y(3)
    real(dp) :: m(3, 3)
    integer :: i

    do i = 1, 3
       m(:, i) = x * y(i)
    end do
  end function outer

  !> Eigenvalues w and orthonormal eigenvectors v(:,k) of a symmetric 3x3 matrix (LAPACK dsyev;
  !> called once per point and increment, not in a vectorised kernel). dsyev fails only on
  !> non-finite input, which the caller never forms from finite strains; w is then NaN so the
  !> VUMAT's non-finite check stops the run instead of going on with a wrong stretch.
  subroutine symmetric_eigen(a_in, w, v)
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    real(dp), intent(in) :: a_in(3, 3)
    real(dp), intent(out) :: w(3), v(3, 3)
    integer, parameter :: lwork = 102   ! (block size 32 + 2) * 3, dsyev's optimal for n = 3
    real(dp) :: work(lwork)
    integer :: info

    v = a_in
    call dsyev('V', 'U', 3, v, 3, w, work, lwork, info)
    if (info /= 0) w = ieee_value(1.0_dp, ieee_quiet_nan)
  end subroutine symmetric_eigen

end module material_kinematics
