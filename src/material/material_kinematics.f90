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
  use material_kinds, only: dp
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
  pure subroutine stretch_from_log_strain(ncomp, e, u)
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

  !> Eigenvalues w and eigenvectors v(:,k) of a symmetric 3x3 matrix (cyclic Jacobi;
  !> converges to round-off in a handful of sweeps for 3x3).
  pure subroutine symmetric_eigen(a_in, w, v)
    real(dp), intent(in) :: a_in(3, 3)
    real(dp), intent(out) :: w(3), v(3, 3)
    real(dp) :: a(3, 3), off, scale, theta, t, c, s, tau, apq, app, aqq
    real(dp) :: ap(3), aq(3)
    integer :: sweep, p, q, i, r

    a = a_in
    v = 0.0_dp
    do i = 1, 3
       v(i, i) = 1.0_dp
    end do
    scale = max(maxval(abs(a)), tiny(1.0_dp))
    do sweep = 1, 50
       off = abs(a(1, 2)) + abs(a(1, 3)) + abs(a(2, 3))
       if (off <= 1.0e-18_dp * scale) exit
       do p = 1, 2
          do q = p + 1, 3
             apq = a(p, q)
             if (abs(apq) <= 1.0e-300_dp) cycle
             app = a(p, p); aqq = a(q, q)
             theta = (aqq - app) / (2.0_dp * apq)
             if (abs(theta) > 1.0e100_dp) then
                ! theta**2 would overflow; t -> 1/(2 theta)
                t = 0.5_dp / theta
             else
                t = sign(1.0_dp, theta) / (abs(theta) + sqrt(theta * theta + 1.0_dp))
             end if
             c = 1.0_dp / sqrt(t * t + 1.0_dp)
             s = t * c
             tau = s / (1.0_dp + c)
             ap = a(:, p); aq = a(:, q)
             do r = 1, 3
                a(r, p) = ap(r) - s * (aq(r) + tau * ap(r))
                a(r, q) = aq(r) + s * (ap(r) - tau * aq(r))
             end do
             a(p, :) = a(:, p); a(q, :) = a(:, q)
             a(p, p) = app - t * apq
             a(q, q) = aqq + t * apq
             a(p, q) = 0.0_dp; a(q, p) = 0.0_dp
             ap = v(:, p); aq = v(:, q)
             v(:, p) = ap - s * (aq + tau * ap)
             v(:, q) = aq + s * (ap - tau * aq)
          end do
       end do
    end do
    do i = 1, 3
       w(i) = a(i, i)
    end do
  end subroutine symmetric_eigen

end module material_kinematics
