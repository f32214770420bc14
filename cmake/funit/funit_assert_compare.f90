!> The checks behind the ordering assertions (assertLessThan(lhs, rhs) passes when lhs < rhs;
!> LessThanOrEqual, GreaterThan, GreaterThanOrEqual likewise) and the IEEE-class assertions
!> (assertIsFinite, assertIsNaN). Their typed generics are generated into funit_assert_typed
!> by cmake/funit_generate.py. Two integers compare exactly, any other pair as real(dp); a NaN
!> operand fails every ordering assertion.
module funit_assert_compare
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_is_finite, ieee_status_type, &
    ieee_get_status, ieee_set_status, ieee_set_halting_mode, ieee_usual
  use, intrinsic :: iso_fortran_env, only: int64
  use funit_core, only: dp, SourceLocation, flat_value, flatten, element_count, tag_name, &
    element_text, index_text, int_text, funit_fail, tag_integer, tag_real
  implicit none
  private

  public :: check_order, check_class
  public :: order_less, order_less_or_equal, order_greater, order_greater_or_equal

  integer, parameter :: order_less = 1, order_less_or_equal = 2, order_greater = 3, &
                        order_greater_or_equal = 4

contains

  subroutine check_order(assertion, relation, lhs, rhs, message, location)
    character(len=*), intent(in) :: assertion
    integer, intent(in) :: relation
    type(flat_value), intent(in) :: lhs, rhs
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    type(ieee_status_type) :: fp_status
    character(len=*), parameter :: words(4) = [character(len=24) :: 'less than', &
      'less than or equal to', 'greater than', 'greater than or equal to']
    logical :: ok

    if (.not. (is_numeric(lhs) .and. is_numeric(rhs))) then
      call funit_fail(assertion // ' failed', '    cannot order ' // tag_name(lhs) // ' and ' // &
                      tag_name(rhs), message, location)
      return
    end if
    if (lhs%tag == tag_integer .and. rhs%tag == tag_integer) then
      select case (relation)
      case (order_less)
        ok = lhs%ints(1) < rhs%ints(1)
      case (order_less_or_equal)
        ok = lhs%ints(1) <= rhs%ints(1)
      case (order_greater)
        ok = lhs%ints(1) > rhs%ints(1)
      case default
        ok = lhs%ints(1) >= rhs%ints(1)
      end select
    else
      ! Ordered comparisons signal "invalid" on NaN, which a debug build traps.
      call ieee_get_status(fp_status)
      call ieee_set_halting_mode(ieee_usual, .false.)
      if (ieee_is_nan(lhs%reals(1)) .or. ieee_is_nan(rhs%reals(1))) then
        ok = .false.
      else
        select case (relation)
        case (order_less)
          ok = lhs%reals(1) < rhs%reals(1)
        case (order_less_or_equal)
          ok = lhs%reals(1) <= rhs%reals(1)
        case (order_greater)
          ok = lhs%reals(1) > rhs%reals(1)
        case default
          ok = lhs%reals(1) >= rhs%reals(1)
        end select
      end if
      call ieee_set_status(fp_status)
    end if
    if (.not. ok) call funit_fail(assertion // ' failed', '    expected ' // element_text(lhs, 1) // &
                                  ' to be ' // trim(words(relation)) // ' ' // element_text(rhs, 1), &
                                  message, location)
  end subroutine check_order

  !> want_finite: every element finite; otherwise: every element NaN.
  subroutine check_class(assertion, want_finite, x, message, location)
    character(len=*), intent(in) :: assertion
    logical, intent(in) :: want_finite
    type(flat_value), intent(in) :: x
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    type(ieee_status_type) :: fp_status
    character(len=:), allocatable :: details
    integer :: k, n, n_bad, first_bad
    logical :: ok

    if (.not. is_numeric(x)) then
      call funit_fail(assertion // ' failed', '    not defined for ' // tag_name(x), message, location)
      return
    end if
    call ieee_get_status(fp_status)
    call ieee_set_halting_mode(ieee_usual, .false.)
    n = element_count(x)
    n_bad = 0
    first_bad = 0
    do k = 1, n
      if (want_finite) then
        ok = ieee_is_finite(x%reals(k))
      else
        ok = ieee_is_nan(x%reals(k))
      end if
      if (.not. ok) then
        n_bad = n_bad + 1
        if (first_bad == 0) first_bad = k
      end if
    end do
    call ieee_set_status(fp_status)
    if (n_bad == 0) return

    details = '    value: ' // element_text(x, first_bad)
    if (size(x%dims) > 0) details = '    ' // int_text(int(n_bad, int64)) // ' of ' // &
      int_text(int(n, int64)) // ' elements fail; first at ' // index_text(x%dims, first_bad) // &
      new_line('a') // details
    call funit_fail(assertion // ' failed', details, message, location)
  end subroutine check_class

  logical function is_numeric(x)
    type(flat_value), intent(in) :: x
    is_numeric = x%tag == tag_integer .or. x%tag == tag_real
  end function is_numeric

end module funit_assert_compare
