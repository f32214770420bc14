!> The scene's digest in a checkpoint (the element driver's and MPM's alike): saved as its
!> first two arrays, `scene_lines` and `scene_digest`, and checked first on restart, so that a
!> restart of an edited scene is refused at the edited line, not at some array's shape later.
module checkpoint_scene
  use, intrinsic :: iso_fortran_env, only: int32
  use error_report, only: error_t
  use model_digest, only: scene_digest_t, digest_lines, digest_words, check_scene_digest
  use output_checkpoint, only: checkpoint_t, checkpoint_put, checkpoint_get
  implicit none
  private

  public :: put_scene_digest, check_saved_scene

contains

  subroutine put_scene_digest(ck, d)
    type(checkpoint_t), intent(inout) :: ck
    type(scene_digest_t), intent(in) :: d

    call checkpoint_put(ck, 'scene_lines', digest_lines(d))
    call checkpoint_put(ck, 'scene_digest', digest_words(d))
  end subroutine put_scene_digest

  !> err when the checkpoint's scene is not d (or the records cannot be read). Every rank holds
  !> the same scene and the same digest, so all find the same difference.
  subroutine check_saved_scene(ck, d, err)
    type(checkpoint_t), intent(inout) :: ck
    type(scene_digest_t), intent(in) :: d
    type(error_t), intent(inout) :: err
    integer(int32), allocatable :: saved(:)
    integer :: n_lines

    n_lines = 0
    call checkpoint_get(ck, 'scene_lines', n_lines, err)
    if (err%raised) return
    allocate (saved(2 * max(n_lines, 0)))
    call checkpoint_get(ck, 'scene_digest', saved, err)
    if (err%raised) return
    call check_scene_digest(d, saved, err)
  end subroutine check_saved_scene
end module checkpoint_scene
