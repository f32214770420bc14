!> Text to numbers (and keyword names) for the keyword reader: the strict syntax of a real and of an integer field
!> and their conversion, in time linear in the text (a deck of a million nodes converts
!> several million fields).
!>
!> Reals: the text is checked against the strict syntax (is_real_text) and converted by the C
!> library's strtod. gfortran's own list-directed read converts through strtod as well
!> (libgfortran io/read.c, convert_real), so the values are the same to the bit; the internal
!> read it replaces cost about a microsecond a field. Integers: digits accumulated in 64 bits,
!> the full 32-bit range accepted (-2147483648 .. 2147483647).
module keyword_numbers
  use, intrinsic :: iso_c_binding, only: c_char, c_double, c_null_char, c_ptr, c_null_ptr
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use base_kinds, only: dp
  implicit none
  private

  public :: upper_case, is_real_text, is_integer_text, is_integer_syntax
  public :: text_to_real, text_to_integer, int_text, real_text, normalize_name
  public :: written_exponent

  interface
     function c_strtod(str, endptr) bind(c, name='strtod') result(x)
       import :: c_char, c_double, c_ptr
       character(kind=c_char), intent(in) :: str(*)
       type(c_ptr), value :: endptr
       real(c_double) :: x
     end function c_strtod
  end interface

contains

  pure function upper_case(text) result(up)
    character(len=*), intent(in) :: text
    character(len=len(text)) :: up
    integer :: k, c

    up = text
    do k = 1, len(text)
       c = iachar(text(k:k))
       if (c >= iachar('a') .and. c <= iachar('z')) up(k:k) = achar(c - 32)
    end do
  end function upper_case

  !> Strict real syntax: [sign] digits [. digits] [(e|d) [sign] digits]; at least one
  !> mantissa digit. Rejects blanks inside, "inf", "nan" and list-directed oddities.
  pure logical function is_real_text(text)
    character(len=*), intent(in) :: text
    integer :: k, n, ndig, nexp

    is_real_text = .false.
    n = len_trim(text)
    if (n == 0) return
    k = 1
    if (text(1:1) == '+' .or. text(1:1) == '-') k = 2
    ndig = 0
    do while (k <= n)
       if (.not. is_digit(text(k:k))) exit
       ndig = ndig + 1
       k = k + 1
    end do
    if (k <= n) then
       if (text(k:k) == '.') then
          k = k + 1
          do while (k <= n)
             if (.not. is_digit(text(k:k))) exit
             ndig = ndig + 1
             k = k + 1
          end do
       end if
    end if
    if (ndig == 0) return
    if (k <= n) then
       if (index('eEdD', text(k:k)) == 0) return
       k = k + 1
       if (k <= n) then
          if (text(k:k) == '+' .or. text(k:k) == '-') k = k + 1
       end if
       nexp = 0
       do while (k <= n)
          if (.not. is_digit(text(k:k))) return
          nexp = nexp + 1
          k = k + 1
       end do
       if (nexp == 0) return
    end if
    is_real_text = (k > n)
  end function is_real_text

  !> [sign] digits, nothing else (any number of digits).
  pure logical function is_integer_syntax(text)
    character(len=*), intent(in) :: text
    integer :: k, n, k0

    is_integer_syntax = .false.
    n = len_trim(text)
    if (n == 0) return
    k0 = 1
    if (text(1:1) == '+' .or. text(1:1) == '-') k0 = 2
    if (k0 > n) return
    do k = k0, n
       if (.not. is_digit(text(k:k))) return
    end do
    is_integer_syntax = .true.
  end function is_integer_syntax

  !> An integer that fits 32 bits: [sign] digits, -2147483648 .. 2147483647.
  pure logical function is_integer_text(text)
    character(len=*), intent(in) :: text
    integer :: value

    call text_to_integer(text, value, is_integer_text)
  end function is_integer_text

  !> value of an integer text; ok = .false. for other syntax or beyond the 32-bit range.
  pure subroutine text_to_integer(text, value, ok)
    character(len=*), intent(in) :: text
    integer, intent(out) :: value
    logical, intent(out) :: ok
    integer(int64) :: acc
    integer :: k, n, k0

    value = 0
    ok = is_integer_syntax(text)
    if (.not. ok) return
    n = len_trim(text)
    k0 = 1
    if (text(1:1) == '+' .or. text(1:1) == '-') k0 = 2
    acc = 0
    do k = k0, n
       acc = 10 * acc + (iachar(text(k:k)) - iachar('0'))
       if (acc > 2147483648_int64) exit      ! beyond any 32-bit value: stop before int64 overflows
    end do
    if (text(1:1) == '-') acc = -acc
    ok = acc >= -2147483648_int64 .and. acc <= 2147483647_int64
    if (ok) value = int(acc)
  end subroutine text_to_integer

  !> value of a real text of the strict syntax; ok = .false. for other text or a value beyond
  !> the range of real(dp).
  subroutine text_to_real(text, value, ok)
    character(len=*), intent(in) :: text
    real(dp), intent(out) :: value
    logical, intent(out) :: ok
    character(kind=c_char, len=64) :: buf
    integer :: n, k, ios

    value = 0.0_dp
    ok = is_real_text(text)
    if (.not. ok) return
    n = len_trim(text)
    ! beyond the range of reals: refused before strtod, which would raise the overflow flag
    ! (a trap in the debug build)
    if (decimal_exponent(text(1:n)) > 308) then
       ok = .false.
       return
    end if
    if (n < len(buf)) then
       buf(1:n) = text(1:n)
       do k = 1, n
          if (buf(k:k) == 'd' .or. buf(k:k) == 'D') buf(k:k) = 'e'
       end do
       buf(n + 1:n + 1) = c_null_char
       value = real(c_strtod(buf, c_null_ptr), dp)
    else
       read (text(1:n), *, iostat=ios) value
       if (ios /= 0) ok = .false.
    end if
    if (.not. ieee_is_finite(value)) then
       ok = .false.
       value = 0.0_dp
    end if
  end subroutine text_to_real

  !> Upper case, blanks trimmed, runs of blanks reduced to one (keyword and parameter names).
  pure function normalize_name(raw) result(name)
    character(len=*), intent(in) :: raw
    character(len=:), allocatable :: name
    character(len=len(raw)) :: t
    integer :: k, n

    t = upper_case(adjustl(raw))
    n = 0
    do k = 1, len_trim(t)
       if (t(k:k) == ' ' .and. k > 1) then
          if (t(k - 1:k - 1) == ' ') cycle
       end if
       n = n + 1
       t(n:n) = t(k:k)
    end do
    name = t(1:n)
  end function normalize_name

  !> The decimal exponent of the leading significant digit of a text of the strict real syntax
  !> ("123.4e5" 7, "0.05" -2; 0 for a zero), the exponent clamped against integer overflow.
  pure integer function decimal_exponent(text) result(e10)
    character(len=*), intent(in) :: text
    integer :: k, n, before, lead, expo
    logical :: in_fraction, found

    n = len(text)
    k = 1
    if (text(1:1) == '+' .or. text(1:1) == '-') k = 2
    before = 0
    lead = 0
    in_fraction = .false.
    found = .false.
    do while (k <= n)
       if (text(k:k) == '.') then
          in_fraction = .true.
       else if (is_digit(text(k:k))) then
          if (text(k:k) /= '0') found = .true.
          if (.not. in_fraction .and. found) before = before + 1
          if (in_fraction .and. .not. found) lead = lead + 1
       else
          exit
       end if
       k = k + 1
    end do
    expo = written_exponent(text(1:n), k)
    if (.not. found) then
       e10 = 0
    else if (before > 0) then
       e10 = before - 1 + expo
    else
       e10 = -(lead + 1) + expo
    end if
  end function decimal_exponent

  !> The exponent written after the exponent letter at `k` of a text of the strict real syntax
  !> (0 when none), clamped against integer overflow.
  pure integer function written_exponent(text, k) result(expo)
    character(len=*), intent(in) :: text
    integer, intent(in) :: k
    integer :: j, n, sgn

    n = len(text)
    expo = 0
    if (k >= n) return
    j = k + 1
    sgn = 1
    if (text(j:j) == '-') sgn = -1
    if (text(j:j) == '+' .or. text(j:j) == '-') j = j + 1
    do while (j <= n)
       if (expo < 100000) expo = 10 * expo + (iachar(text(j:j)) - iachar('0'))
       j = j + 1
    end do
    expo = sgn * expo
  end function written_exponent

  pure logical function is_digit(c)
    character, intent(in) :: c

    is_digit = (c >= '0' .and. c <= '9')
  end function is_digit

  pure function int_text(i) result(t)
    integer, intent(in) :: i
    character(len=:), allocatable :: t
    character(len=16) :: buf

    write (buf, '(i0)') i
    t = trim(buf)
  end function int_text

  pure function real_text(x) result(t)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: t
    character(len=32) :: buf

    write (buf, '(g0)') x
    t = trim(adjustl(buf))
  end function real_text
end module keyword_numbers
