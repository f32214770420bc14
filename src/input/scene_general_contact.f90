!> Abaqus/Explicit general contact (*CONTACT with *CONTACT INCLUSIONS and *CONTACT PROPERTY
!> ASSIGNMENT) read as the contact pairs it means in bulkflow: every included pair of an
!> element-based surface and an analytic rigid surface becomes a *CONTACT PAIR with the
!> interaction assigned to it (to that pair, else the global ", , name" assignment).
!> What bulkflow does not simulate is refused here with the line: the default domain
!> (a blank inclusion: all element-based surfaces, self-contact included), pairs of two
!> element surfaces, exclusions and the other general-contact options.
module scene_general_contact
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t, upper_case, set_field, keep_fields
  use scene_util, only: field_name, field_blank, push_block
  implicit none
  private

  public :: convert_general_contact

contains

  pure logical function is_contact_option(name)
    character(len=*), intent(in) :: name

    is_contact_option = any(name == [character(len=34) :: 'CONTACT INCLUSIONS', 'CONTACT EXCLUSIONS', &
         'CONTACT PROPERTY ASSIGNMENT', 'CONTACT CONTROLS ASSIGNMENT', 'CONTACT FORMULATION', &
         'CONTACT INITIALIZATION ASSIGNMENT', 'SURFACE PROPERTY ASSIGNMENT', 'CONTACT STABILIZATION'])
  end function is_contact_option

  subroutine convert_general_contact(deck, err)
    type(keyword_deck_t), intent(inout) :: deck
    type(error_t), intent(inout) :: err
    type(keyword_block_t), allocatable :: out(:), pairs(:)
    integer :: i, j, n_out, steps, last

    if (.not. any([(deck%blocks(i)%name == 'CONTACT' .or. is_contact_option(deck%blocks(i)%name), &
         i = 1, deck%n_blocks)])) return
    allocate (out(deck%n_blocks + 16))
    n_out = 0
    steps = 0
    i = 0
    do while (i < deck%n_blocks)
       i = i + 1
       associate (blk => deck%blocks(i))
         if (blk%name == 'STEP') steps = steps + 1
         if (is_contact_option(blk%name)) then
            call blk%fail('*' // blk%name // ' does not follow a *CONTACT; expected *CONTACT before it', err)
            return
         end if
         if (blk%name /= 'CONTACT') then
            call push_block(out, n_out, blk)
            cycle
         end if
         last = 0
         if (steps > 1) then
            call blk%fail('*CONTACT in step ' // trim(itext(steps)) // '; bulkflow reads general contact in the ' // &
                 'model data or the first step (use *CONTACT PAIR, OP=ADD|DELETE to change contact later)', err)
            return
         end if
         call blk%check_params([character(len=2) :: 'OP'], err)
         if (err%raised) return
         last = i
         do while (last < deck%n_blocks)
            if (.not. is_contact_option(deck%blocks(last + 1)%name)) exit
            last = last + 1
         end do
         call pairs_of(deck, i, last, pairs, err)
         if (err%raised) return
         do j = 1, size(pairs)
            call push_block(out, n_out, pairs(j))
         end do
       end associate
       if (last > i) i = last
    end do
    deck%blocks = out(1:n_out)
    deck%n_blocks = n_out

  end subroutine convert_general_contact

  pure function itext(i) result(t)
    integer, intent(in) :: i
    character(len=12) :: t

    write (t, '(i0)') i
  end function itext

  !> The *CONTACT PAIR blocks of the *CONTACT at block c with its options c+1..last.
  subroutine pairs_of(deck, c, last, pairs, err)
    type(keyword_deck_t), intent(in) :: deck
    integer, intent(in) :: c, last
    type(keyword_block_t), allocatable, intent(out) :: pairs(:)
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: a, b, kind_a, kind_b, prop
    integer :: j, il, n

    allocate (pairs(0))
    n = 0
    do j = c + 1, last
       associate (blk => deck%blocks(j))
         select case (blk%name)
         case ('CONTACT INCLUSIONS', 'CONTACT PROPERTY ASSIGNMENT')
            call blk%check_params([character(len=12) :: 'ALL EXTERIOR'], err)
            if (err%raised) return
            if (blk%has_param('ALL EXTERIOR')) then
               call blk%fail('*CONTACT INCLUSIONS, ALL EXTERIOR (every exterior face, self-contact included) ' // &
                    'is not simulated; bulkflow offers contact of an element surface with an analytic rigid ' // &
                    'surface: list the pairs as "element surface, rigid surface"', err)
               return
            end if
         case default
            call blk%fail('*' // blk%name // ' is not supported; bulkflow offers *CONTACT INCLUSIONS of ' // &
                 'element/rigid surface pairs with *CONTACT PROPERTY ASSIGNMENT', err)
            return
         end select
       end associate
    end do
    do j = c + 1, last
       if (deck%blocks(j)%name /= 'CONTACT INCLUSIONS') cycle
       do il = 1, deck%blocks(j)%n_lines
          associate (dl => deck%blocks(j)%lines(il))
            if (field_blank(dl, 1) .or. field_blank(dl, 2)) then
               call raise_error(dl%file, dl%line, 'a blank surface in *CONTACT INCLUSIONS (the default domain ' // &
                    'of all element-based surfaces, or self-contact) is not simulated; expected "element ' // &
                    'surface, analytic rigid surface"', err)
               return
            end if
            a = field_name(dl, 1)
            b = field_name(dl, 2)
            kind_a = surface_kind(deck, a)
            kind_b = surface_kind(deck, b)
            if (kind_a == 'ELEMENT' .and. kind_b /= 'ELEMENT' .and. kind_b /= '') then
               continue
            else if (kind_b == 'ELEMENT' .and. kind_a /= 'ELEMENT' .and. kind_a /= '') then
               call swap(a, b)
            else if (kind_a == '' .or. kind_b == '') then
               if (kind_a /= '') call swap(a, b)
               call raise_error(dl%file, dl%line, 'surface ' // a // ' is not defined; expected a *SURFACE, NAME=' // &
                    a, err)
               return
            else
               call raise_error(dl%file, dl%line, 'contact between ' // a // ' and ' // b // ' (' // kind_a // &
                    ' and ' // kind_b // ' surfaces) is not simulated; bulkflow offers contact of an element ' // &
                    'surface with an analytic rigid surface', err)
               return
            end if
            call assigned_property(deck, c, last, a, b, dl, prop, err)
            if (err%raised) return
            pairs = [pairs, contact_pair(deck%blocks(c), dl, a, b, prop)]
            n = n + 1
          end associate
       end do
    end do
    if (n == 0) then
       call deck%blocks(c)%fail('*CONTACT without *CONTACT INCLUSIONS (the default domain of all element-based ' // &
            'surfaces) is not simulated; expected *CONTACT INCLUSIONS with "element surface, rigid surface" lines', err)
    end if
  end subroutine pairs_of

  subroutine swap(a, b)
    character(len=:), allocatable, intent(inout) :: a, b
    character(len=:), allocatable :: t

    t = a
    a = b
    b = t
  end subroutine swap

  !> TYPE of the *SURFACE named `name` ('' when there is none).
  function surface_kind(deck, name) result(kind)
    type(keyword_deck_t), intent(in) :: deck
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: kind
    integer :: i

    kind = ''
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'SURFACE') cycle
       if (param_value(deck%blocks(i), 'NAME') /= name) cycle
       kind = param_value(deck%blocks(i), 'TYPE')
       if (kind == '') kind = 'ELEMENT'
       return
    end do
  end function surface_kind

  !> Upper-case value of a parameter ('' when absent).
  function param_value(blk, name) result(v)
    type(keyword_block_t), intent(in) :: blk
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: v
    integer :: i

    v = ''
    if (.not. allocated(blk%params)) return
    do i = 1, size(blk%params)
       if (blk%params(i)%name == name) then
          v = upper_case(blk%params(i)%value)
          if (blk%params(i)%quoted) v = blk%params(i)%value
          return
       end if
    end do
  end function param_value

  !> The interaction assigned to the pair (a, b): a line naming the pair (either order),
  !> else the global line ", , name".
  subroutine assigned_property(deck, c, last, a, b, where, prop, err)
    type(keyword_deck_t), intent(in) :: deck
    integer, intent(in) :: c, last
    character(len=*), intent(in) :: a, b
    type(data_line_t), intent(in) :: where
    character(len=:), allocatable, intent(out) :: prop
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: global, s1, s2
    integer :: j, il

    prop = ''
    global = ''
    do j = c + 1, last
       if (deck%blocks(j)%name /= 'CONTACT PROPERTY ASSIGNMENT') cycle
       do il = 1, deck%blocks(j)%n_lines
          associate (dl => deck%blocks(j)%lines(il))
            if (dl%n_fields() < 3 .or. field_blank(dl, 3)) then
               call raise_error(dl%file, dl%line, '*CONTACT PROPERTY ASSIGNMENT line without an interaction; ' // &
                    'expected "surface, surface, interaction" or " , , interaction"', err)
               return
            end if
            s1 = ''
            s2 = ''
            if (.not. field_blank(dl, 1)) s1 = field_name(dl, 1)
            if (.not. field_blank(dl, 2)) s2 = field_name(dl, 2)
            if (s1 == '' .and. s2 == '') then
               global = field_name(dl, 3)
            else if ((s1 == a .and. s2 == b) .or. (s1 == b .and. s2 == a)) then
               prop = field_name(dl, 3)
            end if
          end associate
       end do
    end do
    if (prop == '') prop = global
    if (prop == '') call raise_error(where%file, where%line, 'no interaction for the contact of ' // a // &
         ' with ' // b // '; expected *CONTACT PROPERTY ASSIGNMENT with " , , interaction" or this pair', err)
  end subroutine assigned_property

  !> *CONTACT PAIR, INTERACTION=prop with the line "a, b", at the inclusion's file:line.
  function contact_pair(contact, dl, a, b, prop) result(pair)
    type(keyword_block_t), intent(in) :: contact
    type(data_line_t), intent(in) :: dl
    character(len=*), intent(in) :: a, b, prop
    type(keyword_block_t) :: pair

    pair%name = 'CONTACT PAIR'
    pair%file = contact%file
    pair%line = contact%line
    allocate (pair%params(1))
    pair%params(1)%name = 'INTERACTION'
    pair%params(1)%value = prop
    pair%params(1)%has_value = .true.
    pair%params(1)%quoted = .true.
    pair%n_lines = 1
    allocate (pair%lines(1))
    pair%lines(1) = dl
    call keep_fields(pair%lines(1), 0)
    call set_field(pair%lines(1), 1, '"' // a // '"')
    call set_field(pair%lines(1), 2, '"' // b // '"')
  end function contact_pair
end module scene_general_contact
