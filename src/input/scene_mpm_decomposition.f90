!> The reader of `*MPM CONTROLS, DECOMPOSITION=REPLICATED|SPATIAL, REBALANCE=r` (docs/keywords.md,
!> "Material point method"): how an MPI run splits the MPM grid and particles (src/mpm/mpm_domain.f90)
!> and when it partitions again. Model data only; apart from scene_mpm, which calls it for the model
!> data's *MPM CONTROLS, to keep that reader within its size.
module scene_mpm_decomposition
  use base_kinds, only: dp
  use error_report, only: error_t
  use keyword_reader, only: keyword_block_t
  use mpm_scene, only: mpm_scene_t, decomposition_replicated, decomposition_spatial
  implicit none
  private

  public :: read_decomposition

contains

  !> The run's grid decomposition over MPI ranks (mpm_domain) and its re-partition threshold.
  subroutine read_decomposition(blk, mpm, err)
    type(keyword_block_t), intent(in) :: blk
    type(mpm_scene_t), intent(inout) :: mpm
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: kind
    real(dp) :: rebalance

    call blk%get_string('DECOMPOSITION', kind, err, default=trim(merge('SPATIAL   ', 'REPLICATED', &
         mpm%decomposition == decomposition_spatial)), choices=[character(len=10) :: &
         'REPLICATED', 'SPATIAL'])
    if (.not. err%raised) call blk%get_real('REBALANCE', rebalance, err, default=mpm%rebalance, minimum=0.0_dp)
    if (err%raised) return
    mpm%rebalance = rebalance
    mpm%decomposition = decomposition_replicated
    if (kind == 'SPATIAL') mpm%decomposition = decomposition_spatial
  end subroutine read_decomposition
end module scene_mpm_decomposition
