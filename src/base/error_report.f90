!> Error reporting for every bulkflow component.
!>
!> Two ways to fail, both producing the same text
!> `bulkflow: error: <file>:<line>: <message>`:
!>
!> * library routines take an optional `type(error_t)` argument. When the caller
!>   passes one, the error is recorded there and the routine returns, so tests can
!>   look at the message and callers can add context. When the caller does not pass
!>   one, the routine reports the error and stops (`raise_error`).
!> * `fatal_error` / `report_and_stop` print the message on stderr and call the
!>   final-stop procedure.
!>
!> The final stop is a procedure pointer so that the MPI solver can route it to
!> MPI_Abort (a plain `error stop` on one rank would leave the others hanging).
!> The default is `error stop 2` (quiet: the message is said; the runtime's "ERROR STOP 2" and its
!> note on signalling floating-point flags would only add noise): a non-zero exit status.
module error_report
  use, intrinsic :: iso_fortran_env, only: error_unit
  implicit none
  private

  public :: error_t
  public :: set_error, raise_error, fatal_error, report_and_stop
  public :: format_error_location, add_expectation, pass_error
  public :: final_stop_i, set_final_stop, reset_final_stop

  !> One recorded error. `message` holds the full "file:line: text" form
  !> (without the "bulkflow: error: " prefix).
  type :: error_t
     logical :: raised = .false.
     character(len=:), allocatable :: message
     character(len=:), allocatable :: file
     integer :: line = 0
  end type error_t

  abstract interface
     !> What to do after the message is printed; must not return.
     subroutine final_stop_i()
     end subroutine final_stop_i
  end interface

  procedure(final_stop_i), pointer :: final_stop => default_final_stop

contains

  !> "file:line: message", "file: message" or "message", depending on what is known.
  pure function format_error_location(file, line, message) result(text)
    character(len=*), intent(in) :: file
    integer, intent(in) :: line
    character(len=*), intent(in) :: message
    character(len=:), allocatable :: text
    character(len=16) :: buf

    if (len_trim(file) == 0) then
       text = message
    else if (line > 0) then
       write (buf, '(i0)') line
       text = trim(file) // ':' // trim(buf) // ': ' // message
    else
       text = trim(file) // ': ' // message
    end if
  end function format_error_location

  !> Record an error in `err` (overwriting any previous one).
  pure subroutine set_error(err, file, line, message)
    type(error_t), intent(inout) :: err
    character(len=*), intent(in) :: file
    integer, intent(in) :: line
    character(len=*), intent(in) :: message

    err%raised = .true.
    err%file = trim(file)
    err%line = line
    err%message = format_error_location(file, line, message)
  end subroutine set_error

  !> Record the error in `err` when present, otherwise report it and stop.
  subroutine raise_error(file, line, message, err)
    character(len=*), intent(in) :: file
    integer, intent(in) :: line
    character(len=*), intent(in) :: message
    type(error_t), intent(inout), optional :: err

    if (present(err)) then
       call set_error(err, file, line, message)
    else
       call report_and_stop(file, line, message)
    end if
  end subroutine raise_error

  !> Append "; expected <what>" to a raised error unless its message says what was expected
  !> already (the rule for every message: what is wrong and what was expected).
  !> Hand an error recorded in `local` to the caller's `err`, or stop with it when the caller
  !> gave none (the convention of the routines with an optional error argument).
  subroutine pass_error(local, err)
    type(error_t), intent(in) :: local
    type(error_t), intent(inout), optional :: err

    if (present(err)) then
       err = local
    else
       call raise_error('', 0, local%message)
    end if
  end subroutine pass_error

  subroutine add_expectation(err, what)
    type(error_t), intent(inout) :: err
    character(len=*), intent(in) :: what

    if (.not. allocated(err%message)) err%message = 'unspecified error'
    if (index(err%message, 'expected') == 0) err%message = err%message // '; expected ' // what
  end subroutine add_expectation

  !> Print a recorded error and stop.
  subroutine fatal_error(err)
    type(error_t), intent(in) :: err

    if (allocated(err%message)) then
       call print_and_stop(err%message)
    else
       call print_and_stop('unspecified error')
    end if
  end subroutine fatal_error

  !> Print `bulkflow: error: file:line: message` and stop.
  subroutine report_and_stop(file, line, message)
    character(len=*), intent(in) :: file
    integer, intent(in) :: line
    character(len=*), intent(in) :: message

    call print_and_stop(format_error_location(file, line, message))
  end subroutine report_and_stop

  !> Replace the final stop (e.g. by a routine calling MPI_Abort).
  subroutine set_final_stop(proc)
    procedure(final_stop_i) :: proc

    final_stop => proc
  end subroutine set_final_stop

  !> Back to `error stop 2`.
  subroutine reset_final_stop()
    final_stop => default_final_stop
  end subroutine reset_final_stop

  subroutine print_and_stop(text)
    character(len=*), intent(in) :: text

    write (error_unit, '(a)') 'bulkflow: error: ' // text
    flush (error_unit)
    call final_stop()
    ! A final-stop procedure must not return; make sure nothing runs on.
    error stop 2, quiet=.true.
  end subroutine print_and_stop

  subroutine default_final_stop()
    error stop 2, quiet=.true.
  end subroutine default_final_stop

end module error_report
