!> *SOLID SECTION, ELSET=..., MATERIAL=... [, CONTROLS=...] -> model%sections and
!> mesh%elem_section, and the check that every element has exactly one section.
!>
!> The data line is optional: in 2D its first field is the plane-strain thickness
!> (default 1); in 3D it must be empty (Abaqus/CAE writes a lone "," there).
!>
!> *SECTION CONTROLS, NAME=..., HOURGLASS=VISCOUS|STIFFNESS with an optional data line
!> holding Abaqus's hourglass scale factor (default 1): the section's hourglass coefficient
!> is that factor times our default for the form (model_materials). Abaqus's other forms
!> (RELAX STIFFNESS, ENHANCED, COMBINED) and scale factors are not supported.
module scene_sections
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t
  use model, only: model_t
  use model_materials, only: section_t, hourglass_viscous, hourglass_stiffness, &
       default_hourglass_viscous_coefficient, default_hourglass_stiffness_coefficient
  use model_sets, only: find_set
  use scene_layout, only: scene_layout_t
  use scene_mesh, only: mesh_sources_t
  use scene_materials, only: find_material
  use scene_util, only: itoa, rtoa, get_real, expect_lines, expect_fields, field_blank, where_text
  implicit none
  private

  public :: build_sections

contains

  subroutine build_sections(deck, layout, sources, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(mesh_sources_t), intent(in) :: sources
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    type(section_t), allocatable :: tmp(:)
    character(len=:), allocatable :: elset, material, controls
    integer, allocatable :: section_block(:)
    integer :: i, k, km, e, ie, s, kc, ic, hourglass
    real(dp) :: thickness, coefficient

    allocate (model%sections(0), section_block(0))
    model%n_sections = 0
    ! every *SECTION CONTROLS is checked, used or not, and names are unique
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'SECTION CONTROLS') cycle
       kc = 0
       call read_controls(deck%blocks(i), '', hourglass, coefficient, kc, err)
       if (err%raised) return
       call deck%blocks(i)%get_string('NAME', controls, err)
       do ic = 1, i - 1
          if (deck%blocks(ic)%name /= 'SECTION CONTROLS') cycle
          call read_controls(deck%blocks(ic), controls, hourglass, coefficient, kc, err)
          if (kc /= 0) then
             call deck%blocks(i)%fail('section controls ' // controls // ' defined twice; ' // &
                  'expected unique names', err)
             return
          end if
       end do
    end do
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0 .or. deck%blocks(i)%name /= 'SOLID SECTION') cycle
       associate (blk => deck%blocks(i))
         call blk%check_params([character(len=8) :: 'ELSET', 'MATERIAL', 'CONTROLS'], err)
         if (err%raised) return
         call blk%get_string('ELSET', elset, err)
         if (.not. err%raised) call blk%get_string('MATERIAL', material, err)
         if (err%raised) return
         k = find_set(model%elsets, model%n_elsets, elset)
         if (k == 0) then
            call blk%fail('element set ' // elset // ' is not defined; expected the name of an ' // &
                 '*ELSET (or ELSET= of *ELEMENT)', err)
            return
         end if
         km = find_material(model, material)
         if (km == 0) then
            call blk%fail('material ' // material // ' is not defined; expected the name of a ' // &
                 '*MATERIAL', err)
            return
         end if
         hourglass = hourglass_viscous
         coefficient = 0
         if (blk%has_param('CONTROLS')) then
            call blk%get_string('CONTROLS', controls, err)
            if (err%raised) return
            kc = 0
            do ic = 1, deck%n_blocks
               if (deck%blocks(ic)%name /= 'SECTION CONTROLS' .or. layout%step_of(ic) /= 0) cycle
               call read_controls(deck%blocks(ic), controls, hourglass, coefficient, kc, err)
               if (err%raised) return
               if (kc /= 0) exit
            end do
            if (kc == 0) then
               call blk%fail('section controls ' // controls // ' are not defined; expected the ' // &
                    'name of a *SECTION CONTROLS', err)
               return
            end if
         end if
         thickness = 1
         call expect_lines(blk, 0, 1, 'an optional line with the thickness (2D only)', err)
         if (err%raised) return
         if (blk%n_lines == 1) then
            associate (dl => blk%lines(1))
              if (model%mesh%ndim == 2) then
                 call expect_fields(blk, dl, 0, 1, 'the plane-strain thickness', err)
                 if (.not. err%raised) call get_real(dl, 1, thickness, err, default=1.0_dp)
                 if (err%raised) return
                 if (.not. (thickness > 0)) then
                    call raise_error(dl%file, dl%line, 'thickness must be positive; got ' // &
                         rtoa(thickness), err)
                    return
                 end if
              else if (.not. field_blank(dl, 1) .or. dl%n_fields() > 1) then
                 call raise_error(dl%file, dl%line, 'data beyond what *SOLID SECTION takes in 3D; ' // &
                      'expected no thickness (an empty line or none)', err)
                 return
              end if
            end associate
         end if
         allocate (tmp(model%n_sections + 1))
         tmp(1:model%n_sections) = model%sections
         call move_alloc(tmp, model%sections)
         model%n_sections = model%n_sections + 1
         s = model%n_sections
         model%sections(s)%elset = elset
         model%sections(s)%material = km
         model%sections(s)%thickness = thickness
         model%sections(s)%hourglass = hourglass
         model%sections(s)%hourglass_coefficient = coefficient
         section_block = [section_block, i]
         do ie = 1, size(model%elsets(k)%members)
            e = model%elsets(k)%members(ie)
            if (model%mesh%elem_section(e) /= 0) then
               call blk%fail('element ' // itoa(model%mesh%elem_id(e)) // ' already has the section at ' // &
                    where_text(deck%blocks(section_block(model%mesh%elem_section(e)))%file, &
                    deck%blocks(section_block(model%mesh%elem_section(e)))%line) // &
                    '; expected one *SOLID SECTION per element', err)
               return
            end if
            model%mesh%elem_section(e) = s
         end do
       end associate
    end do
    do e = 1, model%mesh%n_elems
       if (model%mesh%elem_section(e) /= 0) cycle
       associate (dl => deck%blocks(sources%elem_block(e))%lines(sources%elem_line(e)))
         call raise_error(dl%file, dl%line, 'element ' // itoa(model%mesh%elem_id(e)) // &
              ' has no section; expected a *SOLID SECTION whose ELSET contains it', err)
       end associate
       return
    end do
  end subroutine build_sections

  !> If `blk` is the *SECTION CONTROLS called `name`: its hourglass form and coefficient,
  !> found = 1; otherwise found stays 0. Every *SECTION CONTROLS met is fully checked.
  subroutine read_controls(blk, name, hourglass, coefficient, found, err)
    type(keyword_block_t), intent(in) :: blk
    character(len=*), intent(in) :: name
    integer, intent(inout) :: hourglass
    real(dp), intent(inout) :: coefficient
    integer, intent(inout) :: found
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: cname, form
    real(dp) :: scale

    call blk%check_params([character(len=9) :: 'NAME', 'HOURGLASS'], err)
    if (.not. err%raised) call blk%get_string('NAME', cname, err)
    if (.not. err%raised) call blk%get_string('HOURGLASS', form, err, default='VISCOUS', &
         choices=[character(len=9) :: 'VISCOUS', 'STIFFNESS'])
    if (.not. err%raised) call expect_lines(blk, 0, 1, 'at most one line: the hourglass scale factor', err)
    if (err%raised) return
    scale = 1
    if (blk%n_lines == 1) then
       call expect_fields(blk, blk%lines(1), 0, 1, 'the hourglass scale factor (the other ' // &
            'Abaqus section-control factors are not supported)', err)
       if (.not. err%raised) call get_real(blk%lines(1), 1, scale, err, default=1.0_dp)
       if (err%raised) return
       if (.not. (scale > 0)) then
          call raise_error(blk%lines(1)%file, blk%lines(1)%line, 'hourglass scale factor ' // &
               rtoa(scale) // ' is not positive; expected a factor > 0', err)
          return
       end if
    end if
    if (cname /= name) return
    found = 1
    if (form == 'STIFFNESS') then
       hourglass = hourglass_stiffness
       coefficient = scale * default_hourglass_stiffness_coefficient
    else
       hourglass = hourglass_viscous
       coefficient = scale * default_hourglass_viscous_coefficient
    end if
  end subroutine read_controls
end module scene_sections
