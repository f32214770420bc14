!> Parts, assembly and instances (Abaqus/CAE's deck layout) mapped onto the flat model the
!> rest of the reader builds: `flatten_assembly` turns a deck with *PART ... *END PART,
!> *ASSEMBLY ... *END ASSEMBLY and *INSTANCE ... *END INSTANCE into the flat deck it means,
!> so no other pass knows about parts. A deck without them is left untouched.
!>
!> The mapping (docs/keywords.md, "Parts, assembly and instances"):
!> * every instance gets a copy of its part's blocks, in the place of its *INSTANCE line;
!>   node and element numbers are offset so that instances do not collide: instance k adds
!>   the largest labels of the instances before it (the first instance keeps its numbers),
!>   and the assembly's own nodes come after all instances;
!> * names defined in a part become `INSTANCE.NAME` (Abaqus's qualified names), so
!>   `Part-1-1.Set-1` written at the assembly or model level finds them; `INSTANCE.n`
!>   names node or element n of that instance;
!> * nodes (and analytic-surface points) of the part are placed by the instance's
!>   translation and rotation (scene_instance_map).
!> Blocks keep the file:line where they were written, so errors point at the part.
module scene_assembly
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, upper_case, is_integer_text
  use scene_util, only: itoa, where_text, field_blank, push_block
  use scene_unsupported, only: unsupported_hint
  use scene_instance_map, only: instance_t, find_instance, rewrite_block, level_part, level_assembly, &
       level_model
  implicit none
  private

  public :: flatten_assembly

  type :: part_t
     character(len=:), allocatable :: name   !< upper case
     integer :: block = 0                    !< its *PART block
     integer :: first = 0, last = -1         !< its content blocks
     integer :: max_node = 0, max_elem = 0
  end type part_t

  ! Where a block stands.
  integer, parameter :: at_model = 0, in_part = 1, in_assembly = 2, in_instance = 3, frame = 4

  real(dp), parameter :: pi = acos(-1.0_dp)

contains

  pure logical function is_frame_keyword(name)
    character(len=*), intent(in) :: name

    is_frame_keyword = any(name == [character(len=12) :: 'PART', 'END PART', 'ASSEMBLY', 'END ASSEMBLY', &
         'INSTANCE', 'END INSTANCE'])
  end function is_frame_keyword

  !> Keywords a part (or the inside of an *INSTANCE) may hold.
  pure logical function is_part_keyword(name)
    character(len=*), intent(in) :: name

    is_part_keyword = any(name == [character(len=13) :: 'NODE', 'ELEMENT', 'NSET', 'ELSET', 'SURFACE', &
         'SOLID SECTION', 'RIGID BODY'])
  end function is_part_keyword

  !> Replace a deck with parts and instances by the flat deck it means.
  subroutine flatten_assembly(deck, err)
    type(keyword_deck_t), intent(inout) :: deck
    type(error_t), intent(inout) :: err
    type(part_t), allocatable :: parts(:)
    type(instance_t), allocatable :: instances(:)
    type(instance_t) :: asm
    integer, allocatable :: zone(:), owner(:)
    integer :: n_parts, n_inst, i

    if (.not. any([(is_frame_keyword(deck%blocks(i)%name), i = 1, deck%n_blocks)])) return
    call scan_frames(deck, zone, owner, parts, n_parts, instances, n_inst, err)
    if (err%raised) return
    call number_instances(deck, zone, owner, parts, instances, n_inst, asm, err)
    if (err%raised) return
    asm%prefix = assembly_prefix(deck)
    call emit_flat(deck, zone, owner, parts, instances, n_inst, asm, err)
  end subroutine flatten_assembly

  !> Classify every block (model, part, assembly, instance content, frame keyword) and
  !> check the frame: parts closed, one assembly, instances of parts defined before.
  subroutine scan_frames(deck, zone, owner, parts, n_parts, instances, n_inst, err)
    type(keyword_deck_t), intent(in) :: deck
    integer, allocatable, intent(out) :: zone(:), owner(:)
    type(part_t), allocatable, intent(out) :: parts(:)
    integer, intent(out) :: n_parts, n_inst
    type(instance_t), allocatable, intent(out) :: instances(:)
    type(error_t), intent(inout) :: err
    integer :: i, part, inst, assembly, n_assemblies, k, loose_mesh
    character(len=:), allocatable :: name, part_name

    allocate (zone(deck%n_blocks), owner(deck%n_blocks), parts(deck%n_blocks), instances(deck%n_blocks))
    zone = at_model
    owner = 0
    n_parts = 0
    n_inst = 0
    part = 0
    inst = 0
    assembly = 0
    n_assemblies = 0
    loose_mesh = 0
    do i = 1, deck%n_blocks
       associate (blk => deck%blocks(i))
         select case (blk%name)
         case ('PART')
            if (part /= 0 .or. assembly /= 0) then
               call blk%fail('*PART inside ' // trim(merge('*PART    ', '*ASSEMBLY', part /= 0)) // ' started at ' // &
                    where_text(deck%blocks(max(part, assembly))%file, deck%blocks(max(part, assembly))%line) // &
                    '; expected *END PART / *END ASSEMBLY first', err)
               return
            end if
            call blk%check_params([character(len=4) :: 'NAME'], err)
            if (.not. err%raised) call blk%get_string('NAME', name, err)
            if (err%raised) return
            if (find_part(parts, n_parts, name) /= 0) then
               call blk%fail('part ' // name // ' is defined twice; expected one *PART per NAME', err)
               return
            end if
            n_parts = n_parts + 1
            parts(n_parts)%name = name
            parts(n_parts)%block = i
            parts(n_parts)%first = i + 1
            part = i
            zone(i) = frame
         case ('END PART')
            if (part == 0) then
               call blk%fail('*END PART without a *PART; expected *PART, NAME=... before it', err)
               return
            end if
            parts(n_parts)%last = i - 1
            part = 0
            zone(i) = frame
         case ('ASSEMBLY')
            if (part /= 0 .or. assembly /= 0 .or. n_assemblies > 0) then
               call blk%fail('*ASSEMBLY here; expected one *ASSEMBLY, outside any *PART', err)
               return
            end if
            call blk%check_params([character(len=4) :: 'NAME'], err)
            if (err%raised) return
            n_assemblies = 1
            assembly = i
            zone(i) = frame
         case ('END ASSEMBLY')
            if (assembly == 0 .or. inst /= 0) then
               call blk%fail('*END ASSEMBLY without an open *ASSEMBLY (or inside an *INSTANCE); expected ' // &
                    '*ASSEMBLY ... *END ASSEMBLY with each *INSTANCE closed by *END INSTANCE', err)
               return
            end if
            assembly = 0
            zone(i) = frame
         case ('INSTANCE')
            if (assembly == 0 .or. inst /= 0) then
               call blk%fail('*INSTANCE outside an *ASSEMBLY (or inside another *INSTANCE); expected it ' // &
                    'between *ASSEMBLY and *END ASSEMBLY', err)
               return
            end if
            call blk%check_params([character(len=4) :: 'NAME', 'PART'], err)
            if (.not. err%raised) call blk%get_string('NAME', name, err)
            if (.not. err%raised) call blk%get_string('PART', part_name, err)
            if (err%raised) return
            k = find_part(parts, n_parts, part_name)
            if (k == 0) then
               call blk%fail('part ' // part_name // ' is not defined; expected *PART, NAME=' // part_name // &
                    ' ... *END PART before this *INSTANCE', err)
               return
            end if
            if (find_instance(instances, n_inst, name) /= 0) then
               call blk%fail('instance ' // name // ' is defined twice; expected one *INSTANCE per NAME', err)
               return
            end if
            n_inst = n_inst + 1
            instances(n_inst)%name = name
            instances(n_inst)%part = k
            call read_placement(blk, instances(n_inst), err)
            if (err%raised) return
            inst = n_inst
            zone(i) = frame
            owner(i) = n_inst
         case ('END INSTANCE')
            if (inst == 0) then
               call blk%fail('*END INSTANCE without an *INSTANCE; expected *INSTANCE, NAME=..., PART=... ' // &
                    'before it', err)
               return
            end if
            inst = 0
            zone(i) = frame
         case default
            if (part /= 0 .or. inst /= 0) then
               if (.not. is_part_keyword(blk%name)) then
                  if (len(unsupported_hint(blk%name)) > 0) then
                     call blk%fail('*' // blk%name // ' is not simulated by bulkflow; ' // &
                          unsupported_hint(blk%name), err)
                  else
                     call blk%fail('*' // blk%name // ' inside a ' // trim(merge('*PART    ', '*INSTANCE', &
                          part /= 0)) // ' is not supported; expected *NODE, *ELEMENT, *NSET, *ELSET, *SURFACE, ' // &
                          '*SOLID SECTION or *RIGID BODY there (and the rest in the *ASSEMBLY or the model)', err)
                  end if
                  return
               end if
               zone(i) = merge(in_part, in_instance, part /= 0)
               owner(i) = merge(n_parts, inst, part /= 0)
            else if (assembly /= 0) then
               zone(i) = in_assembly
            else if ((blk%name == 'NODE' .or. blk%name == 'ELEMENT') .and. loose_mesh == 0) then
               loose_mesh = i   ! reported once the frame itself is known to be sound
            end if
         end select
       end associate
    end do
    if (part /= 0) then
       call deck%blocks(part)%fail('*END PART missing for this *PART; expected *PART ... *END PART', err)
    else if (inst /= 0) then
       call raise_error(deck%blocks(deck%n_blocks)%file, deck%blocks(deck%n_blocks)%line, &
            '*END INSTANCE missing; expected *INSTANCE ... *END INSTANCE', err)
    else if (assembly /= 0) then
       call deck%blocks(assembly)%fail('*END ASSEMBLY missing for this *ASSEMBLY; expected *ASSEMBLY ... ' // &
            '*END ASSEMBLY', err)
    else if (loose_mesh /= 0) then
       call deck%blocks(loose_mesh)%fail('*' // deck%blocks(loose_mesh)%name // ' outside the parts and the ' // &
            'assembly of a model that has them; expected it inside *PART ... *END PART (or *NODE in the ' // &
            '*ASSEMBLY)', err)
    end if
  end subroutine scan_frames

  !> 'NAME.' of the *ASSEMBLY (upper case; '' without NAME=).
  function assembly_prefix(deck) result(prefix)
    type(keyword_deck_t), intent(in) :: deck
    character(len=:), allocatable :: prefix
    integer :: i, k

    prefix = ''
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'ASSEMBLY' .or. .not. allocated(deck%blocks(i)%params)) cycle
       do k = 1, size(deck%blocks(i)%params)
          if (deck%blocks(i)%params(k)%name == 'NAME') prefix = upper_case(deck%blocks(i)%params(k)%value) // '.'
       end do
    end do
    if (prefix == '.') prefix = ''
  end function assembly_prefix

  pure integer function find_part(parts, n, name)
    type(part_t), intent(in) :: parts(:)
    integer, intent(in) :: n
    character(len=*), intent(in) :: name
    integer :: k

    find_part = 0
    do k = 1, n
       if (parts(k)%name == upper_case(name)) then
          find_part = k
          return
       end if
    end do
  end function find_part

  !> *INSTANCE data lines: `tx, ty[, tz]` and optionally `ax, ay, az, bx, by, bz, angle`.
  subroutine read_placement(blk, inst, err)
    type(keyword_block_t), intent(in) :: blk
    type(instance_t), intent(inout) :: inst
    type(error_t), intent(inout) :: err
    real(dp) :: v(7), u(3), c, s, theta
    integer :: j, nf

    if (blk%n_lines > 2) then
       call raise_error(blk%lines(3)%file, blk%lines(3)%line, 'a third data line on *INSTANCE; expected a ' // &
            'translation line and at most one rotation line', err)
       return
    end if
    if (blk%n_lines >= 1) then
       nf = blk%lines(1)%n_fields()
       if (nf > 3) then
          call raise_error(blk%lines(1)%file, blk%lines(1)%line, itoa(nf) // ' values on the *INSTANCE ' // &
               'translation line; expected tx, ty[, tz]', err)
          return
       end if
       do j = 1, nf
          if (.not. field_blank(blk%lines(1), j)) call blk%lines(1)%real_field(j, inst%shift(j), err)
          if (err%raised) return
       end do
    end if
    inst%moved = any(abs(inst%shift) > 0)
    if (blk%n_lines < 2) return
    associate (dl => blk%lines(2))
      v = 0
      nf = dl%n_fields()
      if (nf /= 7) then
         call raise_error(dl%file, dl%line, itoa(nf) // ' values on the *INSTANCE rotation line; expected ' // &
              'ax, ay, az, bx, by, bz, angle (degrees)', err)
         return
      end if
      do j = 1, 7
         if (.not. field_blank(dl, j)) call dl%real_field(j, v(j), err)
         if (err%raised) return
      end do
      u = v(4:6) - v(1:3)
      if (.not. norm2(u) > 0) then
         if (.not. abs(v(7)) > 0) return
         call raise_error(dl%file, dl%line, 'rotation axis points a and b coincide; expected two ' // &
              'different points on the axis', err)
         return
      end if
      if (.not. abs(v(7)) > 0) return
      u = u / norm2(u)
      theta = v(7) * pi / 180
      c = cos(theta)
      s = sin(theta)
      ! Rodrigues: R = c I + s [u]x + (1 - c) u u^T
      inst%rot(:, 1) = [c + (1 - c) * u(1)**2, (1 - c) * u(1) * u(2) + s * u(3), (1 - c) * u(1) * u(3) - s * u(2)]
      inst%rot(:, 2) = [(1 - c) * u(1) * u(2) - s * u(3), c + (1 - c) * u(2)**2, (1 - c) * u(2) * u(3) + s * u(1)]
      inst%rot(:, 3) = [(1 - c) * u(1) * u(3) + s * u(2), (1 - c) * u(2) * u(3) - s * u(1), c + (1 - c) * u(3)**2]
      inst%axis_point = v(1:3)
      inst%moved = .true.
      inst%rotated = .true.
    end associate
  end subroutine read_placement

  !> Label offsets: instance k after the largest labels of the instances before it; the
  !> assembly's own nodes after all instances.
  subroutine number_instances(deck, zone, owner, parts, instances, n_inst, asm, err)
    type(keyword_deck_t), intent(in) :: deck
    integer, intent(in) :: zone(:), owner(:)
    type(part_t), intent(inout) :: parts(:)
    type(instance_t), intent(inout) :: instances(:)
    integer, intent(in) :: n_inst
    type(instance_t), intent(out) :: asm
    type(error_t), intent(inout) :: err
    integer, allocatable :: inst_node(:), inst_elem(:)
    integer :: i, k, nodes, elems

    allocate (inst_node(n_inst), inst_elem(n_inst))
    inst_node = 0
    inst_elem = 0
    do i = 1, deck%n_blocks
       if (zone(i) == in_part) then
          k = owner(i)
          call largest_labels(deck%blocks(i), parts(k)%max_node, parts(k)%max_elem, err)
       else if (zone(i) == in_instance) then
          k = owner(i)
          call largest_labels(deck%blocks(i), inst_node(k), inst_elem(k), err)
       end if
       if (err%raised) return
    end do
    nodes = 0
    elems = 0
    do k = 1, n_inst
       instances(k)%node_offset = nodes
       instances(k)%elem_offset = elems
       nodes = nodes + max(parts(instances(k)%part)%max_node, inst_node(k))
       elems = elems + max(parts(instances(k)%part)%max_elem, inst_elem(k))
    end do
    asm%name = ''
    asm%node_offset = nodes
    asm%elem_offset = elems
  end subroutine number_instances

  subroutine largest_labels(blk, max_node, max_elem, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(inout) :: max_node, max_elem
    type(error_t), intent(inout) :: err
    integer :: il, label

    if (blk%name /= 'NODE' .and. blk%name /= 'ELEMENT') return
    do il = 1, blk%n_lines
       if (.not. is_integer_text(trim(adjustl(blk%lines(il)%field(1))))) cycle
       call blk%lines(il)%integer_field(1, label, err)
       if (err%raised) return
       if (blk%name == 'NODE') then
          max_node = max(max_node, label)
       else
          max_elem = max(max_elem, label)
       end if
    end do
  end subroutine largest_labels

  !> The flat deck: each instance's copy of its part where its *INSTANCE stood, the
  !> assembly's and the model's blocks rewritten, the frame keywords dropped.
  subroutine emit_flat(deck, zone, owner, parts, instances, n_inst, asm, err)
    type(keyword_deck_t), intent(inout) :: deck
    integer, intent(in) :: zone(:), owner(:), n_inst
    type(part_t), intent(in) :: parts(:)
    type(instance_t), intent(in) :: instances(:), asm
    type(error_t), intent(inout) :: err
    type(keyword_block_t), allocatable :: out(:)
    integer :: i, j, n_out, k

    allocate (out(deck%n_blocks + 8))
    n_out = 0
    do i = 1, deck%n_blocks
       select case (zone(i))
       case (frame)
          if (deck%blocks(i)%name /= 'INSTANCE') cycle
          k = owner(i)
          do j = parts(instances(k)%part)%first, parts(instances(k)%part)%last
             call push(deck%blocks(j), level_part, instances(k))
             if (err%raised) return
          end do
       case (in_part)
          cycle
       case (in_instance)
          call push(deck%blocks(i), level_part, instances(owner(i)))
       case (in_assembly)
          call push(deck%blocks(i), level_assembly, asm)
       case default
          call push(deck%blocks(i), level_model, asm)
       end select
       if (err%raised) return
    end do
    deallocate (deck%blocks)
    allocate (deck%blocks(n_out))
    deck%blocks(1:n_out) = out(1:n_out)
    deck%n_blocks = n_out

  contains

    subroutine push(blk, level, inst)
      type(keyword_block_t), intent(in) :: blk
      integer, intent(in) :: level
      type(instance_t), intent(in) :: inst

      call push_block(out, n_out, blk)
      call rewrite_block(out(n_out), level, inst, instances, n_inst, asm, err)
    end subroutine push
  end subroutine emit_flat
end module scene_assembly
