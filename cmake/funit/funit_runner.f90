!> Runs the tests of one .pf file for the driver program that cmake/pf_preprocess.py writes:
!> @before, the test, @after for each test; one PASS/FAIL line per test (failure details below
!> it), a summary line, and a non-zero exit status if anything failed.
module funit_runner
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use funit_core, only: anyExceptions, funit_begin_test, funit_failure_report, int_text
  implicit none
  private

  public :: funit_run_test, funit_suite_end

  abstract interface
    subroutine funit_procedure()
    end subroutine funit_procedure
  end interface

  integer, save :: n_passed = 0, n_failed = 0

contains

  !> As in pFUnit, a failure in @before skips the test; @after runs in every case.
  subroutine funit_run_test(suite, name, test, set_up, tear_down)
    character(len=*), intent(in) :: suite, name
    procedure(funit_procedure) :: test
    procedure(funit_procedure), optional :: set_up, tear_down

    call funit_begin_test()
    if (present(set_up)) call set_up()
    if (.not. anyExceptions()) call test()
    if (present(tear_down)) call tear_down()

    if (anyExceptions()) then
      n_failed = n_failed + 1
      write (output_unit, '(a)') 'FAIL ' // suite // '.' // name
      write (output_unit, '(a)', advance='no') funit_failure_report()
    else
      n_passed = n_passed + 1
      write (output_unit, '(a)') 'PASS ' // suite // '.' // name
    end if
    ! Keep what was printed so far if a later test crashes the program.
    flush (output_unit)
  end subroutine funit_run_test

  !> Print `<suite>: N passed, M failed` and stop with status 1 if M > 0 (plain STOP: an
  !> ERROR STOP would add a misleading backtrace in debug builds).
  subroutine funit_suite_end(suite)
    character(len=*), intent(in) :: suite
    write (output_unit, '(a)') suite // ': ' // int_text(int(n_passed, int64)) // ' passed, ' // &
      int_text(int(n_failed, int64)) // ' failed'
    flush (output_unit)
    if (n_failed > 0) stop 1
  end subroutine funit_suite_end

end module funit_runner
