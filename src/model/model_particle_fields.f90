!> The predefined fields of MPM particles in time: all particles of a material share one
!> temperature (the last *TEMPERATURE entry of the step naming the material, value × a(t), else
!> the material's *INITIAL CONDITIONS, TYPE=TEMPERATURE) and their initial field variables
!> (*INITIAL CONDITIONS, TYPE=FIELD). A user's VUMAT gets them as tempOld/tempNew and fieldOld.
module model_particle_fields
  use base_kinds, only: dp
  use model, only: model_t
  use model_time_variation, only: variation_factor
  implicit none
  private

  public :: particle_temperature, particle_initial_field

contains

  !> The temperature of the particles of `material` in step `step` at the given times.
  real(dp) function particle_temperature(m, step, material, step_time, total_time) result(temp)
    type(model_t), intent(in) :: m
    integer, intent(in) :: step, material
    real(dp), intent(in) :: step_time, total_time
    integer :: j

    if (allocated(m%steps(step)%temperatures)) then
       do j = size(m%steps(step)%temperatures), 1, -1
          associate (t => m%steps(step)%temperatures(j))
            if (t%material /= material) cycle
            temp = t%value * variation_factor(t%variation, m%amplitudes, step_time, total_time)
            return
          end associate
       end do
    end if
    temp = particle_initial_field(m, material, 0)
  end function particle_temperature

  !> *INITIAL CONDITIONS of the particles of `material`: field `variable` (0: temperature); the
  !> last entry naming the material counts, 0 without one.
  real(dp) function particle_initial_field(m, material, variable) result(value)
    type(model_t), intent(in) :: m
    integer, intent(in) :: material, variable
    integer :: j

    value = 0
    if (.not. allocated(m%initial_fields)) return
    do j = size(m%initial_fields), 1, -1
       if (m%initial_fields(j)%material == material .and. m%initial_fields(j)%variable == variable) then
          value = m%initial_fields(j)%value
          return
       end if
    end do
  end function particle_initial_field
end module model_particle_fields
