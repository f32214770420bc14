!> How one instance of a part lands in the flat model: its label offsets, its placement
!> (Abaqus's *INSTANCE data lines) and the rewriting of one keyword block of the part (or of
!> the assembly) into flat-model terms: qualified names (`INSTANCE.NAME`), global node and
!> element numbers, placed coordinates.
!>
!> Placement, as the Abaqus Keywords Reference defines *INSTANCE: the first data line is a
!> translation (tx, ty, tz), the optional second line a rotation by an angle in degrees about
!> the axis through points a and b (right-hand rule about a -> b); the translation is applied
!> first, then the rotation.
module scene_instance_map
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_block_t, data_line_t, upper_case, is_integer_text, is_real_text, &
    set_field, set_line_text
  use scene_util, only: itoa, field_name, field_blank
  implicit none
  private

  public :: instance_t, find_instance, split_label, rewrite_block, place_point

  !> One *INSTANCE (or, with name '', the assembly's own level).
  type :: instance_t
     character(len=:), allocatable :: name   !< upper case; '' for the assembly level
     integer :: part = 0                     !< index of its part (0: assembly level)
     integer :: node_offset = 0, elem_offset = 0
     logical :: moved = .false.              !< a non-zero translation or a rotation
     logical :: rotated = .false.            !< rot and axis_point hold a rotation
     real(dp) :: shift(3) = 0, rot(3, 3) = 0, axis_point(3) = 0
     !> assembly level only: 'ASSEMBLY-NAME.', the prefix Abaqus allows on assembly names
     character(len=:), allocatable :: prefix
  end type instance_t

  !> Where a block stands: in a part (names qualified, numbers offset by the instance),
  !> or at assembly or model level (names as written, `inst.n` labels resolved).
  integer, parameter, public :: level_part = 1, level_assembly = 2, level_model = 3

contains

  pure integer function find_instance(instances, n, name)
    type(instance_t), intent(in) :: instances(:)
    integer, intent(in) :: n
    character(len=*), intent(in) :: name
    integer :: k

    find_instance = 0
    do k = 1, n
       if (instances(k)%name == upper_case(name)) then
          find_instance = k
          return
       end if
    end do
  end function find_instance

  !> `inst.123` -> instance index and 123; k = 0 when the text is not of that form.
  pure subroutine split_label(instances, n, text, k, label)
    type(instance_t), intent(in) :: instances(:)
    integer, intent(in) :: n
    character(len=*), intent(in) :: text
    integer, intent(out) :: k, label
    integer :: dot

    k = 0
    label = 0
    dot = index(text, '.', back=.true.)
    if (dot <= 1 .or. dot >= len(text)) return
    if (.not. is_integer_text(text(dot + 1:))) return
    if (len(text) - dot > 9) return
    k = find_instance(instances, n, text(1:dot - 1))
    if (k /= 0) read (text(dot + 1:), *) label
  end subroutine split_label

  !> The placed position of a point given in the part's coordinates.
  pure function place_point(inst, x) result(y)
    type(instance_t), intent(in) :: inst
    real(dp), intent(in) :: x(3)
    real(dp) :: y(3)

    y = x + inst%shift
    if (inst%rotated) y = inst%axis_point + matmul(inst%rot, y - inst%axis_point)
  end function place_point

  !> Rewrite `blk` (a copy of a part's, the instance's or the assembly's block) for `inst`.
  !> `instances(1:n)` resolves `INSTANCE=` and `inst.n` references.
  subroutine rewrite_block(blk, level, inst, instances, n, asm, err)
    type(keyword_block_t), intent(inout) :: blk
    integer, intent(in) :: level
    type(instance_t), intent(in) :: inst, instances(:), asm
    integer, intent(in) :: n
    type(error_t), intent(inout) :: err
    type(instance_t) :: owner
    integer :: ip, k, il
    character(len=:), allocatable :: kind

    owner = inst
    if (level /= level_part) then
       owner = asm
       call strip_assembly_prefix(blk, asm)
    end if
    ! INSTANCE= on an assembly-level set or surface: its numbers and names are the instance's.
    ip = param_position(blk, 'INSTANCE')
    if (ip > 0) then
       if (level /= level_assembly .or. .not. any(blk%name == [character(len=7) :: 'NSET', 'ELSET', 'SURFACE'])) then
          call blk%fail('INSTANCE= on *' // blk%name // ' here; expected it only on *NSET, *ELSET ' // &
               'or *SURFACE in the *ASSEMBLY', err)
          return
       end if
       k = find_instance(instances, n, blk%params(ip)%value)
       if (k == 0) then
          call blk%fail('instance ' // blk%params(ip)%value // ' is not defined; expected the NAME= ' // &
               'of an *INSTANCE given before', err)
          return
       end if
       owner = instances(k)
       blk%params = [blk%params(1:ip - 1), blk%params(ip + 1:)]
    end if
    call rewrite_params(blk, level, owner, instances, n, asm)
    kind = label_kind(blk)
    do il = 1, blk%n_lines
       select case (blk%name)
       case ('NODE')
          call rewrite_node_line(blk%lines(il), owner, level == level_part .or. ip > 0, err)
       case ('ELEMENT')
          call rewrite_element_line(blk%lines(il), owner, err)
       case ('NSET', 'ELSET')
          call rewrite_set_line(blk, blk%lines(il), owner, level, ip > 0, instances, n, err)
       case ('SURFACE')
          if (kind == 'E') then
             call rewrite_label_field(blk%lines(il), 1, 'E', owner, level, ip > 0, instances, n, asm, err)
          else if (swept_surface(blk)) then
             if (il == 1) call place_swept_system(blk, owner, level == level_part .or. ip > 0, err)
          else
             call rewrite_segment_line(blk%lines(il), owner, level == level_part .or. ip > 0, err)
          end if
       case default
          if (kind /= ' ') call rewrite_label_field(blk%lines(il), 1, kind, owner, level, .false., &
               instances, n, asm, err)
       end select
       if (err%raised) return
    end do
  end subroutine rewrite_block

  !> `Assembly.Set` -> `Set` in parameters and data fields outside the parts.
  subroutine strip_assembly_prefix(blk, asm)
    type(keyword_block_t), intent(inout) :: blk
    type(instance_t), intent(in) :: asm
    character(len=:), allocatable :: f
    integer :: i, il, n

    if (.not. allocated(asm%prefix)) return
    n = len(asm%prefix)
    if (n == 0) return
    if (allocated(blk%params)) then
       do i = 1, size(blk%params)
          if (len(blk%params(i)%value) > n) then
             if (upper_case(blk%params(i)%value(1:n)) == asm%prefix) blk%params(i)%value = blk%params(i)%value(n + 1:)
          end if
       end do
    end if
    do il = 1, blk%n_lines
       do i = 1, blk%lines(il)%n_fields()
          f = blk%lines(il)%field(i)
          if (len(f) > n) then
             if (upper_case(f(1:n)) == asm%prefix) call set_field(blk%lines(il), i, f(n + 1:))
          end if
       end do
    end do
  end subroutine strip_assembly_prefix

  pure integer function param_position(blk, name)
    type(keyword_block_t), intent(in) :: blk
    character(len=*), intent(in) :: name
    integer :: i

    param_position = 0
    if (.not. allocated(blk%params)) return
    do i = 1, size(blk%params)
       if (blk%params(i)%name == name) then
          param_position = i
          return
       end if
    end do
  end function param_position

  !> Which kind of label the first field of a data line holds: 'N' node, 'E' element,
  !> ' ' none (or the block is handled on its own).
  function label_kind(blk) result(kind)
    type(keyword_block_t), intent(in) :: blk
    character(len=:), allocatable :: kind
    integer :: ip

    kind = ' '
    select case (blk%name)
    case ('BOUNDARY', 'CLOAD', 'TEMPERATURE')
       kind = 'N'
    case ('DLOAD')
       kind = 'E'
    case ('SURFACE')
       kind = 'E'
       ip = param_position(blk, 'TYPE')
       if (ip > 0) then
          if (upper_case(blk%params(ip)%value) /= 'ELEMENT') kind = ' '
       end if
    case ('INITIAL CONDITIONS')
       kind = 'N'
       ip = param_position(blk, 'TYPE')
       if (ip > 0) then
          if (upper_case(blk%params(ip)%value) == 'STRESS') kind = 'E'
       end if
    end select
  end function label_kind

  !> Parameters naming sets, surfaces or reference nodes.
  subroutine rewrite_params(blk, level, owner, instances, n, asm)
    type(keyword_block_t), intent(inout) :: blk
    integer, intent(in) :: level
    type(instance_t), intent(in) :: owner, instances(:), asm
    integer, intent(in) :: n
    integer :: i, k, label

    if (.not. allocated(blk%params)) return
    do i = 1, size(blk%params)
       associate (p => blk%params(i))
         select case (p%name)
         case ('NSET', 'ELSET', 'ANALYTICAL SURFACE')
            ! The name an *NSET or *ELSET defines is the instance's only inside a part; at the
            ! assembly level (INSTANCE= or not) it is an assembly name. Names it refers to
            ! are the instance's under INSTANCE=.
            if (level == level_part) then
               p%value = qualified(owner, p%value)
            else if (owner%part /= 0 .and. p%name /= blk%name) then
               p%value = qualified(owner, p%value)
            end if
         case ('NAME')
            if (blk%name == 'SURFACE' .and. level == level_part) p%value = qualified(owner, p%value)
         case ('REF NODE')
            if (is_integer_text(p%value)) then
               read (p%value, *) label
               if (level == level_part) then
                  p%value = itoa(label + owner%node_offset)
               else
                  p%value = itoa(label + asm%node_offset)
               end if
            else
               call split_label(instances, n, p%value, k, label)
               if (k /= 0) then
                  p%value = itoa(label + instances(k)%node_offset)
               else if (level == level_part) then
                  p%value = qualified(owner, p%value)
               end if
            end if
         end select
       end associate
    end do
  end subroutine rewrite_params

  !> `inst.name` for a part-level name; as written at the assembly level.
  pure function qualified(owner, name) result(q)
    type(instance_t), intent(in) :: owner
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: q

    if (len(owner%name) == 0) then
       q = name
    else
       q = owner%name // '.' // name
    end if
  end function qualified

  !> *NODE: the number offset, the coordinates placed (text kept when the instance is not moved).
  subroutine rewrite_node_line(dl, owner, placed, err)
    type(data_line_t), intent(inout) :: dl
    type(instance_t), intent(in) :: owner
    logical, intent(in) :: placed
    type(error_t), intent(inout) :: err
    real(dp) :: x(3), y(3)
    integer :: i, nc, label

    call offset_field(dl, 1, owner%node_offset, err)
    if (err%raised .or. .not. (placed .and. owner%moved)) return
    nc = min(dl%n_fields() - 1, 3)
    x = 0
    do i = 1, nc
       if (.not. field_blank(dl, i + 1)) call dl%real_field(i + 1, x(i), err)
       if (err%raised) return
    end do
    y = place_point(owner, x)
    if (nc < 3 .and. abs(y(3)) > 1e-12_dp * max(1.0_dp, maxval(abs(y)))) then
       call dl%integer_field(1, label, err)
       call raise_error(dl%file, dl%line, 'instance ' // owner%name // ' moves 2D node ' // itoa(label) // &
            ' out of the x-y plane (z = ' // real_text(y(3)) // '); expected a translation in x, y ' // &
            'and rotations about the z axis for a 2D model', err)
       return
    end if
    do i = 1, nc
       call set_field(dl, i + 1, real_text(y(i)))
    end do
  end subroutine rewrite_node_line

  subroutine rewrite_element_line(dl, owner, err)
    type(data_line_t), intent(inout) :: dl
    type(instance_t), intent(in) :: owner
    type(error_t), intent(inout) :: err
    integer :: i

    call offset_field(dl, 1, owner%elem_offset, err)
    do i = 2, dl%n_fields()
       if (err%raised) return
       if (.not. field_blank(dl, i)) call offset_field(dl, i, owner%node_offset, err)
    end do
  end subroutine rewrite_element_line

  !> *NSET / *ELSET data: numbers offset (GENERATE: first and last, not the increment),
  !> set names qualified in a part, `inst.n` resolved elsewhere.
  subroutine rewrite_set_line(blk, dl, owner, level, by_instance, instances, n, err)
    type(keyword_block_t), intent(in) :: blk
    type(data_line_t), intent(inout) :: dl
    type(instance_t), intent(in) :: owner, instances(:)
    integer, intent(in) :: level, n
    logical, intent(in) :: by_instance
    type(error_t), intent(inout) :: err
    integer :: i, last, offset, k, label
    character(len=:), allocatable :: text

    offset = merge(owner%node_offset, owner%elem_offset, blk%name == 'NSET')
    last = dl%n_fields()
    if (blk%has_param('GENERATE')) last = min(last, 2)
    do i = 1, last
       if (field_blank(dl, i)) cycle
       text = trim(adjustl(dl%field(i)))
       if (is_integer_text(text)) then
          call offset_field(dl, i, offset, err)
       else
          call split_label(instances, n, text, k, label)
          if (k /= 0) then
             call set_field(dl, i, itoa(label + merge(instances(k)%node_offset, instances(k)%elem_offset, blk%name == 'NSET')))
          else if (level == level_part .or. by_instance) then
             call set_field(dl, i, qualified(owner, text))
          end if
       end if
       if (err%raised) return
    end do
  end subroutine rewrite_set_line

  !> A label field (node or element number, `inst.n`, or a set name).
  subroutine rewrite_label_field(dl, i, kind, owner, level, by_instance, instances, n, asm, err)
    type(data_line_t), intent(inout) :: dl
    integer, intent(in) :: i, level, n
    character(len=*), intent(in) :: kind
    logical, intent(in) :: by_instance
    type(instance_t), intent(in) :: owner, instances(:), asm
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: text
    integer :: k, label

    if (dl%n_fields() < i) return
    if (field_blank(dl, i)) return
    text = trim(adjustl(dl%field(i)))
    if (is_integer_text(text)) then
       if (kind == 'N') then
          call offset_field(dl, i, merge(owner%node_offset, asm%node_offset, level == level_part .or. by_instance), err)
       else
          call offset_field(dl, i, merge(owner%elem_offset, asm%elem_offset, level == level_part .or. by_instance), err)
       end if
    else
       call split_label(instances, n, text, k, label)
       if (k /= 0) then
          call set_field(dl, i, itoa(label + merge(instances(k)%node_offset, instances(k)%elem_offset, kind == 'N')))
       else if (level == level_part .or. by_instance) then
          call set_field(dl, i, qualified(owner, field_name(dl, i)))
       end if
    end if
  end subroutine rewrite_label_field

  !> *SURFACE, TYPE=SEGMENTS lines (START / LINE / CIRCL): the points placed.
  subroutine rewrite_segment_line(dl, owner, placed, err)
    type(data_line_t), intent(inout) :: dl
    type(instance_t), intent(in) :: owner
    logical, intent(in) :: placed
    type(error_t), intent(inout) :: err
    real(dp) :: x(3), y(3)
    integer :: i, j

    if (.not. (placed .and. owner%moved)) return
    if (dl%n_fields() < 3) return
    if (is_real_text(trim(adjustl(dl%field(1))))) return
    do i = 2, dl%n_fields() - 1, 2
       x = 0
       do j = 0, 1
          if (.not. field_blank(dl, i + j)) call dl%real_field(i + j, x(j + 1), err)
          if (err%raised) return
       end do
       y = place_point(owner, x)
       if (abs(y(3)) > 1e-12_dp * max(1.0_dp, maxval(abs(y)))) then
          call raise_error(dl%file, dl%line, 'instance ' // owner%name // ' moves an analytic 2D surface ' // &
               'out of the x-y plane; expected a translation in x, y and rotations about the z axis', err)
          return
       end if
       call set_field(dl, i, real_text(y(1)))
       call set_field(dl, i + 1, real_text(y(2)))
    end do
  end subroutine rewrite_segment_line

  logical function swept_surface(blk)
    type(keyword_block_t), intent(in) :: blk
    integer :: ip

    swept_surface = .false.
    ip = param_position(blk, 'TYPE')
    if (ip > 0) swept_surface = any(upper_case(blk%params(ip)%value) == ['CYLINDER  ', 'REVOLUTION'])
  end function swept_surface

  !> *SURFACE, TYPE=CYLINDER / REVOLUTION of a moved instance: the points a, b (and c) of its local
  !> system placed (the START/LINE/CIRCL profile is in that system and stays). Lines omitted, as
  !> Abaqus/CAE writes them inside a part, mean the part's axes (docs/keywords.md): written out first.
  subroutine place_swept_system(blk, owner, placed, err)
    type(keyword_block_t), intent(inout) :: blk
    type(instance_t), intent(in) :: owner
    logical, intent(in) :: placed
    type(error_t), intent(inout) :: err
    type(data_line_t), allocatable :: lines(:)
    real(dp) :: x(3), y(3)
    integer :: n_system, il, i, j

    if (.not. (placed .and. owner%moved) .or. blk%n_lines < 1) return
    n_system = 1
    if (upper_case(blk%params(param_position(blk, 'TYPE'))%value) == 'CYLINDER') n_system = 2
    if (.not. is_real_text(trim(adjustl(blk%lines(1)%field(1))))) then
       allocate (lines(blk%n_lines + n_system))
       lines(n_system + 1:) = blk%lines(1:blk%n_lines)
       do il = 1, n_system
          lines(il)%file => blk%lines(1)%file
          lines(il)%line = blk%lines(1)%line
       end do
       if (n_system == 2) then
          call set_line_text(lines(1), '0., 0., 0., 1., 0., 0.')
          call set_line_text(lines(2), '0., 0., 1.')
       else
          call set_line_text(lines(1), '0., 0., 0., 0., 1., 0.')
       end if
       call move_alloc(lines, blk%lines)
       blk%n_lines = size(blk%lines)
    end if
    do il = 1, min(n_system, blk%n_lines)
       associate (dl => blk%lines(il))
         do i = 1, dl%n_fields() - 2, 3
            do j = 0, 2
               call dl%real_field(i + j, x(j + 1), err)
               if (err%raised) return
            end do
            y = place_point(owner, x)
            do j = 0, 2
               call set_field(dl, i + j, real_text(y(j + 1)))
            end do
         end do
       end associate
    end do
  end subroutine place_swept_system

  !> Field i (an integer) + offset.
  subroutine offset_field(dl, i, offset, err)
    type(data_line_t), intent(inout) :: dl
    integer, intent(in) :: i, offset
    type(error_t), intent(inout) :: err
    integer :: label

    if (offset == 0) return
    call dl%integer_field(i, label, err)
    if (err%raised) return
    if (label > huge(label) - offset) then
       call raise_error(dl%file, dl%line, 'label ' // itoa(label) // ' + the instance offset ' // itoa(offset) // &
            ' exceeds the largest number bulkflow reads (' // itoa(huge(label)) // '); expected smaller labels', err)
       return
    end if
    call set_field(dl, i, itoa(label + offset))
  end subroutine offset_field

  !> A real that reads back to the same value.
  pure function real_text(x) result(t)
    real(dp), intent(in) :: x
    character(len=:), allocatable :: t
    character(len=32) :: buf

    write (buf, '(es25.17e3)') x
    t = trim(adjustl(buf))
  end function real_text
end module scene_instance_map
