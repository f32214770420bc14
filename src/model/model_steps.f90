!> Analysis steps (*STEP ... *END STEP) with everything active in them. The model builder
!> resolves Abaqus's propagation rules (boundary conditions, loads, contact pairs and output
!> requests carry over to later steps unless replaced with OP=NEW or removed with OP=DELETE),
!> so each step_t holds its complete active set and the driver never looks back.
module model_steps
  use material_kinds, only: dp
  use model_sets, only: name_length
  implicit none
  private

  integer, parameter, public :: bc_displacement = 1
  integer, parameter, public :: bc_velocity = 2

  !> *BOUNDARY on nodes: dofs first_dof..last_dof (1..ndim) fixed to `value` times the
  !> amplitude (displacement: total displacement; velocity: velocity).
  type, public :: boundary_t
     integer, allocatable :: nodes(:)         !< internal node indices
     integer :: first_dof = 1, last_dof = 1
     integer :: kind = bc_displacement
     real(dp) :: value = 0
     integer :: amplitude = 0                 !< index into model%amplitudes, 0: ramp-free constant
     character(len=256) :: source = ''
  end type boundary_t

  !> *DLOAD, GRAV: body force g·direction on the elements of a set (0: all elements).
  type, public :: gravity_t
     integer :: elset = 0
     real(dp) :: magnitude = 0
     real(dp) :: direction(3) = 0
     integer :: amplitude = 0
  end type gravity_t

  !> *SURFACE INTERACTION + *FRICTION.
  type, public :: interaction_t
     character(len=name_length) :: name = ''
     real(dp) :: friction = 0                 !< Coulomb coefficient μ
  end type interaction_t

  !> *CONTACT PAIR, INTERACTION=...: slave element surface (or node set) against a rigid surface.
  type, public :: contact_pair_t
     integer :: slave_surface = 0             !< index into model%element_surfaces
     integer :: rigid_surface = 0             !< index into model%rigid_surfaces
     integer :: interaction = 0               !< index into model%interactions
  end type contact_pair_t

  !> Field output (*OUTPUT, FIELD + *NODE OUTPUT / *ELEMENT OUTPUT): at `number_interval`
  !> equal intervals of the step or every `time_interval` (one of them > 0).
  type, public :: field_output_t
     integer :: number_interval = 0
     real(dp) :: time_interval = 0
     character(len=8), allocatable :: node_variables(:)     !< U, V, A, RF
     character(len=8), allocatable :: element_variables(:)  !< S, LE, PE, PEEQ, SDV, FV, STATUS
  end type field_output_t

  !> History output (*OUTPUT, HISTORY + *ENERGY OUTPUT / *NODE OUTPUT, NSET=...).
  type, public :: history_output_t
     real(dp) :: time_interval = 0            !< 0: every increment
     integer :: number_interval = 0
     logical :: energies = .false.            !< ALLKE ALLIE ALLVD ALLFD ALLWK ALLAE ETOTAL
     integer :: nset = 0                      !< node set for per-set sums, 0: none
     character(len=8), allocatable :: node_variables(:)     !< e.g. RF1, RF2, U2, V2 summed/averaged over nset
  end type history_output_t

  type, public :: step_t
     character(len=name_length) :: name = ''
     real(dp) :: period = 0                   !< *DYNAMIC, EXPLICIT time period (> 0)
     real(dp) :: dt_fixed = 0                 !< > 0: fixed increment (DIRECT USER CONTROL)
     real(dp) :: dt_scale = 1                 !< scale factor on the stable increment
     real(dp) :: bulk_linear = 0.06_dp        !< *BULK VISCOSITY b1
     real(dp) :: bulk_quadratic = 1.2_dp      !< *BULK VISCOSITY b2
     type(boundary_t), allocatable :: boundaries(:)
     type(gravity_t), allocatable :: gravity(:)
     type(contact_pair_t), allocatable :: contact_pairs(:)
     type(field_output_t), allocatable :: field_outputs(:)
     type(history_output_t), allocatable :: history_outputs(:)
     real(dp) :: restart_interval = 0         !< *RESTART, WRITE: checkpoint every this much step time (0: at step end only if requested)
     logical :: restart_write = .false.
     character(len=256) :: source = ''
  end type step_t
end module model_steps
