!> The whole scene as the solver needs it, built and checked by the input layer before the
!> first increment (nothing is read or resolved later): mesh, sets, surfaces, materials,
!> sections, amplitudes, interactions, initial conditions and steps.
module model
  use base_kinds, only: dp
  use model_mesh, only: mesh_t
  use model_sets, only: index_set_t, name_length
  use model_surfaces, only: element_surface_t, rigid_surface_t
  use model_materials, only: material_t, section_t
  use model_amplitudes, only: amplitude_t
  use model_steps, only: step_t, interaction_t
  use mpm_scene, only: mpm_scene_t
  use model_digest, only: scene_digest_t
  implicit none
  private

  !> *INITIAL CONDITIONS, TYPE=VELOCITY on nodes.
  type, public :: initial_velocity_t
     integer, allocatable :: nodes(:)
     integer :: dof = 1
     real(dp) :: value = 0
  end type initial_velocity_t

  !> *INITIAL CONDITIONS, TYPE=STRESS on elements: components in VUMAT order.
  type, public :: initial_stress_t
     integer, allocatable :: elems(:)
     real(dp) :: stress(6) = 0
  end type initial_stress_t

  !> *INITIAL CONDITIONS, TYPE=FIELD (VARIABLE=n) or TYPE=TEMPERATURE (variable 0) on nodes
  !> (element values are nodal means) or, in MPM scenes, on the particles of a material.
  type, public :: initial_field_t
     integer, allocatable :: nodes(:)
     integer :: material = 0                  !< MPM scenes: the particles of this material
     integer :: variable = 1
     real(dp) :: value = 0
  end type initial_field_t

  type, public :: model_t
     character(len=256) :: heading = ''
     character(len=1024) :: input_file = ''
     type(mesh_t) :: mesh
     integer :: n_nsets = 0, n_elsets = 0
     type(index_set_t), allocatable :: nsets(:), elsets(:)
     integer :: n_element_surfaces = 0, n_rigid_surfaces = 0
     type(element_surface_t), allocatable :: element_surfaces(:)
     type(rigid_surface_t), allocatable :: rigid_surfaces(:)
     integer :: n_materials = 0, n_sections = 0, n_amplitudes = 0, n_interactions = 0
     type(material_t), allocatable :: materials(:)
     type(section_t), allocatable :: sections(:)
     type(amplitude_t), allocatable :: amplitudes(:)
     type(interaction_t), allocatable :: interactions(:)
     type(initial_velocity_t), allocatable :: initial_velocities(:)
     type(initial_stress_t), allocatable :: initial_stresses(:)
     type(initial_field_t), allocatable :: initial_fields(:)
     integer :: n_steps = 0
     type(step_t), allocatable :: steps(:)
     type(mpm_scene_t) :: mpm                 !< material-point part (active with *MPM GRID)
     type(scene_digest_t) :: digest           !< the deck's lines, hashed (restarts check it)
     character(len=1024), allocatable :: warnings(:)  !< "file:line: what" found while building
     character(len=512), allocatable :: notes(:)  !< `file:line: note: ...` for keywords accepted but not acted on
  end type model_t

  public :: name_length
end module model
