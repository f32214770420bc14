!> Host-side state behind the Abaqus utility routines a user subroutine may call.
!>
!> Abaqus's `vgetvrm` takes no argument naming the block, so the host must say beforehand
!> which block is current: `host_set_block` copies its start-of-increment stress and
!> logarithmic strain (VUMAT layout, `(nblock, ncomp)`), and the external `vgetvrm` reads
!> them back in Abaqus's flat layout. `host_set_exit_handler` lets the application decide
!> how `xplb_exit` ends the run (plain exit, or MPI_Abort in the parallel solver).
module abaqus_host
  use material_kinds, only: dp
  implicit none
  private

  abstract interface
     subroutine exit_handler(status)
       integer, intent(in) :: status
     end subroutine exit_handler
  end interface

  real(dp), allocatable :: block_stress(:, :), block_log_strain(:, :)
  integer :: block_size = 0, block_components = 0
  procedure(exit_handler), pointer :: on_exit => null()

  public :: exit_handler
  public :: host_set_block, host_get_variable, host_set_exit_handler, host_exit

contains

  subroutine host_set_block(nblock, ncomp, stress, log_strain)
    integer, intent(in) :: nblock, ncomp
    real(dp), intent(in) :: stress(nblock, ncomp), log_strain(nblock, ncomp)

    if (allocated(block_stress)) then
       if (size(block_stress, 1) < nblock .or. size(block_stress, 2) /= ncomp) &
            deallocate(block_stress, block_log_strain)
    end if
    if (.not. allocated(block_stress)) allocate(block_stress(nblock, ncomp), block_log_strain(nblock, ncomp))
    block_size = nblock
    block_components = ncomp
    block_stress(1:nblock, :) = stress
    block_log_strain(1:nblock, :) = log_strain
  end subroutine host_set_block

  !> Fill `values` in Abaqus's layout (component-major: all points of component 1 first).
  !> `status` is 0 on success, 1 for a key this host does not provide or when no block is set.
  subroutine host_get_variable(key, values, status)
    character(len=*), intent(in) :: key
    real(dp), intent(out) :: values(*)
    integer, intent(out) :: status
    integer :: j

    status = 1
    if (block_size == 0) return
    select case (trim(adjustl(key)))
    case ('S')
       do j = 1, block_components
          values((j - 1) * block_size + 1:j * block_size) = block_stress(1:block_size, j)
       end do
    case ('LE')
       do j = 1, block_components
          values((j - 1) * block_size + 1:j * block_size) = block_log_strain(1:block_size, j)
       end do
    case default
       return
    end select
    status = 0
  end subroutine host_get_variable

  subroutine host_set_exit_handler(handler)
    procedure(exit_handler) :: handler
    on_exit => handler
  end subroutine host_set_exit_handler

  !> End the run on behalf of user code; never returns.
  subroutine host_exit(status)
    integer, intent(in) :: status

    if (associated(on_exit)) call on_exit(status)
    error stop 3
  end subroutine host_exit
end module abaqus_host
