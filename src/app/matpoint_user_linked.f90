!> Compiled into bulkflow-matpoint-user only (src/CMakeLists.txt, bulkflow_add_matpoint_executable
!> with USER_SOURCE): the user's VUMAT/VUSDFLD are linked into the executable, so the driver
!> reads a *USER MATERIAL as the user's (any name) and calls it through the user path.
subroutine bulkflow_matpoint_user_linked(linked)
  implicit none
  logical, intent(out) :: linked

  linked = .true.
end subroutine bulkflow_matpoint_user_linked
