!> Core of bulkflow's stand-in for pFUnit's `funit` module: where an assertion happened, the
!> failure record of the running test, and the conversion of any intrinsic value (passed as
!> `class(*)`) to a flat list that the assertions compare and print.
!>
!> Names visible to test code (`SourceLocation`, `anyExceptions`) are pFUnit's, so a .pf file
!> compiles unchanged against either.
module funit_core
  use, intrinsic :: iso_fortran_env, only: int8, int16, int32, int64, real32, real64
  implicit none
  private

  integer, parameter, public :: dp = real64

  !> Where an assertion was written: the .pf file and its line (the preprocessor passes both).
  type, public :: SourceLocation
    character(len=:), allocatable :: file_name
    integer :: line_number = 0
  end type SourceLocation

  ! What a flattened value holds; `tag_other` covers derived types and unsupported kinds.
  integer, parameter, public :: tag_integer = 1, tag_real = 2, tag_logical = 3, &
                                tag_character = 4, tag_other = 5

  !> Any intrinsic scalar or array, flattened in array element order (column major).
  !> Integers are kept exact in `ints` and also converted to `reals` so they can meet reals.
  type, public :: flat_value
    integer :: tag = tag_other
    integer(int64), allocatable :: ints(:)
    real(dp), allocatable :: reals(:)
    logical, allocatable :: logicals(:)
    character(len=:), allocatable :: text
    integer, allocatable :: dims(:)
  end type flat_value

  interface flatten
    module procedure flatten_0, flatten_1, flatten_2
  end interface flatten

  public :: anyExceptions
  public :: funit_begin_test, funit_failure_report, funit_fail
  public :: flatten, flatten_shaped, element_count, tag_name, element_text, index_text, dims_text
  public :: real_text, int_text

  logical, save :: test_failed = .false.
  character(len=:), allocatable, save :: report

contains

  !> .true. once an assertion of the running test (or its @before/@after) has failed; the
  !> preprocessor puts `if (anyExceptions()) return` after every assertion, as pFUnit does.
  logical function anyExceptions()
    anyExceptions = test_failed
  end function anyExceptions

  !> Forget the previous test's failures.
  subroutine funit_begin_test()
    test_failed = .false.
    report = ''
  end subroutine funit_begin_test

  !> The text of every failure of the running test ('' if none).
  function funit_failure_report() result(text)
    character(len=:), allocatable :: text
    text = ''
    if (allocated(report)) text = report
  end function funit_failure_report

  !> Record a failure as `  file:line: <headline>[: message]` followed by `details` (lines
  !> separated by new_line('a'), may be empty).
  subroutine funit_fail(headline, details, message, location)
    character(len=*), intent(in) :: headline, details
    character(len=*), intent(in), optional :: message
    type(SourceLocation), intent(in), optional :: location
    character(len=:), allocatable :: line

    line = '<unknown location>'
    if (present(location)) then
      if (allocated(location%file_name)) &
        line = location%file_name // ':' // int_text(int(location%line_number, int64))
    end if
    line = '  ' // line // ': ' // headline
    if (present(message)) then
      if (len_trim(message) > 0) line = line // ': ' // trim(message)
    end if
    if (.not. allocated(report)) report = ''
    report = report // line // new_line('a')
    if (len(details) > 0) report = report // details // new_line('a')
    test_failed = .true.
  end subroutine funit_fail

  ! The flatten functions fill their result through subroutines: gfortran 12 reports false
  ! "used uninitialized" warnings for reallocating assignments to allocatable components of a
  ! function result.

  function flatten_0(x) result(f)
    class(*), intent(in) :: x
    type(flat_value) :: f
    select type (x)
    type is (integer(int8))
      call set_integers(f, [int(x, int64)])
    type is (integer(int16))
      call set_integers(f, [int(x, int64)])
    type is (integer(int32))
      call set_integers(f, [int(x, int64)])
    type is (integer(int64))
      call set_integers(f, [x])
    type is (real(real32))
      call set_reals(f, [real(x, dp)])
    type is (real(real64))
      call set_reals(f, [x])
    type is (logical)
      call set_logicals(f, [x])
    type is (character(len=*))
      call set_text(f, x)
    class default
      f%tag = tag_other
    end select
    call set_dims(f, shape(x))
  end function flatten_0

  function flatten_1(x) result(f)
    class(*), intent(in) :: x(:)
    type(flat_value) :: f
    select type (x)
    type is (integer(int8))
      call set_integers(f, int(x, int64))
    type is (integer(int16))
      call set_integers(f, int(x, int64))
    type is (integer(int32))
      call set_integers(f, int(x, int64))
    type is (integer(int64))
      call set_integers(f, x)
    type is (real(real32))
      call set_reals(f, real(x, dp))
    type is (real(real64))
      call set_reals(f, x)
    type is (logical)
      call set_logicals(f, x)
    class default
      f%tag = tag_other
    end select
    call set_dims(f, shape(x))
  end function flatten_1

  function flatten_2(x) result(f)
    class(*), intent(in) :: x(:, :)
    type(flat_value) :: f
    select type (x)
    type is (integer(int8))
      call set_integers(f, int(reshape(x, [size(x)]), int64))
    type is (integer(int16))
      call set_integers(f, int(reshape(x, [size(x)]), int64))
    type is (integer(int32))
      call set_integers(f, int(reshape(x, [size(x)]), int64))
    type is (integer(int64))
      call set_integers(f, reshape(x, [size(x)]))
    type is (real(real32))
      call set_reals(f, real(reshape(x, [size(x)]), dp))
    type is (real(real64))
      call set_reals(f, reshape(x, [size(x)]))
    type is (logical)
      call set_logicals(f, reshape(x, [size(x)]))
    class default
      f%tag = tag_other
    end select
    call set_dims(f, shape(x))
  end function flatten_2

  !> An array of any rank, passed in array element order with its shape.
  function flatten_shaped(x, dims) result(f)
    class(*), intent(in) :: x(:)
    integer, intent(in) :: dims(:)
    type(flat_value) :: f
    f = flatten_1(x)
    call set_dims(f, dims)
  end function flatten_shaped

  subroutine set_integers(f, values)
    type(flat_value), intent(inout) :: f
    integer(int64), intent(in) :: values(:)
    f%tag = tag_integer
    f%ints = values
    f%reals = real(values, dp)
  end subroutine set_integers

  subroutine set_reals(f, values)
    type(flat_value), intent(inout) :: f
    real(dp), intent(in) :: values(:)
    f%tag = tag_real
    f%reals = values
  end subroutine set_reals

  subroutine set_logicals(f, values)
    type(flat_value), intent(inout) :: f
    logical, intent(in) :: values(:)
    f%tag = tag_logical
    f%logicals = values
  end subroutine set_logicals

  subroutine set_text(f, text)
    type(flat_value), intent(inout) :: f
    character(len=*), intent(in) :: text
    f%tag = tag_character
    f%text = text
  end subroutine set_text

  subroutine set_dims(f, dims)
    type(flat_value), intent(inout) :: f
    integer, intent(in) :: dims(:)
    f%dims = dims
  end subroutine set_dims

  !> Number of elements (1 for a character scalar, 0 for unsupported types).
  integer function element_count(f)
    type(flat_value), intent(in) :: f
    select case (f%tag)
    case (tag_integer)
      element_count = size(f%ints)
    case (tag_real)
      element_count = size(f%reals)
    case (tag_logical)
      element_count = size(f%logicals)
    case (tag_character)
      element_count = 1
    case default
      element_count = 0
    end select
  end function element_count

  !> Human name of a flattened value's type, for "cannot compare" messages.
  function tag_name(f) result(name)
    type(flat_value), intent(in) :: f
    character(len=:), allocatable :: name
    select case (f%tag)
    case (tag_integer)
      name = 'integer'
    case (tag_real)
      name = 'real'
    case (tag_logical)
      name = 'logical'
    case (tag_character)
      name = 'character'
    case default
      name = 'an unsupported type'
    end select
  end function tag_name

  !> Element k of a flattened value as text (k = 1 for scalars).
  function element_text(f, k) result(text)
    type(flat_value), intent(in) :: f
    integer, intent(in) :: k
    character(len=:), allocatable :: text
    select case (f%tag)
    case (tag_integer)
      text = int_text(f%ints(k))
    case (tag_real)
      text = real_text(f%reals(k))
    case (tag_logical)
      text = merge('.true. ', '.false.', f%logicals(k))
      text = trim(text)
    case (tag_character)
      text = '"' // f%text // '"'
    case default
      text = '<unprintable>'
    end select
  end function element_text

  !> "(i)" or "(i,j)" for the k-th element (column major) of an array of the given shape.
  function index_text(array_shape, k) result(text)
    integer, intent(in) :: array_shape(:), k
    character(len=:), allocatable :: text
    integer :: r, rest
    if (size(array_shape) == 0) then
      text = ''
      return
    end if
    text = '('
    rest = k - 1
    do r = 1, size(array_shape)
      if (r > 1) text = text // ','
      text = text // int_text(int(modulo(rest, array_shape(r)) + 1, int64))
      rest = rest / array_shape(r)
    end do
    text = text // ')'
  end function index_text

  !> "[n1,n2]" (or "scalar") for shape mismatch messages.
  function dims_text(dims) result(text)
    integer, intent(in) :: dims(:)
    character(len=:), allocatable :: text
    integer :: r
    if (size(dims) == 0) then
      text = 'scalar'
      return
    end if
    text = '['
    do r = 1, size(dims)
      if (r > 1) text = text // ','
      text = text // int_text(int(dims(r), int64))
    end do
    text = text // ']'
  end function dims_text

  !> 17 significant digits: enough to tell any two different doubles apart.
  function real_text(x) result(text)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: text
    character(len=40) :: buffer
    write (buffer, '(es25.16e3)') x
    text = trim(adjustl(buffer))
  end function real_text

  function int_text(i) result(text)
    integer(int64), intent(in) :: i
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write (buffer, '(i0)') i
    text = trim(buffer)
  end function int_text

end module funit_core
