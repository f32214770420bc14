!> *SURFACE INTERACTION, NAME=... with its *FRICTION (Coulomb coefficient mu) ->
!> model%interactions. Without *FRICTION the interaction is frictionless (Abaqus's default).
module scene_interactions
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t
  use model, only: model_t
  use model_steps, only: interaction_t
  use scene_layout, only: scene_layout_t
  use scene_util, only: rtoa, get_real, expect_fields, expect_lines, check_name
  use model_sets, only: name_length
  implicit none
  private

  public :: build_interactions, find_interaction

contains

  pure integer function find_interaction(model, name)
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: name
    integer :: k

    find_interaction = 0
    do k = 1, model%n_interactions
       if (model%interactions(k)%name == name) then
          find_interaction = k
          return
       end if
    end do
  end function find_interaction

  subroutine build_interactions(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    type(interaction_t), allocatable :: tmp(:)
    character(len=:), allocatable :: name
    integer :: i, k, last_owner
    real(dp) :: thickness

    allocate (model%interactions(0))
    model%n_interactions = 0
    last_owner = 0
    do i = 1, deck%n_blocks
       associate (blk => deck%blocks(i))
         if (blk%name == 'SURFACE INTERACTION') then
            call blk%check_params([character(len=4) :: 'NAME'], err)
            if (.not. err%raised) call blk%get_string('NAME', name, err)
            if (.not. err%raised) call check_name(blk, 'surface interaction', name, name_length, err)
            ! Abaqus's optional data line is the out-of-plane thickness of 2D surfaces
            ! (Abaqus/CAE writes "1.,"); the section thickness is what we use.
            if (.not. err%raised) call expect_lines(blk, 0, 1, 'at most one line: the out-of-plane ' // &
                 'thickness (ignored)', err)
            if (err%raised) return
            if (blk%n_lines == 1) then
               call expect_fields(blk, blk%lines(1), 0, 1, 'the out-of-plane thickness', err)
               if (.not. err%raised) call get_real(blk%lines(1), 1, thickness, err, default=1.0_dp)
               if (err%raised) return
               if (.not. (thickness > 0)) then
                  call raise_error(blk%lines(1)%file, blk%lines(1)%line, 'out-of-plane thickness ' // &
                       rtoa(thickness) // ' is not positive; expected a thickness > 0', err)
                  return
               end if
            end if
            if (find_interaction(model, name) /= 0) then
               call blk%fail('surface interaction ' // name // ' defined twice; expected unique names', err)
               return
            end if
            allocate (tmp(model%n_interactions + 1))
            tmp(1:model%n_interactions) = model%interactions
            call move_alloc(tmp, model%interactions)
            model%n_interactions = model%n_interactions + 1
            model%interactions(model%n_interactions)%name = name
         else if (blk%name == 'FRICTION') then
            ! the layout guarantees it follows its *SURFACE INTERACTION (the last one added)
            k = model%n_interactions
            if (layout%owner(i) == 0 .or. k == 0) cycle
            if (layout%owner(i) == last_owner) then
               call blk%fail('second *FRICTION for surface interaction ' // &
                    trim(model%interactions(k)%name) // '; expected one *FRICTION', err)
               return
            end if
            last_owner = layout%owner(i)
            call blk%check_params([character(len=8) ::], err)
            if (.not. err%raised) call expect_lines(blk, 1, 1, 'one line: the friction coefficient', err)
            if (.not. err%raised) call expect_fields(blk, blk%lines(1), 1, 1, 'the friction coefficient', err)
            if (.not. err%raised) call get_real(blk%lines(1), 1, model%interactions(k)%friction, err)
            if (err%raised) return
            if (model%interactions(k)%friction < 0) then
               call raise_error(blk%lines(1)%file, blk%lines(1)%line, 'friction coefficient ' // &
                    rtoa(model%interactions(k)%friction) // ' is negative; expected mu >= 0', err)
               return
            end if
         end if
       end associate
    end do
  end subroutine build_interactions
end module scene_interactions
