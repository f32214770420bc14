!> Reader for Abaqus keyword syntax, shared by every bulkflow input.
!>
!> What it understands (the subset of the Abaqus input rules that our inputs need):
!> * keyword lines `*KEYWORD, PARAM=value, FLAG`; the keyword and the parameter names
!>   are case-insensitive and runs of blanks count as one blank (`*user  material` is
!>   `USER MATERIAL`); a keyword line ending in a comma continues on the next line;
!>   parameter values keep their spelling, quotes (`NAME="a, b"`) protect commas and
!>   case (`get_string` upper-cases unquoted values, as Abaqus does);
!> * data lines: comma-separated fields, free spacing, a trailing comma is allowed;
!> * `**` comment lines and blank lines are skipped;
!> * `*INCLUDE, INPUT=file`: the file (relative to the including file) is read in
!>   place, so its data lines may continue the including file's keyword, as in Abaqus;
!>   includes nest; a missing file is an error at the including file:line.
!>
!> The result is a deck: keyword blocks in input order, each with its own file:line and
!> its data lines (each with its own file:line). Helpers fetch parameters with type and
!> range checks and turn data fields into numbers with `file:line:` messages.
!> Every routine that can fail takes an optional `type(error_t)`: without it the error
!> is reported and the program stops (see error_report).
module keyword_reader
  use material_kinds, only: dp
  use error_report, only: error_t, raise_error
  implicit none
  private

  public :: keyword_param_t, data_line_t, keyword_block_t, keyword_deck_t
  public :: read_keyword_file, read_keyword_string
  public :: upper_case, is_real_text, is_integer_text

  !> Deepest *INCLUDE nesting accepted; deeper means a circular include.
  integer, parameter :: max_include_depth = 32

  type :: string_t
     character(len=:), allocatable :: s
  end type string_t

  !> One `NAME=value` or `FLAG` of a keyword line.
  type :: keyword_param_t
     character(len=:), allocatable :: name   !< normalized: upper case, single blanks
     character(len=:), allocatable :: value  !< as written, quotes removed; '' for a flag
     logical :: has_value = .false.
     logical :: quoted = .false.
  end type keyword_param_t

  !> One data line split into fields (blanks around fields removed).
  type :: data_line_t
     character(len=:), allocatable :: file
     integer :: line = 0
     character(len=:), allocatable :: text   !< the whole line (free text, e.g. *HEADING)
     type(string_t), allocatable :: fields(:)
   contains
     procedure :: n_fields => data_n_fields
     procedure :: field => data_field
     procedure :: real_field => data_real_field
     procedure :: integer_field => data_integer_field
     procedure :: reals => data_reals
     procedure :: integers => data_integers
  end type data_line_t

  !> One keyword with its parameters and data lines.
  type :: keyword_block_t
     character(len=:), allocatable :: name   !< normalized, without the '*'
     character(len=:), allocatable :: file
     integer :: line = 0
     type(keyword_param_t), allocatable :: params(:)
     integer :: n_lines = 0
     type(data_line_t), allocatable :: lines(:)
   contains
     procedure :: has_param => block_has_param
     procedure :: check_params => block_check_params
     procedure :: get_real => block_get_real
     procedure :: get_integer => block_get_integer
     procedure :: get_string => block_get_string
     procedure :: all_reals => block_all_reals
     procedure :: fail => block_fail
  end type keyword_block_t

  !> The whole input: blocks in the order they appear (includes expanded).
  type :: keyword_deck_t
     integer :: n_blocks = 0
     type(keyword_block_t), allocatable :: blocks(:)
  end type keyword_deck_t

contains

  ! ------------------------------------------------------------------ reading

  !> Read `path` (and everything it includes) into `deck`.
  subroutine read_keyword_file(path, deck, err)
    character(len=*), intent(in) :: path
    type(keyword_deck_t), intent(out) :: deck
    type(error_t), intent(inout), optional :: err
    type(string_t), allocatable :: lines(:)
    logical :: ok
    type(error_t) :: local

    call load_file(path, lines, ok)
    if (.not. ok) then
       call raise_error(path, 0, 'cannot open input file', err)
       return
    end if
    call parse_lines(lines, path, deck, 0, local)
    if (local%raised) call forward(local, err)
  end subroutine read_keyword_file

  !> Read keyword text held in a string (lines separated by new_line('a')).
  !> `name` is the file name used in messages (default "<string>"); includes are
  !> resolved relative to the directory part of `name`.
  subroutine read_keyword_string(text, deck, err, name)
    character(len=*), intent(in) :: text
    type(keyword_deck_t), intent(out) :: deck
    type(error_t), intent(inout), optional :: err
    character(len=*), intent(in), optional :: name
    type(string_t), allocatable :: lines(:)
    character(len=:), allocatable :: fname
    type(error_t) :: local
    integer :: i0, i, n

    fname = '<string>'
    if (present(name)) fname = name
    allocate (lines(0))
    n = len(text)
    i0 = 1
    do i = 1, n + 1
       if (i > n) then
          if (i0 <= n) lines = [lines, string_t(text(i0:n))]
       else if (text(i:i) == new_line('a')) then
          lines = [lines, string_t(text(i0:i - 1))]
          i0 = i + 1
       end if
    end do
    call parse_lines(lines, fname, deck, 0, local)
    if (local%raised) call forward(local, err)
  end subroutine read_keyword_string

  !> Hand a recorded error to the caller's error object, or stop with it.
  subroutine forward(local, err)
    type(error_t), intent(in) :: local
    type(error_t), intent(inout), optional :: err

    if (present(err)) then
       err = local
    else
       call raise_error('', 0, local%message)
    end if
  end subroutine forward

  !> All lines of a file, any length; .false. when it cannot be opened.
  subroutine load_file(path, lines, ok)
    use, intrinsic :: iso_fortran_env, only: iostat_end, iostat_eor
    character(len=*), intent(in) :: path
    type(string_t), allocatable, intent(out) :: lines(:)
    logical, intent(out) :: ok
    character(len=512) :: buf
    character(len=:), allocatable :: line
    integer :: unit, ios, nread, n

    allocate (lines(64))
    n = 0
    open (newunit=unit, file=path, status='old', action='read', form='formatted', iostat=ios)
    ok = (ios == 0)
    if (.not. ok) then
       deallocate (lines)
       allocate (lines(0))
       return
    end if
    line = ''
    do
       read (unit, '(a)', advance='no', iostat=ios, size=nread) buf
       if (ios == 0) then
          line = line // buf(1:nread)
          cycle
       end if
       if (ios == iostat_eor .or. (ios == iostat_end .and. len(line) + nread > 0)) then
          line = line // buf(1:nread)
          call append_line(lines, n, line)
          line = ''
          if (ios == iostat_eor) cycle
       end if
       exit
    end do
    close (unit)
    lines = lines(1:n)
  end subroutine load_file

  subroutine append_line(lines, n, line)
    type(string_t), allocatable, intent(inout) :: lines(:)
    integer, intent(inout) :: n
    character(len=*), intent(in) :: line
    type(string_t), allocatable :: tmp(:)

    if (n == size(lines)) then
       allocate (tmp(2 * n + 16))
       tmp(1:n) = lines(1:n)
       call move_alloc(tmp, lines)
    end if
    n = n + 1
    lines(n)%s = line
  end subroutine append_line

  !> Parse the lines of one file into `deck` (appending); recursive for *INCLUDE.
  recursive subroutine parse_lines(lines, file, deck, depth, err)
    type(string_t), intent(in) :: lines(:)
    character(len=*), intent(in) :: file
    type(keyword_deck_t), intent(inout) :: deck
    integer, intent(in) :: depth
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: text, incfile, resolved
    type(string_t), allocatable :: inc_lines(:), fields(:)
    type(keyword_block_t) :: blk
    integer :: i, first
    logical :: ok

    i = 0
    do while (i < size(lines))
       i = i + 1
       text = clean_line(lines(i)%s)
       if (len_trim(text) == 0) cycle
       if (len(text) >= 2) then
          if (text(1:2) == '**') cycle
       end if
       if (text(1:1) == '*') then
          ! keyword line, possibly continued by a trailing comma
          first = i
          do while (ends_with_comma(text) .and. i < size(lines))
             i = i + 1
             text = text // ' ' // clean_line(lines(i)%s)
          end do
          call parse_keyword_line(text, file, first, blk, err)
          if (err%raised) return
          if (blk%name == 'INCLUDE') then
             call block_get_string(blk, 'INPUT', incfile, err, keep_case=.true.)
             if (err%raised) return
             call block_check_params(blk, [character(len=8) :: 'INPUT'], err)
             if (err%raised) return
             if (depth >= max_include_depth) then
                call raise_error(file, first, '*INCLUDE nested more than ' // &
                     int_text(max_include_depth) // ' deep (circular include?)', err)
                return
             end if
             call resolve_path(file, incfile, resolved)
             call load_file(resolved, inc_lines, ok)
             if (.not. ok) then
                call raise_error(file, first, 'cannot open include file "' // incfile // &
                     '" (looked for ' // resolved // ')', err)
                return
             end if
             call parse_lines(inc_lines, resolved, deck, depth + 1, err)
             if (err%raised) return
          else
             call append_block(deck, blk)
          end if
       else
          if (deck%n_blocks == 0) then
             call raise_error(file, i, 'data line before the first keyword: "' // &
                  trim(text) // '"', err)
             return
          end if
          call split_fields(text, fields)
          call append_data_line(deck%blocks(deck%n_blocks), text, fields, file, i)
       end if
    end do
  end subroutine parse_lines

  !> Tabs to blanks, carriage return dropped, leading blanks removed.
  pure function clean_line(raw) result(text)
    character(len=*), intent(in) :: raw
    character(len=:), allocatable :: text
    integer :: k

    text = raw
    do k = 1, len(text)
       if (text(k:k) == achar(9)) text(k:k) = ' '
       if (text(k:k) == achar(13)) text(k:k) = ' '
    end do
    text = trim(adjustl(text))
  end function clean_line

  pure logical function ends_with_comma(text)
    character(len=*), intent(in) :: text
    integer :: n

    n = len_trim(text)
    ends_with_comma = .false.
    if (n > 0) ends_with_comma = (text(n:n) == ',')
  end function ends_with_comma

  !> `included` relative to the directory of `including` unless absolute.
  pure subroutine resolve_path(including, included, path)
    character(len=*), intent(in) :: including, included
    character(len=:), allocatable, intent(out) :: path
    integer :: slash

    if (included(1:1) == '/') then
       path = included
       return
    end if
    slash = index(including, '/', back=.true.)
    if (slash == 0) then
       path = included
    else
       path = including(1:slash) // included
    end if
  end subroutine resolve_path

  !> `*NAME, P1=v1, FLAG` into a block (no data lines yet).
  subroutine parse_keyword_line(text, file, line, blk, err)
    character(len=*), intent(in) :: text
    character(len=*), intent(in) :: file
    integer, intent(in) :: line
    type(keyword_block_t), intent(out) :: blk
    type(error_t), intent(inout) :: err
    type(string_t), allocatable :: parts(:)
    type(keyword_param_t) :: p
    integer :: k, eq, j, i1, i2
    character(len=:), allocatable :: piece

    blk%file = file
    blk%line = line
    blk%n_lines = 0
    allocate (blk%params(0), blk%lines(0))
    call split_fields(text(2:), parts)
    if (size(parts) == 0) then
       call raise_error(file, line, 'empty keyword "*"', err)
       return
    end if
    blk%name = normalize_name(parts(1)%s)
    if (len(blk%name) == 0) then
       call raise_error(file, line, 'empty keyword "*"', err)
       return
    end if
    do k = 2, size(parts)
       piece = parts(k)%s
       if (len_trim(piece) == 0) cycle
       eq = index(piece, '=')
       if (eq > 0 .and. index(piece, '"') > 0) then
          if (index(piece, '"') < eq) eq = 0
       end if
       if (eq == 0) then
          p%name = normalize_name(piece)
          p%value = ''
          p%has_value = .false.
          p%quoted = .false.
       else
          p%name = normalize_name(piece(1:eq - 1))
          ! value: piece(i1:i2) without surrounding blanks, then without quotes
          i2 = len_trim(piece)
          i1 = eq + 1
          do while (i1 <= i2)
             if (piece(i1:i1) /= ' ') exit
             i1 = i1 + 1
          end do
          p%has_value = .true.
          p%quoted = .false.
          if (i2 - i1 >= 1) then
             if (piece(i1:i1) == '"' .and. piece(i2:i2) == '"') then
                i1 = i1 + 1
                i2 = i2 - 1
                p%quoted = .true.
             end if
          end if
          p%value = piece(i1:i2)
       end if
       if (len(p%name) == 0) then
          call raise_error(file, line, 'parameter without a name on *' // blk%name, err)
          return
       end if
       do j = 1, size(blk%params)
          if (blk%params(j)%name == p%name) then
             call raise_error(file, line, 'parameter ' // p%name // ' given twice on *' // &
                  blk%name, err)
             return
          end if
       end do
       blk%params = [blk%params, p]
    end do
    ! *HISTORY OUTPUT is what Abaqus/CAE calls a history output request; the input file
    ! keyword is *OUTPUT, HISTORY. Both are read as the latter (docs/keywords.md).
    if (blk%name == 'HISTORY OUTPUT') then
       do j = 1, size(blk%params)
          if (blk%params(j)%name == 'FIELD' .or. blk%params(j)%name == 'HISTORY') then
             call raise_error(file, line, '*HISTORY OUTPUT takes no ' // blk%params(j)%name // &
                  ' parameter; expected *HISTORY OUTPUT[, TIME INTERVAL=t | NUMBER INTERVAL=n] ' // &
                  '(the same as *OUTPUT, HISTORY)', err)
             return
          end if
       end do
       blk%name = 'OUTPUT'
       p%name = 'HISTORY'
       p%value = ''
       p%has_value = .false.
       p%quoted = .false.
       blk%params = [blk%params, p]
    end if
  end subroutine parse_keyword_line

  !> Split on commas outside double quotes; fields trimmed; a trailing empty field
  !> (trailing comma) is dropped.
  pure subroutine split_fields(text, fields)
    character(len=*), intent(in) :: text
    type(string_t), allocatable, intent(out) :: fields(:)
    integer :: k, start, n
    logical :: inside

    allocate (fields(0))
    n = len_trim(text)
    if (n == 0) return
    start = 1
    inside = .false.
    do k = 1, n
       if (text(k:k) == '"') inside = .not. inside
       if (text(k:k) == ',' .and. .not. inside) then
          fields = [fields, string_t(trim(adjustl(text(start:k - 1))))]
          start = k + 1
       end if
    end do
    if (start <= n) then
       fields = [fields, string_t(trim(adjustl(text(start:n))))]
    end if
  end subroutine split_fields

  !> Upper case, blanks trimmed, runs of blanks reduced to one.
  pure function normalize_name(raw) result(name)
    character(len=*), intent(in) :: raw
    character(len=:), allocatable :: name
    character(len=:), allocatable :: t
    integer :: k

    t = upper_case(trim(adjustl(raw)))
    name = ''
    do k = 1, len(t)
       if (t(k:k) == ' ') then
          if (k > 1) then
             if (t(k - 1:k - 1) == ' ') cycle
          end if
       end if
       name = name // t(k:k)
    end do
  end function normalize_name

  subroutine append_block(deck, blk)
    type(keyword_deck_t), intent(inout) :: deck
    type(keyword_block_t), intent(in) :: blk
    type(keyword_block_t), allocatable :: tmp(:)

    if (.not. allocated(deck%blocks)) allocate (deck%blocks(8))
    if (deck%n_blocks == size(deck%blocks)) then
       allocate (tmp(2 * deck%n_blocks))
       tmp(1:deck%n_blocks) = deck%blocks(1:deck%n_blocks)
       call move_alloc(tmp, deck%blocks)
    end if
    deck%n_blocks = deck%n_blocks + 1
    deck%blocks(deck%n_blocks) = blk
  end subroutine append_block

  subroutine append_data_line(blk, text, fields, file, line)
    type(keyword_block_t), intent(inout) :: blk
    character(len=*), intent(in) :: text
    type(string_t), intent(in) :: fields(:)
    character(len=*), intent(in) :: file
    integer, intent(in) :: line
    type(data_line_t), allocatable :: tmp(:)

    if (.not. allocated(blk%lines)) allocate (blk%lines(0))
    if (blk%n_lines == size(blk%lines)) then
       allocate (tmp(2 * blk%n_lines + 4))
       tmp(1:blk%n_lines) = blk%lines(1:blk%n_lines)
       call move_alloc(tmp, blk%lines)
    end if
    blk%n_lines = blk%n_lines + 1
    blk%lines(blk%n_lines)%file = file
    blk%lines(blk%n_lines)%line = line
    blk%lines(blk%n_lines)%text = text
    blk%lines(blk%n_lines)%fields = fields
  end subroutine append_data_line

  ! ------------------------------------------------------------------ data lines

  pure integer function data_n_fields(self)
    class(data_line_t), intent(in) :: self

    data_n_fields = size(self%fields)
  end function data_n_fields

  !> Field `i` as written ('' beyond the last field).
  pure function data_field(self, i) result(text)
    class(data_line_t), intent(in) :: self
    integer, intent(in) :: i
    character(len=:), allocatable :: text

    text = ''
    if (i >= 1 .and. i <= size(self%fields)) text = self%fields(i)%s
  end function data_field

  !> Field `i` as a real; error "expected a real number in field i, got "x"".
  subroutine data_real_field(self, i, value, err)
    class(data_line_t), intent(in) :: self
    integer, intent(in) :: i
    real(dp), intent(out) :: value
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: t
    integer :: ios

    value = 0.0_dp
    if (i > size(self%fields)) then
       call raise_error(self%file, self%line, 'expected a real number in field ' // &
            int_text(i) // ', but the line has only ' // int_text(size(self%fields)) // &
            ' fields', err)
       return
    end if
    t = self%fields(i)%s
    ios = 1
    if (is_real_text(t)) read (t, *, iostat=ios) value
    if (ios /= 0) then
       call raise_error(self%file, self%line, 'expected a real number in field ' // &
            int_text(i) // ', got "' // t // '"', err)
       value = 0.0_dp
    end if
  end subroutine data_real_field

  !> Field `i` as an integer; error "expected an integer in field i, got "x"".
  subroutine data_integer_field(self, i, value, err)
    class(data_line_t), intent(in) :: self
    integer, intent(in) :: i
    integer, intent(out) :: value
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: t
    integer :: ios

    value = 0
    if (i > size(self%fields)) then
       call raise_error(self%file, self%line, 'expected an integer in field ' // &
            int_text(i) // ', but the line has only ' // int_text(size(self%fields)) // &
            ' fields', err)
       return
    end if
    t = self%fields(i)%s
    ios = 1
    if (is_integer_text(t)) read (t, *, iostat=ios) value
    if (ios /= 0) then
       call raise_error(self%file, self%line, 'expected an integer in field ' // &
            int_text(i) // ', got "' // t // '"', err)
       value = 0
    end if
  end subroutine data_integer_field

  !> All fields of the line as reals.
  subroutine data_reals(self, values, err)
    class(data_line_t), intent(in) :: self
    real(dp), allocatable, intent(out) :: values(:)
    type(error_t), intent(inout), optional :: err
    type(error_t) :: local
    integer :: i

    allocate (values(size(self%fields)))
    do i = 1, size(self%fields)
       call self%real_field(i, values(i), local)
       if (local%raised) then
          call forward(local, err)
          return
       end if
    end do
  end subroutine data_reals

  !> All fields of the line as integers.
  subroutine data_integers(self, values, err)
    class(data_line_t), intent(in) :: self
    integer, allocatable, intent(out) :: values(:)
    type(error_t), intent(inout), optional :: err
    type(error_t) :: local
    integer :: i

    allocate (values(size(self%fields)))
    do i = 1, size(self%fields)
       call self%integer_field(i, values(i), local)
       if (local%raised) then
          call forward(local, err)
          return
       end if
    end do
  end subroutine data_integers

  ! ------------------------------------------------------------------ blocks

  !> Report an error located at the keyword line of this block.
  subroutine block_fail(self, message, err)
    class(keyword_block_t), intent(in) :: self
    character(len=*), intent(in) :: message
    type(error_t), intent(inout), optional :: err

    call raise_error(self%file, self%line, message, err)
  end subroutine block_fail

  pure logical function block_has_param(self, name)
    class(keyword_block_t), intent(in) :: self
    character(len=*), intent(in) :: name

    block_has_param = (param_index(self, name) > 0)
  end function block_has_param

  pure integer function param_index(self, name)
    class(keyword_block_t), intent(in) :: self
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: key
    integer :: k

    key = normalize_name(name)
    param_index = 0
    do k = 1, size(self%params)
       if (self%params(k)%name == key) then
          param_index = k
          return
       end if
    end do
  end function param_index

  !> Error on the first parameter whose name is not in `allowed`.
  subroutine block_check_params(self, allowed, err)
    class(keyword_block_t), intent(in) :: self
    character(len=*), intent(in) :: allowed(:)
    type(error_t), intent(inout), optional :: err
    integer :: k, j
    logical :: found
    character(len=:), allocatable :: known

    do k = 1, size(self%params)
       found = .false.
       do j = 1, size(allowed)
          if (self%params(k)%name == normalize_name(allowed(j))) found = .true.
       end do
       if (.not. found) then
          known = ''
          do j = 1, size(allowed)
             if (j > 1) known = known // ', '
             known = known // trim(allowed(j))
          end do
          if (size(allowed) == 0) known = 'none'
          call self%fail('unknown parameter ' // self%params(k)%name // ' on *' // &
               self%name // ' (known: ' // known // ')', err)
          return
       end if
    end do
  end subroutine block_check_params

  !> Locate a parameter that must carry a value; k = 0 when absent (and not required).
  subroutine lookup_value(self, name, required, k, err)
    class(keyword_block_t), intent(in) :: self
    character(len=*), intent(in) :: name
    logical, intent(in) :: required
    integer, intent(out) :: k
    type(error_t), intent(inout), optional :: err

    k = param_index(self, name)
    if (k == 0) then
       if (required) call self%fail('*' // self%name // ': missing required parameter ' // &
            normalize_name(name), err)
       return
    end if
    if (.not. self%params(k)%has_value .or. len(self%params(k)%value) == 0) then
       call self%fail('*' // self%name // ': parameter ' // self%params(k)%name // &
            ' needs a value', err)
       k = -1
    end if
  end subroutine lookup_value

  !> Real parameter. Without `default` it is required. `minimum`/`maximum` bound it.
  subroutine block_get_real(self, name, value, err, default, minimum, maximum)
    class(keyword_block_t), intent(in) :: self
    character(len=*), intent(in) :: name
    real(dp), intent(out) :: value
    type(error_t), intent(inout), optional :: err
    real(dp), intent(in), optional :: default, minimum, maximum
    type(error_t) :: local
    integer :: k, ios
    character(len=:), allocatable :: t

    value = 0.0_dp
    if (present(default)) value = default
    call lookup_value(self, name, .not. present(default), k, local)
    if (local%raised) then
       call forward(local, err)
       return
    end if
    if (k == 0) return
    t = trim(self%params(k)%value)
    ios = 1
    if (is_real_text(t)) read (t, *, iostat=ios) value
    if (ios /= 0) then
       call self%fail('*' // self%name // ': parameter ' // self%params(k)%name // &
            ' expects a real number, got "' // t // '"', err)
       return
    end if
    if (present(minimum)) then
       if (value < minimum) then
          call self%fail('*' // self%name // ': parameter ' // self%params(k)%name // '=' // &
               t // ' must be >= ' // real_text(minimum), err)
          return
       end if
    end if
    if (present(maximum)) then
       if (value > maximum) then
          call self%fail('*' // self%name // ': parameter ' // self%params(k)%name // '=' // &
               t // ' must be <= ' // real_text(maximum), err)
          return
       end if
    end if
  end subroutine block_get_real

  !> Integer parameter. Without `default` it is required. `minimum`/`maximum` bound it.
  subroutine block_get_integer(self, name, value, err, default, minimum, maximum)
    class(keyword_block_t), intent(in) :: self
    character(len=*), intent(in) :: name
    integer, intent(out) :: value
    type(error_t), intent(inout), optional :: err
    integer, intent(in), optional :: default, minimum, maximum
    type(error_t) :: local
    integer :: k, ios
    character(len=:), allocatable :: t

    value = 0
    if (present(default)) value = default
    call lookup_value(self, name, .not. present(default), k, local)
    if (local%raised) then
       call forward(local, err)
       return
    end if
    if (k == 0) return
    t = trim(self%params(k)%value)
    ios = 1
    if (is_integer_text(t)) read (t, *, iostat=ios) value
    if (ios /= 0) then
       call self%fail('*' // self%name // ': parameter ' // self%params(k)%name // &
            ' expects an integer, got "' // t // '"', err)
       return
    end if
    if (present(minimum)) then
       if (value < minimum) then
          call self%fail('*' // self%name // ': parameter ' // self%params(k)%name // '=' // &
               t // ' must be >= ' // int_text(minimum), err)
          return
       end if
    end if
    if (present(maximum)) then
       if (value > maximum) then
          call self%fail('*' // self%name // ': parameter ' // self%params(k)%name // '=' // &
               t // ' must be <= ' // int_text(maximum), err)
          return
       end if
    end if
  end subroutine block_get_integer

  !> String parameter, upper-cased unless quoted or `keep_case`; blanks inside an
  !> unquoted value are normalized like names ("SIMPLE  shear" -> "SIMPLE SHEAR").
  !> Without `default` it is required; with `choices` the value must be one of them.
  subroutine block_get_string(self, name, value, err, default, choices, keep_case)
    class(keyword_block_t), intent(in) :: self
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(out) :: value
    type(error_t), intent(inout), optional :: err
    character(len=*), intent(in), optional :: default
    character(len=*), intent(in), optional :: choices(:)
    logical, intent(in), optional :: keep_case
    type(error_t) :: local
    integer :: k, j
    logical :: keep
    character(len=:), allocatable :: list

    value = ''
    if (present(default)) value = default
    call lookup_value(self, name, .not. present(default), k, local)
    if (local%raised) then
       call forward(local, err)
       return
    end if
    if (k == 0) return
    keep = self%params(k)%quoted
    if (present(keep_case)) keep = keep .or. keep_case
    if (keep) then
       value = self%params(k)%value
    else
       value = normalize_name(self%params(k)%value)
    end if
    if (present(choices)) then
       do j = 1, size(choices)
          if (value == trim(choices(j))) return
       end do
       list = ''
       do j = 1, size(choices)
          if (j > 1) list = list // ', '
          list = list // trim(choices(j))
       end do
       call self%fail('*' // self%name // ': ' // self%params(k)%name // '=' // value // &
            ' is not one of ' // list, err)
    end if
  end subroutine block_get_string

  !> Every field of every data line as one real array (e.g. *USER MATERIAL constants,
  !> 8 per line in Abaqus, any count per line accepted here).
  subroutine block_all_reals(self, values, err)
    class(keyword_block_t), intent(in) :: self
    real(dp), allocatable, intent(out) :: values(:)
    type(error_t), intent(inout), optional :: err
    real(dp), allocatable :: line_values(:)
    type(error_t) :: local
    integer :: i

    allocate (values(0))
    do i = 1, self%n_lines
       call self%lines(i)%reals(line_values, local)
       if (local%raised) then
          call forward(local, err)
          return
       end if
       values = [values, line_values]
    end do
  end subroutine block_all_reals

  ! ------------------------------------------------------------------ text helpers

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
    character :: c

    is_real_text = .false.
    n = len_trim(text)
    if (n == 0) return
    k = 1
    if (text(1:1) == '+' .or. text(1:1) == '-') k = 2
    ndig = 0
    do while (k <= n)
       c = text(k:k)
       if (.not. is_digit(c)) exit
       ndig = ndig + 1
       k = k + 1
    end do
    if (k <= n) then
       if (text(k:k) == '.') then
          k = k + 1
          do while (k <= n)
             c = text(k:k)
             if (.not. is_digit(c)) exit
             ndig = ndig + 1
             k = k + 1
          end do
       end if
    end if
    if (ndig == 0) return
    if (k <= n) then
       c = text(k:k)
       if (index('eEdD', c) == 0) return
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

  !> [sign] digits, nothing else.
  pure logical function is_integer_text(text)
    character(len=*), intent(in) :: text
    integer :: k, n, k0

    is_integer_text = .false.
    n = len_trim(text)
    if (n == 0) return
    k0 = 1
    if (text(1:1) == '+' .or. text(1:1) == '-') k0 = 2
    if (k0 > n) return
    if (n - k0 + 1 > 9) return
    do k = k0, n
       if (.not. is_digit(text(k:k))) return
    end do
    is_integer_text = .true.
  end function is_integer_text

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

end module keyword_reader
