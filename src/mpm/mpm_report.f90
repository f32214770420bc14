!> What an MPM run reports: the header and the summary on standard output (the progress line
!> and the end report's first lines are the run skeleton's, src/run), the history rows (masses, energies, centre of mass, wall forces; sums over ranks in rank
!> order) and the field frames (every rank writes its own blocks through mpm_output).
module mpm_report
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use base_kinds, only: dp
  use model, only: model_t
  use mpm_state, only: mpm_state_t, sum_over_ranks, max_over_ranks
  use output_effects, only: effects_t
  use mpm_output, only: mpm_writer_t, mpm_writer_frame
  use mpm_domain, only: owned_range
  use parallel_comm, only: comm_max, comm_sum
  use output_history, only: history_t, history_row
  implicit none
  private

  public :: header, summary, history_columns, measure, write_history, write_frame

contains

  !> Does a step of the scene have front and back wall friction (*MPM SIDE FRICTION)? Then the
  !> history has the columns SIDEF1, SIDEF2 and the summary its force.
  pure logical function side_friction_on(m)
    type(model_t), intent(in) :: m
    side_friction_on = .false.
    if (allocated(m%mpm%steps)) side_friction_on = any(m%mpm%steps(:)%side_friction > 0)
  end function side_friction_on

  !> A field frame: every rank writes its own blocks (collective; rows in rank order).
  subroutine write_frame(m, st, wr, step, step_time)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(mpm_writer_t), intent(inout) :: wr
    integer, intent(in) :: step
    real(dp), intent(in) :: step_time

    integer :: olo(3), ohi(3)

    if (st%dom%on) then
       ! a decomposed grid: each rank writes the nodes it owns (mpm_domain)
       call owned_range(st%dom, st%rank, olo, ohi)
       call mpm_writer_frame(wr, m, st%blocks, st%nblocks, st%g, step, st%increment, step_time, st%total_time, &
            olo, ohi)
    else
       call mpm_writer_frame(wr, m, st%blocks, st%nblocks, st%g, step, st%increment, step_time, st%total_time)
    end if
  end subroutine write_frame

  !> The history's columns: the fixed ones, then three force components per wall.
  subroutine history_columns(m, columns)
    type(model_t), intent(in) :: m
    character(len=32), allocatable, intent(out) :: columns(:)
    character(len=*), parameter :: fixed(*) = [character(len=32) :: 'time', 'step', 'step_time', 'increment', &
         'particles', 'MASS', 'MASS_IN', 'MASS_OUT', 'MDR', 'MASS_ERROR', 'ALLKE', 'ALLIE', 'ALLWK', 'ALLFD', &
         'ALLDMD', 'ETOTAL', 'XCM1', 'XCM2', 'XCM3', 'VCM1', 'VCM2', 'VCM3', 'YTOP', 'GUARDED']
    integer :: k, n, j

    n = size(m%mpm%walls)
    allocate (columns(size(fixed) + 3 * n + merge(2, 0, side_friction_on(m))))
    columns(1:size(fixed)) = fixed
    j = size(fixed)
    do k = 1, n
       columns(j + 1) = 'WALLF1_' // trim(m%mpm%walls(k)%name)
       columns(j + 2) = 'WALLF2_' // trim(m%mpm%walls(k)%name)
       columns(j + 3) = 'WALLF3_' // trim(m%mpm%walls(k)%name)
       j = j + 3
    end do
    if (side_friction_on(m)) columns(j + 1:j + 2) = [character(len=32) :: 'SIDEF1', 'SIDEF2']
  end subroutine history_columns

  !> Kinetic and internal energy (global sums) of the particles.
  subroutine measure(st)
    type(mpm_state_t), intent(inout) :: st
    integer :: ib
    real(dp) :: e(2)
    st%e_kinetic = 0
    st%e_internal = 0
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         st%e_kinetic = st%e_kinetic + 0.5_dp * sum(b%mass * sum(b%v**2, dim=2))
         st%e_internal = st%e_internal + sum(b%mass * b%e_int)
       end associate
    end do
    e = [st%e_kinetic, st%e_internal]
    call sum_over_ranks(st, e)
    st%e_kinetic = e(1)
    st%e_internal = e(2)
  end subroutine measure

  !> One history row: global values (sums over ranks in rank order; collective).
  subroutine write_history(m, st, hist, last_time, last_out)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(history_t), intent(inout) :: hist
    real(dp), intent(inout) :: last_time, last_out
    real(dp), allocatable :: row(:)
    real(dp) :: g(12), top(1), mass, xcm(3), vcm(3), mdr, etotal, mass_out
    integer :: ib, k, j

    g = 0
    top = -huge(1.0_dp)
    do ib = 1, st%nblocks
       associate (b => st%blocks(ib))
         g(1) = g(1) + sum(b%mass)
         do k = 1, st%nd
            g(1 + k) = g(1 + k) + sum(b%mass * b%x(:, k))
            g(4 + k) = g(4 + k) + sum(b%mass * b%v(:, k))
         end do
         top(1) = max(top(1), maxval(b%x(:, 2)))
         g(8) = g(8) + b%count
       end associate
    end do
    g(9) = st%mass_out
    g(10) = st%w_external
    g(11) = st%e_out
    g(12) = st%n_guarded
    call sum_over_ranks(st, g)
    call max_over_ranks(st, top)
    mass = g(1)
    ! an emptied domain has no centre of mass and no top: 0, not 0/0 (tests/stability hopper-empty)
    xcm = 0
    vcm = 0
    if (g(8) > 0) then
       xcm = g(2:4) / mass
       vcm = g(5:7) / mass
    else
       top = 0
    end if
    mass_out = g(9)
    mdr = 0
    if (st%total_time > last_time) mdr = (mass_out - last_out) / (st%total_time - last_time)
    etotal = st%e_kinetic + st%e_internal + st%e_walls + st%e_damping + g(11) - st%e_in - g(10)
    allocate (row(24 + 3 * size(m%mpm%walls) + merge(2, 0, side_friction_on(m))))
    row(1:24) = [st%total_time, real(st%step, dp), st%step_time, real(st%increment, dp), g(8), mass, &
         st%mass_in, mass_out, mdr, st%mass_initial + st%mass_in - mass_out - mass, st%e_kinetic, &
         st%e_internal, g(10), st%e_walls, st%e_damping, etotal, xcm, vcm, top(1), g(12)]
    j = 24
    do k = 1, size(m%mpm%walls)
       if (st%impulse_time > 0) then
          st%wall_force_row(:, k) = st%wall_impulse(:, k) / st%impulse_time
       else
          st%wall_force_row(:, k) = st%wall_force(:, k)
       end if
       row(j + 1:j + 3) = st%wall_force_row(:, k)
       j = j + 3
    end do
    if (side_friction_on(m)) row(j + 1:j + 2) = st%side_force(1:2)
    if (allocated(st%wall_impulse)) st%wall_impulse = 0
    st%impulse_time = 0
    call history_row(hist, row)
    last_time = st%total_time
    last_out = mass_out
  end subroutine write_history

  subroutine header(m, st, fx, base)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(in) :: st
    type(effects_t), intent(in) :: fx
    character(len=*), intent(in) :: base

    write (output_unit, '(a)') 'bulkflow: ' // trim(m%heading)
    write (output_unit, '(a,i0,a,i0,a,i0,a,es10.3,a,a,a,i0,a)') '  mpm       ', st%nd, 'D, ', &
         st%n_initial, ' particles, ', merge(product(st%dom%n), st%g%nn, st%dom%on), ' grid nodes, cell ', m%mpm%cell, &
         ', shape ', trim(merge('uGIMP ', 'linear', st%nsup == 3)), ', ', st%nranks, ' rank(s)'
    write (output_unit, '(a)') fx%header_line()
    write (output_unit, '(a)') '  output    ' // base // '.h5/.xmf (particles), ' // base // '_grid.xmf, ' // &
         base // '_history.csv'
    flush (output_unit)
  end subroutine header

  !> The MPM's lines of the end report (collective sums; rank 0 prints), after the skeleton's
  !> "done" line; st%loop_seconds: the step loop's wall time.
  subroutine summary(m, st)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    real(dp) :: g(8), rate
    integer :: ib, k, nmax(5)
    integer, allocatable :: moves(:)

    call measure(st)
    g = 0
    do ib = 1, st%nblocks
       g(1) = g(1) + sum(st%blocks(ib)%mass)
       g(2) = g(2) + st%blocks(ib)%count
    end do
    g(3:8) = [st%mass_out, real(st%n_out, dp), st%w_external, real(st%n_guarded, dp), &
         real(st%particle_steps, dp), real(st%n_dilation_held, dp)]
    call sum_over_ranks(st, g)
    nmax = 0
    if (st%dom%on) then
       ! the halo figures the scaling model reads (docs/scaling.md): ghost nodes (held, not
       ! owned), nodes sent and received per exchange, neighbours
       nmax = [sum(st%blocks(1:st%nblocks)%count), st%g%nn, st%g%nn - count(st%dom%owned), &
            size(st%dom%send_nodes) + size(st%dom%recv_nodes), size(st%dom%nbr)]
       call comm_max(st%comm, nmax)
    end if
    if (st%dom%on) then
       allocate (moves(st%nranks * st%nranks), source=0)
       moves(st%rank * st%nranks + 1:(st%rank + 1) * st%nranks) = st%dom%sent
       call comm_sum(st%comm, moves)
    end if
    if (st%rank /= 0) return
    if (st%dom%on) write (output_unit, '(a,*(i0,:,1x))') '  particles migrated from rank r to ranks 0..N-1 ' // &
         '(rank by rank): ', moves
    if (st%dom%on) write (output_unit, '(a,i0,a,i0,a,i0,a,f6.3,a,i0,a,i0,a)') '  spatial decomposition: ', &
         st%nranks, ' ranks, ', st%dom%rebalances, ' re-partitions; particles per rank now max ', nmax(1), &
         ', max/mean ', nmax(1) * st%nranks / max(g(2), 1.0_dp), '; grid nodes held per rank now max ', nmax(2), &
         ' of ', product(st%dom%n)
    if (st%dom%on) write (output_unit, '(a,i0,a,i0,a,i0,a)') '  halo per rank now max: ', nmax(3), &
         ' ghost nodes, ', nmax(4), ' nodes sent + received per exchange (2 exchanges each way per increment), ', &
         nmax(5), ' neighbours'
    write (output_unit, '(a,i0,a,i0,a,i0,a)') '  particles ', nint(g(2)), ' (', st%n_in, ' in, ', nint(g(4)), ' out)'
    write (output_unit, '(a,4es14.6,a,es10.2)') '  mass      initial, in, out, now:', st%mass_initial, st%mass_in, &
         g(3), g(1), '  balance error', st%mass_initial + st%mass_in - g(3) - g(1)
    write (output_unit, '(a,5es12.4)') '  energies  ALLKE ALLIE ALLWK ALLFD ALLDMD:', st%e_kinetic, st%e_internal, &
         g(5), st%e_walls, st%e_damping
    do k = 1, size(m%mpm%walls)
       write (output_unit, '(a,3es13.5)') '  wall ' // trim(m%mpm%walls(k)%name) // ' force:', st%wall_force_row(:, k)
    end do
    if (side_friction_on(m)) write (output_unit, '(a,2es13.5)') '  front and back walls (side friction) force:', &
         st%side_force(1:2)
    if (g(6) > 0) write (output_unit, '(a,i0)') '  particles put back onto walls: ', nint(g(6))
    if (any(m%mpm%steps%max_dilation > 0)) write (output_unit, '(a,i0,a)') '  particle-increments held at MAX DILATION: ', &
         nint(g(8), int64), ' (since this run or its restart began)'
    rate = g(7) / max(st%loop_seconds, 1.0e-9_dp)
    write (output_unit, '(a,i0,a,es11.4,a,f10.3,a,i0,a,es11.4,a)') '  throughput ', nint(g(7), int64), &
         ' particle-steps, ', rate, ' per second (time loop ', st%loop_seconds, ' s, ', st%nranks, &
         ' ranks: ', rate / st%nranks, ' per rank)'
  end subroutine summary
end module mpm_report
