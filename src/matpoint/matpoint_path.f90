!> The loading path of a material-point test: initial state and a list of stages.
!>
!> In every stage each stress/strain component (VUMAT order 11,22,33,12[,23,31]) is
!> either strain-controlled (the stage prescribes its total increment, applied in equal
!> parts per increment; shear as a TENSOR component, like the VUMAT strainInc) or
!> stress-controlled (the stage prescribes the stress at its end, reached by a linear
!> ramp from the stage-start value; "hold" keeps the stage-start value). The mixed-control
!> solver (matpoint_solver) finds the strains of the stress-controlled components.
!>
!> The laboratory tests are presets mapped onto that general form (`preset_stage`); the
!> vertical/axial direction is `axis` (default 2, i.e. y, as in our plane-strain models
!> whose out-of-plane direction is 3). Stresses are in the Abaqus sign (tension positive).
module matpoint_path
  use base_kinds, only: dp
  use model, only: model_t
  use model_particle_fields, only: particle_temperature
  implicit none
  private

  integer, parameter, public :: max_components = 6

  integer, parameter, public :: control_strain = 1       !< value: strain increment of the stage
  integer, parameter, public :: control_stress = 2       !< value: stress at the end of the stage
  integer, parameter, public :: control_stress_hold = 3  !< stress kept at its stage-start value

  integer, parameter, public :: test_general = 0
  integer, parameter, public :: test_triaxial = 1
  integer, parameter, public :: test_biaxial = 2
  integer, parameter, public :: test_simple_shear = 3
  integer, parameter, public :: test_oedometer = 4
  integer, parameter, public :: test_isotropic = 5

  !> Names as written on `*TEST, TYPE=`.
  character(len=12), parameter, public :: test_names(0:5) = [character(len=12) :: &
       'GENERAL', 'TRIAXIAL', 'BIAXIAL', 'SIMPLE SHEAR', 'OEDOMETER', 'ISOTROPIC']

  !> Component of the shear strain driven in simple shear (12) and of the normal stress held.
  integer, parameter, public :: simple_shear_component = 4
  integer, parameter, public :: simple_shear_normal = 2

  type, public :: matpoint_stage_t
     integer :: n_increments = 1
     real(dp) :: duration = 1.0_dp
     integer :: control(max_components) = control_strain
     real(dp) :: value(max_components) = 0.0_dp
     character(len=:), allocatable :: file   !< where the stage was defined (messages)
     integer :: line = 0
  end type matpoint_stage_t

  type, public :: matpoint_path_t
     integer :: test = test_general
     integer :: ndim = 3                     !< 3: 3D (6 components); 2: plane strain (4)
     integer :: axis = 2                     !< axial direction of triaxial/biaxial/oedometer
     real(dp) :: initial_stress(max_components) = 0.0_dp
     real(dp), allocatable :: initial_state(:)   !< first SDVs (rest zero)
     real(dp), allocatable :: initial_field(:)   !< first field variables (rest zero)
     real(dp) :: temperature = 0.0_dp            !< *INITIAL CONDITIONS, TYPE=TEMPERATURE
     !> The predefined temperature in time, as a material-point (MPM) scene holds it: the one
     !> material, the *AMPLITUDE curves, one step whose *TEMPERATURE entries name the material,
     !> and the initial temperature; evaluated by the scene's own code (temperature_at).
     type(model_t) :: predefined
     integer :: n_stages = 0
     type(matpoint_stage_t), allocatable :: stages(:)
     real(dp) :: tolerance = 1.0e-12_dp      !< mixed control: relative to the stress scale
     integer :: max_iterations = 50
   contains
     procedure :: ncomp => path_ncomp
     procedure :: add_stage => path_add_stage
     procedure :: lateral => path_lateral
     procedure :: temperature_at => path_temperature_at
  end type matpoint_path_t

  public :: component_label, test_from_name, default_dimension, preset_stage

contains

  pure integer function path_ncomp(self)
    class(matpoint_path_t), intent(in) :: self

    path_ncomp = merge(4, 6, self%ndim == 2)
  end function path_ncomp

  !> First direct component other than the axis (the "horizontal" one in the oedometer).
  pure integer function path_lateral(self)
    class(matpoint_path_t), intent(in) :: self

    path_lateral = merge(2, 1, self%axis == 1)
  end function path_lateral

  !> The point's temperature at time t of the path (one Abaqus step: step time = total time):
  !> the last *TEMPERATURE entry, value × a(t), else the initial temperature
  !> (model_particle_fields, the MPM scenes' evaluation).
  real(dp) function path_temperature_at(self, t) result(temp)
    class(matpoint_path_t), intent(in) :: self
    real(dp), intent(in) :: t

    temp = self%temperature
    if (.not. allocated(self%predefined%steps)) return
    temp = particle_temperature(self%predefined, 1, 1, t, t)
  end function path_temperature_at

  subroutine path_add_stage(self, stage)
    class(matpoint_path_t), intent(inout) :: self
    type(matpoint_stage_t), intent(in) :: stage
    type(matpoint_stage_t), allocatable :: tmp(:)

    if (.not. allocated(self%stages)) allocate (self%stages(0))
    allocate (tmp(self%n_stages + 1))
    tmp(1:self%n_stages) = self%stages(1:self%n_stages)
    tmp(self%n_stages + 1) = stage
    call move_alloc(tmp, self%stages)
    self%n_stages = self%n_stages + 1
  end subroutine path_add_stage

  !> '11', '22', '33', '12', '23', '31'.
  pure function component_label(i) result(label)
    integer, intent(in) :: i
    character(len=2) :: label
    character(len=2), parameter :: labels(max_components) = ['11', '22', '33', '12', '23', '31']

    label = '??'
    if (i >= 1 .and. i <= max_components) label = labels(i)
  end function component_label

  !> Test code from its name; -1 when unknown.
  pure integer function test_from_name(name)
    character(len=*), intent(in) :: name
    integer :: k

    test_from_name = -1
    do k = lbound(test_names, 1), ubound(test_names, 1)
       if (trim(name) == trim(test_names(k))) test_from_name = k
    end do
  end function test_from_name

  !> Dimension used when *TEST gives none: plane strain for the plane tests.
  pure integer function default_dimension(test)
    integer, intent(in) :: test

    select case (test)
    case (test_biaxial, test_simple_shear)
       default_dimension = 2
    case default
       default_dimension = 3
    end select
  end function default_dimension

  !> Controls of one stage of a preset test.
  !> `strain`: the driven amount — axial strain (triaxial, biaxial, oedometer), engineering
  !> shear strain γ = 2ε12 (simple shear), volumetric strain (isotropic, split equally).
  !> `stress`: the held stress at the end of the stage — lateral stress (triaxial,
  !> biaxial), normal stress σ22 (simple shear), each direct stress (isotropic); when
  !> absent the held stresses keep their stage-start values.
  !> On a bad combination `message` is non-empty and says why.
  pure subroutine preset_stage(path, n_increments, stage, message, strain, stress)
    type(matpoint_path_t), intent(in) :: path
    integer, intent(in) :: n_increments
    type(matpoint_stage_t), intent(inout) :: stage
    character(len=:), allocatable, intent(out) :: message
    real(dp), intent(in), optional :: strain, stress
    integer :: held, i, ncomp

    message = ''
    ncomp = path%ncomp()
    stage%n_increments = n_increments
    stage%control = control_strain
    stage%value = 0.0_dp
    held = control_stress_hold
    if (present(stress)) held = control_stress

    select case (path%test)
    case (test_triaxial, test_biaxial)
       if (.not. present(strain)) then
          message = 'a ' // trim(test_names(path%test)) // ' stage needs STRAIN (axial strain)'
          return
       end if
       stage%value(path%axis) = strain
       do i = 1, merge(2, 3, path%ndim == 2)
          if (i == path%axis) cycle
          stage%control(i) = held
          if (present(stress)) stage%value(i) = stress
       end do
    case (test_simple_shear)
       if (.not. present(strain)) then
          message = 'a SIMPLE SHEAR stage needs STRAIN (engineering shear strain gamma)'
          return
       end if
       stage%value(simple_shear_component) = 0.5_dp * strain
       stage%control(simple_shear_normal) = held
       if (present(stress)) stage%value(simple_shear_normal) = stress
    case (test_oedometer)
       if (.not. present(strain)) then
          message = 'an OEDOMETER stage needs STRAIN (axial strain)'
          return
       end if
       if (present(stress)) then
          message = 'an OEDOMETER stage is strain-controlled only: STRESS is not allowed'
          return
       end if
       stage%value(path%axis) = strain
    case (test_isotropic)
       if (present(strain) .eqv. present(stress)) then
          message = 'an ISOTROPIC stage needs exactly one of STRAIN (volumetric strain) ' // &
               'and STRESS (direct stress at the end of the stage)'
          return
       end if
       do i = 1, 3
          if (present(strain)) then
             stage%value(i) = strain / 3.0_dp
          else
             stage%control(i) = control_stress
             stage%value(i) = stress
          end if
       end do
    case default
       message = 'a GENERAL stage gives its controls on data lines'
       return
    end select
    ! components beyond ncomp do not exist in plane strain
    stage%control(ncomp + 1:) = control_strain
    stage%value(ncomp + 1:) = 0.0_dp
  end subroutine preset_stage

end module matpoint_path
