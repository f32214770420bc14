!> bulkflow's stand-in for pFUnit's serial `funit` module: the assertions a .pf test calls
!> after cmake/pf_preprocess.py has expanded its @assert directives. Only used when pFUnit is
!> not installed; cmake/README.md lists the supported subset.
module funit
  use funit_core, only: SourceLocation, anyExceptions
  use funit_assert_logical, only: assertTrue, assertFalse, assertFail
  use funit_assert_typed, only: assertEqual, assertRelativelyEqual, assertLessThan, &
    assertLessThanOrEqual, assertGreaterThan, assertGreaterThanOrEqual, assertIsFinite, assertIsNaN
  implicit none
  private

  public :: SourceLocation, anyExceptions
  public :: assertTrue, assertFalse, assertFail
  public :: assertEqual, assertRelativelyEqual
  public :: assertLessThan, assertLessThanOrEqual, assertGreaterThan, assertGreaterThanOrEqual
  public :: assertIsFinite, assertIsNaN
end module funit
