!> Values of Abaqus parametric input and what Python does with them: the binary operators and
!> the functions a `*PARAMETER` expression may call (Python's abs, int, float, min, max and the
!> math module's functions, which Abaqus makes available), each refusing what Python would
!> refuse (division by zero, math domain errors) with a sentence instead of an exception.
!> Integers are 64-bit (Python's are unbounded: a result beyond 9e18 is refused, not wrapped).
module parameter_arithmetic
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use base_kinds, only: dp
  implicit none
  private

  public :: param_value_t, kind_integer, kind_real, kind_string
  public :: binary_operation, call_function, value_text, pi, euler

  integer, parameter :: kind_integer = 1, kind_real = 2, kind_string = 3

  !> A parameter's value: Python int, float or str.
  type :: param_value_t
     integer :: kind = 0
     integer(int64) :: i = 0
     real(dp) :: r = 0.0_dp
     character(len=:), allocatable :: s
  end type param_value_t

  real(dp), parameter :: pi = 3.14159265358979323846264338327950288_dp
  real(dp), parameter :: euler = 2.71828182845904523536028747135266250_dp
  real(dp), parameter :: int_limit = 9.0e18_dp

contains

  !> a = a op b for op in + - * / // % **; problem = '' when it worked.
  pure subroutine binary_operation(op, a, b, problem)
    character(len=*), intent(in) :: op
    type(param_value_t), intent(inout) :: a
    type(param_value_t), intent(in) :: b
    character(len=:), allocatable, intent(out) :: problem

    problem = ''
    if (a%kind == kind_string .or. b%kind == kind_string) then
       if (op == '+' .and. a%kind == kind_string .and. b%kind == kind_string) then
          a%s = a%s // b%s
       else
          problem = 'operator ' // op // ' between ' // kind_name(a) // ' and ' // kind_name(b) // &
               '; expected numbers (strings can only be joined with +)'
       end if
       return
    end if
    if (a%kind == kind_integer .and. b%kind == kind_integer) then
       call integer_operation(op, a, b%i, problem)
    else
       call real_operation(op, a, as_real(b), problem)
    end if
  end subroutine binary_operation

  pure subroutine integer_operation(op, a, j, problem)
    character(len=*), intent(in) :: op
    type(param_value_t), intent(inout) :: a
    integer(int64), intent(in) :: j
    character(len=:), allocatable, intent(inout) :: problem
    real(dp) :: estimate

    if ((op == '/' .or. op == '//' .or. op == '%') .and. j == 0) then
       problem = 'division by zero'
       return
    end if
    select case (op)
    case ('+')
       estimate = real(a%i, dp) + real(j, dp)
    case ('-')
       estimate = real(a%i, dp) - real(j, dp)
    case ('*')
       estimate = real(a%i, dp) * real(j, dp)
    case ('**')
       if (j < 0 .or. overflows('**', real(a%i, dp), real(j, dp))) then
          call real_operation(op, a, real(j, dp), problem)
          return
       end if
       estimate = real(a%i, dp)**real(j, dp)
    case default
       estimate = 0.0_dp
    end select
    if (abs(estimate) > int_limit) then
       problem = 'integer result beyond 9e18 (bulkflow keeps 64-bit integers); expected a real: write ' // &
            'one of the numbers with a decimal point'
       return
    end if
    select case (op)
    case ('+')
       a%i = a%i + j
    case ('-')
       a%i = a%i - j
    case ('*')
       a%i = a%i * j
    case ('**')
       a%i = a%i**j
    case ('//')
       a%i = floor_division(a%i, j)
    case ('%')
       a%i = modulo(a%i, j)
    case ('/')
       if (mod(a%i, j) /= 0) then
          problem = 'integer division ' // int_text(a%i) // '/' // int_text(j) // ' is ambiguous: ' // &
               'Python 2 (Abaqus up to 2023) gives ' // int_text(floor_division(a%i, j)) // &
               ', Python 3 (Abaqus 2024 on) a real; expected a decimal point on one of them ' // &
               '(a real quotient) or // (the floor)'
          return
       end if
       a%i = a%i / j
    end select
  end subroutine integer_operation

  pure subroutine real_operation(op, a, y, problem)
    character(len=*), intent(in) :: op
    type(param_value_t), intent(inout) :: a
    real(dp), intent(in) :: y
    character(len=:), allocatable, intent(inout) :: problem
    real(dp) :: x

    x = as_real(a)
    a%kind = kind_real
    if ((op == '/' .or. op == '//' .or. op == '%') .and. is_zero(y)) then
       problem = 'division by zero'
       return
    end if
    if (overflows(op, x, y)) then
       problem = 'result of ' // op // ' is beyond the largest real (overflow)'
       return
    end if
    select case (op)
    case ('+')
       a%r = x + y
    case ('-')
       a%r = x - y
    case ('*')
       a%r = x * y
    case ('/')
       a%r = x / y
    case ('//')
       a%r = floor_real(x / y)
    case ('%')
       a%r = x - y * floor_real(x / y)
    case ('**')
       if (is_zero(x) .and. y < 0.0_dp) then
          problem = 'zero to a negative power (division by zero)'
          return
       end if
       if (x < 0.0_dp .and. .not. is_zero(y - aint(y))) then
          problem = 'a negative number to a fractional power (not a real number)'
          return
       end if
       ! the C library's pow(), as Python's float ** does (bit for bit the same value)
       a%r = x**y
    end select
    if (.not. ieee_is_finite(a%r)) problem = 'result of ' // op // ' is not a finite number (overflow)'
  end subroutine real_operation

  !> Python's floor division of integers (rounds towards minus infinity).
  pure integer(int64) function floor_division(i, j)
    integer(int64), intent(in) :: i, j

    floor_division = i / j
    if (mod(i, j) /= 0 .and. ((i < 0) .neqv. (j < 0))) floor_division = floor_division - 1
  end function floor_division

  !> name(args): the functions Python and its math module give a parameter expression.
  pure subroutine call_function(name, args, v, problem)
    character(len=*), intent(in) :: name
    type(param_value_t), intent(in) :: args(:)
    type(param_value_t), intent(out) :: v
    character(len=:), allocatable, intent(out) :: problem
    integer :: k

    problem = ''
    do k = 1, size(args)
       if (args(k)%kind == kind_string) then
          problem = name // '() of a string; expected numbers'
          return
       end if
    end do
    select case (name)
    case ('abs', 'int', 'float', 'floor', 'ceil')
       if (arity(1)) call integer_valued(name, args(1), v, problem)
    case ('min', 'max')
       if (size(args) < 2) then
          problem = name // '() needs at least 2 arguments'
          return
       end if
       v = args(1)
       do k = 2, size(args)
          if ((name == 'min' .and. as_real(args(k)) < as_real(v)) .or. &
               (name == 'max' .and. as_real(args(k)) > as_real(v))) v = args(k)
       end do
    case ('atan2', 'pow', 'hypot', 'fmod')
       if (arity(2)) call math_two(name, as_real(args(1)), as_real(args(2)), v, problem)
    case ('log')
       if (size(args) == 2) then
          call math_one('log', as_real(args(1)), v, problem)
          if (len(problem) > 0) return
          if (as_real(args(2)) <= 0.0_dp .or. is_zero(as_real(args(2)) - 1.0_dp)) then
             problem = 'log(x, base) with base <= 0 or 1 (math domain error)'
             return
          end if
          v%r = v%r / log(as_real(args(2)))
       else if (arity(1)) then
          call math_one(name, as_real(args(1)), v, problem)
       end if
    case ('sqrt', 'exp', 'log10', 'sin', 'cos', 'tan', 'asin', 'acos', 'atan', 'sinh', 'cosh', 'tanh', &
         'fabs', 'degrees', 'radians')
       if (arity(1)) call math_one(name, as_real(args(1)), v, problem)
    case ('round')
       problem = 'round() differs between Python 2 and 3 (Abaqus before and from 2024); expected ' // &
            'floor(x + 0.5) or int(x)'
    case default
       problem = 'function ' // name // '() is not supported; expected abs, int, float, min, max or ' // &
            'a math function (sqrt, exp, log, log10, sin, cos, tan, asin, acos, atan, atan2, sinh, ' // &
            'cosh, tanh, pow, hypot, fmod, fabs, floor, ceil, degrees, radians)'
    end select
    if (len(problem) == 0 .and. v%kind == 0) then
       problem = name // '() takes ' // trim(merge('2 arguments', '1 argument ', &
            any(name == [character(len=5) :: 'atan2', 'pow', 'hypot', 'fmod']))) // ', got ' // &
            int_text(int(size(args), int64))
       return
    end if
    if (len(problem) == 0 .and. v%kind == kind_real) then
       if (.not. ieee_is_finite(v%r)) problem = name // '() is not a finite number (math range error)'
    end if

  contains

    !> Does the call have n arguments? (else problem says so)
    pure logical function arity(n)
      integer, intent(in) :: n

      arity = size(args) == n
    end function arity
  end subroutine call_function

  !> Would x op y pass the largest real? Checked before, so the debug build's overflow trap
  !> never fires on a user's expression.
  pure logical function overflows(op, x, y)
    character(len=*), intent(in) :: op
    real(dp), intent(in) :: x, y
    real(dp), parameter :: big = huge(1.0_dp)

    ! (Fortran may evaluate both sides of .and.: each quotient and product below is guarded
    ! by an if, so the check itself never divides by zero or overflows.)
    overflows = .false.
    select case (op)
    case ('+', '-')
       overflows = abs(x) > 0.5_dp * big .and. abs(y) > 0.5_dp * big
    case ('*')
       if (abs(y) > 1.0_dp) overflows = abs(x) > big / abs(y)
    case ('/', '//', '%')
       if (abs(y) < 1.0_dp) overflows = abs(x) > big * abs(y)
    case ('**')
       overflows = .false.
       if (abs(x) > 0.0_dp) overflows = y * log(abs(x)) > 709.0_dp
    case default
       overflows = .false.
    end select
  end function overflows

  !> floor(x) as a real (no integer conversion, so any magnitude).
  pure real(dp) function floor_real(x)
    real(dp), intent(in) :: x

    floor_real = aint(x)
    if (floor_real > x) floor_real = floor_real - 1.0_dp
  end function floor_real

  pure logical function is_zero(x)
    real(dp), intent(in) :: x

    is_zero = .not. (x < 0.0_dp .or. x > 0.0_dp)
  end function is_zero

  !> abs, int, float, floor, ceil (floor and ceil give integers, as in Python 3).
  pure subroutine integer_valued(name, x, v, problem)
    character(len=*), intent(in) :: name
    type(param_value_t), intent(in) :: x
    type(param_value_t), intent(out) :: v
    character(len=:), allocatable, intent(inout) :: problem
    real(dp) :: r

    v = x
    if (name == 'float') then
       v%kind = kind_real
       v%r = as_real(x)
       return
    end if
    if (x%kind == kind_integer) then
       if (name == 'abs') v%i = abs(x%i)
       return
    end if
    if (name == 'abs') then
       v%r = abs(x%r)
       return
    end if
    select case (name)
    case ('floor')
       r = floor_real(x%r)
    case ('ceil')
       r = -floor_real(-x%r)
    case default
       r = aint(x%r)
    end select
    if (abs(r) > int_limit) then
       problem = name // '() of ' // real_text(x%r) // ' is beyond 9e18 (64-bit integers)'
       return
    end if
    v%kind = kind_integer
    v%i = int(r, int64)
  end subroutine integer_valued

  pure subroutine math_one(name, x, v, problem)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: x
    type(param_value_t), intent(out) :: v
    character(len=:), allocatable, intent(inout) :: problem

    v%kind = kind_real
    if (((name == 'sqrt') .and. x < 0.0_dp) .or. ((name == 'log' .or. name == 'log10') .and. x <= 0.0_dp) .or. &
         ((name == 'asin' .or. name == 'acos') .and. abs(x) > 1.0_dp)) then
       problem = name // '(' // real_text(x) // ') is outside its domain (math domain error)'
       return
    end if
    select case (name)
    case ('sqrt')
       v%r = sqrt(x)
    case ('exp')
       if (x > 709.0_dp) then
          problem = 'exp(' // real_text(x) // ') is beyond the largest real (math range error)'
          return
       end if
       v%r = exp(x)
    case ('log')
       v%r = log(x)
    case ('log10')
       v%r = log10(x)
    case ('sin')
       v%r = sin(x)
    case ('cos')
       v%r = cos(x)
    case ('tan')
       v%r = tan(x)
    case ('asin')
       v%r = asin(x)
    case ('acos')
       v%r = acos(x)
    case ('atan')
       v%r = atan(x)
    case ('sinh')
       if (abs(x) > 709.0_dp) problem = name // '() beyond the largest real (math range error)'
       if (abs(x) <= 709.0_dp) v%r = sinh(x)
    case ('cosh')
       if (abs(x) > 709.0_dp) problem = name // '() beyond the largest real (math range error)'
       if (abs(x) <= 709.0_dp) v%r = cosh(x)
    case ('tanh')
       v%r = tanh(x)
    case ('fabs')
       v%r = abs(x)
    case ('degrees')
       v%r = x * (180.0_dp / pi)
    case ('radians')
       v%r = x * (pi / 180.0_dp)
    end select
  end subroutine math_one

  pure subroutine math_two(name, x, y, v, problem)
    character(len=*), intent(in) :: name
    real(dp), intent(in) :: x, y
    type(param_value_t), intent(out) :: v
    character(len=:), allocatable, intent(inout) :: problem
    type(param_value_t) :: base

    v%kind = kind_real
    select case (name)
    case ('atan2')
       v%r = atan2(x, y)
    case ('hypot')
       v%r = hypot(x, y)
    case ('fmod')
       if (is_zero(y)) then
          problem = 'fmod(x, 0) (math domain error)'
          return
       end if
       v%r = mod(x, y)
    case ('pow')
       base%kind = kind_real
       base%r = x
       call real_operation('**', base, y, problem)
       v%r = base%r
    end select
  end subroutine math_two

  !> The text a value stands for where `<name>` is written: an integer in decimal, a real with
  !> the fewest significant digits that read back to the same double (so a parameterized deck
  !> and the same deck written out give the same numbers), a string as it is.
  pure function value_text(v) result(t)
    type(param_value_t), intent(in) :: v
    character(len=:), allocatable :: t

    select case (v%kind)
    case (kind_integer)
       t = int_text(v%i)
    case (kind_real)
       t = real_text(v%r)
    case default
       t = v%s
    end select
  end function value_text

  pure real(dp) function as_real(v)
    type(param_value_t), intent(in) :: v

    if (v%kind == kind_integer) then
       as_real = real(v%i, dp)
    else
       as_real = v%r
    end if
  end function as_real

  pure function kind_name(v) result(t)
    type(param_value_t), intent(in) :: v
    character(len=:), allocatable :: t

    select case (v%kind)
    case (kind_integer)
       t = 'an integer'
    case (kind_real)
       t = 'a real'
    case default
       t = 'a string'
    end select
  end function kind_name

  pure function int_text(i) result(t)
    integer(int64), intent(in) :: i
    character(len=:), allocatable :: t
    character(len=24) :: buf

    write (buf, '(i0)') i
    t = trim(buf)
  end function int_text

  !> Shortest E-format text that reads back to exactly x.
  pure function real_text(x) result(t)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: t
    character(len=40) :: buf
    character(len=16) :: fmt
    real(dp) :: back
    integer :: d, ios

    do d = 1, 17
       write (fmt, '(a, i0, a)') '(es32.', d - 1, 'e3)'
       write (buf, fmt) x
       read (buf, *, iostat=ios) back
       if (ios == 0 .and. is_zero(back - x)) exit
    end do
    t = trim(adjustl(buf))
  end function real_text
end module parameter_arithmetic
