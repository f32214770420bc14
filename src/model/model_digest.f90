!> The scene's digest: one 64-bit hash per keyword line and per data line of the deck (comments,
!> blank lines and *RESTART not counted), in reading order, with where each line stands.
!>
!> Why: a checkpoint continues the run of the scene it was written by. Restarting it with an
!> edited scene (another friction, a moved node, a changed step) would mix the two runs and
!> call the result a restart. The checkpoint stores the hashes; the restart compares them with
!> the scene now and names the first line that differs (file:line), which a comparison of the
!> built model could not. Lines are hashed from their parsed form (keyword name and parameters,
!> data fields), so blanks and the case of keywords do not count; numbers count as written
!> ("1.0" and "1.00" differ).
module model_digest
  use, intrinsic :: iso_fortran_env, only: int32, int64
  use error_report, only: error_t, raise_error
  implicit none
  private

  type, public :: scene_digest_t
     integer(int64), allocatable :: hash(:)           !< (n) one per keyword or data line
     integer, allocatable :: line(:)                  !< (n) its line number
     integer, allocatable :: file(:)                  !< (n) its file: index into files
     character(len=1024), allocatable :: files(:)     !< the scene file and its *INCLUDEs
  end type scene_digest_t

  public :: digest_lines, digest_words, first_difference, check_scene_digest

contains

  pure integer function digest_lines(d)
    type(scene_digest_t), intent(in) :: d

    digest_lines = 0
    if (allocated(d%hash)) digest_lines = size(d%hash)
  end function digest_lines

  !> Index of the first line whose hash differs from saved(:) (a line only one of the two has
  !> counts as differing); 0 when the two are the same.
  pure integer function first_difference(d, saved) result(k)
    type(scene_digest_t), intent(in) :: d
    integer(int64), intent(in) :: saved(:)
    integer :: n

    n = digest_lines(d)
    do k = 1, min(n, size(saved))
       if (d%hash(k) /= saved(k)) return
    end do
    k = min(n, size(saved)) + 1
    if (n == size(saved)) k = 0
  end function first_difference

  !> The hashes as pairs of 32-bit words (checkpoints store 32-bit integers), and back.
  function digest_words(d) result(words)
    type(scene_digest_t), intent(in) :: d
    integer(int32), allocatable :: words(:)
    integer :: k

    allocate (words(2 * digest_lines(d)))
    do k = 1, digest_lines(d)
       words(2 * k - 1:2 * k) = transfer(d%hash(k), words(1:2))
    end do
  end function digest_words

  pure function words_to_hashes(words) result(hash)
    integer(int32), intent(in) :: words(:)
    integer(int64) :: hash(size(words) / 2)
    integer :: k

    do k = 1, size(hash)
       hash(k) = transfer(words(2 * k - 1:2 * k), hash(k))
    end do
  end function words_to_hashes

  !> err (at file:line of the scene now) when the scene is not the one whose digest a
  !> checkpoint saved: the first line that differs, or the end of the shorter scene.
  subroutine check_scene_digest(d, saved_words, err)
    type(scene_digest_t), intent(in) :: d
    integer(int32), intent(in) :: saved_words(:)   !< digest_words of the saved digest
    type(error_t), intent(inout) :: err
    integer(int64) :: saved(size(saved_words) / 2)
    integer :: k, n
    character(len=24) :: counts
    character(len=*), parameter :: expected = '; expected the unchanged scene of the interrupted run ' // &
         '(or a new run without --restart)'

    saved = words_to_hashes(saved_words)
    k = first_difference(d, saved)
    if (k == 0) return
    n = digest_lines(d)
    if (n == 0) then
       call raise_error('', 0, 'the scene has no keyword lines, the checkpoint''s had some' // expected, err)
    else if (k > n) then
       write (counts, '(i0,a,i0)') n, ' lines, it had ', size(saved)
       call raise_error(trim(d%files(d%file(n))), d%line(n), 'the scene ends here, before the end of the ' // &
            'one the checkpoint was written for (keyword and data lines: ' // trim(counts) // ')' // expected, err)
    else if (k > size(saved)) then
       write (counts, '(i0)') size(saved)
       call raise_error(trim(d%files(d%file(k))), d%line(k), 'the scene goes on here, past the end of the ' // &
            'one the checkpoint was written for (' // trim(counts) // ' keyword and data lines)' // expected, err)
    else
       write (counts, '(i0,a,i0)') k, ' of ', size(saved)
       call raise_error(trim(d%files(d%file(k))), d%line(k), 'differs from the scene the checkpoint was ' // &
            'written for (its keyword or data line ' // trim(counts) // ')' // expected, err)
    end if
  end subroutine check_scene_digest
end module model_digest
