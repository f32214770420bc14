!> Named node and element sets (*NSET, *ELSET) holding internal indices.
module model_sets
  implicit none
  private

  integer, parameter, public :: name_length = 80

  type, public :: index_set_t
     character(len=name_length) :: name = ''  !< upper case, as Abaqus compares names
     integer, allocatable :: members(:)       !< internal indices, ascending, unique
  end type index_set_t

  public :: find_set

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
end module model_sets
