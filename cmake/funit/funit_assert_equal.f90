!> The check behind assertEqual and assertRelativelyEqual (their typed generics are generated
!> into funit_assert_typed by cmake/funit_generate.py, with pFUnit's argument order):
!> `expected` may be a scalar compared with every element of `actual`; without a tolerance,
!> reals must match exactly. Passing: |expected - actual| <= tolerance (absolute) or
!> <= tolerance*|expected| (relative, where a zero expected value fails as pFUnit's zero
!> denominator does); NaN never passes, an infinity only matches the same infinity.
module funit_assert_equal
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_is_finite, ieee_class, &
    ieee_class_type, operator(==), ieee_status_type, ieee_get_status, ieee_set_status, &
    ieee_set_halting_mode, ieee_usual
  use, intrinsic :: iso_fortran_env, only: int64
  use funit_core, only: dp, SourceLocation, flat_value, flatten, element_count, tag_name, &
    element_text, index_text, dims_text, real_text, int_text, funit_fail, &
    tag_integer, tag_real, tag_logical, tag_character
  implicit none
  private

  public :: check_equal

contains

  !> Compare element by element (a scalar `expected` against every element of `actual`) and
  !> report the number of mismatches and the first one.
  subroutine check_equal(assertion, expected, actual, tolerance, relative, message, location)
    character(len=*), intent(in) :: assertion
    type(flat_value), intent(in) :: expected, actual
    real(dp), intent(in), optional :: tolerance
    logical, intent(in), optional :: relative
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    type(ieee_status_type) :: fp_status
    character(len=:), allocatable :: details
    real(dp) :: tol
    logical :: is_relative, as_reals, ok
    integer :: k, ke, n, n_bad, first_bad

    if (.not. comparable(expected, actual)) then
      call funit_fail(assertion // ' failed', '    cannot compare ' // tag_name(expected) // &
                      ' (expected) with ' // tag_name(actual) // ' (actual)', message, location)
      return
    end if
    if (size(expected%dims) > 0) then
      ok = size(expected%dims) == size(actual%dims)
      if (ok) ok = all(expected%dims == actual%dims)
      if (.not. ok) then
        call funit_fail(assertion // ' failed', '    shape mismatch: expected ' // dims_text(expected%dims) // &
                        ', actual ' // dims_text(actual%dims), message, location)
        return
      end if
    end if

    tol = 0.0_dp
    if (present(tolerance)) tol = tolerance
    is_relative = .false.
    if (present(relative)) is_relative = relative
    ! Integers stay exact unless a real or a tolerance is involved.
    as_reals = expected%tag == tag_real .or. actual%tag == tag_real .or. present(tolerance)

    ! A debug build traps invalid/overflow/zero-divide; comparing against Inf or NaN, or
    ! subtracting two huge values, must report a failure instead of stopping the program.
    call ieee_get_status(fp_status)
    call ieee_set_halting_mode(ieee_usual, .false.)
    ! pFUnit divides by the expected value and refuses a zero one before comparing anything.
    if (is_relative) then
      if (any(abs(expected%reals) <= 0.0_dp)) then
        call ieee_set_status(fp_status)
        call funit_fail(assertion // ' failed', '    zero denominator: an expected value is 0', &
                        message, location)
        return
      end if
    end if
    n = element_count(actual)
    n_bad = 0
    first_bad = 0
    do k = 1, n
      ke = k
      if (size(expected%dims) == 0) ke = 1
      select case (actual%tag)
      case (tag_logical)
        ok = expected%logicals(ke) .eqv. actual%logicals(k)
      case (tag_character)
        ok = expected%text == actual%text
      case default
        if (as_reals) then
          ok = reals_match(expected%reals(ke), actual%reals(k), tol, is_relative)
        else
          ok = expected%ints(ke) == actual%ints(k)
        end if
      end select
      if (.not. ok) then
        n_bad = n_bad + 1
        if (first_bad == 0) first_bad = k
      end if
    end do

    if (n_bad > 0) then
      details = ''
      if (size(actual%dims) > 0) details = '    ' // int_text(int(n_bad, int64)) // ' of ' // &
        int_text(int(n, int64)) // ' elements differ; first at ' // index_text(actual%dims, first_bad) // new_line('a')
      ke = first_bad
      if (size(expected%dims) == 0) ke = 1
      details = details // '      expected: ' // element_text(expected, ke) // new_line('a') // &
                           '        actual: ' // element_text(actual, first_bad)
      if (as_reals .and. actual%tag /= tag_logical .and. actual%tag /= tag_character) &
        details = details // new_line('a') // &
                  difference_text(expected%reals(ke), actual%reals(first_bad), tol, is_relative)
    end if
    call ieee_set_status(fp_status)
    if (n_bad > 0) call funit_fail(assertion // ' failed', details, message, location)
  end subroutine check_equal

  logical function comparable(expected, actual)
    type(flat_value), intent(in) :: expected, actual
    logical :: numeric_e, numeric_a
    numeric_e = expected%tag == tag_integer .or. expected%tag == tag_real
    numeric_a = actual%tag == tag_integer .or. actual%tag == tag_real
    comparable = (numeric_e .and. numeric_a) .or. &
                 (expected%tag == actual%tag .and. (actual%tag == tag_logical .or. actual%tag == tag_character))
  end function comparable

  logical function reals_match(expected, actual, tolerance, relative)
    real(dp), intent(in) :: expected, actual, tolerance
    logical, intent(in) :: relative
    type(ieee_class_type) :: class_e, class_a
    if (ieee_is_nan(expected) .or. ieee_is_nan(actual)) then
      reals_match = .false.
    else if (.not. (ieee_is_finite(expected) .and. ieee_is_finite(actual))) then
      class_e = ieee_class(expected)
      class_a = ieee_class(actual)
      reals_match = class_e == class_a
    else if (relative) then
      reals_match = abs(expected - actual) <= tolerance * abs(expected)
    else
      reals_match = abs(expected - actual) <= tolerance
    end if
  end function reals_match

  function difference_text(expected, actual, tolerance, relative) result(text)
    real(dp), intent(in) :: expected, actual, tolerance
    logical, intent(in) :: relative
    character(len=:), allocatable :: text
    if (relative) then
      text = '    rel. diff.: ' // real_text(abs(expected - actual) / abs(expected)) // &
             ' (relative tolerance ' // real_text(tolerance) // ')'
    else
      text = '    difference: ' // real_text(abs(expected - actual)) // &
             ' (tolerance ' // real_text(tolerance) // ')'
    end if
  end function difference_text

end module funit_assert_equal
