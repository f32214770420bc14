!> Compiled into bulkflow-matpoint (no user file linked in): *USER MATERIAL names must be ours
!> unless --user loads a file (the counterpart of matpoint_user_linked.f90).
subroutine bulkflow_matpoint_user_linked(linked)
  implicit none
  logical, intent(out) :: linked

  linked = .false.
end subroutine bulkflow_matpoint_user_linked
