!> Node and element sets of a scene (*NSET, *ELSET, and the NSET=/ELSET= parameters of
!> *NODE or *ELEMENT), and the lookup every other keyword uses for a data field that names
!> either one node/element (a number) or a set (a name).
!>
!> As in Abaqus: a set named again gets the new members added; a set may list other sets
!> of its kind by name, which must be defined before (earlier in the file); GENERATE takes
!> first, last[, increment]. Unlike Abaqus, a member number that is not a node/element of
!> the mesh is an error rather than a warning (it is almost always a typo).
module scene_sets
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t, is_integer_syntax
  use model, only: model_t
  use model_sets, only: index_set_t, find_set, name_length
  use scene_layout, only: scene_layout_t
  use scene_util, only: itoa, get_int, field_name, field_blank, last_field, append_int, &
       sort_unique, expect_fields, expect_lines, check_name
  implicit none
  private

  public :: add_members, build_sets, node_targets, elem_targets

contains

  !> Union `members` (internal indices) into the set `name`, creating it if needed.
  subroutine add_members(sets, n, name, members)
    type(index_set_t), allocatable, intent(inout) :: sets(:)
    integer, intent(inout) :: n
    character(len=*), intent(in) :: name
    integer, intent(in) :: members(:)
    type(index_set_t), allocatable :: tmp(:)
    integer, allocatable :: merged(:)
    integer :: k, m

    if (.not. allocated(sets)) allocate (sets(0))
    k = find_set(sets, n, name)
    if (k == 0) then
       if (n >= size(sets)) then
          allocate (tmp(2 * n + 4))
          tmp(1:n) = sets(1:n)
          call move_alloc(tmp, sets)
       end if
       n = n + 1
       k = n
       sets(k)%name = name
       allocate (sets(k)%members(0))
    end if
    m = size(sets(k)%members)
    allocate (merged(m + size(members)))
    merged(1:m) = sets(k)%members
    merged(m + 1:) = members
    call sort_unique(merged, sets(k)%members)
  end subroutine add_members

  !> Every *NSET and *ELSET of the deck, in input order.
  subroutine build_sets(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    integer :: i

    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0) cycle
       select case (deck%blocks(i)%name)
       case ('NSET')
          call read_set(deck%blocks(i), model, .true., err)
       case ('ELSET')
          call read_set(deck%blocks(i), model, .false., err)
       end select
       if (err%raised) return
    end do
  end subroutine build_sets

  subroutine read_set(blk, model, nodal, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(inout) :: model
    logical, intent(in) :: nodal
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name, from
    integer, allocatable :: list(:), part(:)
    integer :: n, il, k, ie
    logical :: generate

    if (nodal) then
       call blk%check_params([character(len=8) :: 'NSET', 'GENERATE', 'ELSET', 'INTERNAL'], err)
       if (err%raised) return
       call blk%get_string('NSET', name, err)
    else
       call blk%check_params([character(len=8) :: 'ELSET', 'GENERATE', 'INTERNAL'], err)
       if (err%raised) return
       call blk%get_string('ELSET', name, err)
    end if
    if (.not. err%raised) call check_name(blk, 'set', name, name_length, err)
    if (err%raised) return
    generate = blk%has_param('GENERATE')
    n = 0
    allocate (list(16))
    if (nodal .and. blk%has_param('ELSET')) then
       ! *NSET, ELSET=...: the nodes of those elements (no data lines)
       call blk%get_string('ELSET', from, err)
       if (err%raised) return
       k = find_set(model%elsets, model%n_elsets, from)
       if (k == 0) then
          call blk%fail('element set ' // from // ' is not defined; expected the name of an ' // &
               '*ELSET defined earlier', err)
          return
       end if
       if (generate) then
          call blk%fail('*NSET: ELSET= and GENERATE cannot be combined; expected one of them', err)
          return
       end if
       call expect_lines(blk, 0, 0, 'no data lines with ELSET=', err)
       if (err%raised) return
       do ie = 1, size(model%elsets(k)%members)
          do il = 1, model%mesh%nen
             call append_int(list, n, model%mesh%conn(il, model%elsets(k)%members(ie)))
          end do
       end do
    else
       call expect_lines(blk, 1, huge(1), 'member numbers or set names', err)
       if (err%raised) return
       do il = 1, blk%n_lines
          if (generate) then
             call generate_members(blk, blk%lines(il), model, nodal, list, n, err)
          else
             do k = 1, last_field(blk%lines(il))
                if (field_blank(blk%lines(il), k)) cycle
                if (nodal) then
                   call node_targets(model, blk%lines(il), k, part, err)
                else
                   call elem_targets(model, blk%lines(il), k, part, err)
                end if
                if (err%raised) return
                do ie = 1, size(part)
                   call append_int(list, n, part(ie))
                end do
             end do
          end if
          if (err%raised) return
       end do
    end if
    if (nodal) then
       call add_members(model%nsets, model%n_nsets, name, list(1:n))
    else
       call add_members(model%elsets, model%n_elsets, name, list(1:n))
    end if
  end subroutine read_set

  !> One GENERATE line: first, last[, increment].
  subroutine generate_members(blk, dl, model, nodal, list, n, err)
    type(keyword_block_t), intent(in) :: blk
    type(data_line_t), intent(in) :: dl
    type(model_t), intent(in) :: model
    logical, intent(in) :: nodal
    integer, allocatable, intent(inout) :: list(:)
    integer, intent(inout) :: n
    type(error_t), intent(inout) :: err
    integer :: first, last, inc, id, idx

    call expect_fields(blk, dl, 2, 3, 'first, last[, increment] with GENERATE', err)
    if (err%raised) return
    call get_int(dl, 1, first, err)
    if (.not. err%raised) call get_int(dl, 2, last, err)
    if (.not. err%raised) call get_int(dl, 3, inc, err, default=1)
    if (err%raised) return
    if (inc <= 0 .or. last < first) then
       call raise_error(dl%file, dl%line, 'GENERATE range ' // itoa(first) // ', ' // itoa(last) // &
            ', ' // itoa(inc) // ' is empty or backwards; expected first <= last and increment > 0', err)
       return
    end if
    if (mod(last - first, inc) /= 0) then
       call raise_error(dl%file, dl%line, 'GENERATE: last - first = ' // itoa(last - first) // &
            ' is not a multiple of the increment ' // itoa(inc) // '; expected a whole number of steps', err)
       return
    end if
    do id = first, last, inc
       if (nodal) then
          idx = model%mesh%node_index(id)
       else
          idx = model%mesh%elem_index(id)
       end if
       if (idx == 0) then
          call raise_error(dl%file, dl%line, trim(merge('node   ', 'element', nodal)) // ' ' // &
               itoa(id) // ' (from GENERATE) is not defined; expected numbers of existing ' // &
               trim(merge('nodes   ', 'elements', nodal)), err)
          return
       end if
       call append_int(list, n, idx)
    end do
  end subroutine generate_members

  !> Field i: a node number or the name of a node set -> internal node indices.
  subroutine node_targets(model, dl, i, nodes, err)
    type(model_t), intent(in) :: model
    type(data_line_t), intent(in) :: dl
    integer, intent(in) :: i
    integer, allocatable, intent(out) :: nodes(:)
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name
    integer :: id, k

    allocate (nodes(0))
    name = field_name(dl, i)
    if (len(name) == 0) then
       call raise_error(dl%file, dl%line, 'empty field ' // itoa(i) // &
            '; expected a node number or a node set name', err)
    else if (is_integer_syntax(name)) then
       call get_int(dl, i, id, err)
       if (err%raised) return
       k = model%mesh%node_index(id)
       if (k == 0) then
          call raise_error(dl%file, dl%line, 'node ' // itoa(id) // ' is not defined; ' // &
               'expected the number of a node given in *NODE', err)
       else
          nodes = [k]
       end if
    else
       k = find_set(model%nsets, model%n_nsets, name)
       if (k == 0) then
          call raise_error(dl%file, dl%line, 'node set ' // name // ' is not defined; ' // &
               'expected a node number or the name of a *NSET defined earlier', err)
       else
          nodes = model%nsets(k)%members
       end if
    end if
  end subroutine node_targets

  !> Field i: an element number or the name of an element set -> internal element indices.
  subroutine elem_targets(model, dl, i, elems, err)
    type(model_t), intent(in) :: model
    type(data_line_t), intent(in) :: dl
    integer, intent(in) :: i
    integer, allocatable, intent(out) :: elems(:)
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name
    integer :: id, k

    allocate (elems(0))
    name = field_name(dl, i)
    if (len(name) == 0) then
       call raise_error(dl%file, dl%line, 'empty field ' // itoa(i) // &
            '; expected an element number or an element set name', err)
    else if (is_integer_syntax(name)) then
       call get_int(dl, i, id, err)
       if (err%raised) return
       k = model%mesh%elem_index(id)
       if (k == 0) then
          call raise_error(dl%file, dl%line, 'element ' // itoa(id) // ' is not defined; ' // &
               'expected the number of an element given in *ELEMENT', err)
       else
          elems = [k]
       end if
    else
       k = find_set(model%elsets, model%n_elsets, name)
       if (k == 0) then
          call raise_error(dl%file, dl%line, 'element set ' // name // ' is not defined; ' // &
               'expected an element number or the name of an *ELSET defined earlier', err)
       else
          elems = model%elsets(k)%members
       end if
    end if
  end subroutine elem_targets
end module scene_sets
