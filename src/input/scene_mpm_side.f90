!> The reader of `*MPM SIDE FRICTION, GAP=t, FRICTION=μw` (docs/keywords.md, "Front and back wall
!> friction of a quasi-2D bin"): the friction of the two walls of a slot on a plane-strain MPM
!> scene, a per-step control that carries over like *MPM CONTROLS. Apart from scene_mpm, which
!> calls it for model data and for each step, to keep that reader within its size.
module scene_mpm_side
  use base_kinds, only: dp
  use error_report, only: error_t
  use keyword_reader, only: keyword_block_t
  use mpm_scene, only: mpm_step_t
  use scene_util, only: itoa, rtoa, expect_lines
  implicit none
  private

  public :: read_side_friction

contains

  !> GAP and FRICTION into the carried controls c; errors name the line and what was expected.
  subroutine read_side_friction(blk, ndim, c, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: ndim                !< of the *MPM GRID
    type(mpm_step_t), intent(inout) :: c
    type(error_t), intent(inout) :: err
    real(dp) :: gap, mu

    if (ndim /= 2) then
       call blk%fail('*MPM SIDE FRICTION in a ' // itoa(ndim) // 'D scene; expected it in a 2D (plane strain) ' // &
            'scene only: in 3D the front and back walls are *MPM WALLs with FRICTION=', err)
       return
    end if
    call blk%check_params([character(len=8) :: 'GAP', 'FRICTION'], err)
    if (.not. err%raised) call blk%get_real('GAP', gap, err)
    if (err%raised) return
    if (.not. gap > 0) then
       call blk%fail('*MPM SIDE FRICTION: GAP=' // rtoa(gap) // '; expected the distance between the front ' // &
            'and back walls, > 0', err)
       return
    end if
    call blk%get_real('FRICTION', mu, err)
    if (err%raised) return
    if (.not. mu >= 0) then
       call blk%fail('*MPM SIDE FRICTION: FRICTION=' // rtoa(mu) // '; expected the Coulomb coefficient ' // &
            'tan(phi_w) >= 0 (0 switches the side friction off)', err)
       return
    end if
    call expect_lines(blk, 0, 0, 'no data lines', err)
    if (err%raised) return
    c%side_gap = gap
    c%side_friction = mu
  end subroutine read_side_friction
end module scene_mpm_side
