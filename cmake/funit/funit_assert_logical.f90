!> Logical assertions and explicit failure, with pFUnit's argument order:
!>   assertTrue(condition[, message][, location])    condition: logical scalar or rank-1 array
!>   assertFalse(condition[, message][, location])
!>   assertFail([message][, location])               always fails
module funit_assert_logical
  use, intrinsic :: iso_fortran_env, only: int64
  use funit_core, only: SourceLocation, funit_fail, int_text
  implicit none
  private

  public :: assertTrue, assertFalse, assertFail

  interface assertTrue
    module procedure true_0, true_1
  end interface assertTrue

  interface assertFalse
    module procedure false_0, false_1
  end interface assertFalse

contains

  subroutine true_0(condition, message, location)
    logical, intent(in) :: condition
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    if (.not. condition) call funit_fail('assertTrue failed', '', message, location)
  end subroutine true_0

  subroutine true_1(condition, message, location)
    logical, intent(in) :: condition(:)
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    call check_all('assertTrue', .true., condition, message, location)
  end subroutine true_1

  subroutine false_0(condition, message, location)
    logical, intent(in) :: condition
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    if (condition) call funit_fail('assertFalse failed', '', message, location)
  end subroutine false_0

  subroutine false_1(condition, message, location)
    logical, intent(in) :: condition(:)
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    call check_all('assertFalse', .false., condition, message, location)
  end subroutine false_1

  subroutine assertFail(message, location)
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    call funit_fail('assertFail', '', message, location)
  end subroutine assertFail

  subroutine check_all(assertion, wanted, condition, message, location)
    character(len=*), intent(in) :: assertion
    logical, intent(in) :: wanted, condition(:)
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    integer :: k, n_bad, first_bad
    n_bad = 0
    first_bad = 0
    do k = 1, size(condition)
      if (condition(k) .neqv. wanted) then
        n_bad = n_bad + 1
        if (first_bad == 0) first_bad = k
      end if
    end do
    if (n_bad > 0) call funit_fail(assertion // ' failed', '    ' // int_text(int(n_bad, int64)) // &
      ' of ' // int_text(int(size(condition), int64)) // ' elements fail; first at (' // &
      int_text(int(first_bad, int64)) // ')', message, location)
  end subroutine check_all

end module funit_assert_logical
