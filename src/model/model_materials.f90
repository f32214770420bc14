!> Materials and sections. Every material reaches the solver as a VUMAT call: built-in
!> keywords (*ELASTIC, *MOHR COULOMB, *DRUCKER PRAGER, ...) are translated by the model
!> builder into the name and props of our own VUMATs (umat/README.md); *USER MATERIAL keeps
!> the user's name and constants.
module model_materials
  use base_kinds, only: dp
  use model_sets, only: name_length
  implicit none
  private

  !> Hourglass control of a section (*SECTION CONTROLS): the codes the element kernels take
  !> (fem_hourglass re-exports them) and the default coefficients when HOURGLASS SCALING is 1.
  integer, parameter, public :: hourglass_none = 0
  integer, parameter, public :: hourglass_viscous = 1
  integer, parameter, public :: hourglass_stiffness = 2
  real(dp), parameter, public :: default_hourglass_viscous_coefficient = 0.1_dp
  real(dp), parameter, public :: default_hourglass_stiffness_coefficient = 0.05_dp

  type, public :: material_t
     character(len=name_length) :: name = ''     !< the scene's name, upper case
     character(len=80) :: vumat_name = ''        !< cmname handed to vumat/vusdfld
     real(dp) :: density = 0
     real(dp), allocatable :: props(:)
     integer :: nstatev = 0                      !< *DEPVAR
     !> The first state variable a user's VUSDFLD sees: 1, except on our built-in plastic models,
     !> whose own SDVs come first (umat/README.md) and are not the VUSDFLD's (Abaqus gives it the
     !> *DEPVAR ones only: SDV first..nstatev).
     integer :: user_state_first = 1
     !> Output names of the state variables from *DEPVAR lines ('' where none given)
     character(len=name_length), allocatable :: sdv_names(:)
     integer :: nfieldv = 0                      !< 1 with *USER DEFINED FIELD (field 1), else 0
     logical :: user_field = .false.             !< call vusdfld before vumat
     !> *USER DEFINED FIELD, PROPERTIES=n constants: the vusdfld's props (Abaqus). Without them
     !> the vusdfld receives the material's props (bulkflow's convention before PROPERTIES=).
     real(dp), allocatable :: field_props(:)
     logical :: user_material = .false.          !< props come from *USER MATERIAL
     !> The --user library's vumat (a *USER MATERIAL with a user file loaded), not ours.
     logical :: user_code = .false.
     !> The --user library's vusdfld (*USER DEFINED FIELD with a user file defining VUSDFLD).
     logical :: user_field_code = .false.
     character(len=256) :: source = ''           !< file:line of *MATERIAL, for messages
  end type material_t

  !> *SOLID SECTION, ELSET=..., MATERIAL=... (data line: thickness for plane strain, default 1),
  !> with its hourglass control.
  type, public :: section_t
     character(len=name_length) :: elset = ''
     integer :: material = 0                     !< index into model%materials
     real(dp) :: thickness = 1
     !> Hourglass control (*SECTION CONTROLS, HOURGLASS=VISCOUS|STIFFNESS, HOURGLASS SCALING):
     !> hourglass_viscous or hourglass_stiffness; coefficient 0 means the default.
     integer :: hourglass = hourglass_viscous
     real(dp) :: hourglass_coefficient = 0
  end type section_t
end module model_materials
