!> The reader of a step's `*MPM CONTROLS` (docs/keywords.md, "Material point method"): FLIP or
!> PIC TIME, CFL, DAMPING, SORT and MAX DILATION of a step, each carried over from the step before unless given
!> (DECOMPOSITION and REBALANCE, model data only, are scene_mpm_decomposition's). Apart from
!> scene_mpm to keep that reader within its size.
module scene_mpm_controls
  use base_kinds, only: dp
  use error_report, only: error_t
  use keyword_reader, only: keyword_block_t
  use mpm_scene, only: mpm_step_t
  use scene_util, only: rtoa, expect_lines
  implicit none
  private

  public :: read_mpm_controls

contains

  !> The block's controls into c (c holds the carried-over values on entry: the defaults).
  subroutine read_mpm_controls(blk, c, err)
    type(keyword_block_t), intent(in) :: blk
    type(mpm_step_t), intent(inout) :: c
    type(error_t), intent(inout) :: err
    real(dp) :: flip, pic_time, cfl, damping, max_dilation
    integer :: sort

    call blk%check_params([character(len=13) :: 'FLIP', 'CFL', 'DAMPING', 'SORT', 'DECOMPOSITION', 'REBALANCE', &
         'MAX DILATION', 'PIC TIME'], err)
    if (.not. err%raised .and. blk%has_param('FLIP') .and. blk%has_param('PIC TIME')) call blk%fail( &
         '*MPM CONTROLS: FLIP and PIC TIME together; expected one of them (the blend per increment, or as a rate)', err)
    if (.not. err%raised) call blk%get_real('FLIP', flip, err, default=c%flip, minimum=0.0_dp, maximum=1.0_dp)
    if (.not. err%raised) call blk%get_real('PIC TIME', pic_time, err, default=c%pic_time, minimum=0.0_dp)
    if (.not. err%raised) call blk%get_real('CFL', cfl, err, default=c%cfl, minimum=1.0e-3_dp, maximum=1.0_dp)
    if (.not. err%raised) call blk%get_real('DAMPING', damping, err, default=c%damping, minimum=0.0_dp, &
         maximum=0.99_dp)
    if (.not. err%raised) call blk%get_integer('SORT', sort, err, default=c%sort, minimum=0)
    if (.not. err%raised) call blk%get_real('MAX DILATION', max_dilation, err, default=c%max_dilation, &
         minimum=0.0_dp)
    if (err%raised) return
    ! not in the line above: Fortran may evaluate max_dilation, unset after an error, anyway
    if (max_dilation > 0 .and. max_dilation < 1) call blk%fail('*MPM CONTROLS: MAX DILATION=' // &
         rtoa(max_dilation) // '; expected 0 (off) or a volume ratio V/V0 >= 1', err)
    if (.not. err%raised) call expect_lines(blk, 0, 0, 'no data lines', err)
    if (err%raised) return
    c%flip = flip
    c%pic_time = pic_time
    ! a FLIP given later replaces an earlier step's PIC TIME (and PIC TIME a FLIP): one rule at a time
    if (blk%has_param('FLIP')) c%pic_time = 0
    c%cfl = cfl
    c%damping = damping
    c%sort = sort
    c%max_dilation = max_dilation
  end subroutine read_mpm_controls
end module scene_mpm_controls
