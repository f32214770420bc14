!> Everything the run writes while it goes: field frames (HDF5 + XDMF) at the requested
!> intervals, history rows (energies, wall forces, node-set values) in CSV, the energy-balance
!> check (the progress line is the run skeleton's: src/run/run_progress.f90).
module driver_output
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use mpi_f08, only: MPI_Comm
  use base_kinds, only: dp
  use model, only: model_t
  use model_steps, only: field_output_t, history_output_t
  use parallel_partition, only: partition_t, local_node_index
  use parallel_assembly, only: global_sum
  use driver_solver, only: solver_t, element_block_t
  use output_hdf5, only: field_writer_t, field_writer_open, field_writer_frame, field_writer_end_frame, &
       field_writer_coordinates, field_writer_node_field, field_writer_element_field, field_writer_close, &
       field_writer_frame_count
  use output_history, only: history_t, history_open, history_row, history_close, history_row_count
  use fem_corotation, only: stored_to_global
  use driver_stop_condition, only: count_stop_columns, add_stop_columns, stop_column_values
  use driver_temperature, only: frame_temperatures, frame_node_temperatures
  implicit none
  private

  type, public :: run_output_t
     character(len=:), allocatable :: base          !< path without extension
     type(field_writer_t) :: fields
     type(history_t) :: history
     logical :: fields_open = .false.
     integer :: n_history_columns = 0
     character(len=32), allocatable :: columns(:)   !< history column names
     real(dp) :: energy_reference = 0               !< ETOTAL at the start (subtracted)
     !> Energy-balance check (write_history): energies below energy_floor are not significant;
     !> energy_peak is the largest max(ALLKE, ALLIE, |ALLWK|) seen so far.
     real(dp) :: energy_floor = 0, energy_peak = 0
     logical :: balance_warned = .false.
  end type run_output_t

  public :: open_run_output, close_run_output, write_frame, write_history, energy_values, sum_over_ranks

contains

  subroutine open_run_output(m, solver, out, base, frames_done, rows_done, restart_time)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    type(run_output_t), intent(inout) :: out
    character(len=*), intent(in) :: base
    integer, intent(in), optional :: frames_done, rows_done
    real(dp), intent(in), optional :: restart_time
    character(len=32), allocatable :: columns(:)
    integer :: i, j, n
    logical :: any_fields

    out%base = base
    any_fields = .false.
    do i = 1, m%n_steps
       if (allocated(m%steps(i)%field_outputs)) any_fields = any_fields .or. size(m%steps(i)%field_outputs) > 0
    end do
    if (any_fields) then
       associate (part => solver%part)
         if (present(frames_done)) then
            call field_writer_open(out%fields, base, part%comm, solver%ndim, m%mesh%element_type, &
                 m%mesh%n_nodes, m%mesh%n_elems, part%node_global, part%node_owned, &
                 m%mesh%node_id(part%node_global), solver%x0, part%elem_global, m%mesh%elem_id(part%elem_global), &
                 global_connectivity(part), restart_frames=frames_done)
         else
            call field_writer_open(out%fields, base, part%comm, solver%ndim, m%mesh%element_type, &
                 m%mesh%n_nodes, m%mesh%n_elems, part%node_global, part%node_owned, &
                 m%mesh%node_id(part%node_global), solver%x0, part%elem_global, m%mesh%elem_id(part%elem_global), &
                 global_connectivity(part))
         end if
       end associate
       out%fields_open = .true.
    end if

    ! History columns: time, energies, the force on each rigid wall, node-set values.
    n = 11 + solver%ndim * m%n_rigid_surfaces
    do i = 1, m%n_steps
       if (.not. allocated(m%steps(i)%history_outputs)) cycle
       do j = 1, size(m%steps(i)%history_outputs)
          if (allocated(m%steps(i)%history_outputs(j)%node_variables)) &
               n = n + size(m%steps(i)%history_outputs(j)%node_variables)
       end do
    end do
    n = n + count_stop_columns(m)
    allocate(columns(n))
    columns(1:11) = [character(len=32) :: 'time', 'step', 'step_time', 'increment', 'ALLKE', 'ALLIE', &
         'ALLVD', 'ALLFD', 'ALLWK', 'ALLAE', 'ETOTAL']
    n = 11
    do i = 1, m%n_rigid_surfaces
       do j = 1, solver%ndim
          n = n + 1
          write (columns(n), '(a,i0,a)') 'WALLF', j, '_' // trim(m%rigid_surfaces(i)%name)
       end do
    end do
    do i = 1, m%n_steps
       if (.not. allocated(m%steps(i)%history_outputs)) cycle
       do j = 1, size(m%steps(i)%history_outputs)
          call add_set_columns(m, m%steps(i)%history_outputs(j), columns, n)
       end do
    end do
    call add_stop_columns(m, columns, n)
    out%n_history_columns = n
    out%columns = columns(1:n)
    if (present(rows_done)) then
       call history_open(out%history, base // '_history.csv', columns(1:n), solver%part%comm, &
            restart_rows=rows_done, restart_time=restart_time)
    else
       call history_open(out%history, base // '_history.csv', columns(1:n), solver%part%comm)
    end if
  end subroutine open_run_output

  !> Columns of one history request, without duplicates of earlier steps' identical requests.
  subroutine add_set_columns(m, h, columns, n)
    type(model_t), intent(in) :: m
    type(history_output_t), intent(in) :: h
    character(len=32), intent(inout) :: columns(:)
    integer, intent(inout) :: n
    integer :: k
    character(len=32) :: name

    if (.not. allocated(h%node_variables) .or. h%nset == 0) return
    do k = 1, size(h%node_variables)
       name = trim(h%node_variables(k)) // '_' // trim(m%nsets(h%nset)%name)
       if (any(columns(1:n) == name)) cycle
       n = n + 1
       columns(n) = name
    end do
  end subroutine add_set_columns

  subroutine close_run_output(out)
    type(run_output_t), intent(inout) :: out
    if (out%fields_open) call field_writer_close(out%fields)
    out%fields_open = .false.
    call history_close(out%history)
  end subroutine close_run_output

  !> One field frame with the variables the step asks for.
  subroutine write_frame(m, solver, out, istep)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: istep
    integer :: j, k
    type(field_output_t) :: f
    character(len=8), allocatable :: written(:)

    if (.not. out%fields_open .or. .not. allocated(m%steps(istep)%field_outputs)) return
    call field_writer_frame(out%fields, istep, solver%step_time, solver%total_time, solver%increment)
    call field_writer_coordinates(out%fields, solver%part%node_global, solver%part%node_owned, &
         solver%x0 + solver%u)
    ! every variable once, however many of the step's requests ask for it
    allocate (written(0))
    do j = 1, size(m%steps(istep)%field_outputs)
       f = m%steps(istep)%field_outputs(j)
       if (allocated(f%node_variables)) then
          do k = 1, size(f%node_variables)
             if (any(written == f%node_variables(k))) cycle
             written = [character(len=8) :: written, f%node_variables(k)]
             call write_node_variable(m, solver, out, trim(f%node_variables(k)))
          end do
       end if
       if (allocated(f%element_variables)) then
          do k = 1, size(f%element_variables)
             if (any(written == f%element_variables(k))) cycle
             written = [character(len=8) :: written, f%element_variables(k)]
             call write_element_variable(m, solver, out, trim(f%element_variables(k)))
          end do
       end if
    end do
    call field_writer_end_frame(out%fields)
  end subroutine write_frame

  subroutine write_node_variable(m, solver, out, name)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    type(run_output_t), intent(inout) :: out
    character(len=*), intent(in) :: name
    real(dp), allocatable :: node_temp(:)

    associate (p => solver%part)
      select case (name)
      case ('U')
         call field_writer_node_field(out%fields, 'U', p%node_global, p%node_owned, solver%u)
      case ('V')
         call field_writer_node_field(out%fields, 'V', p%node_global, p%node_owned, solver%v)
      case ('A')
         call field_writer_node_field(out%fields, 'A', p%node_global, p%node_owned, solver%a)
      case ('RF')
         call field_writer_node_field(out%fields, 'RF', p%node_global, p%node_owned, solver%reaction)
      case ('NT')
         call frame_node_temperatures(m, solver, node_temp)
         call field_writer_node_field(out%fields, 'NT', p%node_global, p%node_owned, &
              reshape(node_temp(p%node_global), [1, size(p%node_global)]))
      end select
    end associate
  end subroutine write_node_variable

  !> Element variables gathered from the blocks into (n_local_elems, ncomp) arrays.
  subroutine write_element_variable(m, solver, out, name)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    type(run_output_t), intent(inout) :: out
    character(len=*), intent(in) :: name
    real(dp), allocatable :: values(:, :), block_values(:, :)
    integer :: ib, n, ns, j
    character(len=16) :: label

    n = solver%part%n_local_elems
    select case (name)
    case ('S')
       allocate(values(n, solver%ncomp))
       do ib = 1, solver%n_blocks
          associate (b => solver%blocks(ib))
            call stored_to_global(b%count, solver%ndim, size(b%rotation, 3), solver%ncomp, b%rotation, &
                 b%stress, values(b%first:b%first + b%count - 1, :))
          end associate
       end do
       call field_writer_element_field(out%fields, 'S', solver%part%elem_global, values)
    case ('LE', 'PE')
       ! LE and PE (driver_plastic_strain) are accumulated in the corotational frame; written,
       ! like S, in global components. Shear components are tensor components, as the VUMAT's
       ! strains. A block that does not keep the field writes zeros.
       allocate(values(n, solver%ncomp))
       values = 0
       do ib = 1, solver%n_blocks
          associate (b => solver%blocks(ib))
            if (name == 'LE') then
               call rotated_block_strain(b, b%log_strain)
            else
               call rotated_block_strain(b, b%plastic_strain)
            end if
          end associate
       end do
       call field_writer_element_field(out%fields, name, solver%part%elem_global, values)
    case ('PEEQ', 'SDV')
       ns = 0
       do ib = 1, solver%n_blocks
          ns = max(ns, m%materials(solver%blocks(ib)%material)%nstatev)
       end do
       if (name == 'PEEQ') ns = min(ns, 1)
       do j = 1, ns
          allocate(values(n, 1))
          values = 0
          do ib = 1, solver%n_blocks
             associate (b => solver%blocks(ib))
               if (j <= m%materials(b%material)%nstatev) values(b%first:b%first + b%count - 1, 1) = b%state(:, j)
             end associate
          end do
          write (label, '(a,i0)') 'SDV', j
          if (name == 'PEEQ') label = 'PEEQ'
          call field_writer_element_field(out%fields, trim(label), solver%part%elem_global, values)
          deallocate(values)
       end do
    case ('FV')
       ! FV1..FVn: every field variable any block has (a VUSDFLD with FIELDS=n writes n).
       ns = 1
       do ib = 1, solver%n_blocks
          ns = max(ns, size(solver%blocks(ib)%field, 2))
       end do
       do j = 1, ns
          allocate(values(n, 1))
          values = 0
          do ib = 1, solver%n_blocks
             associate (b => solver%blocks(ib))
               if (j <= size(b%field, 2)) values(b%first:b%first + b%count - 1, 1) = b%field(:, j)
             end associate
          end do
          write (label, '(a,i0)') 'FV', j
          call field_writer_element_field(out%fields, trim(label), solver%part%elem_global, values)
          deallocate(values)
       end do
    case ('STATUS')
       allocate(values(n, 1))
       values = 1
       call field_writer_element_field(out%fields, 'STATUS', solver%part%elem_global, values)
    case ('TEMP')
       allocate(values(n, 1))
       call frame_temperatures(m, solver, values(:, 1))
       call field_writer_element_field(out%fields, 'TEMP', solver%part%elem_global, values)
    end select
  contains

    subroutine rotated_block_strain(b, strain)
      type(element_block_t), intent(in) :: b
      real(dp), intent(in) :: strain(:, :)

      if (size(strain, 1) /= b%count) return
      allocate(block_values(b%count, solver%ncomp))
      call stored_to_global(b%count, solver%ndim, size(b%rotation, 3), solver%ncomp, b%rotation, strain, &
           block_values)
      values(b%first:b%first + b%count - 1, :) = block_values
      deallocate(block_values)
    end subroutine rotated_block_strain
  end subroutine write_element_variable

  !> Global energies [ALLKE, ALLIE, ALLVD, ALLFD, ALLWK, ALLAE] at t_{n+1}; ALLIE includes ALLAE
  !> as in Abaqus. The kinetic energy is the central-difference one, ½ m v_{n+1/2}·v_{n+3/2} with
  !> the unconstrained v_{n+3/2} = v_{n+1/2} + Δt a_{n+1}: the leapfrog invariant, so the balance
  !> with the trapezoidal work terms is exact for linear problems (v_{n+1} = v_{n+1/2} + Δt/2 a_{n+1}
  !> squared, used before, carries an O(Δt²) term ⅛ Δt² |f|²/m that nothing balances).
  !> ALLWK also gets the pending half of the supports' work, ½ Δt v_{n+1/2}·R_{n+1}: the reaction
  !> at t_{n+1} is part of the force that drives the next half-increment, so its trapezoidal share
  !> belongs to this row (driver_run's constraint_work books the rest in the next increment, in
  !> the impulse at t_{n+1}). Without it ETOTAL is off by ½ R Δu for as long as a support moves
  !> under load (a driven bar end: a constant offset of ~1 % of the energies).
  subroutine energy_values(solver, e)
    type(solver_t), intent(in) :: solver
    real(dp), intent(out) :: e(6)
    integer :: i, ib

    e = 0
    do i = 1, solver%n_nodes
       if (.not. solver%part%node_owned(i)) cycle
       e(1) = e(1) + 0.5_dp * solver%mass(i) * sum(solver%v(:, i) * (solver%v(:, i) + solver%dt * solver%a(:, i)))
       e(5) = e(5) + 0.5_dp * solver%dt * sum(solver%v(:, i) * solver%reaction(:, i))
    end do
    do ib = 1, solver%n_blocks
       e(2) = e(2) + sum(solver%blocks(ib)%mass * solver%blocks(ib)%e_int)
    end do
    e(2) = e(2) + solver%e_artificial
    e(3) = solver%e_viscous
    e(4) = solver%e_friction
    e(5) = e(5) + solver%e_external
    e(6) = solver%e_artificial
    call global_sum(solver%part, e)
  end subroutine energy_values

  !> One history row; also the energy-balance check: a warning, once, when |ETOTAL| exceeds 1 %
  !> of the largest energy max(ALLKE, ALLIE, |ALLWK|) seen so far (the peak, so a decaying run is
  !> still judged against what it had) — but only once that peak is significant: above
  !> energy_floor = 1e-12 × ½ Σ_e M_e V_e (driver_run), the model's strain energy at unit strain.
  !> Below it every strain is under 1e-6 and every velocity under 1e-6 c_d (½ m v² = ½ M V (v/c)²):
  !> a model at rest or barely loaded, whose energies (1e-14 J at the first rows of a ramped load)
  !> are round-off and start-up transients; comparing them said nothing, and the previous check
  !> (no floor) fired there. The start-up term itself is booked exactly (driver_run's
  !> constraint_work), so a suddenly applied load leaves no offset in ETOTAL.
  subroutine write_history(m, solver, out, istep)
    type(model_t), intent(in) :: m
    type(solver_t), intent(inout) :: solver
    type(run_output_t), intent(inout) :: out
    integer, intent(in) :: istep
    real(dp) :: e(6), etotal, row(out%n_history_columns), wall(solver%ndim, max(1, m%n_rigid_surfaces))
    integer :: n, i, j, k

    call energy_values(solver, e)
    etotal = e(1) + e(2) + e(3) + e(4) - e(5) - out%energy_reference
    solver%energies%kinetic = e(1)
    solver%energies%internal = e(2)
    solver%energies%viscous = e(3)
    solver%energies%friction = e(4)
    solver%energies%external = e(5)
    solver%energies%artificial = e(6)
    row(1:11) = [solver%total_time, real(istep, dp), solver%step_time, real(solver%increment, dp), &
         e(1), e(2), e(3), e(4), e(5), e(6), etotal]
    n = 11
    wall = solver%wall_force
    if (m%n_rigid_surfaces > 0) call sum_over_ranks(solver, wall)
    do i = 1, m%n_rigid_surfaces
       do j = 1, solver%ndim
          n = n + 1
          row(n) = wall(j, i)
       end do
    end do
    do k = n + 1, out%n_history_columns
       row(k) = 0
    end do
    call set_values(m, solver, istep, out%columns, row)
    call stop_column_values(m, istep, solver, out%columns, row)
    call history_row(out%history, row)
    out%energy_peak = max(out%energy_peak, e(1), e(2), abs(e(5)))
    if (.not. out%balance_warned .and. solver%part%rank == 0) then
       if (out%energy_peak > out%energy_floor .and. abs(etotal) > 0.01_dp * out%energy_peak) then
          write (error_unit, '(a,es10.3,a,es10.3,a,es12.5)') 'bulkflow: warning: energy balance ETOTAL = ', &
               etotal, ' exceeds 1 % of the largest energy (', out%energy_peak, ') at t = ', solver%total_time
          out%balance_warned = .true.
       end if
    end if
  end subroutine write_history

  !> Node-set values of the step's history requests: RFi summed, Ui/Vi/Ai averaged over the set.
  subroutine set_values(m, solver, istep, columns, row)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    integer, intent(in) :: istep
    character(len=*), intent(in) :: columns(:)
    real(dp), intent(inout) :: row(:)
    integer :: j, k, i, g, li, dof, col, ios
    real(dp) :: acc(2)
    character(len=8) :: var
    character(len=32) :: name

    if (.not. allocated(m%steps(istep)%history_outputs)) return
    do j = 1, size(m%steps(istep)%history_outputs)
       associate (h => m%steps(istep)%history_outputs(j))
         if (.not. allocated(h%node_variables) .or. h%nset == 0) cycle
         do k = 1, size(h%node_variables)
            var = h%node_variables(k)
            read (var(len_trim(var):len_trim(var)), '(i1)', iostat=ios) dof
            if (ios /= 0 .or. dof < 1 .or. dof > solver%ndim) cycle
            acc = 0
            do i = 1, size(m%nsets(h%nset)%members)
               g = m%nsets(h%nset)%members(i)
               li = local_node_index(solver%part, g)
               if (li == 0) cycle
               if (.not. solver%part%node_owned(li)) cycle
               select case (var(1:len_trim(var) - 1))
               case ('RF')
                  acc(1) = acc(1) + solver%reaction(dof, li)
               case ('U')
                  acc(1) = acc(1) + solver%u(dof, li)
               case ('V')
                  acc(1) = acc(1) + solver%v(dof, li)
               case ('A')
                  ! (was missing: A1..A3 history columns were always 0)
                  acc(1) = acc(1) + solver%a(dof, li)
               end select
               acc(2) = acc(2) + 1
            end do
            call global_sum(solver%part, acc)
            ! Forces add up over the set; displacements and velocities are set averages.
            if (var(1:2) /= 'RF' .and. acc(2) > 0) acc(1) = acc(1) / acc(2)
            name = trim(var) // '_' // trim(m%nsets(h%nset)%name)
            do col = 1, size(columns)
               if (columns(col) == name) row(col) = acc(1)
            end do
         end do
       end associate
    end do
  end subroutine set_values

  !> Connectivity of the local elements in global node indices, as the field writer wants it.
  function global_connectivity(part) result(conn)
    type(partition_t), intent(in) :: part
    integer :: conn(size(part%conn, 1), size(part%conn, 2))
    integer :: e, a

    do e = 1, size(part%conn, 2)
       do a = 1, size(part%conn, 1)
          conn(a, e) = part%node_global(part%conn(a, e))
       end do
    end do
  end function global_connectivity

  !> Sum a small (ndim, n) array over the ranks.
  subroutine sum_over_ranks(solver, values)
    type(solver_t), intent(in) :: solver
    real(dp), intent(inout) :: values(:, :)
    real(dp) :: flat(size(values))

    flat = reshape(values, [size(values)])
    call global_sum(solver%part, flat)
    values = reshape(flat, shape(values))
  end subroutine sum_over_ranks

end module driver_output
