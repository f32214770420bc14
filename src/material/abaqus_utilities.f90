! Abaqus/Explicit utility routines that user subroutines call (vgetvrm, vgetnumcpus, vgetrank,
! vgetjobname, vgetoutdir, xplb_abqerr, xplb_exit), provided by the bulkflow host with
! Abaqus's argument lists (Abaqus User Subroutines Reference Guide, "Utility routines for
! Abaqus/Explicit"). They are external procedures on purpose: user code calls them without an
! interface, exactly as in Abaqus. The executables export them, so a user library loaded
! with --user finds them (src/material/user_library.f90).

!> Start-of-increment values of an output variable for the current block.
!> Keys: S, LE, SDV, TEMP, PE (LE − C⁻¹:σ with the packaging call's moduli) and PEEQ for our
!> plastic models. Any other key, or PEEQ for a material that has none (a user's VUMAT, our
!> elastic model), stops the run naming the key and the material (exit 2): Abaqus returns
!> jStatus /= 0, but user code that does not test it would go on with stale data.
subroutine vgetvrm(cVar, rData, jData, cData, jStatus)
  use, intrinsic :: iso_fortran_env, only: error_unit
  use base_kinds, only: dp
  use abaqus_host, only: host_get_variable, host_available_keys, host_exit, host_block_material, &
       host_missing_key_note
  implicit none
  character(len=*), intent(in) :: cVar
  real(dp), intent(out) :: rData(*)
  integer, intent(out) :: jData(*)
  character(len=3), intent(out) :: cData(*)
  integer, intent(inout) :: jStatus

  jData(1) = 0
  cData(1) = ' '
  call host_get_variable(cVar, rData, jStatus)
  if (jStatus /= 0) then
     write (error_unit, '(a)') "bulkflow: error: user subroutine called vgetvrm('" // trim(adjustl(cVar)) // &
          "') for material " // host_block_material() // ': output variable not available; this material ' // &
          'provides ' // host_available_keys() // host_missing_key_note(cVar)
     call host_exit(2)
  end if
end subroutine vgetvrm

!> Message from user code. lop: 1 information, -1 warning, -2 error, -3 error and stop.
!> %I, %R and %S in the text are replaced by successive entries of intv, realv and charv.
subroutine xplb_abqerr(lop, string, intv, realv, charv)
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
  use base_kinds, only: dp
  use abaqus_host, only: host_exit
  implicit none
  integer, intent(in) :: lop
  character(len=*), intent(in) :: string
  integer, intent(in) :: intv(*)
  real(dp), intent(in) :: realv(*)
  character(len=8), intent(in) :: charv(*)
  character(len=:), allocatable :: text
  character(len=32) :: number
  integer :: i, ni, nr, ns

  text = ''
  ni = 0; nr = 0; ns = 0
  i = 1
  do while (i <= len_trim(string))
     if (string(i:i) == '%' .and. i < len_trim(string)) then
        select case (string(i + 1:i + 1))
        case ('I', 'i')
           ni = ni + 1
           write (number, '(i0)') intv(ni)
           text = text // trim(number)
           i = i + 2
           cycle
        case ('R', 'r')
           nr = nr + 1
           write (number, '(es14.6)') realv(nr)
           text = text // trim(adjustl(number))
           i = i + 2
           cycle
        case ('S', 's')
           ns = ns + 1
           text = text // trim(charv(ns))
           i = i + 2
           cycle
        end select
     end if
     text = text // string(i:i)
     i = i + 1
  end do

  select case (lop)
  case (1)
     write (output_unit, '(a)') 'bulkflow: user subroutine: ' // text
  case (-1)
     write (error_unit, '(a)') 'bulkflow: warning: user subroutine: ' // text
  case default
     write (error_unit, '(a)') 'bulkflow: error: ' // text
     if (lop == -3) call host_exit(3)
  end select
end subroutine xplb_abqerr

!> Stop the analysis on behalf of user code.
subroutine xplb_exit()
  use abaqus_host, only: host_exit
  implicit none
  call host_exit(3)
end subroutine xplb_exit

!> Number of processes of the run (Abaqus: CPUs of the analysis).
subroutine vgetnumcpus(numCpus)
  use abaqus_host, only: host_ranks
  implicit none
  integer, intent(out) :: numCpus
  numCpus = host_ranks()
end subroutine vgetnumcpus

!> This process's number, 0 for the first (MPI rank).
subroutine vgetrank(kProcessNum)
  use abaqus_host, only: host_rank
  implicit none
  integer, intent(out) :: kProcessNum
  kProcessNum = host_rank()
end subroutine vgetrank

!> The job name: bulkflow's output base name (--output, else the scene's name).
subroutine vgetjobname(jobName, jobNameLen)
  use abaqus_host, only: host_job_name
  implicit none
  character(len=*), intent(out) :: jobName
  integer, intent(out) :: jobNameLen
  jobName = host_job_name()
  jobNameLen = min(len(jobName), len(host_job_name()))
end subroutine vgetjobname

!> The folder the outputs are written to.
subroutine vgetoutdir(outDir, outDirLen)
  use abaqus_host, only: host_output_dir
  implicit none
  character(len=*), intent(out) :: outDir
  integer, intent(out) :: outDirLen
  outDir = host_output_dir()
  outDirLen = min(len(outDir), len(host_output_dir()))
end subroutine vgetoutdir
