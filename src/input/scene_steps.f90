!> Steps: *STEP ... *END STEP with *DYNAMIC, EXPLICIT, *BOUNDARY, *DLOAD (GRAV), *TEMPERATURE,
!> *CONTACT PAIR, *BULK VISCOSITY, *OUTPUT and *RESTART, resolved into a complete
!> `step_t` each, following Abaqus's propagation rules:
!>
!> * boundary conditions, gravity loads, contact pairs and output requests carry over to
!>   later steps; OP=MOD (default for *BOUNDARY and *DLOAD) replaces what the new lines
!>   name, OP=NEW drops everything inherited (it must then be on every *BOUNDARY or
!>   *DLOAD of the step, as in Abaqus); *CONTACT PAIR, OP=DELETE removes a pair;
!> * a boundary condition or load carried over without being defined again keeps following
!>   an amplitude in total time and is held at its last value when its amplitude is in step
!>   time (model_time_variation); gravity that jumps at a step start is warned about
!>   (scene_step_continuity);
!> * *BULK VISCOSITY and *RESTART, WRITE stay in effect until changed;
!> * *DYNAMIC, SCALE FACTOR= and DIRECT USER CONTROL belong to their step only;
!> * *FIXED MASS SCALING carries over to later steps (Abaqus); a step with its own definitions
!>   replaces all inherited ones (FACTOR=1 alone restores the physical masses);
!> * *STOP CONDITION (ours) belongs to its step only.
!>
!> Model-data *BOUNDARY (zero displacements) and *CONTACT PAIR start the chain.
module scene_steps
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t, is_integer_syntax
  use model, only: model_t
  use model_sets, only: find_set, name_length
  use model_steps, only: step_t, gravity_t, pressure_t, contact_pair_t, mass_scaling_t, mass_scaling_below_min, &
       mass_scaling_uniform, temperature_t
  use scene_temperature, only: read_temperature
  use scene_layout, only: scene_layout_t
  use scene_amplitudes, only: amplitude_param
  use scene_boundaries, only: bc_state_t, bc_init, bc_clear, read_boundary, bc_resolve, boundary_op, &
       bc_carry
  use scene_step_continuity, only: warn_gravity_jumps
  use scene_pressure, only: read_dsload
  use model_time_variation, only: time_variation_t, carry_into_step
  use scene_outputs, only: output_state_t, outputs_step_start, read_output, read_output_option, time_marks
  use scene_time_points, only: build_time_points
  use scene_surfaces, only: find_rigid_surface, require_element_surface
  use scene_interactions, only: find_interaction
  use scene_util, only: itoa, rtoa, get_real, get_real_param, field_name, field_blank, &
       expect_fields, expect_lines, where_text, check_name
  implicit none
  private

  public :: build_steps

  !> What carries from step to step.
  type :: carry_t
     type(bc_state_t) :: bcs
     integer :: n_gravity = 0
     type(gravity_t), allocatable :: gravity(:)
     integer :: n_pressures = 0
     type(pressure_t), allocatable :: pressures(:)
     integer :: n_pairs = 0
     type(contact_pair_t), allocatable :: pairs(:)
     type(output_state_t) :: outputs
     real(dp) :: bulk_linear = 0.06_dp, bulk_quadratic = 1.2_dp
     logical :: restart_write = .false.
     integer :: restart_number = 0
     real(dp) :: restart_time = 0
     integer :: n_mass_scaling = 0
     type(mass_scaling_t), allocatable :: mass_scaling(:)
     integer :: n_temperatures = 0
     type(temperature_t), allocatable :: temperatures(:)
  end type carry_t

contains

  subroutine build_steps(deck, layout, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    type(carry_t) :: c
    integer :: i, s, k
    real(dp) :: step_end

    call bc_init(c%bcs, model%mesh%n_nodes)
    allocate (c%gravity(0), c%pressures(0), c%pairs(0), c%mass_scaling(0), c%temperatures(0))
    call build_time_points(deck, c%outputs%lists, err)
    if (err%raised) return
    do i = 1, deck%n_blocks
       if (layout%step_of(i) /= 0) cycle
       select case (deck%blocks(i)%name)
       case ('BOUNDARY')
          call read_boundary(deck%blocks(i), model, .false., c%bcs, err)
       case ('CONTACT PAIR')
          call read_contact_pair(deck%blocks(i), model, .false., c, err)
       end select
       if (err%raised) return
    end do
    if (layout%n_steps == 0) then
       associate (blk => deck%blocks(deck%n_blocks))
         call blk%fail('the scene has no *STEP; expected at least one *STEP ... *END STEP ' // &
              'with *DYNAMIC, EXPLICIT', err)
       end associate
       return
    end if
    model%n_steps = layout%n_steps
    allocate (model%steps(model%n_steps))
    step_end = 0
    do s = 1, model%n_steps
       if (s > 1) then
          ! what the step does not define again is carried over (Abaqus's rules)
          call bc_carry(c%bcs, model%amplitudes, model%steps(s - 1)%period, step_end)
          do k = 1, c%n_gravity
             call carry_into_step(c%gravity(k)%variation, model%amplitudes, model%steps(s - 1)%period, &
                  step_end)
          end do
          do k = 1, c%n_temperatures
             call carry_into_step(c%temperatures(k)%variation, model%amplitudes, model%steps(s - 1)%period, &
                  step_end)
          end do
          do k = 1, c%n_pressures
             call carry_into_step(c%pressures(k)%variation, model%amplitudes, model%steps(s - 1)%period, &
                  step_end)
          end do
       end if
       call read_step(deck, layout, s, model, c, model%steps(s), err)
       if (err%raised) return
       if (s > 1) call warn_gravity_jumps(model, s, step_end)
       step_end = step_end + model%steps(s)%period
    end do
  end subroutine build_steps

  subroutine read_step(deck, layout, s, model, c, step, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    integer, intent(in) :: s
    type(model_t), intent(in) :: model
    type(carry_t), intent(inout) :: c
    type(step_t), intent(inout) :: step
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name
    integer :: i, i0, i1, j, n_options, dynamic_block, stop_block
    logical :: bc_new, dload_new, dsload_new

    i0 = layout%step_block(s)
    i1 = layout%end_block(s)
    associate (sblk => deck%blocks(i0))
      call sblk%check_params([character(len=6) :: 'NAME', 'NLGEOM'], err)
      if (.not. err%raised) call sblk%get_string('NAME', name, err, default='STEP-' // itoa(s))
      if (.not. err%raised) call check_name(sblk, 'step', name, name_length, err)
      if (err%raised) return
      call check_nlgeom(sblk, err)
      ! an optional data line is the step's description (Abaqus)
      if (.not. err%raised) call expect_lines(sblk, 0, 1, 'at most one description line', err)
      if (err%raised) return
      step%name = name
      step%source = where_text(sblk%file, sblk%line)
    end associate
    call expect_lines(deck%blocks(i1), 0, 0, 'no data lines', err)
    if (.not. err%raised) call deck%blocks(i1)%check_params([character(len=8) ::], err)
    if (err%raised) return

    call op_new_rule(deck, i0, i1, 'BOUNDARY', bc_new, err)
    if (.not. err%raised) call op_new_rule(deck, i0, i1, 'DLOAD', dload_new, err)
    if (.not. err%raised) call op_new_rule(deck, i0, i1, 'DSLOAD', dsload_new, err)
    if (err%raised) return
    if (dsload_new) c%n_pressures = 0
    if (bc_new) call bc_clear(c%bcs)
    if (dload_new) c%n_gravity = 0
    call outputs_step_start(c%outputs)
    dynamic_block = 0
    stop_block = 0
    step%mass_scaling_defined = .false.
    do i = i0 + 1, i1 - 1
       associate (blk => deck%blocks(i))
         select case (blk%name)
         case ('DYNAMIC')
            if (dynamic_block /= 0) then
               call blk%fail('second *DYNAMIC in step ' // trim(step%name) // ' (first at ' // &
                    where_text(deck%blocks(dynamic_block)%file, deck%blocks(dynamic_block)%line) // &
                    '); expected one procedure per step', err)
               return
            end if
            dynamic_block = i
            call read_dynamic(blk, step, err)
         case ('BOUNDARY')
            call read_boundary(blk, model, .true., c%bcs, err)
         case ('DLOAD')
            call read_dload(blk, model, c, err)
         case ('TEMPERATURE')
            call read_temperature(blk, model, c%temperatures, c%n_temperatures, err)
         case ('DSLOAD')
            call read_dsload(blk, model, c%pressures, c%n_pressures, err)
         case ('CONTACT PAIR')
            call read_contact_pair(blk, model, .true., c, err)
         case ('BULK VISCOSITY')
            call read_bulk_viscosity(blk, c, err)
         case ('RESTART')
            call read_restart(blk, c, err)
         case ('FIXED MASS SCALING')
            ! The step's first definition replaces everything inherited.
            if (.not. step%mass_scaling_defined) c%n_mass_scaling = 0
            step%mass_scaling_defined = .true.
            call read_mass_scaling(blk, model, c, err)
         case ('STOP CONDITION')
            if (stop_block /= 0) then
               call blk%fail('second *STOP CONDITION in step ' // trim(step%name) // ' (first at ' // &
                    where_text(deck%blocks(stop_block)%file, deck%blocks(stop_block)%line) // &
                    '); expected at most one per step', err)
               return
            end if
            stop_block = i
         case ('OUTPUT')
            n_options = 0
            do j = i + 1, i1 - 1
               if (layout%owner(j) /= i) exit
               n_options = n_options + 1
            end do
            call read_output(blk, n_options, c%outputs, err)
         case ('NODE OUTPUT', 'ELEMENT OUTPUT', 'ENERGY OUTPUT')
            call read_output_option(blk, model, c%outputs, err)
         case ('AMPLITUDE', 'TIME POINTS')
            ! defined globally by scene_amplitudes and scene_time_points
         case ('MPM CONTROLS', 'MPM WALL', 'INFLOW', 'MPM SIDE FRICTION')
            ! material-point keywords: read by scene_mpm
         case default
            call blk%fail('*' // blk%name // ' cannot stand inside a step; expected step keywords ' // &
                 '(*DYNAMIC, *BOUNDARY, *DLOAD, *OUTPUT, ...)', err)
         end select
         if (err%raised) return
       end associate
    end do
    if (dynamic_block == 0) then
       call deck%blocks(i0)%fail('step ' // trim(step%name) // ' has no procedure; expected ' // &
            '*DYNAMIC, EXPLICIT with the time period', err)
       return
    end if
    if (stop_block /= 0) then
       call read_stop_condition(deck%blocks(stop_block), model, step, err)
       if (err%raised) return
    end if
    ! resolve everything active now into the step
    call bc_resolve(c%bcs, step%boundaries)
    step%mass_scaling = c%mass_scaling(1:c%n_mass_scaling)
    step%gravity = c%gravity(1:c%n_gravity)
    step%temperatures = c%temperatures(1:c%n_temperatures)
    step%pressures = c%pressures(1:c%n_pressures)
    step%contact_pairs = c%pairs(1:c%n_pairs)
    step%field_outputs = c%outputs%field(1:c%outputs%n_field)
    step%history_outputs = c%outputs%history(1:c%outputs%n_history)
    step%bulk_linear = c%bulk_linear
    step%bulk_quadratic = c%bulk_quadratic
    step%restart_write = c%restart_write
    step%restart_interval = 0
    if (c%restart_write) then
       if (c%restart_time > 0) then
          step%restart_interval = c%restart_time
       else
          step%restart_interval = step%period / c%restart_number
       end if
    end if
  end subroutine read_step

  !> Abaqus's NLGEOM: our solver is always geometrically nonlinear. NLGEOM alone means YES
  !> (Abaqus's spelling as a flag); NLGEOM=NO is refused.
  subroutine check_nlgeom(blk, err)
    type(keyword_block_t), intent(in) :: blk
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: nlgeom
    integer :: i

    if (allocated(blk%params)) then
       do i = 1, size(blk%params)
          if (blk%params(i)%name == 'NLGEOM' .and. .not. blk%params(i)%has_value) return
       end do
    end if
    call blk%get_string('NLGEOM', nlgeom, err, default='YES', choices=[character(len=3) :: 'YES'])
  end subroutine check_nlgeom

  !> OP=NEW on one *BOUNDARY (or *DLOAD) of a step requires it on all of them.
  subroutine op_new_rule(deck, i0, i1, keyword, any_new, err)
    type(keyword_deck_t), intent(in) :: deck
    integer, intent(in) :: i0, i1
    character(len=*), intent(in) :: keyword
    logical, intent(out) :: any_new
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: op
    integer :: i, first_new, first_mod

    any_new = .false.
    first_new = 0
    first_mod = 0
    do i = i0 + 1, i1 - 1
       if (deck%blocks(i)%name /= keyword) cycle
       call boundary_op(deck%blocks(i), op, err)
       if (err%raised) return
       if (op == 'NEW' .and. first_new == 0) first_new = i
       if (op /= 'NEW' .and. first_mod == 0) first_mod = i
    end do
    any_new = first_new /= 0
    if (any_new .and. first_mod /= 0) then
       call deck%blocks(first_mod)%fail('*' // keyword // ' without OP=NEW in a step where ' // &
            where_text(deck%blocks(first_new)%file, deck%blocks(first_new)%line) // ' uses OP=NEW; ' // &
            'expected OP=NEW on every *' // keyword // ' of the step', err)
    end if
  end subroutine op_new_rule

  !> *DYNAMIC, EXPLICIT [, DIRECT USER CONTROL] [, SCALE FACTOR=s]; data [dt], period.
  subroutine read_dynamic(blk, step, err)
    type(keyword_block_t), intent(in) :: blk
    type(step_t), intent(inout) :: step
    type(error_t), intent(inout) :: err
    real(dp) :: dt

    call blk%check_params([character(len=19) :: 'EXPLICIT', 'DIRECT USER CONTROL', 'SCALE FACTOR'], err)
    if (err%raised) return
    if (.not. blk%has_param('EXPLICIT')) then
       call blk%fail('*DYNAMIC without EXPLICIT; expected *DYNAMIC, EXPLICIT (bulkflow is an ' // &
            'explicit solver)', err)
       return
    end if
    call get_real_param(blk, 'SCALE FACTOR', step%dt_scale, err, default=1.0_dp, positive=.true.)
    if (err%raised) return
    call expect_lines(blk, 1, 1, 'one line: [time increment], time period', err)
    if (err%raised) return
    associate (dl => blk%lines(1))
      call expect_fields(blk, dl, 2, 2, '[time increment], time period (e.g. ", 1.0")', err)
      if (.not. err%raised) call get_real(dl, 1, dt, err, default=0.0_dp)
      if (.not. err%raised) call get_real(dl, 2, step%period, err)
      if (err%raised) return
      if (.not. (step%period > 0)) then
         call raise_error(dl%file, dl%line, 'time period ' // rtoa(step%period) // &
              ' is not positive; expected a step time period > 0', err)
         return
      end if
      step%dt_fixed = 0
      if (blk%has_param('DIRECT USER CONTROL')) then
         if (.not. (dt > 0)) then
            call raise_error(dl%file, dl%line, 'DIRECT USER CONTROL needs a time increment > 0 ' // &
                 'in field 1; expected dt, period', err)
            return
         end if
         if (dt > step%period) then
            call raise_error(dl%file, dl%line, 'time increment ' // rtoa(dt) // ' exceeds the period ' // &
                 rtoa(step%period) // '; expected dt <= period', err)
            return
         end if
         step%dt_fixed = dt
      else if (dt < 0) then
         call raise_error(dl%file, dl%line, 'negative time increment; expected blank or a positive ' // &
              'value (used only with DIRECT USER CONTROL)', err)
         return
      end if
    end associate
  end subroutine read_dynamic

  !> *DLOAD [, AMPLITUDE=] [, OP=NEW|MOD]; data: element set or blank, GRAV, g, nx, ny[, nz].
  subroutine read_dload(blk, model, c, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    type(carry_t), intent(inout) :: c
    type(error_t), intent(inout) :: err
    type(gravity_t) :: g
    type(gravity_t), allocatable :: tmp(:)
    character(len=:), allocatable :: op, name
    integer :: il, amp, k, ndim, j
    real(dp) :: length

    ndim = model%mesh%ndim
    call blk%check_params([character(len=9) :: 'AMPLITUDE', 'OP'], err)
    if (.not. err%raised) call boundary_op(blk, op, err)
    if (.not. err%raised) call amplitude_param(blk, model, amp, err)
    ! OP=NEW without data lines removes every gravity load (Abaqus)
    if (.not. err%raised) call expect_lines(blk, merge(0, 1, op == 'NEW'), huge(1), &
         'element set or blank, GRAV, g, nx, ny[, nz]', err)
    if (err%raised) return
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         call expect_fields(blk, dl, 5, 6, 'element set or blank, GRAV, g, nx, ny' // &
              trim(merge(', nz', '    ', ndim == 3)), err)
         if (err%raised) return
         if (field_name(dl, 2) /= 'GRAV') then
            call raise_error(dl%file, dl%line, 'load type "' // dl%field(2) // '" is not supported; ' // &
                 'expected GRAV', err)
            return
         end if
         g = gravity_t()
         g%variation = time_variation_t(amplitude=amp)
         g%source = where_text(dl%file, dl%line)
         if (.not. field_blank(dl, 1)) then
            name = field_name(dl, 1)
            if (is_integer_syntax(name)) then
               call raise_error(dl%file, dl%line, 'element number ' // name // ' on a *DLOAD line; ' // &
                    'expected an element set name or a blank field (whole model)', err)
               return
            end if
            g%elset = find_set(model%elsets, model%n_elsets, name)
            if (g%elset == 0) then
               call raise_error(dl%file, dl%line, 'element set ' // name // ' is not defined; expected ' // &
                    'the name of an *ELSET or a blank field (whole model)', err)
               return
            end if
         end if
         call get_real(dl, 3, g%magnitude, err)
         if (err%raised) return
         do k = 1, 3
            call get_real(dl, 3 + k, g%direction(k), err, default=0.0_dp)
            if (err%raised) return
         end do
         if (ndim == 2 .and. abs(g%direction(3)) > 0) then
            call raise_error(dl%file, dl%line, 'gravity direction has a z component in a 2D model; ' // &
                 'expected nx, ny', err)
            return
         end if
         length = norm2(g%direction)
         if (.not. (length > 0)) then
            call raise_error(dl%file, dl%line, 'gravity direction is zero; expected a non-zero ' // &
                 'direction nx, ny' // trim(merge(', nz', '    ', ndim == 3)), err)
            return
         end if
         g%direction = g%direction / length
         ! OP=MOD: a load on the same element set replaces the earlier one
         j = 0
         do k = 1, c%n_gravity
            if (c%gravity(k)%elset == g%elset) j = k
         end do
         if (j == 0) then
            if (c%n_gravity >= size(c%gravity)) then
               allocate (tmp(2 * c%n_gravity + 2))
               tmp(1:c%n_gravity) = c%gravity(1:c%n_gravity)
               call move_alloc(tmp, c%gravity)
            end if
            c%n_gravity = c%n_gravity + 1
            j = c%n_gravity
         end if
         c%gravity(j) = g
       end associate
    end do
  end subroutine read_dload

  !> *CONTACT PAIR, INTERACTION=... [, OP=ADD|DELETE]; data: element surface, rigid surface.
  subroutine read_contact_pair(blk, model, in_step, c, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    logical, intent(in) :: in_step
    type(carry_t), intent(inout) :: c
    type(error_t), intent(inout) :: err
    type(contact_pair_t), allocatable :: tmp(:)
    character(len=:), allocatable :: op, iname, constraint, slave, master
    integer :: il, inter, ks, km, k, j

    call blk%check_params([character(len=21) :: 'INTERACTION', 'OP', 'MECHANICAL CONSTRAINT'], err)
    if (.not. err%raised) call blk%get_string('OP', op, err, default='ADD', &
         choices=[character(len=6) :: 'ADD', 'DELETE'])
    ! kinematic enforcement is what we do (and Abaqus/Explicit's default)
    if (.not. err%raised) call blk%get_string('MECHANICAL CONSTRAINT', constraint, err, &
         default='KINEMATIC', choices=[character(len=9) :: 'KINEMATIC'])
    if (err%raised) return
    if (.not. in_step .and. op == 'DELETE') then
       call blk%fail('*CONTACT PAIR, OP=DELETE in model data; expected it inside a step', err)
       return
    end if
    inter = 0
    if (op == 'ADD') then
       call blk%get_string('INTERACTION', iname, err)
       if (err%raised) return
       inter = find_interaction(model, iname)
       if (inter == 0) then
          call blk%fail('surface interaction ' // iname // ' is not defined; expected the name of a ' // &
               '*SURFACE INTERACTION', err)
          return
       end if
    end if
    call expect_lines(blk, 1, huge(1), 'element surface, rigid surface', err)
    if (err%raised) return
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         call expect_fields(blk, dl, 2, 2, 'element (slave) surface, rigid (master) surface', err)
         if (err%raised) return
         slave = field_name(dl, 1)
         master = field_name(dl, 2)
         if (model%mpm%active) then
            ! a material-point scene pairs its rigid surfaces with the particles: blank field 1
            ks = 0
            if (len(slave) > 0) then
               call raise_error(dl%file, dl%line, 'surface ' // slave // ' in field 1 of a material-point ' // &
                    'scene; expected a blank first field (the particles) and the rigid surface second', err)
               return
            end if
         else
            call require_element_surface(model, dl, slave, 'a rigid surface; expected the element ' // &
                 'surface first and the rigid surface second', ks, err)
            if (err%raised) return
         end if
         km = find_rigid_surface(model, master)
         if (km == 0) then
            call raise_error(dl%file, dl%line, 'surface ' // master // ' is not a rigid surface; ' // &
                 'expected the name of a *SURFACE, TYPE=SEGMENTS or TYPE=PLANE', err)
            return
         end if
         j = 0
         do k = 1, c%n_pairs
            if (c%pairs(k)%slave_surface == ks .and. c%pairs(k)%rigid_surface == km) j = k
         end do
         if (op == 'DELETE') then
            if (j == 0) then
               call raise_error(dl%file, dl%line, 'no active contact pair ' // slave // ', ' // master // &
                    ' to delete; expected a pair defined earlier', err)
               return
            end if
            c%pairs(j:c%n_pairs - 1) = c%pairs(j + 1:c%n_pairs)
            c%n_pairs = c%n_pairs - 1
            cycle
         end if
         if (j /= 0) then
            call raise_error(dl%file, dl%line, 'contact pair ' // slave // ', ' // master // &
                 ' is already active; expected each pair once (OP=DELETE it first to change it)', err)
            return
         end if
         if (c%n_pairs >= size(c%pairs)) then
            allocate (tmp(2 * c%n_pairs + 2))
            tmp(1:c%n_pairs) = c%pairs(1:c%n_pairs)
            call move_alloc(tmp, c%pairs)
         end if
         c%n_pairs = c%n_pairs + 1
         c%pairs(c%n_pairs)%slave_surface = ks
         c%pairs(c%n_pairs)%rigid_surface = km
         c%pairs(c%n_pairs)%interaction = inter
       end associate
    end do
  end subroutine read_contact_pair

  !> *BULK VISCOSITY: b1, b2 (blank keeps the current value).
  subroutine read_bulk_viscosity(blk, c, err)
    type(keyword_block_t), intent(in) :: blk
    type(carry_t), intent(inout) :: c
    type(error_t), intent(inout) :: err
    real(dp) :: b1, b2

    call blk%check_params([character(len=8) ::], err)
    if (.not. err%raised) call expect_lines(blk, 1, 1, 'one line: b1, b2', err)
    if (.not. err%raised) call expect_fields(blk, blk%lines(1), 1, 2, 'b1, b2', err)
    if (.not. err%raised) call get_real(blk%lines(1), 1, b1, err, default=c%bulk_linear)
    if (.not. err%raised) call get_real(blk%lines(1), 2, b2, err, default=c%bulk_quadratic)
    if (err%raised) return
    c%bulk_linear = b1
    c%bulk_quadratic = b2
    if (c%bulk_linear < 0 .or. c%bulk_quadratic < 0) then
       call raise_error(blk%lines(1)%file, blk%lines(1)%line, 'bulk viscosity coefficients ' // &
            rtoa(c%bulk_linear) // ', ' // rtoa(c%bulk_quadratic) // ' include a negative one; ' // &
            'expected b1 >= 0 and b2 >= 0', err)
    end if
  end subroutine read_bulk_viscosity

  !> *RESTART, WRITE [, NUMBER INTERVAL=n | TIME INTERVAL=t] (default: at the step end).
  subroutine read_restart(blk, c, err)
    type(keyword_block_t), intent(in) :: blk
    type(carry_t), intent(inout) :: c
    type(error_t), intent(inout) :: err

    call blk%check_params([character(len=15) :: 'WRITE', 'READ', 'NUMBER INTERVAL', 'TIME INTERVAL', &
         'TIME MARKS'], err)
    if (.not. err%raised) call time_marks(blk, err)
    if (.not. err%raised) call expect_lines(blk, 0, 0, 'no data lines', err)
    if (err%raised) return
    if (blk%has_param('READ')) then
       call blk%fail('*RESTART, READ is not supported in a scene; expected *RESTART, WRITE (restart ' // &
            'a run with bulkflow --restart)', err)
       return
    end if
    if (.not. blk%has_param('WRITE')) then
       call blk%fail('*RESTART without WRITE; expected *RESTART, WRITE [, NUMBER INTERVAL=n | ' // &
            'TIME INTERVAL=t]', err)
       return
    end if
    if (blk%has_param('NUMBER INTERVAL') .and. blk%has_param('TIME INTERVAL')) then
       call blk%fail('*RESTART with both NUMBER INTERVAL and TIME INTERVAL; expected one of them', err)
       return
    end if
    call blk%get_integer('NUMBER INTERVAL', c%restart_number, err, default=1, minimum=1)
    if (.not. err%raised) call get_real_param(blk, 'TIME INTERVAL', c%restart_time, err, &
         default=0.0_dp)
    if (err%raised) return
    if (blk%has_param('TIME INTERVAL') .and. .not. (c%restart_time > 0)) then
       call blk%fail('*RESTART: TIME INTERVAL must be positive; expected a time > 0', err)
       return
    end if
    c%restart_write = .true.
  end subroutine read_restart

  !> *FIXED MASS SCALING [, FACTOR=f] [, DT=dt, TYPE=BELOW MIN|UNIFORM] [, ELSET=name]; no data.
  subroutine read_mass_scaling(blk, model, c, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    type(carry_t), intent(inout) :: c
    type(error_t), intent(inout) :: err
    type(mass_scaling_t) :: ms
    type(mass_scaling_t), allocatable :: tmp(:)
    character(len=:), allocatable :: kind, name

    call blk%check_params([character(len=6) :: 'FACTOR', 'DT', 'TYPE', 'ELSET'], err)
    if (.not. err%raised) call expect_lines(blk, 0, 0, 'no data lines', err)
    if (.not. err%raised) call get_real_param(blk, 'FACTOR', ms%factor, err, default=1.0_dp, positive=.true.)
    if (.not. err%raised) call get_real_param(blk, 'DT', ms%dt, err, default=0.0_dp)
    if (.not. err%raised) call blk%get_string('TYPE', kind, err, default='BELOW MIN', &
         choices=[character(len=9) :: 'BELOW MIN', 'UNIFORM'])
    if (err%raised) return
    if (blk%has_param('DT') .and. .not. (ms%dt > 0)) then
       call blk%fail('*FIXED MASS SCALING: DT=' // rtoa(ms%dt) // ' is not positive; expected a target ' // &
            'element stable time increment > 0', err)
       return
    end if
    if (blk%has_param('TYPE') .and. .not. blk%has_param('DT')) then
       call blk%fail('*FIXED MASS SCALING: TYPE=' // kind // ' without DT; expected DT=<target increment> ' // &
            'with TYPE', err)
       return
    end if
    ms%kind = mass_scaling_below_min
    if (kind == 'UNIFORM') ms%kind = mass_scaling_uniform
    if (blk%has_param('ELSET')) then
       call blk%get_string('ELSET', name, err)
       if (err%raised) return
       ms%elset = find_set(model%elsets, model%n_elsets, name)
       if (ms%elset == 0) then
          call blk%fail('element set ' // name // ' is not defined; expected the name of an *ELSET ' // &
               '(or no ELSET: all elements)', err)
          return
       end if
    end if
    if (c%n_mass_scaling >= size(c%mass_scaling)) then
       allocate (tmp(2 * c%n_mass_scaling + 2))
       tmp(1:c%n_mass_scaling) = c%mass_scaling(1:c%n_mass_scaling)
       call move_alloc(tmp, c%mass_scaling)
    end if
    c%n_mass_scaling = c%n_mass_scaling + 1
    c%mass_scaling(c%n_mass_scaling) = ms
  end subroutine read_mass_scaling

  !> *STOP CONDITION, NSET=name, DISPLACEMENT=d [, KINETIC FRACTION=f] [, HOLD=t] [, MIN TIME=t]
  !> [, GROWTH=g] (ours); no data lines. HOLD defaults to 5 % of the step period.
  subroutine read_stop_condition(blk, model, step, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    type(step_t), intent(inout) :: step
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name

    call blk%check_params([character(len=16) :: 'NSET', 'DISPLACEMENT', 'KINETIC FRACTION', 'HOLD', &
         'MIN TIME', 'GROWTH'], err)
    if (.not. err%raised) call expect_lines(blk, 0, 0, 'no data lines', err)
    if (.not. err%raised) call blk%get_string('NSET', name, err)
    if (err%raised) return
    step%stop%nset = find_set(model%nsets, model%n_nsets, name)
    if (step%stop%nset == 0) then
       call blk%fail('node set ' // name // ' is not defined; expected the name of an *NSET whose ' // &
            'displacements decide FLOW', err)
       return
    end if
    if (.not. blk%has_param('DISPLACEMENT')) then
       call blk%fail('*STOP CONDITION without DISPLACEMENT; expected DISPLACEMENT=<limit> (e.g. half ' // &
            'an element length)', err)
       return
    end if
    call get_real_param(blk, 'DISPLACEMENT', step%stop%displacement, err, positive=.true.)
    if (.not. err%raised) call get_real_param(blk, 'KINETIC FRACTION', step%stop%ke_fraction, err, &
         default=0.01_dp, positive=.true.)
    if (.not. err%raised) call get_real_param(blk, 'HOLD', step%stop%hold, err, default=0.05_dp * step%period, &
         positive=.true.)
    if (.not. err%raised) call get_real_param(blk, 'MIN TIME', step%stop%min_time, err, default=0.0_dp)
    if (.not. err%raised) call get_real_param(blk, 'GROWTH', step%stop%growth, err, default=0.05_dp)
    if (err%raised) return
    if (step%stop%growth < 0 .or. .not. (step%stop%growth < 1)) then
       call blk%fail('*STOP CONDITION: GROWTH=' // rtoa(step%stop%growth) // ' is outside [0, 1); ' // &
            'expected the largest growth of the displacement over HOLD, as a fraction of DISPLACEMENT ' // &
            '(0: the kinetic-energy rule only)', err)
       return
    end if
    if (.not. (step%stop%ke_fraction < 1)) then
       call blk%fail('*STOP CONDITION: KINETIC FRACTION=' // rtoa(step%stop%ke_fraction) // &
            ' is not below 1; expected a fraction 0 < f < 1 of the peak kinetic energy', err)
       return
    end if
    if (step%stop%min_time < 0 .or. step%stop%min_time + step%stop%hold > step%period) then
       call blk%fail('*STOP CONDITION: MIN TIME + HOLD = ' // rtoa(step%stop%min_time + step%stop%hold) // &
            ' exceeds the step period ' // rtoa(step%period) // '; expected MIN TIME >= 0 and ' // &
            'MIN TIME + HOLD <= period', err)
       return
    end if
    step%stop%active = .true.
  end subroutine read_stop_condition
end module scene_steps
