!> *TIME POINTS, NAME=name [, GENERATE]: named lists of step times at which an *OUTPUT with
!> TIME POINTS=name writes (Abaqus Keywords Reference, *TIME POINTS; Analysis User's Guide,
!> "Output to the output database": output at exact times). Lists are read anywhere in the input
!> (model or history data, as in Abaqus) before the steps, each checked at its line: times >= 0,
!> strictly increasing; GENERATE lines are `start, end, increment` (increment > 0, end >= start).
module scene_time_points
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t
  use scene_util, only: itoa, rtoa, get_real, where_text
  implicit none
  private

  public :: time_points_t, build_time_points, find_time_points

  !> One named list.
  type :: time_points_t
     character(len=:), allocatable :: name     !< upper case
     character(len=:), allocatable :: where    !< file:line of its keyword
     real(dp), allocatable :: times(:)
  end type time_points_t

contains

  !> Every *TIME POINTS of the deck.
  subroutine build_time_points(deck, lists, err)
    type(keyword_deck_t), intent(in) :: deck
    type(time_points_t), allocatable, intent(out) :: lists(:)
    type(error_t), intent(inout) :: err
    type(time_points_t) :: one
    character(len=:), allocatable :: name
    integer :: i, k

    allocate (lists(0))
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'TIME POINTS') cycle
       associate (blk => deck%blocks(i))
         call blk%check_params([character(len=8) :: 'NAME', 'GENERATE'], err)
         if (.not. err%raised) call blk%get_string('NAME', name, err)
         if (err%raised) return
         k = find_time_points(lists, name)
         if (k > 0) then
            call blk%fail('*TIME POINTS, NAME=' // name // ' defined twice (first at ' // lists(k)%where // &
                 '); expected one list per name', err)
            return
         end if
         call read_times(blk, one%times, err)
         if (err%raised) return
         one%name = name
         one%where = where_text(blk%file, blk%line)
         lists = [lists, one]
       end associate
    end do
  end subroutine build_time_points

  !> Index of the list called `name` (upper case), 0 if none.
  pure integer function find_time_points(lists, name)
    type(time_points_t), intent(in) :: lists(:)
    character(len=*), intent(in) :: name
    integer :: k

    find_time_points = 0
    do k = 1, size(lists)
       if (lists(k)%name == name) then
          find_time_points = k
          return
       end if
    end do
  end function find_time_points

  !> The times of one *TIME POINTS block, checked line by line.
  subroutine read_times(blk, times, err)
    type(keyword_block_t), intent(in) :: blk
    real(dp), allocatable, intent(out) :: times(:)
    type(error_t), intent(inout) :: err
    real(dp) :: t, start, last, step
    integer :: j, f, n, k
    logical :: generate

    generate = blk%has_param('GENERATE')
    allocate (times(0))
    if (blk%n_lines == 0) then
       call blk%fail('*TIME POINTS without data lines; expected the times (several per line) or, with ' // &
            'GENERATE, lines "start, end, increment"', err)
       return
    end if
    do j = 1, blk%n_lines
       associate (dl => blk%lines(j))
         if (generate) then
            if (dl%n_fields() /= 3) then
               call raise_error(dl%file, dl%line, '*TIME POINTS, GENERATE line with ' // itoa(dl%n_fields()) // &
                    ' fields; expected "start, end, increment"', err)
               return
            end if
            call get_real(dl, 1, start, err)
            if (.not. err%raised) call get_real(dl, 2, last, err)
            if (.not. err%raised) call get_real(dl, 3, step, err)
            if (err%raised) return
            if (.not. (step > 0) .or. last < start) then
               call raise_error(dl%file, dl%line, '*TIME POINTS, GENERATE: increment ' // rtoa(step) // &
                    ' from ' // rtoa(start) // ' to ' // rtoa(last) // '; expected an increment > 0 and ' // &
                    'end >= start', err)
               return
            end if
            n = int((last - start) / step + 1.0e-9_dp)
            if (n > 1000000) then
               call raise_error(dl%file, dl%line, '*TIME POINTS, GENERATE makes ' // itoa(n + 1) // &
                    ' points; expected at most 1000001', err)
               return
            end if
            do k = 0, n
               call add_time(start + k * step, dl%file, dl%line)
               if (err%raised) return
            end do
         else
            do f = 1, dl%n_fields()
               if (len(dl%field(f)) == 0) cycle
               call get_real(dl, f, t, err)
               if (err%raised) return
               call add_time(t, dl%file, dl%line)
               if (err%raised) return
            end do
         end if
       end associate
    end do

  contains

    subroutine add_time(x, file, line)
      real(dp), intent(in) :: x
      character(len=*), intent(in) :: file
      integer, intent(in) :: line

      if (x < 0) then
         call raise_error(file, line, '*TIME POINTS: time ' // rtoa(x) // ' is negative; expected step ' // &
              'times >= 0', err)
      else if (size(times) > 0) then
         if (.not. (x > times(size(times)))) call raise_error(file, line, '*TIME POINTS: time ' // rtoa(x) // &
              ' does not come after ' // rtoa(times(size(times))) // '; expected increasing times', err)
      end if
      if (.not. err%raised) times = [times, x]
    end subroutine add_time
  end subroutine read_times
end module scene_time_points
