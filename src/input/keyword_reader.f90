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
!>
!> Cost linear in the size of the input and in the length of any line (submodule
!> keyword_parse): a file is read whole into one buffer; a data line is a slice of it (`text`
!> points into the buffer, `file` at the file's name) and its fields are index pairs into
!> the line, kept in one growing array per file — no allocation per line or per field. The
!> buffers live as long as the program (a deck is read once).
module keyword_reader
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error, pass_error
  use keyword_numbers, only: upper_case, is_real_text, is_integer_text, text_to_real, &
       text_to_integer, is_integer_syntax, int_text, real_text, normalize_name
  implicit none
  private

  public :: keyword_param_t, data_line_t, keyword_block_t, keyword_deck_t
  public :: read_keyword_file, read_keyword_string
  public :: set_field, keep_fields, set_line_text, reparse_keyword_line
  public :: upper_case, is_real_text, is_integer_text, is_integer_syntax

  !> Deepest *INCLUDE nesting accepted; deeper means a circular include.
  integer, parameter :: max_include_depth = 32

  !> One file's text and the field bounds of its data lines.
  type :: source_t
     character(len=:), allocatable :: name
     character(len=:), allocatable :: text     !< the whole file
     integer, allocatable :: bounds(:)         !< first and last column of each field, by pairs
     integer :: n_bounds = 0
  end type source_t

  !> One `NAME=value` or `FLAG` of a keyword line.
  type :: keyword_param_t
     character(len=:), allocatable :: name   !< normalized: upper case, single blanks
     character(len=:), allocatable :: value  !< as written, quotes removed; '' for a flag
     logical :: has_value = .false.
     logical :: quoted = .false.
  end type keyword_param_t

  !> One data line split into fields (blanks around fields removed).
  type :: data_line_t
     character(len=:), pointer :: file => null()   !< the file's name (shared by its lines)
     integer :: line = 0
     character(len=:), pointer :: text => null()   !< the whole line (free text, e.g. *HEADING)
     type(source_t), pointer, private :: src => null()
     integer, private :: first = 0                 !< src%bounds(first + 1 : first + 2 nf)
     integer, private :: nf = 0
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

  interface
     !> Read `path` (and everything it includes) into `deck`.
     module subroutine read_keyword_file(path, deck, err)
       character(len=*), intent(in) :: path
       type(keyword_deck_t), intent(out) :: deck
       type(error_t), intent(inout), optional :: err
     end subroutine read_keyword_file

     !> Read keyword text held in a string (lines separated by new_line('a')).
     !> `name` is the file name used in messages (default "<string>"); includes are
     !> resolved relative to the directory part of `name`.
     module subroutine read_keyword_string(text, deck, err, name)
       character(len=*), intent(in) :: text
       type(keyword_deck_t), intent(out) :: deck
       type(error_t), intent(inout), optional :: err
       character(len=*), intent(in), optional :: name
     end subroutine read_keyword_string

     !> Replace a data line's whole text (split into fields again), e.g. after `<name>`
     !> substitution; the line owns its new text, the file's buffer is not written.
     module subroutine set_line_text(dl, text)
       type(data_line_t), intent(inout) :: dl
       character(len=*), intent(in) :: text
     end subroutine set_line_text

     !> Parse `text` ("*NAME, P=v, ...") again as the keyword line of `blk`; its data lines,
     !> file and line stay.
     module subroutine reparse_keyword_line(blk, text, err)
       type(keyword_block_t), intent(inout) :: blk
       character(len=*), intent(in) :: text
       type(error_t), intent(inout) :: err
     end subroutine reparse_keyword_line
  end interface

contains

  ! ------------------------------------------------------------------ data lines

  !> Rewrite field `i` of a data line (the deck layer that maps parts and instances onto the flat
  !> model, and general contact, rewrite lines they were given). The line then owns a small text
  !> of its own ("f1, f2, ..."), so the file's buffer, shared by every other line, is never
  !> written; a field beyond the last one extends the line with blank fields.
  subroutine set_field(dl, i, value)
    type(data_line_t), intent(inout) :: dl
    integer, intent(in) :: i
    character(len=*), intent(in) :: value
    integer :: n

    n = max(dl%nf, i)
    call rebuild_line(dl, n, i, value)
  end subroutine set_field

  !> Drop every field after the first `n` (fewer fields only).
  subroutine keep_fields(dl, n)
    type(data_line_t), intent(inout) :: dl
    integer, intent(in) :: n

    if (n >= dl%nf) return
    call rebuild_line(dl, max(n, 0), 0, '')
  end subroutine keep_fields

  !> The line made again from its first `n` fields, field `i` (if 1..n) replaced by `value`.
  subroutine rebuild_line(dl, n, i, value)
    type(data_line_t), intent(inout) :: dl
    integer, intent(in) :: n, i
    character(len=*), intent(in) :: value
    type(source_t), pointer :: own
    character(len=:), allocatable :: text, f
    integer, allocatable :: bounds(:)
    integer :: k

    allocate (bounds(2 * n))
    text = ''
    do k = 1, n
       if (k == i) then
          f = value
       else
          f = dl%field(k)
       end if
       if (k > 1) text = text // ', '
       bounds(2 * k - 1) = len(text) + 1
       text = text // f
       bounds(2 * k) = len(text)
    end do
    allocate (own)
    if (associated(dl%file)) own%name = dl%file
    own%text = text
    call move_alloc(bounds, own%bounds)
    own%n_bounds = 2 * n
    dl%src => own
    dl%text => own%text
    dl%first = 0
    dl%nf = n
  end subroutine rebuild_line

  pure integer function data_n_fields(self)
    class(data_line_t), intent(in) :: self

    data_n_fields = self%nf
  end function data_n_fields

  !> Field `i` as written ('' beyond the last field).
  pure function data_field(self, i) result(text)
    class(data_line_t), intent(in) :: self
    integer, intent(in) :: i
    character(len=:), allocatable :: text

    text = ''
    if (i >= 1 .and. i <= self%nf) then
       associate (b => self%src%bounds)
         text = self%text(b(self%first + 2 * i - 1):b(self%first + 2 * i))
       end associate
    end if
  end function data_field

  !> Field `i` as a real; error "expected a real number in field i, got "x"".
  subroutine data_real_field(self, i, value, err)
    class(data_line_t), intent(in) :: self
    integer, intent(in) :: i
    real(dp), intent(out) :: value
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: t
    logical :: ok

    value = 0.0_dp
    if (i > self%nf) then
       call raise_error(self%file, self%line, 'expected a real number in field ' // &
            int_text(i) // ', but the line has only ' // int_text(self%nf) // &
            ' fields', err)
       return
    end if
    t = self%field(i)
    call text_to_real(t, value, ok)
    if (.not. ok) then
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
    logical :: ok

    value = 0
    if (i > self%nf) then
       call raise_error(self%file, self%line, 'expected an integer in field ' // &
            int_text(i) // ', but the line has only ' // int_text(self%nf) // &
            ' fields', err)
       return
    end if
    t = self%field(i)
    call text_to_integer(t, value, ok)
    if (.not. ok .and. is_integer_syntax(t)) then
       call raise_error(self%file, self%line, 'integer "' // t // '" in field ' // int_text(i) // &
            ' is out of range; expected -2147483648 .. 2147483647', err)
    else if (.not. ok) then
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

    allocate (values(self%nf))
    do i = 1, self%nf
       call self%real_field(i, values(i), local)
       if (local%raised) then
          call pass_error(local, err)
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

    allocate (values(self%nf))
    do i = 1, self%nf
       call self%integer_field(i, values(i), local)
       if (local%raised) then
          call pass_error(local, err)
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
    integer :: k
    logical :: ok
    character(len=:), allocatable :: t

    value = 0.0_dp
    if (present(default)) value = default
    call lookup_value(self, name, .not. present(default), k, local)
    if (local%raised) then
       call pass_error(local, err)
       return
    end if
    if (k == 0) return
    t = trim(self%params(k)%value)
    call text_to_real(t, value, ok)
    if (.not. ok) then
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
    integer :: k
    logical :: ok
    character(len=:), allocatable :: t

    value = 0
    if (present(default)) value = default
    call lookup_value(self, name, .not. present(default), k, local)
    if (local%raised) then
       call pass_error(local, err)
       return
    end if
    if (k == 0) return
    t = trim(self%params(k)%value)
    call text_to_integer(t, value, ok)
    if (.not. ok) then
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
       call pass_error(local, err)
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
    type(error_t) :: local
    integer :: i, j, n

    n = 0
    do i = 1, self%n_lines
       n = n + self%lines(i)%nf
    end do
    allocate (values(n))
    n = 0
    do i = 1, self%n_lines
       do j = 1, self%lines(i)%nf
          n = n + 1
          call self%lines(i)%real_field(j, values(n), local)
          if (local%raised) then
             call pass_error(local, err)
             return
          end if
       end do
    end do
  end subroutine block_all_reals

end module keyword_reader
