!> Analysis steps (*STEP ... *END STEP) with everything active in them. The model builder
!> resolves Abaqus's propagation rules (boundary conditions, loads, contact pairs and output
!> requests carry over to later steps unless replaced with OP=NEW or removed with OP=DELETE;
!> a carried condition's time variation follows model_time_variation), so each step_t holds
!> its complete active set and the driver never looks back.
module model_steps
  use base_kinds, only: dp
  use model_sets, only: name_length
  use model_time_variation, only: time_variation_t
  implicit none
  private

  integer, parameter, public :: bc_displacement = 1
  integer, parameter, public :: bc_velocity = 2

  !> *BOUNDARY on nodes: dofs first_dof..last_dof (1..ndim) fixed to `value` times the
  !> time variation's factor (displacement: total displacement; velocity: velocity).
  type, public :: boundary_t
     integer, allocatable :: nodes(:)         !< internal node indices
     integer :: first_dof = 1, last_dof = 1
     integer :: kind = bc_displacement
     real(dp) :: value = 0
     type(time_variation_t) :: variation      !< amplitude, or held from an earlier step
     character(len=256) :: source = ''
  end type boundary_t

  !> *DLOAD, GRAV: body force g·direction on the elements of a set (0: all elements).
  type, public :: gravity_t
     integer :: elset = 0
     real(dp) :: magnitude = 0
     real(dp) :: direction(3) = 0
     type(time_variation_t) :: variation      !< amplitude, or held from an earlier step
     character(len=256) :: source = ''        !< file:line of the *DLOAD data line
  end type gravity_t

  !> *TEMPERATURE in a step (a predefined field): the temperature of nodes (MPM: of the particles
  !> of a material) is `value` times the time variation's factor; nodes it does not name keep
  !> their initial temperature. Several entries naming a node: the last one counts.
  type, public :: temperature_t
     integer, allocatable :: nodes(:)         !< internal node indices (empty in MPM scenes)
     integer :: material = 0                  !< MPM: the particles of this material
     real(dp) :: value = 0
     type(time_variation_t) :: variation      !< amplitude, or held from an earlier step
     character(len=256) :: source = ''
  end type temperature_t
  !> *DSLOAD, P: uniform pressure on the faces of an element surface (a follower load, on the
  !> current geometry; positive pushes into the elements, as in Abaqus).
  type, public :: pressure_t
     integer :: surface = 0                   !< element surface index (model%element_surfaces)
     real(dp) :: magnitude = 0
     type(time_variation_t) :: variation      !< amplitude, or held from an earlier step
     character(len=256) :: source = ''        !< file:line of the *DSLOAD data line
  end type pressure_t

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
  !> equal intervals of the step, every `time_interval` or every `frequency` increments (one > 0).
  type, public :: field_output_t
     integer :: number_interval = 0
     real(dp) :: time_interval = 0
     integer :: frequency = 0                 !< FREQUENCY=n: every n increments of the step (and its end)
     real(dp), allocatable :: time_points(:)  !< TIME POINTS=: at these step times exactly (increments cut)
     character(len=8), allocatable :: node_variables(:)     !< U, V, A, RF
     character(len=8), allocatable :: element_variables(:)  !< S, LE, PE, PEEQ, SDV, FV, STATUS
  end type field_output_t

  !> History output (*OUTPUT, HISTORY + *ENERGY OUTPUT / *NODE OUTPUT, NSET=...).
  type, public :: history_output_t
     real(dp) :: time_interval = 0            !< 0: every increment
     integer :: number_interval = 0
     integer :: frequency = 0                 !< FREQUENCY=n: every n increments of the step (and its end)
     real(dp), allocatable :: time_points(:)  !< TIME POINTS=: at these step times exactly (increments cut)
     logical :: energies = .false.            !< ALLKE ALLIE ALLVD ALLFD ALLWK ALLAE ETOTAL
     integer :: nset = 0                      !< node set for per-set sums, 0: none
     character(len=8), allocatable :: node_variables(:)     !< e.g. RF1, RF2, U2, V2 summed/averaged over nset
  end type history_output_t

  integer, parameter, public :: mass_scaling_below_min = 1
  integer, parameter, public :: mass_scaling_uniform = 2

  !> *FIXED MASS SCALING: element masses scaled once at the start of the step that defines it
  !> (first by `factor`, then, with dt > 0, to reach the element stable increment dt: only the
  !> elements below it (BELOW MIN) or all by one factor (UNIFORM)). Abaqus's semantics: a step
  !> without its own definition keeps the scaled masses of the step before.
  type, public :: mass_scaling_t
     integer :: elset = 0                     !< element set, 0: all elements
     real(dp) :: factor = 1
     real(dp) :: dt = 0                       !< target element stable increment, 0: none
     integer :: kind = mass_scaling_below_min
  end type mass_scaling_t

  !> *STOP CONDITION (ours): end the run early once the step's outcome is clear. FLOW: the largest
  !> displacement since the step start over the node set exceeds `displacement`; ARREST (from
  !> `min_time` on, the displacement still below the limit): the kinetic energy stays below
  !> `ke_fraction` of its peak in the step for `hold` step time, or the largest displacement grows
  !> by at most `growth` × `displacement` over a window of `hold` step time.
  type, public :: stop_condition_t
     logical :: active = .false.
     integer :: nset = 0
     real(dp) :: displacement = 0
     real(dp) :: ke_fraction = 0.01_dp
     real(dp) :: hold = 0
     real(dp) :: min_time = 0
     real(dp) :: growth = 0.05_dp
  end type stop_condition_t

  type, public :: step_t
     character(len=name_length) :: name = ''
     real(dp) :: period = 0                   !< *DYNAMIC, EXPLICIT time period (> 0)
     real(dp) :: dt_fixed = 0                 !< > 0: fixed increment (DIRECT USER CONTROL)
     real(dp) :: dt_scale = 1                 !< scale factor on the stable increment
     real(dp) :: bulk_linear = 0.06_dp        !< *BULK VISCOSITY b1
     real(dp) :: bulk_quadratic = 1.2_dp      !< *BULK VISCOSITY b2
     type(boundary_t), allocatable :: boundaries(:)
     type(gravity_t), allocatable :: gravity(:)
     type(temperature_t), allocatable :: temperatures(:)
     type(pressure_t), allocatable :: pressures(:)
     type(contact_pair_t), allocatable :: contact_pairs(:)
     type(field_output_t), allocatable :: field_outputs(:)
     type(history_output_t), allocatable :: history_outputs(:)
     real(dp) :: restart_interval = 0         !< *RESTART, WRITE: checkpoint every this much step time (0: at step end only if requested)
     logical :: restart_write = .false.
     !> Mass scaling active in the step (inherited or its own); recomputed at the step start only
     !> when the step defines it (`mass_scaling_defined`).
     type(mass_scaling_t), allocatable :: mass_scaling(:)
     logical :: mass_scaling_defined = .false.
     type(stop_condition_t) :: stop
     character(len=256) :: source = ''
  end type step_t
end module model_steps
