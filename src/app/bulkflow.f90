!> bulkflow: explicit dynamics of bulk solids from an Abaqus-syntax scene.
!>
!>   mpirun -np N bulkflow scene.inp [--check] [--output BASE] [--restart] [--stop-after N]
!>                                   [--quiet] [--user FILE [--user-include DIR]...]
!>
!> --user FILE: the user's VUMAT/VUSDFLD file, as Abaqus's user=FILE: compiled into a cached
!> shared library (rank 0 compiles, the others wait) and loaded on every rank; every
!> *USER MATERIAL then calls the user's vumat (docs/user_subroutines.md). --user-linked: the
!> same, with the vumat linked into this executable (a CMake BULKFLOW_USER_SUBROUTINE build, or
!> ours: what scripts/bench_user.py compares run-time loading with).
!>
!> The scene is read and checked completely before the first increment; any problem stops with
!> `file:line: message` and exit status 2. Outputs: BASE.h5 + BASE.xmf (field frames),
!> BASE_history.csv (energies, wall forces, node-set values), BASE.rst.<rank> (checkpoints).
!> BASE defaults to the scene's file name without its extension, in the working directory.
program bulkflow
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_COMM_WORLD, MPI_Comm_rank, MPI_Comm_size, MPI_Bcast, &
       MPI_INTEGER, MPI_CHARACTER
  use error_report, only: error_t, set_final_stop
  use model, only: model_t
  use scene_reader, only: read_scene
  use run_technique, only: run_options_t, technique_t
  use run_loop, only: run_scene
  use run_element, only: element_technique_t
  use run_mpm, only: mpm_technique_t
  use abaqus_host, only: host_set_exit_handler, host_set_job
  use user_library, only: user_library_prepare, user_library_open
  use material_entry, only: use_linked_entries
  use parallel_abort, only: abort_all, abort_all_status
  use output_collective, only: stop_agreed_error
  implicit none
  type(model_t) :: m
  type(error_t) :: err
  type(run_options_t) :: opts
  class(technique_t), allocatable :: technique
  character(len=:), allocatable :: scene, user_file
  character(len=1024), allocatable :: user_includes(:)
  logical :: check_only, user_linked
  integer :: rank, nranks, iw, i_note

  call MPI_Init()
  call MPI_Comm_rank(MPI_COMM_WORLD, rank)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks)
  ! With several ranks an error on one must end them all.
  if (nranks > 1) then
     call set_final_stop(abort_all)
     call host_set_exit_handler(abort_all_status)
  end if
  call parse_arguments(scene, opts, check_only)
  call host_set_job(base_name(opts%output_base), folder_of(opts%output_base), rank, nranks)
  if (len(user_file) > 0) call load_user_file()
  if (user_linked) call use_linked_entries()

  call read_scene(scene, m, err, user_subroutine=len(user_file) > 0 .or. user_linked)
  if (err%raised) call input_error_exit(err)
  if (rank == 0 .and. allocated(m%warnings)) then
     do iw = 1, size(m%warnings)
        write (error_unit, '(a)') 'bulkflow: warning: ' // trim(m%warnings(iw))
     end do
  end if
  if (rank == 0 .and. allocated(m%notes)) then
     do i_note = 1, size(m%notes)
        write (output_unit, '(a)') 'bulkflow: ' // trim(m%notes(i_note))
     end do
  end if
  if (check_only) then
     if (rank == 0 .and. m%mpm%active) then
        write (output_unit, '(a,i0,a,i0,a,i0,a,i0,a)') 'bulkflow: ' // scene // ': OK (material points, ', &
             m%mpm%ndim, 'D, ', size(m%mpm%regions), ' particle regions, ', size(m%mpm%walls), ' walls, ', &
             m%n_steps, ' steps)'
     else if (rank == 0) then
        write (output_unit, '(a,i0,a,i0,a,i0,a)') 'bulkflow: ' // scene // ': OK (', &
             m%mesh%n_nodes, ' nodes, ', m%mesh%n_elems, ' elements, ', m%n_steps, ' steps)'
     end if
  else
     ! One step loop for every scene (src/run): the technique is the scene's — the material
     ! point method for a scene with *MPM GRID, the element solver otherwise.
     if (m%mpm%active) then
        allocate (mpm_technique_t :: technique)
     else
        allocate (element_technique_t :: technique)
     end if
     call run_scene(technique, m, MPI_COMM_WORLD, opts)
  end if
  call MPI_Finalize()

contains

  subroutine parse_arguments(scene, opts, check_only)
    character(len=:), allocatable, intent(out) :: scene
    type(run_options_t), intent(inout) :: opts
    logical, intent(out) :: check_only
    character(len=1024) :: arg, value
    integer :: i, n, ios, dot, slash

    check_only = .false.
    n = command_argument_count()
    i = 1
    scene = ''
    user_file = ''
    user_linked = .false.
    allocate (user_includes(0))
    do while (i <= n)
       call get_command_argument(i, arg)
       select case (trim(arg))
       case ('--check')
          check_only = .true.
       case ('--restart')
          opts%restart = .true.
       case ('--quiet')
          opts%progress = .false.
       case ('--user-linked')
          user_linked = .true.
       case ('--output', '--stop-after', '--user', '--user-include')
          if (i == n) call usage('option ' // trim(arg) // ' needs a value')
          call get_command_argument(i + 1, value)
          if (trim(arg) == '--user') then
             user_file = trim(value)
          else if (trim(arg) == '--user-include') then
             user_includes = [character(len=1024) :: user_includes, value]
          else if (trim(arg) == '--output') then
             opts%output_base = trim(value)
          else
             read (value, *, iostat=ios) opts%stop_after
             if (ios /= 0 .or. opts%stop_after < 1) call usage('--stop-after needs a positive increment number')
          end if
          i = i + 1
       case ('-h', '--help')
          call usage('')
       case default
          if (arg(1:1) == '-') call usage('unknown option ' // trim(arg))
          if (len(scene) > 0) call usage('one scene file only')
          scene = trim(arg)
       end select
       i = i + 1
    end do
    if (len(scene) == 0) call usage('no scene file given')
    if (size(user_includes) > 0 .and. len(user_file) == 0) call usage('--user-include without --user')
    if (user_linked .and. len(user_file) > 0) call usage('--user and --user-linked together')
    if (.not. allocated(opts%output_base)) then
       slash = index(scene, '/', back=.true.)
       dot = index(scene, '.', back=.true.)
       if (dot <= slash) dot = len(scene) + 1
       opts%output_base = scene(slash + 1:dot - 1)
    end if
  end subroutine parse_arguments

  subroutine usage(problem)
    character(len=*), intent(in) :: problem
    if (rank == 0) then
       if (len(problem) > 0) write (error_unit, '(a)') 'bulkflow: error: ' // problem
       write (error_unit, '(a)') 'usage: [mpirun -np N] bulkflow scene.inp [--check] [--output BASE] ' // &
            '[--restart] [--stop-after N] [--quiet] [--user FILE [--user-include DIR]... | --user-linked]'
    end if
    call MPI_Finalize()
    if (len(problem) > 0) error stop 2, quiet=.true.
    stop
  end subroutine usage

  !> --user: rank 0 compiles (or finds in the cache) the library, every rank loads it. A file
  !> that does not compile, or has no vumat, ends the run with exit status 2.
  subroutine load_user_file()
    character(len=:), allocatable :: library, message
    character(len=4096) :: path
    integer :: status, n

    status = 0
    path = ''
    if (rank == 0) then
       call user_library_prepare(user_file, user_includes, library, message, status)
       if (status == 0) path = library
    end if
    call MPI_Bcast(status, 1, MPI_INTEGER, 0, MPI_COMM_WORLD)
    if (status /= 0) call user_file_error(message)
    call MPI_Bcast(path, len(path), MPI_CHARACTER, 0, MPI_COMM_WORLD)
    n = len_trim(path)
    call user_library_open(path(1:n), user_file, message, status)
    if (status /= 0) call user_file_error(message)
  end subroutine load_user_file

  !> The same problem on every rank (rank 0's message): said once, exit status 2.
  subroutine user_file_error(message)
    character(len=:), allocatable, intent(in) :: message
    if (rank == 0 .and. allocated(message)) write (error_unit, '(a)') 'bulkflow: error: ' // message
    call MPI_Finalize()
    error stop 2, quiet=.true.
  end subroutine user_file_error

  pure function base_name(path) result(name)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: name
    name = path(index(path, '/', back=.true.) + 1:)
  end function base_name

  pure function folder_of(path) result(folder)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: folder
    integer :: slash
    slash = index(path, '/', back=.true.)
    folder = '.'
    if (slash > 1) folder = path(1:slash - 1)
    if (slash == 1) folder = '/'
  end function folder_of

  !> Every rank reads the scene and finds the same problem: rank 0 says it once, all ranks
  !> leave MPI cleanly, exit status 2 (no MPI_Abort noise, no backtrace).
  !> Every rank read the same scene and found the same error: said once, a clean exit.
  subroutine input_error_exit(err)
    type(error_t), intent(in) :: err
    call stop_agreed_error(MPI_COMM_WORLD, err)
  end subroutine input_error_exit
end program bulkflow
