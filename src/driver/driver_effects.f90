!> The element solver's effects: their ids and which of them a scene calls for, declared once
!> from the model before the first increment into the run's registry (output_effects). The
!> driver runs only the active effects: an inactive one is never called, allocates nothing and
!> has no timer, so it shows no time in the report. Output and checkpoints are the run
!> skeleton's effects (src/run).
module driver_effects
  use model, only: model_t
  use output_effects, only: effects_t, first_technique_effect
  implicit none
  private

  integer, parameter, public :: effect_elements = first_technique_effect   !< kinematics and internal forces
  integer, parameter, public :: effect_material = first_technique_effect + 1   !< VUMAT calls
  integer, parameter, public :: effect_user_field = first_technique_effect + 2 !< VUSDFLD calls and the LE they read
  integer, parameter, public :: effect_hourglass = first_technique_effect + 3
  integer, parameter, public :: effect_bulk_viscosity = first_technique_effect + 4
  integer, parameter, public :: effect_gravity = first_technique_effect + 5
  integer, parameter, public :: effect_rigid_walls = first_technique_effect + 6  !< contact with friction
  integer, parameter, public :: effect_boundary = first_technique_effect + 7     !< prescribed displacement/velocity
  integer, parameter, public :: effect_assembly = first_technique_effect + 8     !< force assembly incl. MPI exchange
  integer, parameter, public :: effect_pressure = first_technique_effect + 9     !< *DSLOAD follower pressure

  public :: declare_element_effects

contains

  !> Declare the element solver's effects: those any step of the scene needs are active.
  subroutine declare_element_effects(m, fx)
    type(model_t), intent(in) :: m
    type(effects_t), intent(inout) :: fx
    logical :: user_field, gravity, pressure, bulk, walls, boundary
    integer :: i

    user_field = .false.
    do i = 1, m%n_materials
       if (m%materials(i)%user_field) user_field = .true.
    end do
    gravity = .false.
    pressure = .false.
    bulk = .false.
    walls = .false.
    boundary = .false.
    do i = 1, m%n_steps
       associate (s => m%steps(i))
         if (allocated(s%gravity)) gravity = gravity .or. size(s%gravity) > 0
         if (allocated(s%pressures)) pressure = pressure .or. size(s%pressures) > 0
         bulk = bulk .or. s%bulk_linear > 0 .or. s%bulk_quadratic > 0
         if (allocated(s%contact_pairs)) walls = walls .or. size(s%contact_pairs) > 0
         if (allocated(s%boundaries)) boundary = boundary .or. size(s%boundaries) > 0
       end associate
    end do
    call fx%declare(effect_elements, 'elements', active=m%mesh%n_elems > 0)
    call fx%declare(effect_material, 'material', active=m%mesh%n_elems > 0)
    call fx%declare(effect_user_field, 'user field', active=user_field)
    ! one-point elements always need hourglass control
    call fx%declare(effect_hourglass, 'hourglass', active=m%mesh%n_elems > 0)
    call fx%declare(effect_bulk_viscosity, 'bulk viscosity', active=bulk)
    call fx%declare(effect_gravity, 'gravity', active=gravity)
    call fx%declare(effect_rigid_walls, 'rigid walls', active=walls)
    call fx%declare(effect_boundary, 'boundary', active=boundary)
    call fx%declare(effect_assembly, 'assembly', active=.true.)
    call fx%declare(effect_pressure, 'pressure', active=pressure)
  end subroutine declare_element_effects
end module driver_effects
