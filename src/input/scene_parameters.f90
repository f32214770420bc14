!> Abaqus parametric input on a deck: the `*PARAMETER` definitions evaluated in input order
!> (parameter_expression), then every `<name>` in data lines and keyword lines replaced by the
!> text of its value, and the `*PARAMETER` blocks removed, so every later pass reads the deck
!> the parameters mean (the same deck written out by hand reads, and runs, the same bit for bit).
!>
!> As in Abaqus, all definitions are read before any substitution: a `<name>` means the last
!> value given to `name` anywhere in the input, while an expression sees only the parameters
!> defined above it. The substitution is textual (Abaqus allows `-<x>` and `CONSTANTS=40 <opt>`);
!> `<` followed by anything but a name and `>` is left alone, and *HEADING text is not touched.
module scene_parameters
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t, set_line_text, &
       reparse_keyword_line
  use parameter_expression, only: named_value_t, evaluate_expression, value_text, is_parameter_name
  use parameter_arithmetic, only: param_value_t
  use scene_util, only: itoa
  implicit none
  private

  public :: apply_parameters

contains

  !> Evaluate, substitute, remove the *PARAMETER blocks. The first problem ends it with file:line.
  subroutine apply_parameters(deck, err)
    type(keyword_deck_t), intent(inout) :: deck
    type(error_t), intent(inout) :: err
    type(named_value_t), allocatable :: known(:)
    integer :: n, i, j, kept

    allocate (known(16))
    n = 0
    do i = 1, deck%n_blocks
       associate (blk => deck%blocks(i))
         select case (blk%name)
         case ('PARAMETER')
            if (size(blk%params) > 0) then
               call raise_error(blk%file, blk%line, '*PARAMETER with parameters on its keyword line ' // &
                    '(INPUT=, a parameter table) is not supported; expected *PARAMETER alone, followed by ' // &
                    '"name = expression" lines', err)
               return
            end if
            do j = 1, blk%n_lines
               call define_statements(blk%lines(j), known, n, err)
               if (err%raised) return
            end do
         case ('PARAMETER TABLE', 'PARAMETER TABLE TYPE', 'PARAMETER DEPENDENCE', 'PARAMETER SHAPE VARIATION', &
              'DESIGN PARAMETER', 'TABLE COLLECTION')
            call blk%fail('*' // blk%name // ' is not supported (bulkflow reads the *PARAMETER subset of ' // &
                 'parametric input: "name = expression" lines of numbers, strings, arithmetic and math ' // &
                 'functions); expected its values written as *PARAMETER definitions', err)
            return
         end select
       end associate
    end do
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name == 'PARAMETER' .or. deck%blocks(i)%name == 'HEADING') cycle
       call substitute_block(deck%blocks(i), known, n, err)
       if (err%raised) return
    end do
    kept = 0
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name == 'PARAMETER') cycle
       kept = kept + 1
       if (kept /= i) deck%blocks(kept) = deck%blocks(i)
    end do
    deck%n_blocks = kept
  end subroutine apply_parameters

  !> A *PARAMETER line: assignments separated by ';' (Python's statement separator; a trailing
  !> ';' is allowed), a '#' comment at the end.
  subroutine define_statements(dl, known, n, err)
    type(data_line_t), intent(in) :: dl
    type(named_value_t), allocatable, intent(inout) :: known(:)
    integer, intent(inout) :: n
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: text
    integer :: hash, semi

    text = dl%text
    hash = index(text, '#')
    if (hash > 0) text = text(1:hash - 1)
    do
       semi = index(text, ';')
       if (semi == 0) exit
       if (len_trim(text(1:semi - 1)) > 0) call define(text(1:semi - 1), dl, known, n, err)
       if (err%raised) return
       text = text(semi + 1:)
    end do
    if (len_trim(text) > 0 .or. index(dl%text, ';') == 0) call define(text, dl, known, n, err)
  end subroutine define_statements

  !> One `name = expression` statement of a *PARAMETER line.
  subroutine define(statement, dl, known, n, err)
    character(len=*), intent(in) :: statement
    type(data_line_t), intent(in) :: dl
    type(named_value_t), allocatable, intent(inout) :: known(:)
    integer, intent(inout) :: n
    type(error_t), intent(inout) :: err
    type(named_value_t), allocatable :: grown(:)
    type(param_value_t) :: value
    character(len=:), allocatable :: text, name, problem
    integer :: eq, column, k

    text = statement
    eq = index(text, '=')
    name = ''
    if (eq > 1) name = trim(adjustl(text(1:eq - 1)))
    if (eq == 0 .or. .not. is_parameter_name(name) .or. text(min(eq + 1, len(text)):min(eq + 1, len(text))) == '=') then
       call raise_error(dl%file, dl%line, '*PARAMETER line "' // trim(text) // '" is not "name = expression" ' // &
            '(Python statements other than one assignment of arithmetic are not supported); expected ' // &
            'e.g. "width = 2.5" or "area = width**2"', err)
       return
    end if
    call evaluate_expression(text(eq + 1:), known, n, value, problem, column)
    if (len(problem) > 0) then
       call raise_error(dl%file, dl%line, '*PARAMETER ' // name // ': ' // problem // ' (column ' // &
            itoa(eq + column) // ' of "' // trim(text) // '")', err)
       return
    end if
    do k = 1, n
       if (known(k)%name == name .and. len(known(k)%name) == len(name)) then
          known(k)%value = value
          return
       end if
    end do
    if (n == size(known)) then
       allocate (grown(2 * n))
       grown(1:n) = known(1:n)
       call move_alloc(grown, known)
    end if
    n = n + 1
    known(n)%name = name
    known(n)%value = value
  end subroutine define

  !> `<name>` in the keyword line and the data lines of one block.
  subroutine substitute_block(blk, known, n, err)
    type(keyword_block_t), intent(inout) :: blk
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: line, replaced
    logical :: changed
    integer :: j, k

    changed = .false.
    do k = 1, size(blk%params)
       if (index(blk%params(k)%value, '<') > 0 .or. index(blk%params(k)%name, '<') > 0) changed = .true.
    end do
    if (changed) then
       line = '*' // blk%name
       do k = 1, size(blk%params)
          line = line // ', ' // blk%params(k)%name
          if (.not. blk%params(k)%has_value) cycle
          if (blk%params(k)%quoted) then
             line = line // '="' // blk%params(k)%value // '"'
          else
             line = line // '=' // blk%params(k)%value
          end if
       end do
       call substitute(line, blk%file, blk%line, known, n, replaced, changed, err)
       if (err%raised) return
       call reparse_keyword_line(blk, replaced, err)
       if (err%raised) return
    end if
    do j = 1, blk%n_lines
       if (index(blk%lines(j)%text, '<') == 0) cycle
       call substitute(blk%lines(j)%text, blk%lines(j)%file, blk%lines(j)%line, known, n, replaced, changed, err)
       if (err%raised) return
       if (changed) call set_line_text(blk%lines(j), replaced)
    end do
  end subroutine substitute_block

  !> `text` with every `<name>` replaced by the text of name's value.
  subroutine substitute(text, file, line, known, n, replaced, changed, err)
    character(len=*), intent(in) :: text, file
    integer, intent(in) :: line
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    character(len=:), allocatable, intent(out) :: replaced
    logical, intent(out) :: changed
    type(error_t), intent(inout) :: err
    integer :: pos, lt, gt, k
    logical :: found

    replaced = ''
    changed = .false.
    pos = 1
    do
       lt = index(text(pos:), '<')
       if (lt == 0) exit
       lt = pos + lt - 1
       gt = index(text(lt + 1:), '>')
       if (gt == 0) exit
       gt = lt + gt
       if (.not. is_parameter_name(text(lt + 1:gt - 1))) then
          replaced = replaced // text(pos:lt)
          pos = lt + 1
          cycle
       end if
       found = .false.
       do k = n, 1, -1
          if (known(k)%name == text(lt + 1:gt - 1) .and. len(known(k)%name) == gt - lt - 1) then
             found = .true.
             exit
          end if
       end do
       if (.not. found) then
          call raise_error(file, line, 'parameter ' // text(lt:gt) // ' is not defined; expected a ' // &
               '*PARAMETER line "' // text(lt + 1:gt - 1) // ' = ..." (names are case-sensitive)' // &
               defined_list(known, n), err)
          return
       end if
       replaced = replaced // text(pos:lt - 1) // value_text(known(k)%value)
       changed = .true.
       pos = gt + 1
    end do
    replaced = replaced // text(pos:)
  end subroutine substitute

  !> "; defined: a, b, c" (at most 12 names), or that none is.
  pure function defined_list(known, n) result(t)
    type(named_value_t), intent(in) :: known(:)
    integer, intent(in) :: n
    character(len=:), allocatable :: t
    integer :: k

    if (n == 0) then
       t = '; the input defines no parameter'
       return
    end if
    t = '; defined: ' // known(1)%name
    do k = 2, min(n, 12)
       t = t // ', ' // known(k)%name
    end do
    if (n > 12) t = t // ', ...'
  end function defined_list

end module scene_parameters
