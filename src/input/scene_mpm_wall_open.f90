!> The reader of `*MPM WALL, OPEN=` (docs/keywords.md, `*MPM WALL`; docs/theory/mpm.md §4.4, "Open
!> wall ends"): which end of a wall meets an opening, so that the wall holds the particles there
!> and not the grid nodes whose support reaches past it (src/mpm/mpm_wall_edges.f90). 2D: START,
!> END or BOTH ends of the segment p0 -> p1. 3D: a face of the wall's box, XLOW ... ZHIGH, which
!> the wall's plane must cross (a face parallel to the plane is no edge of it). Apart from
!> scene_mpm, which calls it once the wall's geometry is read, to keep that reader within its size.
module scene_mpm_wall_open
  use base_kinds, only: dp
  use error_report, only: error_t
  use keyword_reader, only: keyword_block_t
  use mpm_scene, only: mpm_wall_t
  implicit none
  private

  public :: read_wall_open

  !> A plane whose normal is within this of a box axis is parallel to that axis' faces.
  real(dp), parameter :: parallel_tolerance = 1.0e-6_dp

contains

  !> OPEN of the wall block blk into w (its geometry already read); symmetry: TYPE=SYMMETRY.
  subroutine read_wall_open(blk, ndim, symmetry, w, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: ndim
    logical, intent(in) :: symmetry
    type(mpm_wall_t), intent(inout) :: w
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: open_ends
    character(len=*), parameter :: faces = 'XLOW  XHIGH YLOW  YHIGH ZLOW  ZHIGH'
    integer :: k

    call blk%get_string('OPEN', open_ends, err, default='NONE', choices=[character(len=5) :: &
         'NONE', 'START', 'END', 'BOTH', 'XLOW', 'XHIGH', 'YLOW', 'YHIGH', 'ZLOW', 'ZHIGH'])
    if (err%raised .or. open_ends == 'NONE') return
    if (symmetry .or. w%reach > 0) then
       call blk%fail('*MPM WALL, OPEN= is for a friction wall without REACH; expected no OPEN here', err)
       return
    end if
    if (ndim == 2) then
       if (index(faces, open_ends) > 0) then
          call blk%fail('*MPM WALL, OPEN=' // open_ends // ' in a 2D scene; expected START, END or BOTH ' // &
               '(the ends p0, p1 of the segment)', err)
          return
       end if
       w%open_start = open_ends == 'START' .or. open_ends == 'BOTH'
       w%open_end = open_ends == 'END' .or. open_ends == 'BOTH'
       return
    end if
    if (index(faces, open_ends) == 0) then
       call blk%fail('*MPM WALL, OPEN=' // open_ends // ' in a 3D scene; expected a face of the wall''s box: ' // &
            'XLOW, XHIGH, YLOW, YHIGH, ZLOW or ZHIGH', err)
       return
    end if
    if (.not. w%bounded) then
       call blk%fail('*MPM WALL, OPEN=' // open_ends // ' on a wall without a box; expected the low and high ' // &
            'corner lines of the box whose face is open', err)
       return
    end if
    k = index('XYZ', open_ends(1:1))
    if (abs(w%normal(k)) > 1 - parallel_tolerance) then
       call blk%fail('*MPM WALL, OPEN=' // open_ends // ': that face of the box is parallel to the wall''s ' // &
            'plane; expected a face the plane crosses (an axis along the wall)', err)
       return
    end if
    w%open_axis = k
    w%open_start = open_ends(2:) == 'LOW'
    w%open_end = open_ends(2:) == 'HIGH'
  end subroutine read_wall_open
end module scene_mpm_wall_open
