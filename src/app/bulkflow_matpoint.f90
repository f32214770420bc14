!> bulkflow-matpoint: drive a VUMAT (ours or a user's) through a laboratory test at one
!> material point, with mixed stress/strain control.
!>
!> Usage: bulkflow-matpoint input.inp [-o out.csv] [--user FILE [--user-include DIR]...]
!> --user FILE: the user's VUMAT/VUSDFLD file, compiled and loaded at run time as in bulkflow
!> (docs/user_subroutines.md); the point's *USER MATERIAL then calls the user's vumat.
!> Reads the keyword input (inputs/matpoint/README.md), runs the path, writes the CSV
!> (default: the input's name with .csv) and prints a short summary. Any error is one
!> line "bulkflow: error: file:line: message" on stderr and exit status 2.
program bulkflow_matpoint
  use, intrinsic :: iso_fortran_env, only: output_unit
  use base_kinds, only: dp
  use error_report, only: report_and_stop
  use model_materials, only: material_t
  use matpoint_path, only: matpoint_path_t, test_names, test_triaxial, test_biaxial, &
       test_oedometer, test_simple_shear, simple_shear_component
  use matpoint_input, only: read_matpoint_file
  use matpoint_solver, only: matpoint_history_t, run_material_point
  use matpoint_csv, only: write_matpoint_csv, mean_pressure, von_mises
  use user_library, only: user_library_prepare, user_library_open
  use material_entry, only: use_linked_entries
  implicit none

  character(len=:), allocatable :: input, output, title, user_file
  character(len=1024), allocatable :: user_includes(:)
  type(material_t) :: mat
  type(matpoint_path_t) :: path
  type(matpoint_history_t) :: history
  logical :: help

  call parse_arguments(input, output, help)
  if (.not. help) then
     if (len(user_file) > 0) call load_user_file()
     ! bulkflow-matpoint-user (a user's file compiled in): *USER MATERIALs are the user's.
     if (user_linked() .and. len(user_file) == 0) call use_linked_entries()
     call read_matpoint_file(input, mat, path, title=title)
     call run_material_point(mat, path, history)
     call write_matpoint_csv(output, mat, path, history)
     call print_summary()
  end if

contains

  subroutine parse_arguments(input, output, help)
    character(len=:), allocatable, intent(out) :: input, output
    logical, intent(out) :: help
    character(len=:), allocatable :: arg
    integer :: i, n, dot

    input = ''
    output = ''
    user_file = ''
    allocate (user_includes(0))
    help = .false.
    n = command_argument_count()
    i = 0
    do while (i < n)
       i = i + 1
       arg = argument(i)
       select case (arg)
       case ('-h', '--help')
          write (output_unit, '(a)') 'usage: bulkflow-matpoint input.inp [-o out.csv] ' // &
               '[--user FILE [--user-include DIR]...]'
          write (output_unit, '(a)') '  runs the material-point test of input.inp through the ' // &
               'VUMAT and writes one CSV row per increment (default out: input name with .csv)'
          help = .true.
          return
       case ('-o')
          if (i == n) call usage('-o needs a file name')
          i = i + 1
          output = argument(i)
       case ('--user')
          if (i == n) call usage('--user needs a file name')
          i = i + 1
          user_file = argument(i)
       case ('--user-include')
          if (i == n) call usage('--user-include needs a directory')
          i = i + 1
          user_includes = [character(len=1024) :: user_includes, argument(i)]
       case default
          if (arg(1:1) == '-') call usage('unknown option ' // arg)
          if (len(input) > 0) call usage('more than one input file')
          input = arg
       end select
    end do
    if (len(input) == 0) call usage('no input file')
    if (size(user_includes) > 0 .and. len(user_file) == 0) call usage('--user-include without --user')
    if (len(output) == 0) then
       dot = index(input, '.', back=.true.)
       if (dot > index(input, '/', back=.true.) + 1) then
          output = input(1:dot) // 'csv'
       else
          output = input // '.csv'
       end if
    end if
  end subroutine parse_arguments

  function argument(i) result(arg)
    integer, intent(in) :: i
    character(len=:), allocatable :: arg
    integer :: length

    call get_command_argument(i, length=length)
    allocate (character(len=length) :: arg)
    call get_command_argument(i, arg)
  end function argument

  !> Compile (or find in the cache) and load the --user file; any problem: exit status 2.
  subroutine load_user_file()
    character(len=:), allocatable :: library, message
    integer :: status

    call user_library_prepare(user_file, user_includes, library, message, status)
    if (status == 0) call user_library_open(library, user_file, message, status)
    if (status /= 0) call report_and_stop('', 0, message)
  end subroutine load_user_file

  !> True in bulkflow-matpoint-user, whose user file is linked in (matpoint_user_linked.f90).
  logical function user_linked()
    external :: bulkflow_matpoint_user_linked

    call bulkflow_matpoint_user_linked(user_linked)
  end function user_linked

  subroutine usage(message)
    character(len=*), intent(in) :: message

    call report_and_stop('', 0, message // ' (usage: bulkflow-matpoint input.inp [-o out.csv] ' // &
         '[--user FILE [--user-include DIR]...])')
  end subroutine usage

  subroutine print_summary()
    integer :: row, peak_row, nc, last, k
    real(dp) :: q, peak_q
    character(len=:), allocatable :: yes_no

    nc = history%ncomp
    last = history%n_rows
    peak_q = -1.0_dp
    peak_row = 1
    do row = 1, history%n_rows
       q = von_mises(nc, history%stress(:, row))
       if (q > peak_q) then
          peak_q = q
          peak_row = row
       end if
    end do
    yes_no = merge('yes', 'no ', mat%user_field)
    if (len_trim(title) > 0) write (output_unit, '(a)') 'bulkflow-matpoint: ' // title
    write (output_unit, '(a,i0,a,i0,a)') '  material  ' // trim(mat%name) // ' (VUMAT ' // &
         trim(mat%vumat_name) // ', ', size(mat%props), ' constants, ', mat%nstatev, &
         ' SDVs, user field: ' // trim(yes_no) // ')'
    write (output_unit, '(a,i0,a,i0,a,i0,a,i0,a)') '  test      ' // trim(test_names(path%test)) // &
         ', ', merge(3, 2, path%ndim == 3), 'D, axis ', path%axis, ', ', path%n_stages, &
         ' stage(s), ', last - 1, ' increments'
    write (output_unit, '(a,es12.5,a,es12.5)') '  moduli    2G = ', history%two_g, &
         ', K = ', history%bulk
    write (output_unit, '(a,es14.7,a,es12.5,a,es12.5)') '  peak q    ', peak_q, ' at time ', &
         history%time(peak_row), ', ev = ', sum(history%strain(1:3, peak_row))
    write (output_unit, '(a,es14.7,a,es14.7,a,es14.7)') '  final     p = ', &
         mean_pressure(nc, history%stress(:, last)), ', q = ', von_mises(nc, history%stress(:, last)), &
         ', ev = ', sum(history%strain(1:3, last))
    select case (path%test)
    case (test_triaxial, test_biaxial, test_oedometer)
       write (output_unit, '(a,es14.7,a,es14.7)') '            ea = ', history%strain(path%axis, last), &
            ', s_axial = ', history%stress(path%axis, last)
    case (test_simple_shear)
       k = simple_shear_component
       write (output_unit, '(a,es14.7,a,es14.7,a,es14.7)') '            gamma = ', &
            2.0_dp * history%strain(k, last), ', tau = ', history%stress(k, last), &
            ', e22 = ', history%strain(2, last)
    end select
    write (output_unit, '(a,i0)') '  Newton    most iterations in one increment: ', &
         maxval(history%iterations(1:last))
    write (output_unit, '(a)') '  output    ' // output
  end subroutine print_summary

end program bulkflow_matpoint
