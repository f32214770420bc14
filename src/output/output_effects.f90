!> The effects registry of a run, the same for every technique: which pieces of physics the scene
!> calls for (decided once, before the first increment), their names, the wall time of each, the
!> header's "effects" line and the timing table of the end report.
!>
!> A technique names its effects by integer ids of its own (module constants) and declares each
!> once in its set-up, in the order the header and the table list them:
!>
!>   call fx%declare(fx_walls, 'walls', active=size(m%mpm%walls) > 0)
!>   call fx%declare(fx_gravity, 'gravity', active=..., timed=.false.)   ! listed, timed inside another
!>   if (fx%active(fx_walls)) then; call fx%start(fx_walls); ...; call fx%stop(fx_walls); end if
!>
!> Adding an effect is its id constant and one declare line. Ids 1 and 2 are the run skeleton's
!> (output and checkpoint, declared by src/run's loop after the technique's own); a technique's
!> ids start at first_technique_effect. An inactive effect is never called, has no timer and
!> shows nowhere; an active one "timed=.false." (it runs inside another effect's loop) is listed
!> in the header but has no row in the table.
!> Why here (src/output, a service) and not in src/run: the techniques time their effects inside
!> their own phases (the material call within the element block loop), so the registry must sit
!> below the techniques; src/run (above them) owns the registry of a run (technique_t%effects)
!> and the output and checkpoint effects, and prints the table.
module output_effects
  use mpi_f08, only: MPI_Comm
  use output_timer, only: timer_set_t, timer_init, timer_register, timer_start, timer_stop, timer_report
  use error_report, only: raise_error
  implicit none
  private

  integer, parameter, public :: effect_output = 1       !< field frames, history rows (the skeleton's)
  integer, parameter, public :: effect_checkpoint = 2   !< checkpoints (the skeleton's)
  integer, parameter, public :: first_technique_effect = 3
  integer, parameter :: name_length = 32

  type, public :: effects_t
     !> by effect id: is the effect in this scene (an undeclared id within the size is .false.)
     logical, allocatable :: active(:)
     integer, allocatable :: timer(:)      !< by id: the timer of an active timed effect, else 0
     character(len=name_length), allocatable :: names(:)   !< by id
     integer, allocatable :: order(:)      !< ids in the order of their declaration
     integer :: n_declared = 0
     type(timer_set_t) :: timers
   contains
     procedure :: init => effects_init
     procedure :: declare => effects_declare
     procedure :: start => effects_start
     procedure :: stop => effects_stop
     procedure :: active_list => effects_active_list
     procedure :: header_line => effects_header_line
     procedure :: report => effects_report
  end type effects_t

contains

  !> Forget every effect and start the run's clock (the table's "total" counts from here).
  subroutine effects_init(this)
    class(effects_t), intent(inout) :: this

    if (allocated(this%active)) deallocate (this%active, this%timer, this%names, this%order)
    allocate (this%active(16), this%timer(16), this%names(16), this%order(16))
    this%active = .false.
    this%timer = 0
    this%names = ''
    this%order = 0
    this%n_declared = 0
    call timer_init(this%timers)
  end subroutine effects_init

  !> Declare effect `id` named `name`: in the scene or not (active), timed apart or only listed
  !> (timed, default .true.). Each id once.
  subroutine effects_declare(this, id, name, active, timed)
    class(effects_t), intent(inout) :: this
    integer, intent(in) :: id
    character(len=*), intent(in) :: name
    logical, intent(in) :: active
    logical, intent(in), optional :: timed
    logical :: with_timer

    if (.not. allocated(this%active)) call this%init()
    if (id < 1) call raise_error('effects_declare', 0, 'effect "' // name // '": id must be positive')
    call grow(this, id)
    if (any(this%order(1:this%n_declared) == id)) &
         call raise_error('effects_declare', 0, 'effect "' // name // '": id declared twice')
    this%n_declared = this%n_declared + 1
    this%order(this%n_declared) = id
    this%names(id) = name
    this%active(id) = active
    this%timer(id) = 0
    with_timer = .true.
    if (present(timed)) with_timer = timed
    if (active .and. with_timer) call timer_register(this%timers, name, this%timer(id))
  end subroutine effects_declare

  !> Arrays indexed by id up to at least `id`, and room for one more declaration.
  subroutine grow(this, id)
    type(effects_t), intent(inout) :: this
    integer, intent(in) :: id
    logical, allocatable :: active(:)
    integer, allocatable :: timer(:), order(:)
    character(len=name_length), allocatable :: names(:)
    integer :: n, k

    n = size(this%active)
    if (id <= n .and. this%n_declared < n) return
    k = max(2 * n, id)
    allocate (active(k), source=.false.)
    allocate (timer(k), source=0)
    allocate (order(k), source=0)
    allocate (names(k), source=repeat(' ', name_length))
    active(1:n) = this%active
    timer(1:n) = this%timer
    order(1:n) = this%order
    names(1:n) = this%names
    call move_alloc(active, this%active)
    call move_alloc(timer, this%timer)
    call move_alloc(order, this%order)
    call move_alloc(names, this%names)
  end subroutine grow

  subroutine effects_start(this, id)
    class(effects_t), intent(inout) :: this
    integer, intent(in) :: id
    call timer_start(this%timers, this%timer(id))
  end subroutine effects_start

  subroutine effects_stop(this, id)
    class(effects_t), intent(inout) :: this
    integer, intent(in) :: id
    call timer_stop(this%timers, this%timer(id))
  end subroutine effects_stop

  !> "elements, material, gravity, ...": the active effects in the order of their declaration.
  function effects_active_list(this) result(text)
    class(effects_t), intent(in) :: this
    character(len=:), allocatable :: text
    integer :: k, id

    text = ''
    do k = 1, this%n_declared
       id = this%order(k)
       if (.not. this%active(id)) cycle
       if (len(text) > 0) text = text // ', '
       text = text // trim(this%names(id))
    end do
  end function effects_active_list

  !> The header's line of the run: "  effects   elements, material, ...".
  function effects_header_line(this) result(line)
    class(effects_t), intent(in) :: this
    character(len=:), allocatable :: line

    line = '  effects   ' // this%active_list()
  end function effects_header_line

  !> The end report's timing table of the timed effects (collective with comm; rank 0 prints).
  subroutine effects_report(this, unit, comm)
    class(effects_t), intent(in) :: this
    integer, intent(in) :: unit
    type(MPI_Comm), intent(in) :: comm

    call timer_report(this%timers, unit, comm)
  end subroutine effects_report
end module output_effects
