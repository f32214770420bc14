!> One-dimensional property tables y(x) with Abaqus `DEPENDENCIES` semantics: piecewise-linear
!> interpolation between rows, the end value held constant beyond either end, a single row means
!> a constant. Used per material point for the (φ, ψ) table against a field variable, the
!> cohesion table against PEEQ and the tabulated flow function.
!>
!> interpolate_table runs inside the per-point loop, so it allocates nothing and accepts strided
!> sections (the tables are columns of props, e.g. props(k:k+3*n-1:3)) without copies. Tables are
!> a handful of rows, where a linear scan beats a bisection; bisection is used only for long tables.
module property_table
  use material_kinds, only: dp
  implicit none
  private

  public :: interpolate_table
  public :: table_is_ascending

  ! Up to this many rows a linear scan is used; longer tables are bisected.
  integer, parameter :: linear_scan_max_rows = 8

contains

  !> y(x) from rows (x_tab(i), y_tab(i)), x_tab ascending (see table_is_ascending).
  !> Rows beyond min(size(x_tab), size(y_tab)) are ignored; an empty table gives 0.
  !> A repeated abscissa gives a step: x at the repeated value takes the later row's y.
  pure function interpolate_table(x_tab, y_tab, x) result(y)
    real(dp), intent(in) :: x_tab(:)
    real(dp), intent(in) :: y_tab(:)
    real(dp), intent(in) :: x
    real(dp) :: y

    integer :: n, i, lo, hi, mid
    real(dp) :: w

    n = min(size(x_tab), size(y_tab))
    if (n == 0) then
      y = 0.0_dp
      return
    end if
    ! Ends (and single-row tables): hold the end value.
    if (x <= x_tab(1)) then
      y = y_tab(1)
      return
    end if
    if (x >= x_tab(n)) then
      y = y_tab(n)
      return
    end if

    ! Now x_tab(1) < x < x_tab(n), so n ≥ 2. Find i with x_tab(i) ≤ x < x_tab(i+1); then
    ! x_tab(i+1) > x_tab(i) and the weight below is well defined.
    if (n <= linear_scan_max_rows) then
      i = 1
      do while (x >= x_tab(i + 1))
        i = i + 1
      end do
    else
      lo = 1
      hi = n
      do while (hi - lo > 1)
        mid = (lo + hi) / 2
        if (x >= x_tab(mid)) then
          lo = mid
        else
          hi = mid
        end if
      end do
      i = lo
    end if

    w = (x - x_tab(i)) / (x_tab(i + 1) - x_tab(i))
    y = y_tab(i) + w * (y_tab(i + 1) - y_tab(i))
  end function interpolate_table

  !> True when the abscissae are strictly ascending (a single row counts as ascending). An empty
  !> table is reported as not ascending: callers use this to validate a table they are about to
  !> interpolate, and an empty one is not usable.
  pure function table_is_ascending(x_tab) result(ok)
    real(dp), intent(in) :: x_tab(:)
    logical :: ok

    integer :: i

    ok = size(x_tab) > 0
    do i = 2, size(x_tab)
      if (.not. (x_tab(i) > x_tab(i - 1))) then
        ok = .false.
        return
      end if
    end do
  end function table_is_ascending

end module property_table
