!> The reader of `*NONLOCAL, LENGTH=ℓ [, VARIABLE=FVn] [, MATERIAL=name]` (docs/keywords.md,
!> docs/nonlocal.md): the length scale of an MPM scene's softening. Model data only, once per
!> scene; the variable must be one the material's VUSDFLD writes (*USER DEFINED FIELD), since the
!> averaged value reaches the VUMAT as that field variable. Apart from scene_mpm to keep that
!> reader within its size.
module scene_mpm_nonlocal
  use base_kinds, only: dp
  use error_report, only: error_t
  use keyword_reader, only: keyword_block_t
  use model, only: model_t
  use scene_materials, only: find_material
  use scene_util, only: itoa, rtoa, expect_lines, where_text
  implicit none
  private

  public :: read_nonlocal

contains

  !> LENGTH, VARIABLE and MATERIAL into model%mpm%nonlocal; errors name the line and what was
  !> expected.
  subroutine read_nonlocal(blk, model, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: variable, name
    real(dp) :: length
    integer :: field, k, ios

    associate (nl => model%mpm%nonlocal)
      if (nl%on) then
         call blk%fail('second *NONLOCAL (first at ' // trim(nl%source) // '); expected one per scene', err)
         return
      end if
      call blk%check_params([character(len=8) :: 'LENGTH', 'VARIABLE', 'MATERIAL'], err)
      if (.not. err%raised) call blk%get_real('LENGTH', length, err)
      if (err%raised) return
      ! not (length > 0) also catches NaN; huge lengths are allowed (every particle a neighbour)
      if (.not. (length > 0 .and. length <= huge(length))) then
         call blk%fail('*NONLOCAL, LENGTH=' // rtoa(length) // '; expected the radius of the averaging, a ' // &
              'finite length > 0 (a few grain diameters, or a few particle spacings to be resolved)', err)
         return
      end if
      call blk%get_string('VARIABLE', variable, err, default='FV1')
      if (err%raised) return
      field = 0
      ios = 1
      if (len(variable) > 2) then
         if (variable(1:2) == 'FV') read (variable(3:), *, iostat=ios) field
      end if
      if (ios /= 0 .or. field < 1) then
         call blk%fail('*NONLOCAL, VARIABLE=' // variable // '; expected FVn, the field variable n >= 1 ' // &
              'that the material''s VUSDFLD writes', err)
         return
      end if
      k = 0
      if (blk%has_param('MATERIAL')) then
         call blk%get_string('MATERIAL', name, err)
         if (err%raised) return
         k = find_material(model, name)
         if (k == 0) then
            call blk%fail('material ' // name // ' is not defined; expected the name of a *MATERIAL', err)
            return
         end if
         call check_material(blk, model, k, field, err)
      else
         if (.not. any(model%materials(1:model%n_materials)%user_field)) then
            call blk%fail('*NONLOCAL but no material has *USER DEFINED FIELD; expected a material whose ' // &
                 'VUSDFLD writes the variable averaged', err)
            return
         end if
         do k = 1, model%n_materials
            if (.not. model%materials(k)%user_field) cycle
            call check_material(blk, model, k, field, err)
            if (err%raised) return
         end do
         k = 0
      end if
      if (.not. err%raised) call expect_lines(blk, 0, 0, 'no data lines', err)
      if (err%raised) return
      nl%on = .true.
      nl%length = length
      nl%field = field
      nl%material = k
      nl%source = where_text(blk%file, blk%line)
    end associate
  end subroutine read_nonlocal

  !> Material k has a VUSDFLD that writes field variable `field`.
  subroutine check_material(blk, model, k, field, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    integer, intent(in) :: k, field
    type(error_t), intent(inout) :: err

    associate (mat => model%materials(k))
      if (.not. mat%user_field) then
         call blk%fail('*NONLOCAL on material ' // trim(mat%name) // ', which has no *USER DEFINED FIELD; ' // &
              'expected a material whose VUSDFLD writes the variable averaged', err)
      else if (field > mat%nfieldv) then
         call blk%fail('*NONLOCAL, VARIABLE=FV' // itoa(field) // ' but material ' // trim(mat%name) // &
              ' has ' // itoa(mat%nfieldv) // ' field variable(s); expected FV1..FV' // itoa(mat%nfieldv), err)
      end if
    end associate
  end subroutine check_material
end module scene_mpm_nonlocal
