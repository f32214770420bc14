!> A user's VUMAT/VUSDFLD file given with `--user FILE`, as Abaqus takes `user=FILE`: compiled
!> with this build's Fortran compiler and flags into a shared library, kept in a cache directory
!> under a name made from the content hash of everything that goes into it (the file, the files
!> it INCLUDEs, the compiler and its flags), and loaded with dlopen. Its `vumat` and `vusdfld`
!> become the procedure pointers `user_vumat` and `user_vusdfld` (docs/user_subroutines.md).
!>
!> Two steps, so that a parallel run compiles once: `user_library_prepare` (rank 0 only:
!> compiles when the cache has no library yet, prints the compiler's messages when it fails)
!> and `user_library_open` (every rank). A library is written under a process-unique name and
!> renamed into place, so two runs sharing a cache never load a half-written file.
!>
!> The user's code calls our utilities (vgetvrm, xplb_abqerr, ...) and, if it wants, our models
!> (bulkflow_vumat): the executables export them (CMake ENABLE_EXPORTS) and the library, linked
!> with undefined references, finds them when it is opened. -Bsymbolic binds the library's calls
!> to its own routines first (a user's file that brings its own module named like one of ours).
module user_library
  use, intrinsic :: iso_c_binding, only: c_ptr, c_funptr, c_char, c_int, c_null_char, c_associated, &
       c_f_procpointer, c_f_pointer, c_size_t
  use, intrinsic :: iso_fortran_env, only: error_unit, int64
  use user_build_config, only: user_compiler, user_flags, user_include_dir
  implicit none
  private

  !> The user's entry points (implicit interfaces: called exactly as Abaqus calls them).
  procedure(), pointer, public, protected :: user_vumat => null(), user_vusdfld => null()

  public :: user_library_prepare, user_library_open, user_library_loaded, user_library_name
  public :: user_library_use_linked

  character(len=:), allocatable :: loaded_name    !< the file given with --user, for messages

  integer(c_int), parameter :: rtld_now = 2, rtld_local = 0

  interface
     function c_dlopen(filename, flag) bind(C, name='dlopen') result(handle)
       import :: c_ptr, c_char, c_int
       character(kind=c_char), intent(in) :: filename(*)
       integer(c_int), value :: flag
       type(c_ptr) :: handle
     end function c_dlopen
     function c_dlsym(handle, symbol) bind(C, name='dlsym') result(address)
       import :: c_ptr, c_funptr, c_char
       type(c_ptr), value :: handle
       character(kind=c_char), intent(in) :: symbol(*)
       type(c_funptr) :: address
     end function c_dlsym
     function c_dlerror() bind(C, name='dlerror') result(text)
       import :: c_ptr
       type(c_ptr) :: text
     end function c_dlerror
     function c_rename(old, new) bind(C, name='rename') result(status)
       import :: c_char, c_int
       character(kind=c_char), intent(in) :: old(*), new(*)
       integer(c_int) :: status
     end function c_rename
     function c_getpid() bind(C, name='getpid') result(pid)
       import :: c_int
       integer(c_int) :: pid
     end function c_getpid
     function c_strlen(text) bind(C, name='strlen') result(n)
       import :: c_ptr, c_size_t
       type(c_ptr), value :: text
       integer(c_size_t) :: n
     end function c_strlen
  end interface

contains

  logical function user_library_loaded()
    user_library_loaded = associated(user_vumat)
  end function user_library_loaded

  !> The --user file of the loaded library ('' when none).
  function user_library_name() result(name)
    character(len=:), allocatable :: name
    name = ''
    if (allocated(loaded_name)) name = loaded_name
  end function user_library_name

  !> The shared library for `source`: `source` itself when it is one (.so), else the cached
  !> library built from it (compiled now if the cache has none). `status` 0 on success; else
  !> `message` says why (the compiler's own messages are printed to stderr first).
  subroutine user_library_prepare(source, include_dirs, library, message, status)
    character(len=*), intent(in) :: source
    character(len=*), intent(in) :: include_dirs(:)
    character(len=:), allocatable, intent(out) :: library
    character(len=:), allocatable, intent(out) :: message
    integer, intent(out) :: status
    character(len=:), allocatable :: ext, form, command, cache, text, log_file, temp
    character(len=16) :: key
    character(len=12) :: pid
    logical :: exists
    integer :: k, exit_status, command_status

    status = 2
    message = ''
    inquire (file=source, exist=exists)
    if (.not. exists) then
       message = 'user subroutine file ' // source // ' not found; expected a .f, .for, .f90, .o or .so file'
       return
    end if
    do k = 1, size(include_dirs)
       inquire (file=trim(include_dirs(k)) // '/.', exist=exists)
       if (.not. exists) then
          message = '--user-include ' // trim(include_dirs(k)) // ': no such directory'
          return
       end if
    end do
    if (index(source, "'") > 0 .or. any(index(include_dirs, "'") > 0)) then
       message = 'user subroutine path ' // source // " contains a quote ('); expected a plain path"
       return
    end if
    ext = lower(extension(source))
    if (ext == 'so') then
       library = source
       if (index(library, '/') == 0) library = './' // library
       status = 0
       return
    end if
    call read_text(source, text, exists)
    if (.not. exists) then
       message = 'cannot read user subroutine file ' // source
       return
    end if
    select case (ext)
    case ('f', 'for', 'f77', 'ftn')
       form = '-ffixed-form -ffixed-line-length-132'
    case ('ff', 'fpp')
       form = '-cpp -ffixed-form -ffixed-line-length-132'
    case ('f90', 'f95', 'f03', 'f08')
       form = '-ffree-form -ffree-line-length-none'
    case ('ff90')
       form = '-cpp -ffree-form -ffree-line-length-none'
    case ('o')
       form = ''
    case default
       message = 'user subroutine file ' // source // ': extension .' // ext // ' not understood; ' // &
            'expected .f or .for (fixed form, 132 columns), .f90 (free form), .o or .so'
       return
    end select
    if (extension(source) == 'F' .or. extension(source) == 'FOR') form = '-cpp ' // form
    if (extension(source) == 'F90') form = '-cpp ' // form
    ! Abaqus's compilers honour the Intel directive that switches a .f file to free form.
    if (ext /= 'o' .and. has_freeform_directive(text)) form = '-ffree-form -ffree-line-length-none'

    if (ext == 'o') then
       command = "'" // user_compiler // "' -shared -Wl,-Bsymbolic"
       key = content_key(text // user_compiler)
    else
       command = "'" // user_compiler // "' " // user_flags // ' ' // form // ' -fPIC -fno-semantic-interposition -shared -Wl,-Bsymbolic'
       command = command // " -I'" // directory_of(source) // "'"
       do k = 1, size(include_dirs)
          command = command // " -I'" // trim(include_dirs(k)) // "'"
       end do
       command = command // " -I'" // user_include_dir // "'"
       key = content_key(text // included_text(text, source, include_dirs) // command)
    end if
    cache = cache_directory()
    library = cache // '/user-' // key // '.so'
    inquire (file=library, exist=exists)
    if (exists) then
       status = 0
       return
    end if
    write (pid, '(i0)') c_getpid()
    temp = cache // '/user-' // key // '.' // trim(pid)
    log_file = temp // '.log'
    call execute_command_line("mkdir -p '" // cache // "' '" // temp // ".mod'", exitstat=exit_status, &
         cmdstat=command_status)
    if (command_status /= 0 .or. exit_status /= 0) then
       message = 'cannot create the cache directory ' // cache // ' (set BULKFLOW_CACHE_DIR to a writable directory)'
       return
    end if
    if (ext /= 'o') command = command // " -J '" // temp // ".mod'"
    command = command // " -o '" // temp // ".so' '" // source // "' > '" // log_file // "' 2>&1"
    call execute_command_line(command, exitstat=exit_status, cmdstat=command_status)
    call print_file(log_file, exit_status /= 0 .or. command_status /= 0)
    call execute_command_line("rm -rf '" // temp // ".mod' '" // log_file // "'")
    if (command_status /= 0 .or. exit_status /= 0) then
       call execute_command_line("rm -f '" // temp // ".so'")
       message = 'user subroutine file ' // source // ' did not compile (compiler messages above; ' // &
            'compiler ' // user_compiler // ')'
       return
    end if
    if (c_rename(c_string(temp // '.so'), c_string(library)) /= 0) then
       message = 'cannot move the compiled user library into ' // library
       return
    end if
    status = 0
  end subroutine user_library_prepare

  !> dlopen `library` and take its vumat and vusdfld (at least one of them).
  subroutine user_library_open(library, source, message, status)
    character(len=*), intent(in) :: library, source
    character(len=:), allocatable, intent(out) :: message
    integer, intent(out) :: status
    type(c_ptr) :: handle
    type(c_funptr) :: address

    status = 2
    message = ''
    handle = c_dlopen(c_string(library), ior(rtld_now, rtld_local))
    if (.not. c_associated(handle)) then
       message = 'cannot load the user subroutines of ' // source // ': ' // dl_error_text() // &
            ' (a routine the file calls that neither it nor bulkflow defines?)'
       return
    end if
    ! A file with only a VUSDFLD serves *USER DEFINED FIELD of our built-in materials (as in
    ! Abaqus, where user=FILE need not hold a VUMAT); it must hold at least one of the two.
    address = find_symbol(handle, 'vusdfld')
    if (c_associated(address)) call c_f_procpointer(address, user_vusdfld)
    address = find_symbol(handle, 'vumat')
    if (c_associated(address)) then
       call c_f_procpointer(address, user_vumat)
    else if (.not. associated(user_vusdfld)) then
       message = 'user subroutine file ' // source // ' defines no subroutine VUMAT (nor VUSDFLD); ' // &
            'expected SUBROUTINE VUMAT with the Abaqus/Explicit argument list'
       return
    end if
    loaded_name = source
    status = 0
  end subroutine user_library_open

  !> The entry points linked into the executable serve as the user's (--user-linked): the same
  !> path as a loaded library, without the library; for a build whose vumat is a user's file
  !> linked in (CMake BULKFLOW_USER_SUBROUTINE), and to measure what run-time loading costs.
  subroutine user_library_use_linked(umat, usdfld, name)
    procedure() :: umat, usdfld
    character(len=*), intent(in) :: name
    user_vumat => umat
    user_vusdfld => usdfld
    loaded_name = name
  end subroutine user_library_use_linked

  !> The address of `name` as compilers spell Fortran names (gfortran and Intel: name_).
  function find_symbol(handle, name) result(address)
    type(c_ptr), intent(in) :: handle
    character(len=*), intent(in) :: name
    type(c_funptr) :: address

    address = c_dlsym(handle, c_string(name // '_'))
    if (.not. c_associated(address)) address = c_dlsym(handle, c_string(name))
  end function find_symbol

  function dl_error_text() result(text)
    character(len=:), allocatable :: text
    type(c_ptr) :: p
    character(kind=c_char), pointer :: chars(:)
    integer :: n, k

    p = c_dlerror()
    text = 'unknown dlopen error'
    if (.not. c_associated(p)) return
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    deallocate (text)
    allocate (character(len=n) :: text)
    do k = 1, n
       text(k:k) = chars(k)
    end do
  end function dl_error_text

  !> $BULKFLOW_CACHE_DIR, else $XDG_CACHE_HOME/bulkflow, else $HOME/.cache/bulkflow, else /tmp.
  function cache_directory() result(dir)
    character(len=:), allocatable :: dir

    dir = environment('BULKFLOW_CACHE_DIR')
    if (len(dir) > 0) return
    dir = environment('XDG_CACHE_HOME')
    if (len(dir) > 0) then
       dir = dir // '/bulkflow'
       return
    end if
    dir = environment('HOME')
    if (len(dir) > 0) then
       dir = dir // '/.cache/bulkflow'
    else
       dir = '/tmp/bulkflow-cache'
    end if
  end function cache_directory

  function environment(name) result(value)
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: value
    integer :: n, status

    call get_environment_variable(name, length=n, status=status)
    value = ''
    if (status /= 0 .or. n == 0) return
    deallocate (value)
    allocate (character(len=n) :: value)
    call get_environment_variable(name, value)
  end function environment

  !> The text of every file `text` INCLUDEs (found as the compiler will find it), with its name.
  function included_text(text, source, include_dirs) result(all)
    character(len=*), intent(in) :: text, source
    character(len=*), intent(in) :: include_dirs(:)
    character(len=:), allocatable :: all, name, body, path
    integer :: start, finish, k
    logical :: found

    all = ''
    start = 1
    do while (start <= len(text))
       finish = index(text(start:), new_line('a'))
       if (finish == 0) then
          finish = len(text)
       else
          finish = start + finish - 1
       end if
       name = include_name(text(start:finish))
       start = finish + 1
       if (len(name) == 0) cycle
       found = .false.
       path = directory_of(source) // '/' // name
       call read_text(path, body, found)
       do k = 1, size(include_dirs)
          if (found) exit
          path = trim(include_dirs(k)) // '/' // name
          call read_text(path, body, found)
       end do
       if (.not. found) call read_text(user_include_dir // '/' // name, body, found)
       if (found) all = all // name // body
    end do
  end function included_text

  !> The file name of an INCLUDE line ('' for any other line).
  function include_name(line) result(name)
    character(len=*), intent(in) :: line
    character(len=:), allocatable :: name, l
    integer :: q

    name = ''
    l = lower(adjustl(line))
    if (len(l) < 9) return
    if (l(1:7) /= 'include') return
    l = adjustl(l(8:))
    if (len(l) < 2) return
    if (l(1:1) /= "'" .and. l(1:1) /= '"') return
    q = index(l(2:), l(1:1))
    if (q < 2) return
    ! The name as written (the lower-cased copy is only for finding the keyword).
    l = adjustl(line)
    l = adjustl(l(8:))
    name = l(2:q)
  end function include_name

  logical function has_freeform_directive(text)
    character(len=*), intent(in) :: text
    has_freeform_directive = index(lower(text(1:min(len(text), 4000))), '!dir$ freeform') > 0
  end function has_freeform_directive

  !> 16 hex digits: two 32-bit FNV-1a hashes (different offsets) of `text`.
  function content_key(text) result(key)
    character(len=*), intent(in) :: text
    character(len=16) :: key
    integer(int64), parameter :: prime = 16777619_int64, modulus = 4294967296_int64
    integer(int64) :: h1, h2
    integer :: k

    h1 = 2166136261_int64
    h2 = 3735928559_int64
    do k = 1, len(text)
       h1 = modulo(ieor(h1, int(ichar(text(k:k)), int64)) * prime, modulus)
       h2 = modulo(ieor(h2, int(ichar(text(k:k)), int64)) * prime, modulus)
    end do
    write (key, '(z8.8,z8.8)') h1, h2
  end function content_key

  subroutine read_text(path, text, ok)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: text
    logical, intent(out) :: ok
    integer :: unit, ios, n

    text = ''
    inquire (file=path, exist=ok, size=n)
    if (.not. ok) return
    ok = .false.
    if (n < 0) return
    open (newunit=unit, file=path, access='stream', form='unformatted', status='old', action='read', iostat=ios)
    if (ios /= 0) return
    deallocate (text)
    allocate (character(len=n) :: text)
    if (n > 0) read (unit, iostat=ios) text
    close (unit)
    ok = ios == 0
  end subroutine read_text

  !> Copy a text file to stderr (`show`: only then).
  subroutine print_file(path, show)
    character(len=*), intent(in) :: path
    logical, intent(in) :: show
    character(len=:), allocatable :: text
    logical :: ok

    if (.not. show) return
    call read_text(path, text, ok)
    if (ok .and. len(text) > 0) write (error_unit, '(a)', advance='no') text
  end subroutine print_file

  function directory_of(path) result(dir)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: dir
    integer :: slash

    slash = index(path, '/', back=.true.)
    if (slash == 0) then
       dir = '.'
    else if (slash == 1) then
       dir = '/'
    else
       dir = path(1:slash - 1)
    end if
  end function directory_of

  function extension(path) result(ext)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: ext
    integer :: dot

    dot = index(path, '.', back=.true.)
    ext = ''
    if (dot > index(path, '/', back=.true.)) ext = path(dot + 1:)
  end function extension

  pure function lower(text) result(out)
    character(len=*), intent(in) :: text
    character(len=len(text)) :: out
    integer :: k, c

    out = text
    do k = 1, len(text)
       c = ichar(text(k:k))
       if (c >= ichar('A') .and. c <= ichar('Z')) out(k:k) = char(c + 32)
    end do
  end function lower

  pure function c_string(text) result(s)
    character(len=*), intent(in) :: text
    character(kind=c_char, len=len(text) + 1) :: s
    s = text // c_null_char
  end function c_string
end module user_library
