!> Builds the material and the loading path of a material-point run from keyword blocks
!> (keyword_reader). Every mistake stops at its file:line. The material is read by the scene
!> reader's material part (scene_materials: the same keywords, checks and translation into our
!> VUMATs as in a scene); this module reads the path. Keywords (inputs/matpoint/README.md has
!> the full description):
!>
!>   *HEADING                        title (data lines), optional
!>   *MATERIAL, NAME=name            exactly one, with its options right after it, as in a scene:
!>     *DENSITY, *ELASTIC, *MOHR COULOMB [, DEPENDENCIES=1], *MOHR COULOMB HARDENING,
!>     *TENSION CUTOFF, *FLOW FUNCTION, *DRUCKER PRAGER, *DRUCKER PRAGER HARDENING,
!>     *USER MATERIAL, CONSTANTS=n, *DEPVAR (optional lines "i, NAME[, description"),
!>     *USER DEFINED FIELD [, FIELDS=n]          (docs/keywords.md)
!>   *INITIAL CONDITIONS, TYPE=STRESS    data: s11, s22, s33, s12[, s23, s31] (VUMAT order)
!>   *INITIAL CONDITIONS, TYPE=SOLUTION  data: SDV1, SDV2, ...
!>   *INITIAL CONDITIONS, TYPE=FIELD, VARIABLE=i   data: value of field i
!>   *INITIAL CONDITIONS, TYPE=TEMPERATURE         data: the initial temperature
!>   *AMPLITUDE, NAME=a [, DEFINITION=, TIME=]      as in a scene (scene_amplitudes)
!>   *TEMPERATURE [, AMPLITUDE=a] [, OP=MOD|NEW]    data: "material name, value" as in an MPM
!>                                   scene (scene_temperature): T(t) = value × a(t), tempOld at
!>                                   the increment's start, tempNew at its end
!>   *TEST, TYPE=t [, DIMENSION=2|3] [, AXIS=1|2|3]
!>   *STAGE, INC=n [, TIME=t] [, STRAIN=x] [, STRESS=s]   (GENERAL: data "comp, STRAIN|STRESS|HOLD, value")
!>   *DRIVER CONTROLS [, TOLERANCE=tol] [, ITERATIONS=n]
module matpoint_input
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, read_keyword_file, &
       read_keyword_string, upper_case
  use model_materials, only: material_t
  use scene_layout, only: is_material_option
  use scene_materials, only: build_deck_materials
  use scene_amplitudes, only: build_amplitudes
  use scene_temperature, only: read_temperature
  use model_steps, only: temperature_t
  use user_library, only: user_library_loaded
  use matpoint_path, only: matpoint_path_t, matpoint_stage_t, max_components, control_strain, &
       control_stress, control_stress_hold, test_general, test_triaxial, test_biaxial, &
       test_oedometer, test_isotropic, test_names, test_from_name, default_dimension, &
       preset_stage
  implicit none
  private

  public :: build_matpoint_input, read_matpoint_file, read_matpoint_string

  character(len=24), parameter :: known_keywords(21) = [character(len=24) :: &
       'HEADING', 'MATERIAL', 'DENSITY', 'ELASTIC', 'MOHR COULOMB', 'MOHR COULOMB HARDENING', &
       'TENSION CUTOFF', 'FLOW FUNCTION', 'INERTIAL FRICTION', 'DRUCKER PRAGER', 'DRUCKER PRAGER HARDENING', &
       'USER MATERIAL', 'DEPVAR', 'USER DEFINED FIELD', 'INITIAL CONDITIONS', 'TEST', 'STAGE', &
       'DRIVER CONTROLS', 'AMPLITUDE', 'TEMPERATURE', 'INCLUDE']

  !> What has been seen so far (for order and completeness checks).
  type :: build_state_t
     integer :: material_block = 0
     logical :: have_test = .false.
     type(keyword_block_t) :: stress_block
     logical :: have_stress = .false.
  end type build_state_t

contains

  !> Read an input file and build material + path.
  subroutine read_matpoint_file(filename, mat, path, err, title)
    character(len=*), intent(in) :: filename
    type(material_t), intent(out) :: mat
    type(matpoint_path_t), intent(out) :: path
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable, intent(out), optional :: title
    type(keyword_deck_t) :: deck
    type(error_t) :: local
    character(len=:), allocatable :: t

    call read_keyword_file(filename, deck, local)
    if (.not. local%raised) call build_matpoint_input(deck, mat, path, local, t)
    if (local%raised) call raise_error('', 0, local%message, err)
    if (present(title)) then
       title = ''
       if (allocated(t)) title = t
    end if
  end subroutine read_matpoint_file

  !> Same from keyword text in a string (tests); `name` is used in messages.
  subroutine read_matpoint_string(text, mat, path, err, name)
    character(len=*), intent(in) :: text
    type(material_t), intent(out) :: mat
    type(matpoint_path_t), intent(out) :: path
    type(error_t), intent(inout), optional :: err
    character(len=*), intent(in), optional :: name
    type(keyword_deck_t) :: deck
    type(error_t) :: local
    character(len=:), allocatable :: t

    call read_keyword_string(text, deck, local, name)
    if (.not. local%raised) call build_matpoint_input(deck, mat, path, local, t)
    if (local%raised) call raise_error('', 0, local%message, err)
  end subroutine read_matpoint_string

  !> Interpret the keyword blocks.
  subroutine build_matpoint_input(deck, mat, path, err, title)
    type(keyword_deck_t), intent(in) :: deck
    type(material_t), intent(out) :: mat
    type(matpoint_path_t), intent(out) :: path
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable, intent(out), optional :: title
    type(error_t) :: local
    type(build_state_t) :: st
    character(len=:), allocatable :: t
    integer :: b, chain

    t = ''
    chain = 0
    do b = 1, deck%n_blocks
       associate (blk => deck%blocks(b))
         if (blk%name == 'MATERIAL') then
            if (st%material_block /= 0) then
               call blk%fail('a material-point input has exactly one *MATERIAL', local)
            else
               st%material_block = b
               chain = b
            end if
         else if (is_material_option(blk%name)) then
            ! read with its *MATERIAL by the scene reader's material part (read_point_material)
            if (chain == 0) call blk%fail('*' // blk%name // ' must follow *MATERIAL (right after ' // &
                 'it or after another option of the material)', local)
         else
            chain = 0
            select case (blk%name)
            case ('HEADING')
               call read_heading(blk, t)
            case ('INITIAL CONDITIONS')
               call read_initial_conditions(blk, path, st, local)
            case ('TEST')
               call read_test(blk, path, st, local)
            case ('STAGE')
               call read_stage(blk, path, st, local)
            case ('DRIVER CONTROLS')
               call read_controls(blk, path, local)
            case ('AMPLITUDE', 'TEMPERATURE')
               ! read once the material is known (read_predefined_temperature)
            case default
               call blk%fail('unknown keyword *' // blk%name // ' (the material-point driver ' // &
                    'knows ' // keyword_list() // ')', local)
            end select
         end if
       end associate
       if (local%raised) exit
    end do
    if (.not. local%raised) call read_point_material(deck, st, mat, path, local)
    if (.not. local%raised) call read_predefined_temperature(deck, path, local)
    if (.not. local%raised) call final_checks(deck, mat, path, st, local)
    if (local%raised) call raise_error('', 0, local%message, err)
    if (present(title)) title = t
  end subroutine build_matpoint_input

  function keyword_list() result(list)
    character(len=:), allocatable :: list
    integer :: k

    list = ''
    do k = 1, size(known_keywords)
       if (k > 1) list = list // ', '
       list = list // '*' // trim(known_keywords(k))
    end do
  end function keyword_list

  subroutine read_heading(blk, title)
    type(keyword_block_t), intent(in) :: blk
    character(len=:), allocatable, intent(inout) :: title
    integer :: i

    do i = 1, blk%n_lines
       if (len(title) > 0) title = title // ' '
       title = title // blk%lines(i)%text
    end do
  end subroutine read_heading

  !> Error unless the block has exactly `n` data lines.
  subroutine expect_lines(blk, n, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: n
    type(error_t), intent(inout) :: err
    character(len=16) :: buf

    if (blk%n_lines == n) return
    if (n == 0) then
       call raise_error(blk%lines(1)%file, blk%lines(1)%line, '*' // blk%name // &
            ' takes no data lines', err)
    else if (blk%n_lines < n) then
       write (buf, '(i0)') n
       call blk%fail('*' // blk%name // ' needs ' // trim(buf) // ' data line(s)', err)
    else
       call raise_error(blk%lines(n + 1)%file, blk%lines(n + 1)%line, 'too many data lines for *' &
            // blk%name, err)
    end if
  end subroutine expect_lines

  !> The one *MATERIAL and its options, read as a scene's (scene_materials): with a user file
  !> loaded (--user, or linked into bulkflow-matpoint-user) a *USER MATERIAL is the user's. The
  !> scene the reader built is kept in path%predefined (its temperature in time).
  subroutine read_point_material(deck, st, mat, path, err)
    type(keyword_deck_t), intent(in) :: deck
    type(build_state_t), intent(in) :: st
    type(material_t), intent(out) :: mat
    type(matpoint_path_t), intent(inout) :: path
    type(error_t), intent(inout) :: err

    if (st%material_block == 0) then
       call raise_error(deck_file(deck), 0, 'no *MATERIAL in the input', err)
       return
    end if
    call build_deck_materials(deck, path%predefined, user_library_loaded(), err)
    if (err%raised) return
    mat = path%predefined%materials(1)
  end subroutine read_point_material

  !> *AMPLITUDE and *TEMPERATURE read by the scene reader into path%predefined as an MPM scene
  !> holds them (no mesh: *TEMPERATURE names the material), the whole path being one step; the
  !> initial temperature is the material's *INITIAL CONDITIONS, TYPE=TEMPERATURE.
  subroutine read_predefined_temperature(deck, path, err)
    type(keyword_deck_t), intent(in) :: deck
    type(matpoint_path_t), intent(inout) :: path
    type(error_t), intent(inout) :: err
    type(temperature_t), allocatable :: active(:)
    integer :: b, n

    call build_amplitudes(deck, path%predefined, err)
    if (err%raised) return
    n = 0
    allocate (active(0))
    do b = 1, deck%n_blocks
       if (deck%blocks(b)%name /= 'TEMPERATURE') cycle
       call read_temperature(deck%blocks(b), path%predefined, active, n, err)
       if (err%raised) return
    end do
    allocate (path%predefined%steps(1), path%predefined%initial_fields(1))
    path%predefined%n_steps = 1
    path%predefined%steps(1)%temperatures = active(1:n)
    path%predefined%initial_fields(1)%material = 1
    path%predefined%initial_fields(1)%variable = 0
    path%predefined%initial_fields(1)%value = path%temperature
    allocate (path%predefined%initial_fields(1)%nodes(0))
  end subroutine read_predefined_temperature

  function deck_file(deck) result(file)
    type(keyword_deck_t), intent(in) :: deck
    character(len=:), allocatable :: file

    file = '<input>'
    if (deck%n_blocks > 0) file = deck%blocks(1)%file
  end function deck_file

  subroutine read_initial_conditions(blk, path, st, err)
    type(keyword_block_t), intent(in) :: blk
    type(matpoint_path_t), intent(inout) :: path
    type(build_state_t), intent(inout) :: st
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: kind
    real(dp), allocatable :: values(:), tmp(:)
    integer :: var

    call blk%check_params([character(len=8) :: 'TYPE', 'VARIABLE'], err)
    if (err%raised) return
    call blk%get_string('TYPE', kind, err, choices=[character(len=11) :: 'STRESS', 'SOLUTION', 'FIELD', &
         'TEMPERATURE'])
    if (err%raised) return
    if (kind /= 'FIELD' .and. blk%has_param('VARIABLE')) then
       call blk%fail('VARIABLE is only used with TYPE=FIELD', err)
       return
    end if
    call blk%all_reals(values, err)
    if (err%raised) return
    select case (kind)
    case ('STRESS')
       if (size(values) < 1 .or. size(values) > max_components) then
          call blk%fail('*INITIAL CONDITIONS, TYPE=STRESS takes 1 to 6 values: ' // &
               's11, s22, s33, s12, s23, s31', err)
          return
       end if
       path%initial_stress = 0.0_dp
       path%initial_stress(1:size(values)) = values
       st%have_stress = .true.
       st%stress_block = blk
    case ('SOLUTION')
       path%initial_state = values
    case ('TEMPERATURE')
       if (size(values) /= 1) then
          call blk%fail('*INITIAL CONDITIONS, TYPE=TEMPERATURE takes one value (the point''s ' // &
               'temperature)', err)
          return
       end if
       path%temperature = values(1)
    case ('FIELD')
       call blk%get_integer('VARIABLE', var, err, default=1, minimum=1)
       if (err%raised) return
       if (size(values) /= 1) then
          call blk%fail('*INITIAL CONDITIONS, TYPE=FIELD takes one value', err)
          return
       end if
       if (.not. allocated(path%initial_field)) allocate (path%initial_field(0))
       if (size(path%initial_field) < var) then
          allocate (tmp(var))
          tmp = 0.0_dp
          tmp(1:size(path%initial_field)) = path%initial_field
          call move_alloc(tmp, path%initial_field)
       end if
       path%initial_field(var) = values(1)
    end select
  end subroutine read_initial_conditions

  subroutine read_test(blk, path, st, err)
    type(keyword_block_t), intent(in) :: blk
    type(matpoint_path_t), intent(inout) :: path
    type(build_state_t), intent(inout) :: st
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name
    integer :: max_axis

    if (st%have_test) then
       call blk%fail('only one *TEST per input', err)
       return
    end if
    call blk%check_params([character(len=9) :: 'TYPE', 'DIMENSION', 'AXIS'], err)
    if (err%raised) return
    call blk%get_string('TYPE', name, err, choices=test_names)
    if (err%raised) return
    path%test = test_from_name(name)
    call blk%get_integer('DIMENSION', path%ndim, err, default=default_dimension(path%test), &
         minimum=2, maximum=3)
    if (err%raised) return
    if (path%test == test_triaxial .and. path%ndim /= 3) then
       call blk%fail('TYPE=TRIAXIAL is a 3D test (use TYPE=BIAXIAL for plane strain)', err)
       return
    end if
    if (path%test == test_biaxial .and. path%ndim /= 2) then
       call blk%fail('TYPE=BIAXIAL is a plane-strain test (DIMENSION=2)', err)
       return
    end if
    if (blk%has_param('AXIS')) then
       select case (path%test)
       case (test_triaxial, test_biaxial, test_oedometer)
       case default
          call blk%fail('AXIS is only used by TRIAXIAL, BIAXIAL and OEDOMETER', err)
          return
       end select
    end if
    max_axis = merge(2, 3, path%ndim == 2)
    call blk%get_integer('AXIS', path%axis, err, default=2, minimum=1, maximum=max_axis)
    if (err%raised) return
    call expect_lines(blk, 0, err)
    if (err%raised) return
    st%have_test = .true.
  end subroutine read_test

  subroutine read_stage(blk, path, st, err)
    type(keyword_block_t), intent(in) :: blk
    type(matpoint_path_t), intent(inout) :: path
    type(build_state_t), intent(inout) :: st
    type(error_t), intent(inout) :: err
    type(matpoint_stage_t) :: stage
    integer :: n_inc
    real(dp) :: strain, stress
    character(len=:), allocatable :: message

    if (.not. st%have_test) then
       call blk%fail('*STAGE needs a *TEST before it', err)
       return
    end if
    call blk%check_params([character(len=6) :: 'INC', 'TIME', 'STRAIN', 'STRESS'], err)
    if (err%raised) return
    call blk%get_integer('INC', n_inc, err, minimum=1)
    if (err%raised) return
    call blk%get_real('TIME', stage%duration, err, default=1.0_dp)
    if (err%raised) return
    if (.not. (stage%duration > 0.0_dp)) then
       call blk%fail('*STAGE: TIME must be positive', err)
       return
    end if
    stage%file = blk%file
    stage%line = blk%line
    stage%n_increments = n_inc

    if (path%test == test_general) then
       if (blk%has_param('STRAIN') .or. blk%has_param('STRESS')) then
          call blk%fail('a GENERAL *STAGE gives its controls on data lines ' // &
               '"component, STRAIN|STRESS|HOLD, value", not as STRAIN=/STRESS=', err)
          return
       end if
       call read_general_controls(blk, path, stage, err)
       if (err%raised) return
    else
       if (blk%n_lines > 0) then
          call expect_lines(blk, 0, err)
          return
       end if
       call blk%get_real('STRAIN', strain, err, default=0.0_dp)
       if (err%raised) return
       call blk%get_real('STRESS', stress, err, default=0.0_dp)
       if (err%raised) return
       if (blk%has_param('STRAIN') .and. blk%has_param('STRESS')) then
          call preset_stage(path, n_inc, stage, message, strain=strain, stress=stress)
       else if (blk%has_param('STRAIN')) then
          call preset_stage(path, n_inc, stage, message, strain=strain)
       else if (blk%has_param('STRESS')) then
          call preset_stage(path, n_inc, stage, message, stress=stress)
       else
          call preset_stage(path, n_inc, stage, message)
       end if
       if (len(message) > 0) then
          call blk%fail('*STAGE: ' // message, err)
          return
       end if
    end if
    call path%add_stage(stage)
  end subroutine read_stage

  !> GENERAL stage data lines: "component, STRAIN|STRESS|HOLD[, value]"; components not
  !> listed are strain-controlled with zero increment.
  subroutine read_general_controls(blk, path, stage, err)
    type(keyword_block_t), intent(in) :: blk
    type(matpoint_path_t), intent(in) :: path
    type(matpoint_stage_t), intent(inout) :: stage
    type(error_t), intent(inout) :: err
    logical :: seen(max_components)
    integer :: i, code, comp, nf
    character(len=8) :: kind

    stage%control = control_strain
    stage%value = 0.0_dp
    seen = .false.
    do i = 1, blk%n_lines
       associate (ln => blk%lines(i))
         nf = ln%n_fields()
         call ln%integer_field(1, code, err)
         if (err%raised) return
         comp = component_index(code, path%ndim)
         if (comp == 0) then
            call raise_error(ln%file, ln%line, 'field 1: "' // ln%field(1) // &
                 '" is not a component of this test (' // &
                 trim(merge('11, 22, 33, 12        ', '11, 22, 33, 12, 23, 31', path%ndim == 2)) // &
                 ')', err)
            return
         end if
         if (seen(comp)) then
            call raise_error(ln%file, ln%line, 'component ' // ln%field(1) // ' given twice', err)
            return
         end if
         seen(comp) = .true.
         kind = upper_case(ln%field(2))
         select case (kind)
         case ('STRAIN', 'STRESS')
            if (nf /= 3) then
               call raise_error(ln%file, ln%line, 'expected "component, ' // trim(kind) // &
                    ', value"', err)
               return
            end if
            call ln%real_field(3, stage%value(comp), err)
            if (err%raised) return
            stage%control(comp) = merge(control_strain, control_stress, trim(kind) == 'STRAIN')
         case ('HOLD')
            if (nf /= 2) then
               call raise_error(ln%file, ln%line, 'expected "component, HOLD" (no value)', err)
               return
            end if
            stage%control(comp) = control_stress_hold
         case default
            call raise_error(ln%file, ln%line, 'field 2: expected STRAIN, STRESS or HOLD, got "' &
                 // ln%field(2) // '"', err)
            return
         end select
       end associate
    end do
  end subroutine read_general_controls

  !> 11,22,33,12,23,31 (also 21,32,13) to the VUMAT index; 0 when not a component.
  pure integer function component_index(code, ndim)
    integer, intent(in) :: code, ndim

    select case (code)
    case (11)
       component_index = 1
    case (22)
       component_index = 2
    case (33)
       component_index = 3
    case (12, 21)
       component_index = 4
    case (23, 32)
       component_index = 5
    case (31, 13)
       component_index = 6
    case default
       component_index = 0
    end select
    if (ndim == 2 .and. component_index > 4) component_index = 0
  end function component_index

  subroutine read_controls(blk, path, err)
    type(keyword_block_t), intent(in) :: blk
    type(matpoint_path_t), intent(inout) :: path
    type(error_t), intent(inout) :: err
    real(dp) :: tol
    integer :: iterations

    call blk%check_params([character(len=10) :: 'TOLERANCE', 'ITERATIONS'], err)
    if (err%raised) return
    call blk%get_real('TOLERANCE', tol, err, default=path%tolerance, &
         minimum=1.0e-15_dp, maximum=1.0e-2_dp)
    if (err%raised) return
    call blk%get_integer('ITERATIONS', iterations, err, default=path%max_iterations, minimum=1)
    if (err%raised) return
    path%tolerance = tol
    path%max_iterations = iterations
    call expect_lines(blk, 0, err)
  end subroutine read_controls

  !> What must be there once every block is read.
  subroutine final_checks(deck, mat, path, st, err)
    type(keyword_deck_t), intent(in) :: deck
    type(material_t), intent(inout) :: mat
    type(matpoint_path_t), intent(inout) :: path
    type(build_state_t), intent(in) :: st
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: file

    file = deck_file(deck)
    if (.not. st%have_test) then
       call raise_error(file, 0, 'no *TEST in the input', err)
       return
    end if
    if (path%n_stages == 0) then
       call raise_error(file, 0, 'no *STAGE in the input', err)
       return
    end if
    if (st%have_stress .and. path%ndim == 2) then
       if (any(abs(path%initial_stress(5:6)) > 0.0_dp)) then
          call st%stress_block%fail('plane strain has no s23/s31 initial stress', err)
          return
       end if
    end if
    if (allocated(path%initial_state)) then
       if (size(path%initial_state) > mat%nstatev) then
          call raise_error(file, 0, 'more *INITIAL CONDITIONS, TYPE=SOLUTION values than *DEPVAR', err)
          return
       end if
    end if
    ! The VUMAT gets every field the input defines (FIELDS= of *USER DEFINED FIELD or the
    ! highest VARIABLE= of *INITIAL CONDITIONS, TYPE=FIELD), as in Abaqus.
    if (allocated(path%initial_field)) mat%nfieldv = max(mat%nfieldv, size(path%initial_field))
  end subroutine final_checks

end module matpoint_input
