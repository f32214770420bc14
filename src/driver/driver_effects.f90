!> The effects registry: which pieces of physics a scene calls for, decided once from the
!> model before the first increment, and the wall time each one costs. The driver runs only
!> the active effects: an inactive one is never called, allocates nothing and has no timer,
!> so it shows no time in the report.
module driver_effects
  use model, only: model_t
  use output_timer, only: timer_set_t, timer_init, timer_register, timer_start, timer_stop
  implicit none
  private

  integer, parameter, public :: effect_elements = 1        !< kinematics and internal forces
  integer, parameter, public :: effect_material = 2        !< VUMAT calls
  integer, parameter, public :: effect_user_field = 3      !< VUSDFLD calls and the LE they read
  integer, parameter, public :: effect_hourglass = 4
  integer, parameter, public :: effect_bulk_viscosity = 5
  integer, parameter, public :: effect_gravity = 6
  integer, parameter, public :: effect_rigid_walls = 7     !< contact with friction
  integer, parameter, public :: effect_boundary = 8        !< prescribed displacement/velocity
  integer, parameter, public :: effect_assembly = 9        !< force assembly incl. MPI exchange
  integer, parameter, public :: effect_output = 10         !< field, history, progress
  integer, parameter, public :: effect_checkpoint = 11
  integer, parameter, public :: effect_pressure = 12       !< *DSLOAD follower pressure
  integer, parameter, public :: n_effects = 12

  character(len=16), parameter, public :: effect_names(n_effects) = [character(len=16) :: &
       'elements', 'material', 'user field', 'hourglass', 'bulk viscosity', 'gravity', &
       'rigid walls', 'boundary', 'assembly', 'output', 'checkpoint', 'pressure']

  type, public :: effects_t
     logical :: active(n_effects) = .false.
     integer :: timer_id(n_effects) = 0
     type(timer_set_t) :: timers
   contains
     procedure :: decide => effects_decide
     procedure :: start => effects_start
     procedure :: stop => effects_stop
     procedure :: active_list => effects_active_list
  end type effects_t

contains

  !> Decide from the scene which effects exist in any step, and give each a timer.
  subroutine effects_decide(this, m)
    class(effects_t), intent(inout) :: this
    type(model_t), intent(in) :: m
    integer :: i

    this%active = .false.
    this%active(effect_elements) = m%mesh%n_elems > 0
    this%active(effect_material) = m%mesh%n_elems > 0
    ! One-point elements always need hourglass control.
    this%active(effect_hourglass) = m%mesh%n_elems > 0
    this%active(effect_assembly) = .true.
    this%active(effect_output) = .true.
    do i = 1, m%n_materials
       if (m%materials(i)%user_field) this%active(effect_user_field) = .true.
    end do
    do i = 1, m%n_steps
       associate (s => m%steps(i))
         if (allocated(s%gravity)) then
            if (size(s%gravity) > 0) this%active(effect_gravity) = .true.
         end if
         if (allocated(s%pressures)) then
            if (size(s%pressures) > 0) this%active(effect_pressure) = .true.
         end if
         if (s%bulk_linear > 0 .or. s%bulk_quadratic > 0) this%active(effect_bulk_viscosity) = .true.
         if (allocated(s%contact_pairs)) then
            if (size(s%contact_pairs) > 0) this%active(effect_rigid_walls) = .true.
         end if
         if (allocated(s%boundaries)) then
            if (size(s%boundaries) > 0) this%active(effect_boundary) = .true.
         end if
         if (s%restart_write) this%active(effect_checkpoint) = .true.
       end associate
    end do
    call timer_init(this%timers)
    do i = 1, n_effects
       if (this%active(i)) call timer_register(this%timers, trim(effect_names(i)), this%timer_id(i))
    end do
  end subroutine effects_decide

  subroutine effects_start(this, id)
    class(effects_t), intent(inout) :: this
    integer, intent(in) :: id
    call timer_start(this%timers, this%timer_id(id))
  end subroutine effects_start

  subroutine effects_stop(this, id)
    class(effects_t), intent(inout) :: this
    integer, intent(in) :: id
    call timer_stop(this%timers, this%timer_id(id))
  end subroutine effects_stop

  !> "elements, material, gravity, ..." — the active effects, for the run header.
  function effects_active_list(this) result(text)
    class(effects_t), intent(in) :: this
    character(len=:), allocatable :: text
    integer :: i

    text = ''
    do i = 1, n_effects
       if (.not. this%active(i)) cycle
       if (len(text) > 0) text = text // ', '
       text = text // trim(effect_names(i))
    end do
  end function effects_active_list
end module driver_effects
