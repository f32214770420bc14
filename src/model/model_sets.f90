!> Named node and element sets (*NSET, *ELSET) holding internal indices.
module model_sets
  implicit none
  private

  integer, parameter, public :: name_length = 80

  type, public :: index_set_t
     character(len=name_length) :: name = ''  !< upper case, as Abaqus compares names
     integer, allocatable :: members(:)       !< internal indices, ascending, unique
  end type index_set_t

  public :: find_set, sorted_position

contains

  !> Position of the set called `name` (already upper case) in `sets`, 0 if none.
  pure integer function find_set(sets, n, name)
    type(index_set_t), intent(in) :: sets(:)
    integer, intent(in) :: n
    character(len=*), intent(in) :: name
    integer :: i

    find_set = 0
    do i = 1, n
       if (sets(i)%name == name) then
          find_set = i
          return
       end if
    end do
  end function find_set

  !> Position of `value` in an ascending list of integers (set members, node or element
  !> numbers, global indices), 0 if it is not there. Binary search.
  pure integer function sorted_position(list, value) result(pos)
    integer, intent(in) :: list(:), value
    integer :: lo, hi, mid

    pos = 0
    lo = 1
    hi = size(list)
    do while (lo <= hi)
       mid = lo + (hi - lo) / 2
       if (list(mid) == value) then
          pos = mid
          return
       else if (list(mid) < value) then
          lo = mid + 1
       else
          hi = mid - 1
       end if
    end do
  end function sorted_position
end module model_sets
