!> Small dense linear solve for the mixed-control Newton step (n <= 6), by LAPACK's dgesv
!> (LU with partial pivoting). A pivot of U below `rel_tol` times the largest entry of the
!> matrix marks it singular (dgesv itself only reports an exact zero), so the caller can fall
!> back to the elastic stiffness instead of producing Inf/NaN.
module matpoint_dense_solve
  use base_kinds, only: dp
  use lapack_interfaces, only: dgesv
  implicit none
  private

  public :: solve_dense

contains

  subroutine solve_dense(n, a_in, b, x, singular, rel_tol)
    integer, intent(in) :: n
    real(dp), intent(in) :: a_in(n, n), b(n)
    real(dp), intent(out) :: x(n)
    logical, intent(out) :: singular
    real(dp), intent(in) :: rel_tol
    real(dp) :: lu(n, n), rhs(n, 1), amax
    integer :: pivots(n), info, k

    x = 0.0_dp
    singular = .true.
    if (n == 0) then
       singular = .false.
       return
    end if
    amax = maxval(abs(a_in))
    if (.not. (amax > 0.0_dp) .or. amax > huge(1.0_dp)) return
    lu = a_in
    rhs(:, 1) = b
    call dgesv(n, 1, lu, n, pivots, rhs, n, info)
    if (info /= 0) return
    do k = 1, n
       if (.not. (abs(lu(k, k)) > rel_tol * amax)) return
    end do
    x = rhs(:, 1)
    singular = .false.
  end subroutine solve_dense

end module matpoint_dense_solve
