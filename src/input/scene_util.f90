!> Small helpers shared by the scene_* modules (the Abaqus-syntax scene reader):
!> numbers from data lines and parameters with range checks, data-line and field-count
!> checks with `file:line: what is wrong; what was expected` messages, growable integer
!> lists and a stable integer sort.
!>
!> Why our own number check in front of keyword_reader's: reading "1e999" with the
!> debug build's floating-point traps stops the program inside the C library, and the
!> scene reader must never crash. We therefore reject any number whose decimal exponent
!> puts it at or beyond `max_magnitude` before Fortran's read sees it.
module scene_util
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: data_line_t, keyword_block_t, upper_case, is_real_text
  use keyword_numbers, only: written_exponent
  implicit none
  private

  public :: itoa, rtoa, where_text, keyword_text
  public :: get_real, get_int, get_real_param, field_blank, field_name, last_field
  public :: expect_fields, expect_lines
  public :: append_int, sort_permutation, sort_unique, check_name, push_block

  !> Largest magnitude accepted for any real in a scene (far above any physical value,
  !> far below overflow, so squares and products of two inputs stay finite).
  real(dp), parameter, public :: max_magnitude = 1.0e99_dp
  integer, parameter :: max_decimal_exponent = 99

contains

  ! ------------------------------------------------------------------ text

  pure function itoa(i) result(t)
    integer, intent(in) :: i
    character(len=:), allocatable :: t
    character(len=16) :: buf

    write (buf, '(i0)') i
    t = trim(buf)
  end function itoa

  !> A real for messages, short and without trailing zeros: 0.05, 25, 1732.050808,
  !> 1E+10, 2.5E-07.
  pure function rtoa(x) result(t)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: t
    character(len=32) :: buf
    integer :: e, k

    if (abs(x) >= 1.0e-4_dp .and. abs(x) < 1.0e7_dp) then
       write (buf, '(f0.6)') x
       t = trim(adjustl(buf))
       e = len(t) + 1
    else if (x > 0 .or. x < 0) then
       write (buf, '(es14.6)') x
       t = trim(adjustl(buf))
       e = index(t, 'E')
    else
       t = '0'
       return
    end if
    ! strip trailing zeros of the mantissa, then a bare point
    k = e - 1
    do while (k > 1)
       if (t(k:k) /= '0') exit
       k = k - 1
    end do
    if (t(k:k) == '.') k = k - 1
    t = t(1:k) // t(e:)
    ! Fortran writes ".05"; people write "0.05"
    if (t(1:1) == '.') t = '0' // t
    if (len(t) >= 2) then
       if (t(1:2) == '-.') t = '-0' // t(2:)
    end if
  end function rtoa

  !> "file:line" for messages that point elsewhere ("first defined at ...").
  pure function where_text(file, line) result(t)
    character(len=*), intent(in) :: file
    integer, intent(in) :: line
    character(len=:), allocatable :: t

    t = trim(file) // ':' // itoa(line)
  end function where_text

  !> "*NAME" of a block, for messages.
  pure function keyword_text(blk) result(t)
    type(keyword_block_t), intent(in) :: blk
    character(len=:), allocatable :: t

    t = '*' // blk%name
  end function keyword_text

  ! ------------------------------------------------------------------ fields

  !> Field i is absent or empty.
  pure logical function field_blank(dl, i)
    type(data_line_t), intent(in) :: dl
    integer, intent(in) :: i

    field_blank = len_trim(dl%field(i)) == 0
  end function field_blank

  !> Field i as a name: upper case (Abaqus compares names case-insensitively), quotes
  !> removed (a quoted name keeps its case, as on keyword lines).
  pure function field_name(dl, i) result(name)
    type(data_line_t), intent(in) :: dl
    integer, intent(in) :: i
    character(len=:), allocatable :: name
    character(len=:), allocatable :: t
    integer :: n

    t = trim(adjustl(dl%field(i)))
    n = len(t)
    if (n >= 2) then
       if (t(1:1) == '"' .and. t(n:n) == '"') then
          name = t(2:n - 1)
          return
       end if
    end if
    name = upper_case(t)
  end function field_name

  !> Append a copy of `blk` to out(1:n), growing `out` by doubling.
  subroutine push_block(out, n, blk)
    type(keyword_block_t), allocatable, intent(inout) :: out(:)
    integer, intent(inout) :: n
    type(keyword_block_t), intent(in) :: blk
    type(keyword_block_t), allocatable :: tmp(:)

    if (.not. allocated(out)) allocate (out(8))
    if (n == size(out)) then
       allocate (tmp(2 * n + 8))
       tmp(1:n) = out(1:n)
       call move_alloc(tmp, out)
    end if
    n = n + 1
    out(n) = blk
  end subroutine push_block

  !> Position of the last non-blank field (a trailing ", ," adds nothing).
  pure integer function last_field(dl)
    type(data_line_t), intent(in) :: dl
    integer :: i

    last_field = 0
    do i = dl%n_fields(), 1, -1
       if (len_trim(dl%field(i)) > 0) then
          last_field = i
          return
       end if
    end do
  end function last_field

  !> .true. when the decimal exponent of a syntactically valid real stays below
  !> max_decimal_exponent (digits before the point plus the written exponent).
  pure logical function magnitude_ok(text)
    character(len=*), intent(in) :: text
    integer :: k, n, int_digits, expo
    logical :: leading

    n = len_trim(text)
    k = 1
    if (text(1:1) == '+' .or. text(1:1) == '-') k = 2
    int_digits = 0
    leading = .true.
    do while (k <= n)
       if (text(k:k) < '0' .or. text(k:k) > '9') exit
       if (text(k:k) /= '0') leading = .false.
       if (.not. leading) int_digits = int_digits + 1
       k = k + 1
    end do
    do while (k <= n)
       if (index('eEdD', text(k:k)) > 0) exit
       k = k + 1
    end do
    expo = written_exponent(text(1:n), k)
    magnitude_ok = expo + int_digits <= max_decimal_exponent
  end function magnitude_ok

  !> Real in field i of a data line. With `default`, a blank field gives the default.
  !> Rejects text that is not a number and magnitudes >= max_magnitude.
  subroutine get_real(dl, i, x, err, default)
    type(data_line_t), intent(in) :: dl
    integer, intent(in) :: i
    real(dp), intent(out) :: x
    type(error_t), intent(inout) :: err
    real(dp), intent(in), optional :: default
    character(len=:), allocatable :: t

    x = 0
    if (present(default)) then
       x = default
       if (field_blank(dl, i)) return
    end if
    t = dl%field(i)
    if (is_real_text(t)) then
       if (.not. magnitude_ok(t)) then
          call raise_error(dl%file, dl%line, 'number "' // t // '" in field ' // itoa(i) // &
               ' is out of range; expected a magnitude below 1e99', err)
          return
       end if
    end if
    call dl%real_field(i, x, err)
    if (err%raised) x = 0
  end subroutine get_real

  !> Integer in field i of a data line (blank allowed only with `default`).
  subroutine get_int(dl, i, n, err, default)
    type(data_line_t), intent(in) :: dl
    integer, intent(in) :: i
    integer, intent(out) :: n
    type(error_t), intent(inout) :: err
    integer, intent(in), optional :: default

    n = 0
    if (present(default)) then
       n = default
       if (field_blank(dl, i)) return
    end if
    call dl%integer_field(i, n, err)
  end subroutine get_int

  !> Real keyword parameter with the same magnitude guard as get_real; `default`
  !> makes it optional; `positive` requires a value > 0.
  subroutine get_real_param(blk, name, x, err, default, positive)
    type(keyword_block_t), intent(in) :: blk
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: x
    type(error_t), intent(inout) :: err
    real(dp), intent(in), optional :: default
    logical, intent(in), optional :: positive
    integer :: k

    x = 0
    if (present(default)) x = default
    do k = 1, size(blk%params)
       if (blk%params(k)%name /= upper_case(name)) cycle
       if (is_real_text(blk%params(k)%value)) then
          if (.not. magnitude_ok(blk%params(k)%value)) then
             call blk%fail(keyword_text(blk) // ': parameter ' // trim(upper_case(name)) // '=' // &
                  blk%params(k)%value // ' is out of range; expected a magnitude below 1e99', err)
             return
          end if
       end if
    end do
    if (present(default)) then
       call blk%get_real(name, x, err, default=default)
    else
       call blk%get_real(name, x, err)
    end if
    if (err%raised) return
    if (present(positive)) then
       if (positive .and. .not. (x > 0)) then
          call blk%fail(keyword_text(blk) // ': parameter ' // trim(upper_case(name)) // &
               ' must be positive; got ' // rtoa(x), err)
       end if
    end if
  end subroutine get_real_param

  !> Check the number of fields of a data line: at least nmin, at most nmax non-blank
  !> (trailing blanks do not count). `expected` describes the layout.
  subroutine expect_fields(blk, dl, nmin, nmax, expected, err)
    type(keyword_block_t), intent(in) :: blk
    type(data_line_t), intent(in) :: dl
    integer, intent(in) :: nmin, nmax
    character(len=*), intent(in) :: expected
    type(error_t), intent(inout) :: err
    integer :: n

    n = last_field(dl)
    if (n < nmin) then
       call raise_error(dl%file, dl%line, 'too few values for ' // keyword_text(blk) // &
            ' (' // itoa(n) // '); expected ' // expected, err)
    else if (n > nmax) then
       call raise_error(dl%file, dl%line, 'data beyond what ' // keyword_text(blk) // &
            ' takes (' // itoa(n) // ' values, field ' // itoa(nmax + 1) // ' is "' // &
            dl%field(nmax + 1) // '"); expected ' // expected, err)
    end if
  end subroutine expect_fields

  !> Check the number of data lines of a block.
  subroutine expect_lines(blk, nmin, nmax, expected, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: nmin, nmax
    character(len=*), intent(in) :: expected
    type(error_t), intent(inout) :: err

    if (blk%n_lines < nmin) then
       call blk%fail('missing data line after ' // keyword_text(blk) // '; expected ' // &
            expected, err)
    else if (blk%n_lines > nmax) then
       call raise_error(blk%lines(nmax + 1)%file, blk%lines(nmax + 1)%line, &
            'data beyond what ' // keyword_text(blk) // ' takes (' // itoa(nmax) // &
            ' data line(s)); expected ' // expected, err)
    end if
  end subroutine expect_lines

  !> A name the model will store: at most `max_length` characters (Abaqus allows 80;
  !> model_sets%name_length is 80 and built-in material names get a prefix).
  subroutine check_name(blk, what, name, max_length, err)
    type(keyword_block_t), intent(in) :: blk
    character(len=*), intent(in) :: what, name
    integer, intent(in) :: max_length
    type(error_t), intent(inout) :: err

    if (len(name) > max_length) call blk%fail(what // ' name "' // name // '" has ' // itoa(len(name)) // &
         ' characters; expected at most ' // itoa(max_length), err)
  end subroutine check_name

  ! ------------------------------------------------------------------ lists

  !> Append v to list(1:n), growing the storage geometrically.
  pure subroutine append_int(list, n, v)
    integer, allocatable, intent(inout) :: list(:)
    integer, intent(inout) :: n
    integer, intent(in) :: v
    integer, allocatable :: tmp(:)

    if (.not. allocated(list)) allocate (list(16))
    if (n >= size(list)) then
       allocate (tmp(2 * size(list) + 16))
       tmp(1:n) = list(1:n)
       call move_alloc(tmp, list)
    end if
    n = n + 1
    list(n) = v
  end subroutine append_int

  !> Stable ascending order of keys: keys(perm) is sorted (merge sort, O(n log n)).
  pure subroutine sort_permutation(keys, perm)
    integer, intent(in) :: keys(:)
    integer, allocatable, intent(out) :: perm(:)
    integer, allocatable :: work(:)
    integer :: n, width, lo, mid, hi, i, j, k

    n = size(keys)
    allocate (perm(n), work(n))
    do i = 1, n
       perm(i) = i
    end do
    width = 1
    do while (width < n)
       lo = 1
       do while (lo <= n)
          mid = min(lo + width - 1, n)
          hi = min(lo + 2 * width - 1, n)
          i = lo
          j = mid + 1
          k = lo
          do while (i <= mid .and. j <= hi)
             if (keys(perm(j)) < keys(perm(i))) then
                work(k) = perm(j)
                j = j + 1
             else
                work(k) = perm(i)
                i = i + 1
             end if
             k = k + 1
          end do
          do while (i <= mid)
             work(k) = perm(i)
             i = i + 1
             k = k + 1
          end do
          do while (j <= hi)
             work(k) = perm(j)
             j = j + 1
             k = k + 1
          end do
          lo = lo + 2 * width
       end do
       perm(1:n) = work(1:n)
       width = 2 * width
    end do
  end subroutine sort_permutation

  !> Sorted distinct values of `values`.
  pure subroutine sort_unique(values, result)
    integer, intent(in) :: values(:)
    integer, allocatable, intent(out) :: result(:)
    integer, allocatable :: perm(:)
    integer :: i, n

    call sort_permutation(values, perm)
    allocate (result(size(values)))
    n = 0
    do i = 1, size(values)
       if (n > 0) then
          if (result(n) == values(perm(i))) cycle
       end if
       n = n + 1
       result(n) = values(perm(i))
    end do
    result = result(1:n)
  end subroutine sort_unique
end module scene_util
