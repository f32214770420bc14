!> *INITIAL CONDITIONS, TYPE=STRESS | VELOCITY | FIELD | TEMPERATURE -> model%initial_stresses,
!> initial_velocities, initial_fields (one entry per data line; temperature is stored as
!> variable 0).
!>
!> STRESS data follow Abaqus's input-file order: element or element set, s11, s22, s33,
!> s12, s13, s23 (2D: up to s12); omitted trailing components are zero. They are stored in
!> VUMAT order 11, 22, 33, 12, 23, 31, so s13 goes to slot 6 and s23 to slot 5.
!> VELOCITY: node or node set, dof, value. FIELD, VARIABLE=n (default 1): node or node set,
!> value. TEMPERATURE: node or node set, value (the temperature a VUMAT receives as
!> tempOld/tempNew until a step's *TEMPERATURE changes it). In material-point scenes only FIELD
!> and TEMPERATURE, on the particles of a material (`material name, value`).
module scene_initial
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t
  use model, only: model_t, initial_velocity_t, initial_stress_t, initial_field_t
  use scene_layout, only: scene_layout_t
  use scene_sets, only: node_targets, elem_targets
  use scene_temperature, only: predefined_line
  use scene_util, only: itoa, get_real, get_int, expect_fields, expect_lines
  implicit none
  private

  public :: build_initial_conditions

  !> The most field variables a scene may define (VARIABLE=1..max_field_variables).
  integer, parameter, public :: max_field_variables = 64

  !> Input position (after the element field) of each VUMAT stress slot.
  integer, parameter :: input_of_vumat_slot(6) = [1, 2, 3, 4, 6, 5]

contains

  subroutine build_initial_conditions(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: ctype
    integer :: i

    allocate (model%initial_velocities(0), model%initial_stresses(0), model%initial_fields(0))
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0 .or. deck%blocks(i)%name /= 'INITIAL CONDITIONS') cycle
       associate (blk => deck%blocks(i))
         call blk%check_params([character(len=8) :: 'TYPE', 'VARIABLE'], err)
         if (.not. err%raised) call blk%get_string('TYPE', ctype, err, &
              choices=[character(len=11) :: 'STRESS', 'VELOCITY', 'FIELD', 'TEMPERATURE'])
         if (err%raised) return
         if (ctype /= 'FIELD' .and. blk%has_param('VARIABLE')) then
            call blk%fail('VARIABLE= on *INITIAL CONDITIONS, TYPE=' // ctype // &
                 '; expected it only with TYPE=FIELD', err)
            return
         end if
         call expect_lines(blk, 1, huge(1), 'initial values', err)
         if (err%raised) return
         if (model%mesh%n_nodes == 0 .and. ctype /= 'FIELD' .and. ctype /= 'TEMPERATURE') then
            call blk%fail('*INITIAL CONDITIONS, TYPE=' // ctype // ' in a material-point scene; expected ' // &
                 'TYPE=TEMPERATURE or FIELD (particles start at rest and stress free)', err)
            return
         end if
         select case (ctype)
         case ('STRESS')
            call read_stress(blk, model, err)
         case ('VELOCITY')
            call read_velocity(blk, model, err)
         case ('TEMPERATURE')
            call read_field(blk, model, err, temperature=.true.)
         case default
            call read_field(blk, model, err, temperature=.false.)
         end select
         if (err%raised) return
       end associate
    end do
  end subroutine build_initial_conditions

  subroutine read_stress(blk, model, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    type(initial_stress_t) :: entry
    real(dp) :: s_in(6)
    integer :: il, k, ncomp

    ncomp = merge(4, 6, model%mesh%ndim == 2)
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         if (ncomp == 4) then
            call expect_fields(blk, dl, 2, 5, 'element or element set, s11, s22, s33, s12', err)
         else
            call expect_fields(blk, dl, 2, 7, 'element or element set, s11, s22, s33, s12, s13, s23', err)
         end if
         if (.not. err%raised) call elem_targets(model, dl, 1, entry%elems, err)
         if (err%raised) return
         s_in = 0
         do k = 1, ncomp
            call get_real(dl, 1 + k, s_in(k), err, default=0.0_dp)
            if (err%raised) return
         end do
         entry%stress = 0
         do k = 1, ncomp
            entry%stress(k) = s_in(input_of_vumat_slot(k))
         end do
         model%initial_stresses = [model%initial_stresses, entry]
       end associate
    end do
  end subroutine read_stress

  subroutine read_velocity(blk, model, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    type(initial_velocity_t) :: entry
    integer :: il

    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         call expect_fields(blk, dl, 3, 3, 'node or node set, dof, velocity', err)
         if (.not. err%raised) call node_targets(model, dl, 1, entry%nodes, err)
         if (.not. err%raised) call get_int(dl, 2, entry%dof, err)
         if (err%raised) return
         if (entry%dof < 1 .or. entry%dof > model%mesh%ndim) then
            call raise_error(dl%file, dl%line, 'degree of freedom ' // itoa(entry%dof) // &
                 ' is not a translation of this ' // itoa(model%mesh%ndim) // 'D model; expected 1..' // &
                 itoa(model%mesh%ndim), err)
            return
         end if
         call get_real(dl, 3, entry%value, err)
         if (err%raised) return
         model%initial_velocities = [model%initial_velocities, entry]
       end associate
    end do
  end subroutine read_velocity

  !> Field variable n (TYPE=FIELD, VARIABLE=n) or the temperature (stored as variable 0).
  subroutine read_field(blk, model, err, temperature)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    logical, intent(in) :: temperature
    type(initial_field_t) :: entry
    integer :: il

    if (temperature) then
       entry%variable = 0
    else
       call blk%get_integer('VARIABLE', entry%variable, err, default=1, minimum=1, maximum=max_field_variables)
       if (err%raised) return
    end if
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         call predefined_line(blk, dl, model, 'value', entry%nodes, entry%material, entry%value, err)
         if (err%raised) return
         model%initial_fields = [model%initial_fields, entry]
       end associate
    end do
  end subroutine read_field
end module scene_initial
