!> One-dimensional property tables y(x) with Abaqus `DEPENDENCIES` semantics: piecewise-linear
!> interpolation between rows, the end value held constant beyond either end, a single row means
!> a constant. Used per material point for the (φ, ψ) table against a field variable, the
!> cohesion table against PEEQ and the tabulated flow function.
!>
!> interpolate_table runs inside the per-point loop, so it allocates nothing and accepts strided
!> sections (the tables are columns of props, e.g. props(k:k+3*n-1:3)) without copies. Tables are
!> a handful of rows, where a linear scan beats a bisection; bisection is used only for long tables.
!>
!> interpolate_table_field is the same for a property with one field dependence besides its own
!> variable (Abaqus `*MOHR COULOMB HARDENING, DEPENDENCIES=1`: c against plastic strain and
!> field 1): rows in blocks of equal field value, the blocks in ascending field order (the first
!> independent variable varies fastest, Abaqus's data order for dependent material data).
module property_table
  use material_kinds, only: dp
  implicit none
  private

  public :: interpolate_table
  public :: table_is_ascending
  public :: interpolate_table_field
  public :: field_table_is_ordered

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

  !> y(x, f) from rows (x_tab(i), f_tab(i), y_tab(i)) in blocks of equal f (ascending from block
  !> to block, x ascending inside a block). Inside a block y(x) is interpolate_table's; between
  !> the two blocks around f it is linear in f; below the first and above the last block that
  !> block's y(x) holds. One block ignores f. Rows beyond the shortest array are ignored.
  pure function interpolate_table_field(x_tab, f_tab, y_tab, x, f) result(y)
    real(dp), intent(in) :: x_tab(:)
    real(dp), intent(in) :: f_tab(:)
    real(dp), intent(in) :: y_tab(:)
    real(dp), intent(in) :: x
    real(dp), intent(in) :: f
    real(dp) :: y

    integer :: n, b_start, b_end, c_end
    real(dp) :: y_next, w

    n = min(size(x_tab), size(f_tab), size(y_tab))
    if (n == 0) then
      y = 0.0_dp
      return
    end if
    ! The last block whose field value is <= f (the first block when f lies below all).
    b_start = 1
    do
      b_end = block_end(f_tab, b_start, n)
      if (b_end == n) exit
      if (f_tab(b_end + 1) > f) exit
      b_start = b_end + 1
    end do
    y = interpolate_table(x_tab(b_start:b_end), y_tab(b_start:b_end), x)
    if (b_end == n .or. .not. (f > f_tab(b_start))) return
    c_end = block_end(f_tab, b_end + 1, n)
    y_next = interpolate_table(x_tab(b_end + 1:c_end), y_tab(b_end + 1:c_end), x)
    w = (f - f_tab(b_start)) / (f_tab(b_end + 1) - f_tab(b_start))
    y = y + w * (y_next - y)
  end function interpolate_table_field

  !> True when the field values never decrease and x is strictly ascending inside every block of
  !> equal field value (the order interpolate_table_field needs). An empty table is not ordered.
  pure function field_table_is_ordered(x_tab, f_tab) result(ok)
    real(dp), intent(in) :: x_tab(:)
    real(dp), intent(in) :: f_tab(:)
    logical :: ok

    integer :: n, b_start, b_end

    n = min(size(x_tab), size(f_tab))
    ok = n > 0
    b_start = 1
    do while (ok .and. b_start <= n)
      b_end = block_end(f_tab, b_start, n)
      ok = table_is_ascending(x_tab(b_start:b_end))
      if (b_end < n) ok = ok .and. f_tab(b_end + 1) > f_tab(b_end)
      b_start = b_end + 1
    end do
  end function field_table_is_ordered

  !> Last row of the block of equal field value that starts at row `first` (rows up to n).
  pure integer function block_end(f_tab, first, n)
    real(dp), intent(in) :: f_tab(:)
    integer, intent(in) :: first, n

    block_end = first
    do while (block_end < n)
      ! (> or <: a different field value; written so because -Wcompare-reals flags ==)
      if (f_tab(block_end + 1) > f_tab(first) .or. f_tab(block_end + 1) < f_tab(first)) exit
      block_end = block_end + 1
    end do
  end function block_end

end module property_table
