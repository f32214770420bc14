!> The material-point part of a scene (bulkflow's own keywords, docs/keywords.md "MPM"):
!> background grid, particle regions, rigid walls, outflow and inflow, and the MPM controls of
!> each step. Filled and checked by src/input/scene_mpm.f90; read by src/mpm/mpm_run.f90.
!> Only data here: the model keeps one `mpm_scene_t`, inactive unless the scene has *MPM GRID.
module mpm_scene
  use base_kinds, only: dp
  implicit none
  private

  integer, parameter, public :: shape_linear = 1      !< standard MPM hat functions
  integer, parameter, public :: shape_gimp = 2        !< uGIMP (particle domain kept, not stretched)
  integer, parameter, public :: decomposition_replicated = 1, decomposition_spatial = 2

  integer, parameter, public :: region_box = 1
  integer, parameter, public :: region_polygon = 2    !< 2D polygon; in 3D extruded over z1..z2

  integer, parameter, public :: wall_friction = 1     !< unilateral contact with Coulomb friction
  integer, parameter, public :: wall_symmetry = 2     !< bilateral, frictionless (v·n = 0)

  integer, parameter, public :: wall_name_length = 80

  !> *PARTICLES: a region filled with a regular lattice of PPC particles per cell direction.
  type, public :: particle_region_t
     integer :: material = 0                !< index into model%materials
     integer :: kind = region_box
     integer :: ppc = 2                     !< particles per cell and direction
     real(dp) :: lo(3) = 0, hi(3) = 0       !< box (and the z range of an extruded polygon)
     real(dp), allocatable :: polygon(:, :) !< (2, n_vertices)
     real(dp) :: velocity(3) = 0            !< initial velocity
     character(len=256) :: source = ''
  end type particle_region_t

  !> *MPM WALL: a rigid, fixed wall. 2D: the segment p0 -> p1, material on its left (as Abaqus
  !> TYPE=SEGMENTS); 3D: the plane through p0 with unit normal n into the material, limited to
  !> the box lo..hi when given. Active in the steps flagged in `active(step)`.
  !> A wall with `surface` > 0 is instead a rigid surface of the model (*SURFACE, TYPE=SEGMENTS
  !> or PLANE, paired with the particles by *CONTACT PAIR): its geometry (lines, arcs, plane)
  !> and its motion (the *RIGID BODY reference node) come from model%rigid_surfaces(surface);
  !> p0, p1, normal, reach and the box are not used.
  type, public :: mpm_wall_t
     character(len=wall_name_length) :: name = ''
     integer :: kind = wall_friction
     real(dp) :: friction = 0               !< Coulomb μ = tan δ_w
     real(dp) :: reach = 0                  !< nodes up to reach·h in front of the wall are constrained too
     !> OPEN=START|END|BOTH (2D): at an open end the wall holds the particles, not the grid nodes
     !> whose support reaches past the end (mpm_wall_edges). 3D (OPEN=XLOW ... ZHIGH): the wall's
     !> box face on axis open_axis, its low (open_start) or high (open_end) side
     logical :: open_start = .false., open_end = .false.
     integer :: open_axis = 0               !< 0: 2D, along p0 -> p1; 1..3: 3D, the box's axis
     real(dp) :: p0(3) = 0, p1(3) = 0
     real(dp) :: normal(3) = 0              !< unit, into the material
     logical :: bounded = .false.           !< 3D: limited to lo..hi
     real(dp) :: lo(3) = 0, hi(3) = 0
     logical, allocatable :: active(:)      !< per step
     character(len=256) :: source = ''
     integer :: surface = 0                 !< > 0: index into model%rigid_surfaces (a rigid-surface wall)
  end type mpm_wall_t

  !> *INFLOW of a step: keep the free surface at `level` (along the vertical axis) over the
  !> band lo..hi of the other coordinate(s) by adding layers of particles of `material`.
  type, public :: mpm_inflow_t
     logical :: on = .false.
     integer :: material = 0
     integer :: ppc = 2
     real(dp) :: level = 0
     real(dp) :: lo(3) = 0, hi(3) = 0
  end type mpm_inflow_t

  !> MPM controls of one step (*MPM CONTROLS carries over to later steps until repeated).
  type, public :: mpm_step_t
     real(dp) :: flip = 0.99_dp             !< PIC/FLIP blend α (1: FLIP, 0: PIC) of every increment
     !> *MPM CONTROLS, PIC TIME=τ: the blend as a rate, α = exp(-Δt/τ) in an increment Δt, so the
     !> PIC part's damping per second does not depend on Δt (0: off, the fixed α above)
     real(dp) :: pic_time = 0
     real(dp) :: cfl = 0.3_dp               !< Δt = cfl h / max(c + |v|)
     real(dp) :: damping = 0                !< local non-viscous damping coefficient on the grid
     !> particles sorted by cell every `sort` increments, P2G and remap particle by particle
     !> (src/mpm/mpm_sort.f90); 0: block order and node-major sums (the results of before, bit for bit)
     integer :: sort = 0
     !> *MPM SIDE FRICTION: Coulomb μw of the front and back walls a gap side_gap apart (2D; 0: off)
     real(dp) :: side_friction = 0, side_gap = 0
     !> *MPM CONTROLS, MAX DILATION=j: a particle's volume ratio J = det F is held at most j by an
     !> isotropic scaling of its F (in plane in 2D) after its stress update (0: off; docs/keywords.md)
     real(dp) :: max_dilation = 0
     type(mpm_inflow_t) :: inflow
  end type mpm_step_t

  !> *NONLOCAL: a length scale for the particles' softening (docs/nonlocal.md). Field variable
  !> `field` of the VUSDFLD of the chosen materials is replaced, before the VUMAT reads it, by its
  !> average over the particles of the same material within `length` (bell-shaped weight).
  type, public :: mpm_nonlocal_t
     logical :: on = .false.
     real(dp) :: length = 0                 !< radius of the weight's support
     integer :: field = 1                   !< field variable number averaged (FVn)
     integer :: material = 0                !< index into model%materials; 0: every material with a user field
     character(len=256) :: source = ''      !< file:line of the keyword (messages)
  end type mpm_nonlocal_t

  type, public :: mpm_scene_t
     logical :: active = .false.
     integer :: ndim = 0
     integer :: shape = shape_gimp
     real(dp) :: cell = 0                   !< grid spacing h (all directions)
     real(dp) :: lo(3) = 0, hi(3) = 0       !< grid box (node lines at lo + i h)
     integer :: vertical = 2                !< axis of "up" for outflow/inflow (2 in 2D, AXIS= in 3D)
     type(particle_region_t), allocatable :: regions(:)
     type(mpm_wall_t), allocatable :: walls(:)
     logical :: outflow = .false.
     real(dp) :: outflow_level = 0          !< particles below this (vertical axis) leave
     type(mpm_step_t), allocatable :: steps(:)
     !> grid over MPI ranks: replicated (every rank the whole grid) or spatial (mpm_domain)
     integer :: decomposition = decomposition_replicated
     real(dp) :: rebalance = 0.02_dp         !< spatial: re-partition when max/mean − 1 of counts exceeds it
     type(mpm_nonlocal_t) :: nonlocal
  end type mpm_scene_t
end module mpm_scene
