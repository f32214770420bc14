!> Replays a fixed, pseudo-random sequence of VUSDFLD + VUMAT calls (every model, plane
!> strain and 3D, tables, flow functions, tension cut-off, packaging call) and writes every
!> output array to a binary file. Linked once against the bulkflow library and once against
!> the generated single-file Abaqus source: the two files must be identical byte for byte.
program vumat_replay
  use, intrinsic :: iso_fortran_env, only: int64
  use material_kinds, only: dp
  use abaqus_host, only: host_set_block
  implicit none
  external :: vumat, vusdfld
  integer, parameter :: nblock = 37, nstatev = 8, nfieldv = 1, increments = 60
  integer(int64) :: seed = 20261123_int64
  character(len=256) :: out_path
  integer :: unit, icase

  call get_command_argument(1, out_path)
  if (len_trim(out_path) == 0) error stop 'usage: vumat_replay <output file>'
  open (newunit=unit, file=trim(out_path), access='stream', form='unformatted', status='replace')
  do icase = 1, 6
     call replay_case(icase, unit)
  end do
  close (unit)

contains

  subroutine replay_case(icase, unit)
    integer, intent(in) :: icase, unit
    character(len=80) :: cmname
    integer :: ndir, nshr, ncomp, nprops, inc, k
    real(dp), allocatable :: props(:)
    real(dp) :: strain_inc(nblock, 6), stress_new(nblock, 6)
    real(dp), target :: stress_old(nblock, 6)   ! the host points at it (host_set_block)
    real(dp) :: state_old(nblock, nstatev), state_new(nblock, nstatev)
    real(dp) :: field_old(nblock, nfieldv), field_new(nblock, nfieldv)
    real(dp), target :: log_strain(nblock, 6)
    real(dp) :: e_int_old(nblock), e_int_new(nblock), e_inel_old(nblock), e_inel_new(nblock)
    real(dp) :: density(nblock), coord(nblock, 3), char_length(nblock), rel_spin(nblock, 3)
    real(dp) :: temp(nblock), stretch(nblock, 6), defgrad(nblock, 9), direct(nblock, 3, 3), tmat(nblock, 3, 3)
    real(dp) :: step_time, total_time, dt
    integer :: jblock(4 + nblock), jelem(nblock)

    ndir = 3
    nshr = merge(1, 3, mod(icase, 2) == 1)
    ncomp = ndir + nshr
    select case (icase)
    case (1, 2)
       cmname = 'ELASTIC-CHECK'
       call set_props(props, [10.0e6_dp, 0.3_dp])
    case (3, 4)
       ! Mohr-Coulomb with an angle table on field 1, bilinear flow function, tension cut-off.
       cmname = 'MC-CHECK'
       call set_props(props, [10.0e6_dp, 0.25_dp, 30.0_dp, 5.0_dp, 2.0e3_dp, 1.0_dp, 500.0_dp, 2.0_dp, 1.9e3_dp, 0.6_dp, &
            0.3_dp, 0.0_dp, 2.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, &
            46.0_dp, 15.0_dp, 0.0_dp, 34.0_dp, 0.0_dp, 0.2_dp])
    case (5)
       ! Cohesionless Mohr-Coulomb, zero dilation, cohesion table against PEEQ.
       cmname = 'MOHRCOULOMB_CHECK'
       call set_props(props, [8.0e6_dp, 0.3_dp, 34.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, &
            0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 2.0_dp, 0.0_dp, 3.0e3_dp, 0.0_dp, 1.0e3_dp, 0.05_dp])
    case default
       cmname = 'DP-CHECK'
       call set_props(props, [10.0e6_dp, 0.2_dp, 30.0_dp, 10.0_dp, 1.0e3_dp, 1.0_dp])
    end select
    nprops = size(props)

    jblock(1:4) = [nblock, 1, 1, 1]
    do k = 1, nblock
       jblock(4 + k) = k
    end do
    jelem = jblock(5:)
    density = 1600
    coord = 0; char_length = 0.05_dp; rel_spin = 0; temp = 0; stretch = 0; defgrad = 0
    direct = 0; tmat = 0
    stress_old = 0; state_old = 0; field_old = 0; log_strain = 0
    e_int_old = 0; e_inel_old = 0
    do k = 1, nblock
       stress_old(k, 1:3) = -1.0e4_dp * (1 + uniform())
    end do

    ! Packaging call first, as Abaqus does; its result is written too.
    call fill_increments(strain_inc, 1.0e-6_dp)
    call vumat(jblock, ndir, nshr, nstatev, nfieldv, nprops, 0, 0.0_dp, 0.0_dp, 1.0e-6_dp, cmname, &
         coord, char_length, props, density, strain_inc(:, 1:ncomp), rel_spin(:, 1:nshr), temp, &
         stretch(:, 1:ncomp), defgrad(:, 1:ncomp + nshr), field_old, stress_old(:, 1:ncomp), state_old, &
         e_int_old, e_inel_old, temp, stretch(:, 1:ncomp), defgrad(:, 1:ncomp + nshr), field_old, &
         stress_new(:, 1:ncomp), state_new, e_int_new, e_inel_new)
    write (unit) stress_new(:, 1:ncomp)

    dt = 1.0e-3_dp
    step_time = 0
    do inc = 1, increments
       step_time = step_time + dt
       total_time = step_time
       call fill_increments(strain_inc, 2.0e-3_dp)
       call host_set_block(nblock, ncomp, stress_old(:, 1:ncomp), log_strain(:, 1:ncomp))
       field_new = field_old
       call vusdfld(nblock, nstatev, nfieldv, nprops, ndir, nshr, jelem, 1, 1, 1, step_time, total_time, dt, &
            cmname, coord, direct, tmat, char_length, props, state_old, state_new, field_new)
       state_old = state_new
       call vumat(jblock, ndir, nshr, nstatev, nfieldv, nprops, 0, step_time, total_time, dt, cmname, &
            coord, char_length, props, density, strain_inc(:, 1:ncomp), rel_spin(:, 1:nshr), temp, &
            stretch(:, 1:ncomp), defgrad(:, 1:ncomp + nshr), field_old, stress_old(:, 1:ncomp), state_old, &
            e_int_old, e_inel_old, temp, stretch(:, 1:ncomp), defgrad(:, 1:ncomp + nshr), field_new, &
            stress_new(:, 1:ncomp), state_new, e_int_new, e_inel_new)
       write (unit) stress_new(:, 1:ncomp), state_new, field_new, e_int_new, e_inel_new
       log_strain(:, 1:ncomp) = log_strain(:, 1:ncomp) + strain_inc(:, 1:ncomp)
       stress_old = stress_new
       state_old = state_new
       field_old = field_new
       e_int_old = e_int_new
       e_inel_old = e_inel_new
    end do
  end subroutine replay_case

  !> Explicit allocation: gfortran 12 warns falsely (-Wmaybe-uninitialized) on reallocation
  !> by assignment of an array constructor.
  subroutine set_props(props, values)
    real(dp), allocatable, intent(inout) :: props(:)
    real(dp), intent(in) :: values(:)
    if (allocated(props)) deallocate(props)
    allocate(props(size(values)))
    props(:) = values
  end subroutine set_props

  !> Random strain increments with a compressive, shearing bias so that every return region
  !> (and unloading) occurs during the replay.
  subroutine fill_increments(strain_inc, scale)
    real(dp), intent(out) :: strain_inc(nblock, 6)
    real(dp), intent(in) :: scale
    integer :: k, j

    do j = 1, 6
       do k = 1, nblock
          strain_inc(k, j) = scale * (2 * uniform() - 1)
       end do
    end do
    strain_inc(:, 2) = strain_inc(:, 2) - 0.5_dp * scale
  end subroutine fill_increments

  !> Our own generator so both builds see the same numbers whatever the runtime library.
  real(dp) function uniform()
    ! xorshift64: shifts and xors only, so no integer overflow in any build mode.
    seed = ieor(seed, ishft(seed, 13))
    seed = ieor(seed, ishft(seed, -7))
    seed = ieor(seed, ishft(seed, 17))
    uniform = real(ishft(seed, -11), dp) / 9007199254740992.0_dp
  end function uniform
end program vumat_replay
