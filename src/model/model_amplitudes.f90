!> Amplitudes (*AMPLITUDE): tabular (piecewise linear, constant beyond the last point) and
!> smooth step (Abaqus: a = A_i + (A_i+1 - A_i) ξ³(10 - 15ξ + 6ξ²) between data points),
!> over step time or total time.
module model_amplitudes
  use base_kinds, only: dp
  use model_sets, only: name_length
  implicit none
  private

  integer, parameter, public :: amplitude_tabular = 1
  integer, parameter, public :: amplitude_smooth_step = 2

  type, public :: amplitude_t
     character(len=name_length) :: name = ''
     integer :: kind = amplitude_tabular
     logical :: total_time = .false.          !< TIME=TOTAL TIME instead of STEP TIME
     real(dp), allocatable :: t(:), a(:)      !< data points, t strictly ascending
   contains
     procedure :: value => amplitude_value
  end type amplitude_t

contains

  !> Amplitude at the given step and total time. Before the first point: the first value;
  !> after the last: the last value (Abaqus holds the end values).
  pure real(dp) function amplitude_value(this, step_time, total_time)
    class(amplitude_t), intent(in) :: this
    real(dp), intent(in) :: step_time, total_time
    real(dp) :: t, xi
    integer :: i, n

    t = merge(total_time, step_time, this%total_time)
    n = size(this%t)
    if (t <= this%t(1)) then
       amplitude_value = this%a(1)
       return
    end if
    if (t >= this%t(n)) then
       amplitude_value = this%a(n)
       return
    end if
    do i = 1, n - 1
       if (t < this%t(i + 1)) exit
    end do
    xi = (t - this%t(i)) / (this%t(i + 1) - this%t(i))
    if (this%kind == amplitude_smooth_step) xi = xi**3 * (10 - 15 * xi + 6 * xi**2)
    amplitude_value = this%a(i) + (this%a(i + 1) - this%a(i)) * xi
  end function amplitude_value
end module model_amplitudes
