!> The keyword reader's parser (submodule of keyword_reader): a file read whole into one
!> buffer, split into lines, keyword lines into blocks and data lines into slices of the
!> buffer with their field bounds.
!>
!> Why this shape: the reader had a cost growing with the square of a line's length (a line
!> was assembled from 512-character reads by concatenation, and its fields and a keyword's
!> parameters were appended one by one to arrays that were copied every time) and kept every
!> line three times (the file's lines, the text and one string per field). A 1 M-node deck
!> took about 50 s and 2.4 GB. Now every step is linear: one read of the file, one pass over
!> its characters, field bounds appended to one array per file that grows geometrically, and
!> data lines that hold pointers into the buffer.
submodule (keyword_reader) keyword_parse
  use, intrinsic :: iso_fortran_env, only: int64
  implicit none

contains

  module subroutine read_keyword_file(path, deck, err)
    character(len=*), intent(in) :: path
    type(keyword_deck_t), intent(out) :: deck
    type(error_t), intent(inout), optional :: err
    type(source_t), pointer :: src
    character(len=:), allocatable :: problem
    type(error_t) :: local

    call load_source(path, src, problem)
    if (len(problem) > 0) then
       call raise_error(path, 0, problem, err)
       return
    end if
    call parse_source(src, deck, 0, local)
    if (local%raised) call pass_error(local, err)
  end subroutine read_keyword_file

  module subroutine read_keyword_string(text, deck, err, name)
    character(len=*), intent(in) :: text
    type(keyword_deck_t), intent(out) :: deck
    type(error_t), intent(inout), optional :: err
    character(len=*), intent(in), optional :: name
    type(source_t), pointer :: src
    type(error_t) :: local

    allocate (src)
    src%name = '<string>'
    if (present(name)) src%name = name
    src%text = text
    allocate (src%bounds(64))
    call parse_source(src, deck, 0, local)
    if (local%raised) call pass_error(local, err)
  end subroutine read_keyword_string

  !> The whole file `path` as a new source; `problem` is '' or why it cannot be read.
  subroutine load_source(path, src, problem)
    character(len=*), intent(in) :: path
    type(source_t), pointer, intent(out) :: src
    character(len=:), allocatable, intent(out) :: problem
    integer :: unit, ios
    integer(int64) :: size_bytes
    character(len=256) :: msg

    problem = ''
    src => null()
    open (newunit=unit, file=path, status='old', action='read', access='stream', &
         form='unformatted', iostat=ios, iomsg=msg)
    if (ios /= 0) then
       if (is_directory(path)) then
          problem = 'cannot read "' // path // '": it is a directory, not a file'
       else
          problem = 'cannot open input file'
       end if
       return
    end if
    inquire (unit=unit, size=size_bytes)
    allocate (src)
    src%name = path
    allocate (character(len=max(size_bytes, 0_int64)) :: src%text)
    ios = 0
    if (size_bytes > 0) read (unit, iostat=ios, iomsg=msg) src%text
    close (unit)
    if (size_bytes < 0 .or. ios /= 0) then
       if (is_directory(path)) then
          problem = 'cannot read "' // path // '": it is a directory, not a file'
       else
          problem = 'cannot read "' // path // '" (' // trim(msg) // ')'
       end if
       deallocate (src)
       return
    end if
    allocate (src%bounds(64))
  end subroutine load_source

  !> True when `path` names a directory ("path/." exists only then).
  logical function is_directory(path)
    character(len=*), intent(in) :: path
    logical :: there

    inquire (file=path // '/.', exist=there)
    is_directory = there
  end function is_directory

  module subroutine set_line_text(dl, text)
    type(data_line_t), intent(inout) :: dl
    character(len=*), intent(in) :: text
    type(source_t), pointer :: own

    allocate (own)
    if (associated(dl%file)) own%name = dl%file
    own%text = text
    allocate (own%bounds(64))
    call field_bounds(own%text, own%bounds, own%n_bounds)
    dl%src => own
    dl%text => own%text
    dl%first = 0
    dl%nf = own%n_bounds / 2
  end subroutine set_line_text

  module subroutine reparse_keyword_line(blk, text, err)
    type(keyword_block_t), intent(inout) :: blk
    character(len=*), intent(in) :: text
    type(error_t), intent(inout) :: err
    type(keyword_block_t) :: again

    call parse_keyword_line(text, blk%file, blk%line, again, err)
    if (err%raised) return
    call move_alloc(again%name, blk%name)
    call move_alloc(again%params, blk%params)
  end subroutine reparse_keyword_line

  !> Parse one source into `deck` (appending); recursive for *INCLUDE.
  recursive subroutine parse_source(src, deck, depth, err)
    type(source_t), pointer, intent(in) :: src
    type(keyword_deck_t), intent(inout) :: deck
    integer, intent(in) :: depth
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: key
    integer(int64) :: pos, a, b
    integer :: line, first, nkey

    pos = 1
    line = 0
    do while (next_line(src, pos, line, a, b))
       if (b < a) cycle
       if (b > a) then
          if (src%text(a:a + 1) == '**') cycle
       end if
       if (src%text(a:a) == '*') then
          ! keyword line, possibly continued by a trailing comma
          first = line
          nkey = 0
          call append_text(key, nkey, src%text(a:b))
          do while (key(nkey:nkey) == ',')
             if (.not. next_line(src, pos, line, a, b)) exit
             call append_text(key, nkey, ' ')
             if (b >= a) call append_text(key, nkey, src%text(a:b))
             nkey = len_trim(key(1:nkey))
          end do
          call keyword_line(src, key(1:nkey), first, deck, depth, err)
          if (err%raised) return
       else
          if (deck%n_blocks == 0) then
             call raise_error(src%name, line, 'data line before the first keyword: "' // &
                  src%text(a:b) // '"', err)
             return
          end if
          call append_data_line(deck%blocks(deck%n_blocks), src, a, b, line)
       end if
    end do
  end subroutine parse_source

  !> The next line of the source from `pos`: its number, and its text src%text(a:b) without
  !> leading and trailing blanks (b < a: blank). Tabs and carriage returns become blanks in
  !> the buffer. .false. at the end of the text.
  logical function next_line(src, pos, line, a, b)
    type(source_t), intent(inout) :: src
    integer(int64), intent(inout) :: pos
    integer, intent(inout) :: line
    integer(int64), intent(out) :: a, b
    integer(int64) :: n, q, k

    n = len(src%text, kind=int64)
    next_line = pos <= n
    a = pos
    b = pos - 1
    if (.not. next_line) return
    line = line + 1
    q = index(src%text(pos:n), new_line('a'), kind=int64)
    if (q == 0) then
       q = n + 1
    else
       q = pos + q - 1
    end if
    do k = pos, q - 1
       if (src%text(k:k) == achar(9) .or. src%text(k:k) == achar(13)) src%text(k:k) = ' '
    end do
    a = pos
    b = q - 1
    pos = q + 1
    do while (a <= b)
       if (src%text(a:a) /= ' ') exit
       a = a + 1
    end do
    do while (b >= a)
       if (src%text(b:b) /= ' ') exit
       b = b - 1
    end do
  end function next_line

  !> buf(1:n) // piece, the buffer growing geometrically.
  pure subroutine append_text(buf, n, piece)
    character(len=:), allocatable, intent(inout) :: buf
    integer, intent(inout) :: n
    character(len=*), intent(in) :: piece
    character(len=:), allocatable :: grown

    if (.not. allocated(buf)) allocate (character(len=max(256, 2 * len(piece))) :: buf)
    if (n + len(piece) > len(buf)) then
       allocate (character(len=2 * (n + len(piece))) :: grown)
       grown(1:n) = buf(1:n)
       call move_alloc(grown, buf)
    end if
    buf(n + 1:n + len(piece)) = piece
    n = n + len(piece)
  end subroutine append_text

  !> A keyword line: a new block, or the file an *INCLUDE names read in its place.
  recursive subroutine keyword_line(src, text, line, deck, depth, err)
    type(source_t), pointer, intent(in) :: src
    character(len=*), intent(in) :: text
    integer, intent(in) :: line
    type(keyword_deck_t), intent(inout) :: deck
    integer, intent(in) :: depth
    type(error_t), intent(inout) :: err
    type(keyword_block_t) :: blk
    type(source_t), pointer :: inc
    character(len=:), allocatable :: incfile, resolved, problem

    call parse_keyword_line(text, src%name, line, blk, err)
    if (err%raised) return
    if (blk%name /= 'INCLUDE') then
       call append_block(deck, blk)
       return
    end if
    call block_get_string(blk, 'INPUT', incfile, err, keep_case=.true.)
    if (err%raised) return
    call block_check_params(blk, [character(len=8) :: 'INPUT'], err)
    if (err%raised) return
    if (depth >= max_include_depth) then
       call raise_error(src%name, line, '*INCLUDE nested more than ' // &
            int_text(max_include_depth) // ' deep (circular include?)', err)
       return
    end if
    call resolve_path(src%name, incfile, resolved)
    call load_source(resolved, inc, problem)
    if (problem == 'cannot open input file') then
       call raise_error(src%name, line, 'cannot open include file "' // incfile // &
            '" (looked for ' // resolved // ')', err)
       return
    else if (len(problem) > 0) then
       call raise_error(src%name, line, '*INCLUDE, INPUT=' // incfile // ': ' // problem // &
            '; expected INPUT= to name a file', err)
       return
    end if
    call parse_source(inc, deck, depth + 1, err)
  end subroutine keyword_line

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

  !> First and last column of each comma-separated field of `text` (commas inside double
  !> quotes do not separate), blanks around a field excluded (last < first: an empty field);
  !> a trailing empty field (trailing comma) is dropped. Appended to bounds(n + 1:).
  pure subroutine field_bounds(text, bounds, n)
    character(len=*), intent(in) :: text
    integer, allocatable, intent(inout) :: bounds(:)
    integer, intent(inout) :: n
    integer :: k, start, last
    logical :: inside

    last = len_trim(text)
    if (last == 0) return
    start = 1
    inside = .false.
    do k = 1, last
       if (text(k:k) == '"') inside = .not. inside
       if (text(k:k) == ',' .and. .not. inside) then
          call add_field(text, start, k - 1, bounds, n)
          start = k + 1
       end if
    end do
    if (start <= last) call add_field(text, start, last, bounds, n)
  end subroutine field_bounds

  !> Bounds of text(i1:i2) without its surrounding blanks appended to bounds(n + 1:n + 2).
  pure subroutine add_field(text, i1, i2, bounds, n)
    character(len=*), intent(in) :: text
    integer, intent(in) :: i1, i2
    integer, allocatable, intent(inout) :: bounds(:)
    integer, intent(inout) :: n
    integer, allocatable :: grown(:)
    integer :: a, b

    a = i1
    b = i2
    do while (a <= b)
       if (text(a:a) /= ' ') exit
       a = a + 1
    end do
    do while (b >= a)
       if (text(b:b) /= ' ') exit
       b = b - 1
    end do
    if (n + 2 > size(bounds)) then
       allocate (grown(2 * size(bounds) + 64))
       grown(1:n) = bounds(1:n)
       call move_alloc(grown, bounds)
    end if
    bounds(n + 1) = a
    bounds(n + 2) = b
    n = n + 2
  end subroutine add_field

  !> `*NAME, P1=v1, FLAG` into a block (no data lines yet).
  subroutine parse_keyword_line(text, file, line, blk, err)
    character(len=*), intent(in) :: text
    character(len=*), intent(in) :: file
    integer, intent(in) :: line
    type(keyword_block_t), intent(out) :: blk
    type(error_t), intent(inout) :: err
    type(keyword_param_t), allocatable :: params(:), grown(:)
    integer, allocatable :: bounds(:)
    integer :: k, nb, np, dup

    blk%file = file
    blk%line = line
    blk%n_lines = 0
    allocate (blk%lines(0), bounds(64), params(8))
    nb = 0
    call field_bounds(text(2:), bounds, nb)
    if (nb > 0) blk%name = normalize_name(text(1 + bounds(1):1 + bounds(2)))
    if (nb == 0 .or. len(blk%name) == 0) then
       call raise_error(file, line, 'empty keyword "*"', err)
       return
    end if
    np = 0
    do k = 2, nb / 2
       associate (piece => text(1 + bounds(2 * k - 1):1 + bounds(2 * k)))
         if (len(piece) == 0) cycle
         if (np == size(params)) then
            allocate (grown(2 * np))
            grown(1:np) = params(1:np)
            call move_alloc(grown, params)
         end if
         np = np + 1
         call parse_parameter(piece, params(np))
         if (len(params(np)%name) == 0) then
            call raise_error(file, line, 'parameter without a name on *' // blk%name, err)
            return
         end if
       end associate
    end do
    dup = first_repeated(params(1:np))
    if (dup > 0) then
       call raise_error(file, line, 'parameter ' // params(dup)%name // ' given twice on *' // &
            blk%name, err)
       return
    end if
    blk%params = params(1:np)
    ! *HISTORY OUTPUT is what Abaqus/CAE calls a history output request; the input file
    ! keyword is *OUTPUT, HISTORY. Both are read as the latter (docs/keywords.md).
    if (blk%name == 'HISTORY OUTPUT') then
       do k = 1, size(blk%params)
          if (blk%params(k)%name == 'FIELD' .or. blk%params(k)%name == 'HISTORY') then
             call raise_error(file, line, '*HISTORY OUTPUT takes no ' // blk%params(k)%name // &
                  ' parameter; expected *HISTORY OUTPUT[, TIME INTERVAL=t | NUMBER INTERVAL=n] ' // &
                  '(the same as *OUTPUT, HISTORY)', err)
             return
          end if
       end do
       blk%name = 'OUTPUT'
       blk%params = [blk%params, keyword_param_t('HISTORY', '', .false., .false.)]
    end if
  end subroutine parse_keyword_line

  !> One `NAME=value` or `FLAG` (blanks around it already removed).
  pure subroutine parse_parameter(piece, p)
    character(len=*), intent(in) :: piece
    type(keyword_param_t), intent(out) :: p
    integer :: eq, i1, i2

    eq = index(piece, '=')
    if (eq > 0 .and. index(piece, '"') > 0) then
       if (index(piece, '"') < eq) eq = 0
    end if
    p%quoted = .false.
    if (eq == 0) then
       p%name = normalize_name(piece)
       p%value = ''
       p%has_value = .false.
       return
    end if
    p%name = normalize_name(piece(1:eq - 1))
    ! value: piece(i1:i2) without surrounding blanks, then without quotes
    i2 = len_trim(piece)
    i1 = eq + 1
    do while (i1 <= i2)
       if (piece(i1:i1) /= ' ') exit
       i1 = i1 + 1
    end do
    p%has_value = .true.
    if (i2 - i1 >= 1) then
       if (piece(i1:i1) == '"' .and. piece(i2:i2) == '"') then
          i1 = i1 + 1
          i2 = i2 - 1
          p%quoted = .true.
       end if
    end if
    p%value = piece(i1:i2)
  end subroutine parse_parameter

  !> The first parameter (in order) whose name an earlier one has, 0 if none. The names go
  !> into an open-addressing hash table as they come, so a keyword line of many parameters
  !> costs n, not n² comparisons.
  pure integer function first_repeated(params) result(dup)
    type(keyword_param_t), intent(in) :: params(:)
    integer, allocatable :: table(:)
    integer :: size_table, k, slot, c
    integer(int64) :: h

    dup = 0
    size_table = 16
    do while (size_table < 2 * size(params))
       size_table = 2 * size_table
    end do
    allocate (table(0:size_table - 1))
    table = 0
    do k = 1, size(params)
       h = 5381
       do c = 1, len(params(k)%name)
          h = mod(33 * h + iachar(params(k)%name(c:c)), 2147483647_int64)
       end do
       slot = int(mod(h, int(size_table, int64)))
       do while (table(slot) /= 0)
          if (params(table(slot))%name == params(k)%name) then
             dup = k
             return
          end if
          slot = mod(slot + 1, size_table)
       end do
       table(slot) = k
    end do
  end function first_repeated

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

  !> Data line src%text(a:b) (line `line` of its file) to the block.
  subroutine append_data_line(blk, src, a, b, line)
    type(keyword_block_t), intent(inout) :: blk
    type(source_t), pointer, intent(in) :: src
    integer(int64), intent(in) :: a, b
    integer, intent(in) :: line
    type(data_line_t), allocatable :: tmp(:)
    integer :: first

    if (.not. allocated(blk%lines)) allocate (blk%lines(0))
    if (blk%n_lines == size(blk%lines)) then
       allocate (tmp(2 * blk%n_lines + 4))
       tmp(1:blk%n_lines) = blk%lines(1:blk%n_lines)
       call move_alloc(tmp, blk%lines)
    end if
    blk%n_lines = blk%n_lines + 1
    first = src%n_bounds
    call field_bounds(src%text(a:b), src%bounds, src%n_bounds)
    associate (dl => blk%lines(blk%n_lines))
      dl%file => src%name
      dl%line = line
      dl%text => src%text(a:b)
      dl%src => src
      dl%first = first
      dl%nf = (src%n_bounds - first) / 2
    end associate
  end subroutine append_data_line
end submodule keyword_parse
