!> *DSLOAD [, AMPLITUDE=] [, OP=NEW|MOD]; data: element surface, P, magnitude — a uniform
!> pressure on the faces of a *SURFACE, TYPE=ELEMENT (edges in 2D, faces in 3D). OP=MOD (the
!> default) replaces a load on the same surface; OP=NEW drops every pressure of the earlier steps
!> (the rule of *DLOAD: on one *DSLOAD of a step, on all of them). Loads carry over to later
!> steps like gravity (model_time_variation).
module scene_pressure
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_block_t
  use model, only: model_t
  use model_steps, only: pressure_t
  use model_time_variation, only: time_variation_t
  use scene_amplitudes, only: amplitude_param
  use scene_boundaries, only: boundary_op
  use scene_surfaces, only: require_element_surface
  use scene_util, only: get_real, field_name, expect_fields, expect_lines, where_text
  implicit none
  private

  public :: read_dsload

contains

  !> Adds (or replaces, per surface) the pressures of one *DSLOAD block in list(1:n).
  subroutine read_dsload(blk, model, list, n, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    type(pressure_t), allocatable, intent(inout) :: list(:)
    integer, intent(inout) :: n
    type(error_t), intent(inout) :: err
    type(pressure_t) :: p
    character(len=:), allocatable :: op, name
    integer :: il, amp, j, k

    call blk%check_params([character(len=9) :: 'AMPLITUDE', 'OP'], err)
    if (.not. err%raised) call boundary_op(blk, op, err)
    if (.not. err%raised) call amplitude_param(blk, model, amp, err)
    ! OP=NEW without data lines removes every pressure (as *DLOAD does gravity)
    if (.not. err%raised) call expect_lines(blk, merge(0, 1, op == 'NEW'), huge(1), &
         'element surface, P, magnitude', err)
    if (err%raised) return
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         ! the load type first: a traction (TRSHR, TRVEC: more fields) is named as such
         call expect_fields(blk, dl, 2, huge(1), 'element surface, P, magnitude', err)
         if (err%raised) return
         if (field_name(dl, 2) /= 'P') then
            call raise_error(dl%file, dl%line, 'load type "' // dl%field(2) // '" is not supported; ' // &
                 'expected P (uniform pressure)', err)
            return
         end if
         call expect_fields(blk, dl, 3, 3, 'element surface, P, magnitude', err)
         if (err%raised) return
         name = field_name(dl, 1)
         p = pressure_t()
         call require_element_surface(model, dl, name, 'an analytic rigid surface; expected a ' // &
              '*SURFACE, TYPE=ELEMENT of the mesh', p%surface, err)
         if (err%raised) return
         call get_real(dl, 3, p%magnitude, err)
         if (err%raised) return
         p%variation = time_variation_t(amplitude=amp)
         p%source = where_text(dl%file, dl%line)
         j = 0
         do k = 1, n
            if (list(k)%surface == p%surface) j = k
         end do
         if (j > 0) then
            list(j) = p
         else
            ! a new surface: lists are short (one entry per loaded surface)
            if (.not. allocated(list)) allocate (list(0))
            list = [list(1:n), p]
            n = n + 1
         end if
       end associate
    end do
  end subroutine read_dsload
end module scene_pressure
