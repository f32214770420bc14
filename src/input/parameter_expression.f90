!> The arithmetic of Abaqus parametric input (`*PARAMETER`): one Python expression of numbers,
!> strings and earlier parameters evaluated to an integer, a real or a string, with Python's
!> precedence and types (Abaqus Analysis User's Guide, "Parametric input"; docs/keywords.md
!> §*PARAMETER lists what is accepted and where we differ). Pure: no I/O, the caller turns a
!> `problem` and its column into a file:line message.
!>
!> Grammar (Python's, restricted to arithmetic):
!>   sum    := term (('+' | '-') term)*
!>   term   := unary (('*' | '/' | '//' | '%') unary)*
!>   unary  := ('-' | '+') unary | power
!>   power  := atom ['**' unary]             (right-associative, binds tighter than a unary minus on its left)
!>   atom   := number | 'string' | "string" | name | name '(' sum {',' sum} ')' | '(' sum ')'
module parameter_expression
  use, intrinsic :: iso_fortran_env, only: int64
  use keyword_numbers, only: int_text
  use parameter_arithmetic, only: param_value_t, kind_integer, kind_real, kind_string, value_text, &
       binary_operation, call_function, pi, euler
  implicit none
  private

  public :: param_value_t, named_value_t, evaluate_expression, value_text, is_parameter_name
  public :: kind_integer, kind_real, kind_string

  type :: named_value_t
     character(len=:), allocatable :: name      !< case-sensitive, as in Python
     type(param_value_t) :: value
  end type named_value_t

  !> Cursor over the expression; the first problem stops everything.
  type :: cursor_t
     character(len=:), allocatable :: text
     integer :: pos = 1
     integer :: column = 0
     character(len=:), allocatable :: problem
  end type cursor_t


contains

  !> Evaluate `text` (a Python comment `# ...` ends it) with the parameters `known(1:n)`.
  !> On failure `problem` says what (otherwise '') and `column` where in `text`.
  pure subroutine evaluate_expression(text, known, n, value, problem, column)
    character(len=*), intent(in) :: text
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    type(param_value_t), intent(out) :: value
    character(len=:), allocatable, intent(out) :: problem
    integer, intent(out) :: column
    type(cursor_t) :: c

    c%text = text
    c%problem = ''
    call skip_blanks(c)
    if (at_end(c)) then
       call fail(c, 'expected an expression after "="')
    else
       call parse_sum(c, known, n, value)
       if (len(c%problem) == 0) then
          call skip_blanks(c)
          if (.not. at_end(c)) call fail(c, 'unexpected "' // c%text(c%pos:c%pos) // &
               '"; expected an operator (+ - * / // % **) or the end of the expression')
       end if
    end if
    problem = c%problem
    column = c%column
  end subroutine evaluate_expression

  !> A Python identifier: a letter or '_' first, then letters, digits and '_'.
  pure logical function is_parameter_name(name)
    character(len=*), intent(in) :: name
    integer :: k

    is_parameter_name = len(name) > 0
    if (.not. is_parameter_name) return
    is_parameter_name = is_letter(name(1:1))
    do k = 2, len(name)
       if (.not. (is_letter(name(k:k)) .or. is_digit(name(k:k)))) is_parameter_name = .false.
    end do
  end function is_parameter_name

  ! ------------------------------------------------------------------ grammar

  pure recursive subroutine parse_sum(c, known, n, v)
    type(cursor_t), intent(inout) :: c
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    type(param_value_t), intent(out) :: v
    type(param_value_t) :: rhs
    character :: op
    integer :: where

    call parse_term(c, known, n, v)
    do while (len(c%problem) == 0)
       call skip_blanks(c)
       if (at_end(c)) return
       op = c%text(c%pos:c%pos)
       if (op /= '+' .and. op /= '-') return
       where = c%pos
       c%pos = c%pos + 1
       call parse_term(c, known, n, rhs)
       if (len(c%problem) > 0) return
       call binary(c, op, v, rhs, where)
    end do
  end subroutine parse_sum

  pure recursive subroutine parse_term(c, known, n, v)
    type(cursor_t), intent(inout) :: c
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    type(param_value_t), intent(out) :: v
    type(param_value_t) :: rhs
    character(len=2) :: op
    integer :: where

    call parse_unary(c, known, n, v)
    do while (len(c%problem) == 0)
       call skip_blanks(c)
       if (at_end(c)) return
       op = c%text(c%pos:min(c%pos + 1, len(c%text)))
       if (op == '**') return
       if (op == '//') then
          where = c%pos
          c%pos = c%pos + 2
       else if (op(1:1) == '*' .or. op(1:1) == '/' .or. op(1:1) == '%') then
          op = op(1:1)
          where = c%pos
          c%pos = c%pos + 1
       else
          return
       end if
       call parse_unary(c, known, n, rhs)
       if (len(c%problem) > 0) return
       call binary(c, trim(op), v, rhs, where)
    end do
  end subroutine parse_term

  pure recursive subroutine parse_unary(c, known, n, v)
    type(cursor_t), intent(inout) :: c
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    type(param_value_t), intent(out) :: v
    character :: op
    integer :: where

    call skip_blanks(c)
    if (at_end(c)) then
       call fail(c, 'the expression ends too early; expected a number, a name or "("')
       return
    end if
    op = c%text(c%pos:c%pos)
    if (op == '-' .or. op == '+') then
       where = c%pos
       c%pos = c%pos + 1
       call parse_unary(c, known, n, v)
       if (len(c%problem) > 0 .or. op == '+') then
          if (v%kind == kind_string .and. len(c%problem) == 0) call fail_at(c, where, 'a sign before a string')
          return
       end if
       select case (v%kind)
       case (kind_integer)
          v%i = -v%i
       case (kind_real)
          v%r = -v%r
       case default
          call fail_at(c, where, 'a sign before a string')
       end select
       return
    end if
    call parse_power(c, known, n, v)
  end subroutine parse_unary

  pure recursive subroutine parse_power(c, known, n, v)
    type(cursor_t), intent(inout) :: c
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    type(param_value_t), intent(out) :: v
    type(param_value_t) :: rhs
    integer :: where

    call parse_atom(c, known, n, v)
    if (len(c%problem) > 0) return
    call skip_blanks(c)
    if (c%pos + 1 > len(c%text)) return
    if (c%text(c%pos:c%pos + 1) /= '**') return
    where = c%pos
    c%pos = c%pos + 2
    call parse_unary(c, known, n, rhs)
    if (len(c%problem) > 0) return
    call binary(c, '**', v, rhs, where)
  end subroutine parse_power

  pure recursive subroutine parse_atom(c, known, n, v)
    type(cursor_t), intent(inout) :: c
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    type(param_value_t), intent(out) :: v
    character :: ch
    integer :: start, k

    call skip_blanks(c)
    if (at_end(c)) then
       call fail(c, 'the expression ends too early; expected a number, a name or "("')
       return
    end if
    ch = c%text(c%pos:c%pos)
    start = c%pos
    if (ch == '(') then
       c%pos = c%pos + 1
       call parse_sum(c, known, n, v)
       if (len(c%problem) > 0) return
       call expect(c, ')', 'a ")" to close the "(" at column ' // int_text(start))
    else if (is_digit(ch) .or. ch == '.') then
       call parse_number(c, v)
    else if (ch == '"' .or. ch == "'") then
       k = index(c%text(c%pos + 1:), ch)
       if (k == 0) then
          call fail(c, 'string not closed; expected a closing ' // ch)
          return
       end if
       v%kind = kind_string
       v%s = c%text(c%pos + 1:c%pos + k - 1)
       c%pos = c%pos + k + 1
    else if (is_letter(ch)) then
       do while (c%pos <= len(c%text))
          if (.not. (is_letter(c%text(c%pos:c%pos)) .or. is_digit(c%text(c%pos:c%pos)))) exit
          c%pos = c%pos + 1
       end do
       call skip_blanks(c)
       if (.not. at_end(c)) then
          if (c%text(c%pos:c%pos) == '(') then
             call parse_call(c, known, n, trim(c%text(start:c%pos - 1)), start, v)
             return
          end if
       end if
       call lookup(c, known, n, trim(c%text(start:c%pos - 1)), start, v)
    else
       call fail(c, 'unexpected "' // ch // '"; expected a number, a parameter name, a string or "("')
    end if
  end subroutine parse_atom

  !> A Python int or float literal (1, 2., .5, 1e-3, 2.5E+2); Fortran's 1.d0 and octal 017 are refused.
  pure subroutine parse_number(c, v)
    type(cursor_t), intent(inout) :: c
    type(param_value_t), intent(out) :: v
    integer :: start, ios, k
    logical :: is_float

    start = c%pos
    is_float = .false.
    do while (c%pos <= len(c%text))
       if (.not. is_digit(c%text(c%pos:c%pos))) exit
       c%pos = c%pos + 1
    end do
    if (c%pos <= len(c%text)) then
       if (c%text(c%pos:c%pos) == '.') then
          is_float = .true.
          c%pos = c%pos + 1
          do while (c%pos <= len(c%text))
             if (.not. is_digit(c%text(c%pos:c%pos))) exit
             c%pos = c%pos + 1
          end do
       end if
    end if
    if (c%pos <= len(c%text)) then
       if (scan(c%text(c%pos:c%pos), 'eE') > 0) then
          k = c%pos + 1
          if (k <= len(c%text)) then
             if (scan(c%text(k:k), '+-') > 0) k = k + 1
          end if
          if (k <= len(c%text)) then
             if (is_digit(c%text(k:k))) then
                is_float = .true.
                c%pos = k
                do while (c%pos <= len(c%text))
                   if (.not. is_digit(c%text(c%pos:c%pos))) exit
                   c%pos = c%pos + 1
                end do
             end if
          end if
       end if
    end if
    if (c%pos == start + 1 .and. c%text(start:start) == '.') then
       call fail_at(c, start, 'a lone "."; expected a number')
       return
    end if
    if (c%pos <= len(c%text)) then
       if (is_letter(c%text(c%pos:c%pos))) then
          call fail_at(c, start, 'number "' // c%text(start:c%pos) // '..." is not a Python number ' // &
               '(Fortran 1.d0 is written 1.e0 or 1.0 in a *PARAMETER expression)')
          return
       end if
    end if
    if (is_float) then
       v%kind = kind_real
       read (c%text(start:c%pos - 1), *, iostat=ios) v%r
    else
       if (c%pos - start > 1 .and. c%text(start:start) == '0') then
          call fail_at(c, start, 'integer "' // c%text(start:c%pos - 1) // '" with a leading zero ' // &
               '(octal in Python 2, an error in Python 3); expected it without the leading zeros')
          return
       end if
       v%kind = kind_integer
       read (c%text(start:c%pos - 1), *, iostat=ios) v%i
    end if
    if (ios /= 0) call fail_at(c, start, 'number "' // c%text(start:c%pos - 1) // '" out of range')
  end subroutine parse_number

  !> A parameter defined above, or the math module's pi and e.
  pure subroutine lookup(c, known, n, name, where, v)
    type(cursor_t), intent(inout) :: c
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    character(len=*), intent(in) :: name
    integer, intent(in) :: where
    type(param_value_t), intent(out) :: v
    integer :: k

    do k = n, 1, -1
       if (known(k)%name == name .and. len(known(k)%name) == len(name)) then
          v = known(k)%value
          return
       end if
    end do
    v%kind = kind_real
    select case (name)
    case ('pi')
       v%r = pi
    case ('e')
       v%r = euler
    case ('if', 'else', 'for', 'in', 'and', 'or', 'not', 'lambda', 'import', 'while', 'is')
       call fail_at(c, where, 'Python "' // name // '" is not supported; a *PARAMETER line is ' // &
            '"name = arithmetic expression"')
    case default
       call fail_at(c, where, 'name "' // name // '" is not defined (a *PARAMETER line above this ' // &
            'one must define it; names are case-sensitive)')
    end select
  end subroutine lookup

  !> name(arg, ...): Python's abs, int, float, min, max and the math module's functions.
  pure recursive subroutine parse_call(c, known, n, name, where, v)
    type(cursor_t), intent(inout) :: c
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    character(len=*), intent(in) :: name
    integer, intent(in) :: where
    type(param_value_t), intent(out) :: v
    type(param_value_t) :: args(8)
    integer :: na

    c%pos = c%pos + 1          ! the '('
    na = 0
    call skip_blanks(c)
    if (.not. at_end(c)) then
       if (c%text(c%pos:c%pos) == ')') then
          c%pos = c%pos + 1
          call apply_function(c, name, where, args(1:0), v)
          return
       end if
    end if
    do
       if (na == size(args)) then
          call fail_at(c, where, name // '() with more than 8 arguments')
          return
       end if
       na = na + 1
       call parse_sum(c, known, n, args(na))
       if (len(c%problem) > 0) return
       call skip_blanks(c)
       if (at_end(c)) exit
       if (c%text(c%pos:c%pos) /= ',') exit
       c%pos = c%pos + 1
    end do
    call expect(c, ')', 'a "," or the ")" closing ' // name // '(')
    if (len(c%problem) > 0) return
    call apply_function(c, name, where, args(1:na), v)
  end subroutine parse_call

  ! ------------------------------------------------------------------ lexing helpers

  pure subroutine expect(c, ch, what)
    type(cursor_t), intent(inout) :: c
    character, intent(in) :: ch
    character(len=*), intent(in) :: what

    call skip_blanks(c)
    if (at_end(c)) then
       call fail(c, 'the expression ends too early; expected ' // what)
    else if (c%text(c%pos:c%pos) /= ch) then
       call fail(c, 'unexpected "' // c%text(c%pos:c%pos) // '"; expected ' // what)
    else
       c%pos = c%pos + 1
    end if
  end subroutine expect

  pure subroutine skip_blanks(c)
    type(cursor_t), intent(inout) :: c

    do while (c%pos <= len(c%text))
       if (c%text(c%pos:c%pos) /= ' ' .and. c%text(c%pos:c%pos) /= achar(9)) exit
       c%pos = c%pos + 1
    end do
  end subroutine skip_blanks

  !> End of the text or a Python comment.
  pure logical function at_end(c)
    type(cursor_t), intent(in) :: c

    at_end = c%pos > len(c%text)
    if (.not. at_end) at_end = c%text(c%pos:c%pos) == '#'
  end function at_end

  pure subroutine fail(c, what)
    type(cursor_t), intent(inout) :: c
    character(len=*), intent(in) :: what

    call fail_at(c, c%pos, what)
  end subroutine fail

  pure subroutine fail_at(c, column, what)
    type(cursor_t), intent(inout) :: c
    integer, intent(in) :: column
    character(len=*), intent(in) :: what

    if (len(c%problem) > 0) return
    c%problem = what
    c%column = column
  end subroutine fail_at

  pure logical function is_digit(ch)
    character, intent(in) :: ch

    is_digit = ch >= '0' .and. ch <= '9'
  end function is_digit

  pure logical function is_letter(ch)
    character, intent(in) :: ch

    is_letter = (ch >= 'a' .and. ch <= 'z') .or. (ch >= 'A' .and. ch <= 'Z') .or. ch == '_'
  end function is_letter

  !> v = v op rhs, or the problem at column `where`.
  pure subroutine binary(c, op, v, rhs, where)
    type(cursor_t), intent(inout) :: c
    character(len=*), intent(in) :: op
    type(param_value_t), intent(inout) :: v
    type(param_value_t), intent(in) :: rhs
    integer, intent(in) :: where
    character(len=:), allocatable :: problem

    call binary_operation(op, v, rhs, problem)
    if (len(problem) > 0) call fail_at(c, where, problem)
  end subroutine binary

  pure subroutine apply_function(c, name, where, args, v)
    type(cursor_t), intent(inout) :: c
    character(len=*), intent(in) :: name
    integer, intent(in) :: where
    type(param_value_t), intent(in) :: args(:)
    type(param_value_t), intent(out) :: v
    character(len=:), allocatable :: problem

    call call_function(name, args, v, problem)
    if (len(problem) > 0) call fail_at(c, where, problem)
  end subroutine apply_function
end module parameter_expression
