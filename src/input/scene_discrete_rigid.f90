!> Discrete rigid walls. 2D: R2D2 elements of a `*RIGID BODY, ELSET=..., REF NODE=...`, with a
!> `*SURFACE` on their SPOS or SNEG side, become the analytic `*SURFACE, TYPE=SEGMENTS` chain they
!> describe (one straight segment per element) and a `*RIGID BODY, REF NODE=..., ANALYTICAL
!> SURFACE=...`, so the contact of such a wall is our kinematic contact with analytic walls
!> (src/contact). The R2D2 elements and their element sets leave the deck; their nodes stay
!> (nodes of no element: they carry no mass and do not move, the wall follows its reference node).
!>
!> Side (Abaqus Analysis User's Guide, "Rigid elements", element normal definition): the positive
!> normal of a 2D rigid element is the direction node 1 -> node 2 turned 90 degrees
!> counter-clockwise, i.e. the left of travel, which is the material side of a SEGMENTS chain: SPOS
!> keeps each element's direction, SNEG reverses it. The elements of one surface must form one
!> chain (open, or closed: then it starts and ends at the same node).
!>
!> Discrete rigid walls in 3D: R3D3 and R3D4 elements become bulkflow's *SURFACE, TYPE=FACETS, one
!> facet line (the element's node coordinates, 3 or 4 points) per element, SNEG faces with their
!> node order reversed; each facet line keeps the file:line of its element, so the facet checks of
!> scene_facet_surface (zero area, warping) name the element's line. Side: the positive normal of a
!> 3D rigid element is the right-hand normal of its node order (Abaqus Analysis User's Guide,
!> "Defining contact surfaces on structural and rigid elements": SPOS is the side the positive
!> element normal points to; the connectivity defines it as for shells).
module scene_discrete_rigid
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t, set_line_text, &
       reparse_keyword_line, is_integer_text
  use parameter_arithmetic, only: param_value_t, value_text, kind_real
  use scene_util, only: itoa
  implicit none
  private

  public :: rewrite_discrete_rigid

  !> The deck's R2D2, R3D3 and R3D4 elements and the element sets made of them.
  type :: rigid_elements_t
     integer :: n = 0
     integer, allocatable :: id(:), nodes(:, :)
     integer, allocatable :: nnode(:)                 !< 2 (R2D2), 3 (R3D3) or 4 (R3D4)
     integer, allocatable :: src_block(:), src_line(:)  !< where each element is written
     character(len=64), allocatable :: set_name(:)   !< one row per (set, element)
     integer, allocatable :: set_element(:)
     character(len=64), allocatable :: surface_name(:), surface_label(:)  !< surfaces made, by face label
  end type rigid_elements_t

contains

  subroutine rewrite_discrete_rigid(deck, err)
    type(keyword_deck_t), intent(inout) :: deck
    type(error_t), intent(inout) :: err
    type(rigid_elements_t) :: r
    character(len=:), allocatable :: etype
    logical, allocatable :: keep(:)
    integer :: i, kept

    allocate (keep(deck%n_blocks))
    keep = .true.
    allocate (r%id(0), r%nodes(4, 0), r%nnode(0), r%src_block(0), r%src_line(0), r%set_name(0), &
         r%set_element(0), r%surface_name(0), r%surface_label(0))
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'ELEMENT') cycle
       call deck%blocks(i)%get_string('TYPE', etype, err, default='')
       if (err%raised) return
       select case (etype)
       case ('R2D2')
          call read_rigid_elements(deck%blocks(i), i, 2, r, err)
          keep(i) = .false.
       case ('R3D3', 'R3D4')
          if (has_2d_elements(deck)) then
             call deck%blocks(i)%fail('rigid element type ' // etype // ' in a 2D model (the mesh has ' // &
                  'CPE4R/CAX4R or R2D2 elements); expected R2D2 elements for a 2D wall, R3D3/R3D4 with C3D8R', err)
             return
          end if
          call read_rigid_elements(deck%blocks(i), i, merge(3, 4, etype == 'R3D3'), r, err)
          keep(i) = .false.
       case ('RAX2', 'RB2D2', 'RB3D2')
          call deck%blocks(i)%fail('rigid element type ' // etype // ' is not supported; expected R2D2 ' // &
               '(2D discrete rigid walls), R3D3/R3D4 (3D) or an analytic surface (*SURFACE, TYPE=SEGMENTS ' // &
               'in 2D, TYPE=PLANE, CYLINDER or REVOLUTION in 3D)', err)
       end select
       if (err%raised) return
    end do
    if (r%n == 0) return
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name == 'ELSET') call read_rigid_elset(deck%blocks(i), r, keep(i), err)
       if (err%raised) return
    end do
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name == 'SURFACE') call surface_to_segments(deck, deck%blocks(i), r, err)
       if (err%raised) return
    end do
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name == 'RIGID BODY') call rigid_body_surface(deck%blocks(i), r, err)
       if (err%raised) return
    end do
    kept = 0
    do i = 1, deck%n_blocks
       if (.not. keep(i)) cycle
       kept = kept + 1
       if (kept /= i) deck%blocks(kept) = deck%blocks(i)
    end do
    deck%n_blocks = kept
  end subroutine rewrite_discrete_rigid

  !> The element lines of one *ELEMENT block of R2D2 (nnode = 2), R3D3 (3) or R3D4 (4) elements.
  subroutine read_rigid_elements(blk, iblock, nnode, r, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: iblock, nnode
    type(rigid_elements_t), intent(inout) :: r
    type(error_t), intent(inout) :: err
    character(len=*), parameter :: names(2:4) = ['R2D2', 'R3D3', 'R3D4']
    character(len=*), parameter :: fields(2:4) = ['node 1, node 2                ', &
         'node 1, node 2, node 3        ', 'node 1, node 2, node 3, node 4']
    character(len=:), allocatable :: elset
    integer, allocatable :: v(:)
    integer :: j, column(4)

    call blk%check_params([character(len=8) :: 'TYPE', 'ELSET'], err)
    if (.not. err%raised) call blk%get_string('ELSET', elset, err, default='')
    if (err%raised) return
    do j = 1, blk%n_lines
       call blk%lines(j)%integers(v, err)
       if (err%raised) return
       if (size(v) /= nnode + 1) then
          call raise_error(blk%lines(j)%file, blk%lines(j)%line, names(nnode) // ' element line with ' // &
               itoa(size(v)) // ' fields; expected "element number, ' // trim(fields(nnode)) // '"', err)
          return
       end if
       r%n = r%n + 1
       r%id = [r%id, v(1)]
       column = 0
       column(1:nnode) = v(2:nnode + 1)
       r%nodes = reshape([r%nodes, column], [4, r%n])
       r%nnode = [r%nnode, nnode]
       r%src_block = [r%src_block, iblock]
       r%src_line = [r%src_line, j]
       if (len(elset) > 0) call add_member(r, elset, v(1))
    end do
  end subroutine read_rigid_elements

  !> The mesh is 2D: it has CPE4R, CAX4R (or other plane and axisymmetric) or R2D2 elements.
  logical function has_2d_elements(deck)
    type(keyword_deck_t), intent(in) :: deck
    type(error_t) :: ignored
    character(len=:), allocatable :: etype
    integer :: i

    has_2d_elements = .false.
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'ELEMENT') cycle
       call deck%blocks(i)%get_string('TYPE', etype, ignored, default='')
       if (ignored%raised) cycle
       if (len(etype) < 3) cycle
       if (etype == 'R2D2' .or. etype(1:3) == 'CPE' .or. etype(1:3) == 'CPS' .or. etype(1:3) == 'CAX') then
          has_2d_elements = .true.
          return
       end if
    end do
  end function has_2d_elements

  subroutine add_member(r, set, element)
    type(rigid_elements_t), intent(inout) :: r
    character(len=*), intent(in) :: set
    integer, intent(in) :: element

    call push(r%set_name, set)
    r%set_element = [r%set_element, element]
  end subroutine add_member

  !> An *ELSET of rigid elements is recorded and leaves the deck; one mixing rigid and other
  !> elements is refused.
  subroutine read_rigid_elset(blk, r, keep, err)
    type(keyword_block_t), intent(in) :: blk
    type(rigid_elements_t), intent(inout) :: r
    logical, intent(inout) :: keep
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name
    integer, allocatable :: v(:), members(:)
    integer :: j, k, n_rigid

    call blk%get_string('ELSET', name, err)
    if (err%raised) return
    allocate (members(0))
    do j = 1, blk%n_lines
       do k = 1, blk%lines(j)%n_fields()
          if (.not. is_integer_text(blk%lines(j)%field(k)) .and. len(blk%lines(j)%field(k)) > 0) return
       end do
       call blk%lines(j)%integers(v, err)
       if (err%raised) return
       if (blk%has_param('GENERATE') .and. size(v) >= 2) then
          members = [members, (k, k = v(1), v(2), merge(v(3), 1, size(v) >= 3))]
       else
          members = [members, v]
       end if
    end do
    n_rigid = count([(any(r%id == members(k)), k = 1, size(members))])
    if (n_rigid == 0) return
    if (n_rigid /= size(members)) then
       call blk%fail('*ELSET, ELSET=' // name // ' mixes rigid elements (R2D2, R3D3, R3D4) with other elements; expected ' // &
            'the rigid elements in sets of their own', err)
       return
    end if
    do k = 1, size(members)
       call add_member(r, name, members(k))
    end do
    keep = .false.
  end subroutine read_rigid_elset

  !> *SURFACE on rigid elements (faces SPOS/SNEG) -> *SURFACE, TYPE=SEGMENTS, NAME=same (R2D2)
  !> or *SURFACE, TYPE=FACETS, NAME=same (R3D3/R3D4).
  subroutine surface_to_segments(deck, blk, r, err)
    type(keyword_deck_t), intent(in) :: deck
    type(keyword_block_t), intent(inout) :: blk
    type(rigid_elements_t), intent(inout) :: r
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name, kind, face, label
    integer, allocatable :: a(:), b(:), order(:), ks(:)
    logical, allocatable :: negative(:)
    type(data_line_t), allocatable :: lines(:)
    integer :: j, k, e, id
    logical :: rigid

    call blk%get_string('TYPE', kind, err, default='ELEMENT')
    if (err%raised .or. kind /= 'ELEMENT' .or. blk%n_lines == 0) return
    rigid = .false.
    allocate (a(0), b(0), ks(0), negative(0))
    do j = 1, blk%n_lines
       face = upper(blk%lines(j)%field(2))
       if (face /= 'SPOS' .and. face /= 'SNEG') then
          if (rigid) call raise_error(blk%lines(j)%file, blk%lines(j)%line, 'face ' // face // ' on a surface ' // &
               'of rigid elements; expected SPOS or SNEG', err)
          return
       end if
       rigid = .true.
       label = blk%lines(j)%field(1)
       do k = 1, r%n
          id = r%id(k)
          if (is_integer_text(label)) then
             if (label /= itoa(id)) cycle
          else if (.not. any(r%set_name == upper(label) .and. r%set_element == id)) then
             cycle
          end if
          ks = [ks, k]
          negative = [negative, face == 'SNEG']
          if (face == 'SPOS') then
             a = [a, r%nodes(1, k)]
             b = [b, r%nodes(2, k)]
          else
             a = [a, r%nodes(2, k)]
             b = [b, r%nodes(1, k)]
          end if
       end do
    end do
    if (size(a) == 0) then
       call blk%fail('*SURFACE with SPOS/SNEG faces names no R2D2, R3D3 or R3D4 element; expected an ' // &
            'element set or number of rigid elements', err)
       return
    end if
    if (any(r%nnode(ks) > 2)) then
       if (any(r%nnode(ks) == 2)) then
          call blk%fail('*SURFACE mixes R2D2 with R3D3/R3D4 elements; expected the rigid elements of one ' // &
               'dimension', err)
       else
          call surface_to_facets(deck, blk, r, ks, negative, err)
       end if
       return
    end if
    call chain_order(a, b, order)
    if (size(order) /= size(a)) then
       call blk%fail('the R2D2 elements of this surface do not form one chain (each element''s node 2 the ' // &
            'node 1 of the next, with SPOS/SNEG applied); expected one connected line of elements', err)
       return
    end if
    call blk%get_string('NAME', name, err)
    if (err%raised) return
    allocate (lines(size(order) + 1))
    do e = 0, size(order)
       lines(e + 1)%file => blk%lines(1)%file
       lines(e + 1)%line = blk%lines(1)%line
       if (e == 0) then
          call set_line_text(lines(1), 'START, ' // node_coordinates(deck, a(order(1)), 2, err))
       else
          call set_line_text(lines(e + 1), 'LINE, ' // node_coordinates(deck, b(order(e)), 2, err))
       end if
       if (err%raised) then
          call blk%fail('node of an R2D2 element is not defined in *NODE', err)
          return
       end if
    end do
    call replace_surface(blk, r, name, 'SEGMENTS', lines, err)
  end subroutine surface_to_segments

  !> Segment indices in chain order (a(next) = b(current)); shorter than a if not one chain.
  pure subroutine chain_order(a, b, order)
    integer, intent(in) :: a(:), b(:)
    integer, allocatable, intent(out) :: order(:)
    integer :: start, k, cur

    start = 1
    do k = 1, size(a)
       if (.not. any(b == a(k))) then
          start = k
          exit
       end if
    end do
    order = [start]
    cur = start
    do while (size(order) < size(a))
       do k = 1, size(a)
          if (a(k) == b(cur) .and. .not. any(order == k)) exit
       end do
       if (k > size(a)) return
       order = [order, k]
       cur = k
    end do
  end subroutine chain_order

  !> Facet lines of R3D3/R3D4 elements ks (SNEG: node order reversed), each at its element's line.
  subroutine surface_to_facets(deck, blk, r, ks, negative, err)
    type(keyword_deck_t), intent(in) :: deck
    type(keyword_block_t), intent(inout) :: blk
    type(rigid_elements_t), intent(inout) :: r
    integer, intent(in) :: ks(:)
    logical, intent(in) :: negative(:)
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name, text
    type(data_line_t), allocatable :: lines(:)
    integer :: e, j, k, nn, node

    call blk%get_string('NAME', name, err)
    if (err%raised) return
    allocate (lines(size(ks)))
    do e = 1, size(ks)
       k = ks(e)
       nn = r%nnode(k)
       associate (src => deck%blocks(r%src_block(k))%lines(r%src_line(k)))
         lines(e)%file => src%file
         lines(e)%line = src%line
       end associate
       text = ''
       do j = 1, nn
          node = r%nodes(merge(nn + 1 - j, j, negative(e)), k)
          if (j > 1) text = text // ', '
          text = text // node_coordinates(deck, node, 3, err)
          if (err%raised) then
             call raise_error(lines(e)%file, lines(e)%line, 'node ' // itoa(node) // ' of this rigid element ' // &
                  'is not defined in *NODE; expected its coordinates x, y, z', err)
             return
          end if
       end do
       call set_line_text(lines(e), text)
    end do
    call replace_surface(blk, r, name, 'FACETS', lines, err)
  end subroutine surface_to_facets

  !> The rigid *SURFACE `blk` becomes *SURFACE, TYPE=kind, NAME=name with data `lines`; its labels
  !> are recorded for *RIGID BODY, ELSET=.
  subroutine replace_surface(blk, r, name, kind, lines, err)
    type(keyword_block_t), intent(inout) :: blk
    type(rigid_elements_t), intent(inout) :: r
    character(len=*), intent(in) :: name, kind
    type(data_line_t), allocatable, intent(inout) :: lines(:)
    type(error_t), intent(inout) :: err
    integer :: j

    do j = 1, blk%n_lines
       call push(r%surface_label, upper(blk%lines(j)%field(1)))
       call push(r%surface_name, name)
    end do
    call reparse_keyword_line(blk, '*SURFACE, TYPE=' // kind // ', NAME=' // name, err)
    call move_alloc(lines, blk%lines)
    blk%n_lines = size(blk%lines)
  end subroutine replace_surface

  !> "x, y" (ncoord = 2) or "x, y, z" of node `id` from the *NODE blocks (coordinates written back
  !> exactly).
  function node_coordinates(deck, id, ncoord, err) result(t)
    type(keyword_deck_t), intent(in) :: deck
    integer, intent(in) :: id, ncoord
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: t
    type(param_value_t) :: c
    integer :: i, j, k, nid

    t = ''
    c%kind = kind_real
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'NODE') cycle
       do j = 1, deck%blocks(i)%n_lines
          associate (dl => deck%blocks(i)%lines(j))
            call dl%integer_field(1, nid, err)
            if (err%raised) return
            if (nid /= id) cycle
            do k = 1, ncoord
               call dl%real_field(k + 1, c%r, err)
               if (err%raised) return
               if (k > 1) t = t // ', '
               t = t // value_text(c)
            end do
            return
          end associate
       end do
    end do
    call raise_error('', 0, 'node ' // itoa(id) // ' not found', err)
  end function node_coordinates

  !> *RIGID BODY, ELSET=set of R2D2 elements -> ANALYTICAL SURFACE= the surface built on them.
  subroutine rigid_body_surface(blk, r, err)
    type(keyword_block_t), intent(inout) :: blk
    type(rigid_elements_t), intent(in) :: r
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: elset, ref, label, surface
    integer :: i

    if (.not. blk%has_param('ELSET')) return
    call blk%check_params([character(len=10) :: 'ELSET', 'REF NODE', 'ISOTHERMAL', 'POSITION'], err)
    if (.not. err%raised) call blk%get_string('ELSET', elset, err)
    if (.not. err%raised) call blk%get_string('REF NODE', ref, err)
    if (err%raised) return
    if (.not. any(r%set_name == elset)) then
       call blk%fail('*RIGID BODY, ELSET=' // elset // ' is not a set of R2D2, R3D3 or R3D4 elements; ' // &
            'expected the element set of the rigid part''s rigid elements', err)
       return
    end if
    ! the surface on this set (by its name, or on one of its elements by number)
    surface = ''
    do i = 1, size(r%surface_label)
       label = trim(r%surface_label(i))
       if (label == elset) then
          surface = trim(r%surface_name(i))
       else if (is_integer_text(label)) then
          if (any(r%set_name == elset .and. r%set_element == atoi(label))) surface = trim(r%surface_name(i))
       end if
       if (len(surface) > 0) exit
    end do
    if (len(surface) == 0) then
       call blk%fail('*RIGID BODY, ELSET=' // elset // ': no *SURFACE on these ' // set_kind(r, elset) // &
            ' elements (SPOS or SNEG); ' // &
            'expected one, the contact surface of the rigid wall', err)
       return
    end if
    call reparse_keyword_line(blk, '*RIGID BODY, REF NODE=' // ref // ', ANALYTICAL SURFACE=' // surface, err)
    blk%n_lines = 0
  end subroutine rigid_body_surface

  !> 'R2D2' or 'R3D3/R3D4': the kind of rigid elements in set `set`.
  function set_kind(r, set) result(kind)
    type(rigid_elements_t), intent(in) :: r
    character(len=*), intent(in) :: set
    character(len=:), allocatable :: kind
    integer :: k

    kind = 'R2D2'
    do k = 1, size(r%set_name)
       if (r%set_name(k) /= set) cycle
       if (any(r%id == r%set_element(k) .and. r%nnode > 2)) kind = 'R3D3/R3D4'
       exit
    end do
  end function set_kind

  !> Append to a list of names (grown by hand: gfortran's -fcheck=all refuses the array
  !> constructor [zero-size list, name] although both have length 64).
  subroutine push(list, text)
    character(len=64), allocatable, intent(inout) :: list(:)
    character(len=*), intent(in) :: text
    character(len=64), allocatable :: grown(:)
    integer :: n

    n = size(list)
    allocate (grown(n + 1))
    grown(1:n) = list
    grown(n + 1) = text
    call move_alloc(grown, list)
  end subroutine push

  integer function atoi(t)
    character(len=*), intent(in) :: t

    read (t, *) atoi
  end function atoi

  pure function upper(t) result(u)
    character(len=*), intent(in) :: t
    character(len=len(t)) :: u
    integer :: k

    u = t
    do k = 1, len(t)
       if (t(k:k) >= 'a' .and. t(k:k) <= 'z') u(k:k) = achar(iachar(t(k:k)) - 32)
    end do
  end function upper
end module scene_discrete_rigid
