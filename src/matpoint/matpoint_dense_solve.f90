!> Small dense linear solve for the mixed-control Newton step (n <= 6).
!> Gaussian elimination with partial pivoting; a pivot below `rel_tol` times the largest
!> entry marks the matrix singular, so the caller can fall back to the elastic stiffness
!> instead of producing Inf/NaN.
module matpoint_dense_solve
  use material_kinds, only: dp
  implicit none
  private

  public :: solve_dense

contains

  pure subroutine solve_dense(n, a_in, b, x, singular, rel_tol)
    integer, intent(in) :: n
    real(dp), intent(in) :: a_in(n, n), b(n)
    real(dp), intent(out) :: x(n)
    logical, intent(out) :: singular
    real(dp), intent(in) :: rel_tol
    real(dp) :: a(n, n), r(n), amax, f, row(n), rk
    integer :: k, i, p

    a = a_in
    r = b
    x = 0.0_dp
    singular = .true.
    if (n == 0) then
       singular = .false.
       return
    end if
    amax = maxval(abs(a))
    if (.not. (amax > 0.0_dp) .or. amax > huge(1.0_dp)) return
    do k = 1, n
       p = k - 1 + maxloc(abs(a(k:n, k)), dim=1)
       if (.not. (abs(a(p, k)) > rel_tol * amax)) return
       if (p /= k) then
          row = a(k, :); a(k, :) = a(p, :); a(p, :) = row
          rk = r(k); r(k) = r(p); r(p) = rk
       end if
       do i = k + 1, n
          f = a(i, k) / a(k, k)
          a(i, k:n) = a(i, k:n) - f * a(k, k:n)
          r(i) = r(i) - f * r(k)
       end do
    end do
    do k = n, 1, -1
       x(k) = (r(k) - dot_product(a(k, k + 1:n), x(k + 1:n))) / a(k, k)
    end do
    singular = .false.
  end subroutine solve_dense

end module matpoint_dense_solve
