! The two Abaqus/Standard utility routines our UMAT calls, for hosts that do not have them
! (CalculiX, bulkflow's tests). Abaqus provides its own; never link this into an Abaqus job.
! stdb_abqerr: lop = 1 information, −1 warning, −2 error, −3 error that ends the analysis
! (Abaqus's codes); the message is printed on standard error. xit ends the run with status 2.
subroutine stdb_abqerr(lop, string, intv, realv, charv)
  use, intrinsic :: iso_fortran_env, only: error_unit
  implicit none
  integer, intent(in) :: lop
  character(len=*), intent(in) :: string
  integer, intent(in) :: intv(*)
  double precision, intent(in) :: realv(*)
  character(len=8), intent(in) :: charv(*)
  character(len=12) :: kind

  select case (lop)
  case (1)
     kind = 'information'
  case (-1)
     kind = 'warning'
  case default
     kind = 'error'
  end select
  write (error_unit, '(a)') '***' // trim(kind) // ': ' // trim(string)
  if (lop == -3) call xit()
end subroutine stdb_abqerr

subroutine xit()
  implicit none
  stop 2
end subroutine xit
