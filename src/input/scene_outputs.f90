!> Output requests: *OUTPUT, FIELD|HISTORY with *NODE OUTPUT, *ELEMENT OUTPUT and
!> *ENERGY OUTPUT, and their propagation between steps (requests carry over; OP=NEW on an
!> *OUTPUT drops the requests of that kind inherited from earlier steps).
!>
!> Field output: *NODE OUTPUT U, V, A, RF and *ELEMENT OUTPUT S, LE, PE, PEEQ, SDV, FV,
!> STATUS. History output: *ENERGY OUTPUT (all energies) and *NODE OUTPUT, NSET=... with
!> components RF1.., U1.., V1.., A1.. (or RF, U, V, A for all components). Frequencies:
!> NUMBER INTERVAL=, TIME INTERVAL= or FREQUENCY= (every n increments, Abaqus's meaning);
!> defaults 20 intervals (field) and 200 (history). VARIABLE=PRESELECT asks for U, V, A,
!> RF, S, LE, PE, PEEQ, STATUS (field) or the energies (history); VARIABLE=ALL for every
!> field variable we have (adds SDV) or the energies.
module scene_outputs
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_block_t, data_line_t
  use model, only: model_t
  use model_sets, only: find_set
  use model_steps, only: field_output_t, history_output_t
  use scene_util, only: itoa, field_name, field_blank, get_real_param, expect_lines
  use scene_time_points, only: time_points_t, find_time_points
  implicit none
  private

  public :: output_state_t, outputs_step_start, read_output, read_output_option, time_marks

  integer, parameter :: default_field_intervals = 20
  integer, parameter :: default_history_intervals = 200

  type :: output_state_t
     integer :: n_field = 0, n_history = 0
     type(field_output_t), allocatable :: field(:)
     type(history_output_t), allocatable :: history(:)
     integer :: n_field_inherited = 0, n_history_inherited = 0
     ! the *OUTPUT whose options are being read
     logical :: current_is_field = .false.
     integer :: current_number = 0
     real(dp) :: current_time = 0
     integer :: current_frequency = 0
     real(dp), allocatable :: current_points(:)
     type(time_points_t), allocatable :: lists(:)   !< the deck's *TIME POINTS
  end type output_state_t

contains

  !> At *STEP: what is there now was inherited.
  subroutine outputs_step_start(os)
    type(output_state_t), intent(inout) :: os

    if (.not. allocated(os%field)) allocate (os%field(0))
    if (.not. allocated(os%history)) allocate (os%history(0))
    os%n_field_inherited = os%n_field
    os%n_history_inherited = os%n_history
  end subroutine outputs_step_start

  !> *OUTPUT, FIELD|HISTORY. `n_options`: option blocks that follow it.
  subroutine read_output(blk, n_options, os, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: n_options
    type(output_state_t), intent(inout) :: os
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: op, variable
    real(dp) :: t
    integer :: n, frequency
    type(field_output_t) :: f

    call blk%check_params([character(len=15) :: 'FIELD', 'HISTORY', 'NUMBER INTERVAL', 'TIME INTERVAL', &
         'OP', 'VARIABLE', 'TIME MARKS', 'FREQUENCY', 'TIME POINTS'], err)
    if (.not. err%raised) call time_marks(blk, err)
    if (err%raised) return
    if (blk%has_param('FIELD') .eqv. blk%has_param('HISTORY')) then
       call blk%fail('*OUTPUT needs exactly one of FIELD or HISTORY; expected *OUTPUT, FIELD or ' // &
            '*OUTPUT, HISTORY', err)
       return
    end if
    if (count([blk%has_param('NUMBER INTERVAL'), blk%has_param('TIME INTERVAL'), blk%has_param('FREQUENCY'), &
         blk%has_param('TIME POINTS')]) > 1) then
       call blk%fail('*OUTPUT with more than one of NUMBER INTERVAL, TIME INTERVAL, FREQUENCY and TIME POINTS; ' // &
            'expected one of them', err)
       return
    end if
    call blk%get_string('OP', op, err, default='ADD', choices=[character(len=3) :: 'ADD', 'NEW'])
    if (.not. err%raised) call blk%get_string('VARIABLE', variable, err, default='', &
         choices=[character(len=9) :: 'PRESELECT', 'ALL'])
    if (.not. err%raised) call blk%get_integer('NUMBER INTERVAL', n, err, default=0, minimum=1)
    if (.not. err%raised) call blk%get_integer('FREQUENCY', frequency, err, default=0, minimum=1)
    if (.not. err%raised) call get_real_param(blk, 'TIME INTERVAL', t, err, default=0.0_dp)
    if (.not. err%raised) call time_points_of(blk, os, err)
    if (err%raised) return
    if (blk%has_param('TIME INTERVAL') .and. .not. (t > 0)) then
       call blk%fail('*OUTPUT: TIME INTERVAL must be positive; expected a time > 0', err)
       return
    end if
    call expect_lines(blk, 0, 0, 'no data lines (variables go on *NODE OUTPUT, ...)', err)
    if (err%raised) return
    if (n_options == 0 .and. variable == '') then
       call blk%fail('*OUTPUT requests nothing; expected *NODE OUTPUT, *ELEMENT OUTPUT or ' // &
            '*ENERGY OUTPUT after it, or VARIABLE=PRESELECT', err)
       return
    end if
    os%current_is_field = blk%has_param('FIELD')
    if (n == 0 .and. .not. (t > 0) .and. frequency == 0 .and. .not. blk%has_param('TIME POINTS')) n = merge(default_field_intervals, &
         default_history_intervals, os%current_is_field)
    os%current_number = n
    os%current_time = t
    os%current_frequency = frequency
    if (op == 'NEW') call drop_inherited(os, os%current_is_field)
    if (os%current_is_field) then
       f%number_interval = n
       f%time_interval = t
       f%frequency = frequency
       if (allocated(os%current_points)) allocate (f%time_points, source=os%current_points)
       allocate (f%node_variables(0), f%element_variables(0))
       if (variable == 'PRESELECT') then
          f%node_variables = [character(len=8) :: 'U', 'V', 'A', 'RF']
          f%element_variables = [character(len=8) :: 'S', 'LE', 'PE', 'PEEQ', 'STATUS']
       else if (variable == 'ALL') then
          f%node_variables = [character(len=8) :: 'U', 'V', 'A', 'RF']
          f%element_variables = [character(len=8) :: 'S', 'LE', 'PE', 'PEEQ', 'SDV', 'STATUS']
       end if
       call push_field(os, f)
    else if (variable /= '') then
       call push_history(os, new_history(os, 0, .true.))
    end if
  end subroutine read_output

  !> TIME MARKS=YES|NO (Abaqus/CAE writes it): accepted, our output times are those of
  !> the increments that reach each interval.
  subroutine time_marks(blk, err)
    type(keyword_block_t), intent(in) :: blk
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: marks

    call blk%get_string('TIME MARKS', marks, err, default='NO', choices=[character(len=3) :: 'YES', 'NO'])
  end subroutine time_marks

  !> TIME POINTS=name: the times of the *TIME POINTS list of that name (none: an empty list).
  subroutine time_points_of(blk, os, err)
    type(keyword_block_t), intent(in) :: blk
    type(output_state_t), intent(inout) :: os
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name, known
    integer :: k

    os%current_points = [real(dp) ::]
    if (.not. blk%has_param('TIME POINTS')) return
    call blk%get_string('TIME POINTS', name, err)
    if (err%raised) return
    if (.not. allocated(os%lists)) allocate (os%lists(0))
    k = find_time_points(os%lists, name)
    if (k == 0) then
       known = 'none defined'
       if (size(os%lists) > 0) known = 'defined: ' // os%lists(1)%name
       do k = 2, size(os%lists)
          known = known // ', ' // os%lists(k)%name
       end do
       call blk%fail('*OUTPUT, TIME POINTS=' // name // ': no *TIME POINTS, NAME=' // name // ' (' // known // &
            '); expected the name of a *TIME POINTS list', err)
       return
    end if
    os%current_points = os%lists(k)%times
  end subroutine time_points_of

  !> Drop the requests of one kind inherited from earlier steps (OP=NEW).
  subroutine drop_inherited(os, field)
    type(output_state_t), intent(inout) :: os
    logical, intent(in) :: field
    integer :: m

    if (field .and. os%n_field_inherited > 0) then
       m = os%n_field - os%n_field_inherited
       os%field(1:m) = os%field(os%n_field_inherited + 1:os%n_field)
       os%n_field = m
       os%n_field_inherited = 0
    else if (.not. field .and. os%n_history_inherited > 0) then
       m = os%n_history - os%n_history_inherited
       os%history(1:m) = os%history(os%n_history_inherited + 1:os%n_history)
       os%n_history = m
       os%n_history_inherited = 0
    end if
  end subroutine drop_inherited

  subroutine push_field(os, f)
    type(output_state_t), intent(inout) :: os
    type(field_output_t), intent(in) :: f
    type(field_output_t), allocatable :: tmp(:)

    allocate (tmp(os%n_field + 1))
    tmp(1:os%n_field) = os%field(1:os%n_field)
    tmp(os%n_field + 1) = f
    call move_alloc(tmp, os%field)
    os%n_field = os%n_field + 1
  end subroutine push_field

  subroutine push_history(os, h)
    type(output_state_t), intent(inout) :: os
    type(history_output_t), intent(in) :: h
    type(history_output_t), allocatable :: tmp(:)

    allocate (tmp(os%n_history + 1))
    tmp(1:os%n_history) = os%history(1:os%n_history)
    tmp(os%n_history + 1) = h
    call move_alloc(tmp, os%history)
    os%n_history = os%n_history + 1
  end subroutine push_history

  function new_history(os, nset, energies) result(h)
    type(output_state_t), intent(in) :: os
    integer, intent(in) :: nset
    logical, intent(in) :: energies
    type(history_output_t) :: h

    h%number_interval = os%current_number
    h%time_interval = os%current_time
    h%frequency = os%current_frequency
    if (allocated(os%current_points)) allocate (h%time_points, source=os%current_points)
    h%nset = nset
    h%energies = energies
    allocate (h%node_variables(0))
  end function new_history

  !> Append `name` to `list` unless it is there.
  subroutine add_name(list, name)
    character(len=8), allocatable, intent(inout) :: list(:)
    character(len=*), intent(in) :: name
    character(len=8), allocatable :: tmp(:)
    integer :: n

    if (any(list == name)) return
    n = size(list)
    allocate (tmp(n + 1))
    tmp(1:n) = list
    tmp(n + 1) = name
    call move_alloc(tmp, list)
  end subroutine add_name

  !> *NODE OUTPUT, *ELEMENT OUTPUT or *ENERGY OUTPUT after the current *OUTPUT.
  subroutine read_output_option(blk, model, os, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    type(output_state_t), intent(inout) :: os
    type(error_t), intent(inout) :: err

    select case (blk%name)
    case ('NODE OUTPUT')
       if (os%current_is_field) then
          call node_field_output(blk, model%mpm%active, os, err)
       else
          call node_history_output(blk, model, os, err)
       end if
    case ('ELEMENT OUTPUT')
       call element_output(blk, os, err)
    case default
       call energy_output(blk, os, err)
    end select
  end subroutine read_output_option

  !> particles: a material-point scene (no node fields are written; NT is refused there).
  subroutine node_field_output(blk, particles, os, err)
    type(keyword_block_t), intent(in) :: blk
    logical, intent(in) :: particles
    type(output_state_t), intent(inout) :: os
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name
    integer :: il, k

    call blk%check_params([character(len=8) ::], err)
    if (.not. err%raised) call expect_lines(blk, 1, huge(1), 'variable names U, V, A, RF, NT', err)
    if (err%raised) return
    do il = 1, blk%n_lines
       do k = 1, blk%lines(il)%n_fields()
          if (field_blank(blk%lines(il), k)) cycle
          name = field_name(blk%lines(il), k)
          select case (name)
          case ('U', 'V', 'A', 'RF')
             call add_name(os%field(os%n_field)%node_variables, name)
          case ('NT')
             if (particles) then
                call raise_error(blk%lines(il)%file, blk%lines(il)%line, 'node field output variable NT ' // &
                     'is written for the nodes of element scenes; expected TEMP in *ELEMENT OUTPUT for ' // &
                     'the particles of a material-point scene', err)
                return
             end if
             call add_name(os%field(os%n_field)%node_variables, name)
          case default
             call raise_error(blk%lines(il)%file, blk%lines(il)%line, 'node field output variable ' // &
                  name // ' is not available; expected U, V, A, RF or NT', err)
             return
          end select
       end do
    end do
  end subroutine node_field_output

  subroutine node_history_output(blk, model, os, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    type(output_state_t), intent(inout) :: os
    type(error_t), intent(inout) :: err
    type(history_output_t) :: h
    character(len=:), allocatable :: name, nset
    integer :: il, k, comp, ks, ndim

    ndim = model%mesh%ndim
    call blk%check_params([character(len=4) :: 'NSET'], err)
    if (err%raised) return
    if (.not. blk%has_param('NSET')) then
       call blk%fail('history *NODE OUTPUT without NSET=; expected *NODE OUTPUT, NSET=<node set>', err)
       return
    end if
    call blk%get_string('NSET', nset, err)
    if (err%raised) return
    ks = find_set(model%nsets, model%n_nsets, nset)
    if (ks == 0) then
       call blk%fail('node set ' // nset // ' is not defined; expected the name of an *NSET', err)
       return
    end if
    call expect_lines(blk, 1, huge(1), 'variable names such as RF2, U1, V2', err)
    if (err%raised) return
    h = new_history(os, ks, .false.)
    do il = 1, blk%n_lines
       do k = 1, blk%lines(il)%n_fields()
          if (field_blank(blk%lines(il), k)) cycle
          name = field_name(blk%lines(il), k)
          select case (name)
          case ('U', 'V', 'A', 'RF')
             do comp = 1, ndim
                call add_name(h%node_variables, name // itoa(comp))
             end do
             cycle
          end select
          comp = 0
          if (len(name) >= 2) then
             if (verify(name(len(name):), '123') == 0) comp = index('123', name(len(name):))
          end if
          if (comp >= 1 .and. comp <= ndim) then
             select case (name(1:len(name) - 1))
             case ('U', 'V', 'A', 'RF')
                call add_name(h%node_variables, name)
                cycle
             end select
          end if
          call raise_error(blk%lines(il)%file, blk%lines(il)%line, 'node history output variable ' // &
               name // ' is not available; expected RF, U, V, A or a component 1..' // itoa(ndim) // &
               ' of them (e.g. RF2)', err)
          return
       end do
    end do
    call push_history(os, h)
  end subroutine node_history_output

  !> TEMP: the temperature of the elements (mean of their nodes') or of the particles.
  subroutine element_output(blk, os, err)
    type(keyword_block_t), intent(in) :: blk
    type(output_state_t), intent(inout) :: os
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name, directions
    integer :: il, k

    if (.not. os%current_is_field) then
       call blk%fail('*ELEMENT OUTPUT in history output is not supported; expected it after ' // &
            '*OUTPUT, FIELD', err)
       return
    end if
    ! DIRECTIONS= is what Abaqus/CAE writes; our components are global anyway
    call blk%check_params([character(len=10) :: 'DIRECTIONS'], err)
    if (.not. err%raised) call blk%get_string('DIRECTIONS', directions, err, default='YES', &
         choices=[character(len=3) :: 'YES', 'NO'])
    if (.not. err%raised) call expect_lines(blk, 1, huge(1), 'variable names S, LE, PE, PEEQ, SDV, FV, STATUS, TEMP', err)
    if (err%raised) return
    do il = 1, blk%n_lines
       do k = 1, blk%lines(il)%n_fields()
          if (field_blank(blk%lines(il), k)) cycle
          name = field_name(blk%lines(il), k)
          select case (name)
          case ('S', 'LE', 'PE', 'PEEQ', 'SDV', 'FV', 'STATUS', 'TEMP')
             call add_name(os%field(os%n_field)%element_variables, name)
          case default
             call raise_error(blk%lines(il)%file, blk%lines(il)%line, 'element output variable ' // &
                  name // ' is not available; expected S, LE, PE, PEEQ, SDV, FV, STATUS or TEMP', err)
             return
          end select
       end do
    end do
  end subroutine element_output

  subroutine energy_output(blk, os, err)
    type(keyword_block_t), intent(in) :: blk
    type(output_state_t), intent(inout) :: os
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name, variable
    integer :: il, k

    if (os%current_is_field) then
       call blk%fail('*ENERGY OUTPUT in field output; expected it after *OUTPUT, HISTORY', err)
       return
    end if
    call blk%check_params([character(len=8) :: 'VARIABLE'], err)
    if (.not. err%raised) call blk%get_string('VARIABLE', variable, err, default='ALL', &
         choices=[character(len=9) :: 'ALL', 'PRESELECT'])
    if (err%raised) return
    ! the whole-model energies are always written together; names are only checked
    do il = 1, blk%n_lines
       do k = 1, blk%lines(il)%n_fields()
          if (field_blank(blk%lines(il), k)) cycle
          name = field_name(blk%lines(il), k)
          select case (name)
          case ('ALLKE', 'ALLIE', 'ALLVD', 'ALLFD', 'ALLWK', 'ALLAE', 'ETOTAL')
          case default
             call raise_error(blk%lines(il)%file, blk%lines(il)%line, 'energy output variable ' // &
                  name // ' is not available; expected ALLKE, ALLIE, ALLVD, ALLFD, ALLWK, ALLAE, ETOTAL', err)
             return
          end select
       end do
    end do
    call push_history(os, new_history(os, 0, .true.))
  end subroutine energy_output
end module scene_outputs
