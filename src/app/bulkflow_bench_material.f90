!> bulkflow-bench-material: material-point updates per second through the VUMAT door.
!>
!> Every call goes through `vumat` exactly as the solver calls it (name dispatch, props
!> decoding, elastic trial, principal decomposition, return, rebuild, state and energies).
!> The points are prepared so that every update is plastic, over a mix of return regions.
!> Usage: bulkflow-bench-material [model] [seconds per case]
!>   model: MC (default), MC-MUI (MC with mu(I)), MC-TABLE (angle table + flow function), DP, ELASTIC
program bulkflow_bench_material
  use, intrinsic :: iso_fortran_env, only: int64, output_unit
  use base_kinds, only: dp
  use material_state, only: sdv_yield
  implicit none
  external :: vumat

  integer, parameter :: max_block = 512, n_points = 8192, nstatev = 8, nfieldv = 1
  integer, parameter :: block_sizes(10) = [1, 2, 4, 8, 16, 32, 64, 128, 256, 512]
  character(len=32) :: model_arg, seconds_arg
  character(len=80) :: cmname
  real(dp), allocatable :: props(:)
  real(dp) :: seconds
  integer :: ib, idim
  integer(int64) :: seed = 88172645463325252_int64

  model_arg = 'MC'
  seconds = 0.4_dp
  if (command_argument_count() >= 1) call get_command_argument(1, model_arg)
  if (command_argument_count() >= 2) then
     call get_command_argument(2, seconds_arg)
     read (seconds_arg, *) seconds
  end if
  select case (trim(model_arg))
  case ('MC')
     cmname = 'MC-BENCH'
     props = [10.0e6_dp, 0.3_dp, 30.0_dp, 10.0_dp, 5.0e3_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, &
          0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp]
  case ('MC-MUI')
     ! MC with the rate-dependent friction mu(I) (docs/mu_of_i.md): phi2 45, I0 0.279, d 0.5 mm.
     cmname = 'MC-BENCH'
     props = [10.0e6_dp, 0.3_dp, 30.0_dp, 10.0_dp, 5.0e3_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, &
          0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 45.0_dp, 0.279_dp, 0.5e-3_dp, 2450.0_dp]
  case ('MC-TABLE')
     cmname = 'MC-BENCH'
     props = [10.0e6_dp, 0.3_dp, 30.0_dp, 10.0_dp, 5.0e3_dp, 0.0_dp, 0.0_dp, 1.0_dp, 2.0e3_dp, 0.3_dp, &
          0.0_dp, 0.0_dp, 2.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 46.0_dp, 15.0_dp, 0.0_dp, 34.0_dp, 0.0_dp, 0.2_dp]
  case ('DP')
     cmname = 'DP-BENCH'
     props = [10.0e6_dp, 0.3_dp, 30.0_dp, 10.0_dp, 5.0e3_dp, 1.0_dp]
  case ('ELASTIC')
     cmname = 'ELASTIC-BENCH'
     props = [10.0e6_dp, 0.3_dp]
  case default
     write (output_unit, '(a)') 'usage: bulkflow-bench-material [MC|MC-MUI|MC-TABLE|DP|ELASTIC] [seconds per case]'
     error stop 2
  end select

  write (output_unit, '(a)') '# model ' // trim(model_arg) // ': material-point updates per second, one core'
  write (output_unit, '(a)') '# dimension  nblock  updates/s  plastic_fraction'
  do idim = 1, 2
     do ib = 1, size(block_sizes)
        call run_case(idim == 1, block_sizes(ib))
     end do
  end do

contains

  subroutine run_case(plane, nblock)
    logical, intent(in) :: plane
    integer, intent(in) :: nblock
    integer :: ndir, nshr, ncomp, nprops, k, j, ib, nb, calls, nplastic
    ! Blocks stored contiguously, (nblock, ncomp, block), as a solver hands them over.
    real(dp), allocatable :: stress_old(:, :, :), strain_inc(:, :, :), stress_new(:, :)
    real(dp), allocatable :: state_old(:, :, :), state_new(:, :), field(:, :, :)
    real(dp) :: density(max_block), e_old(max_block), e_new(max_block), ei_old(max_block), ei_new(max_block)
    real(dp) :: coord(max_block, 3), char_length(max_block), spin(max_block, 3), temp(max_block)
    real(dp) :: stretch(max_block, 6), defgrad(max_block, 9)
    integer :: jblock(4 + max_block)
    integer(int64) :: t0, t1, rate
    real(dp) :: elapsed

    ndir = 3
    nshr = merge(1, 3, plane)
    ncomp = ndir + nshr
    nprops = size(props)
    nb = n_points / nblock
    allocate(stress_old(nblock, ncomp, nb), strain_inc(nblock, ncomp, nb), stress_new(nblock, ncomp))
    allocate(state_old(nblock, nstatev, nb), state_new(nblock, nstatev), field(nblock, nfieldv, nb))
    ! Confined compressive states with strain increments large enough to yield.
    do ib = 1, nb
       do k = 1, nblock
          stress_old(k, 1:3, ib) = -1.0e5_dp * (1 + uniform())
          stress_old(k, 4:ncomp, ib) = 0
          do j = 1, ncomp
             strain_inc(k, j, ib) = 5.0e-2_dp * (2 * uniform() - 1)
          end do
          ! Mostly deviatoric, so the trial states spread over the plane and both edges,
          ! with a small volumetric part that sends a few to the apex.
          strain_inc(k, 1:3, ib) = strain_inc(k, 1:3, ib) - sum(strain_inc(k, 1:3, ib)) / 3 &
               + 2.0e-3_dp * (2 * uniform() - 1)
          field(k, 1, ib) = 0.25_dp * uniform()
       end do
    end do
    state_old = 0
    density = 1600; e_old = 0; ei_old = 0; coord = 0; char_length = 0.05_dp; spin = 0; temp = 0
    stretch = 0; defgrad = 0
    jblock(1:4) = [nblock, 1, 1, 1]
    do k = 1, nblock
       jblock(4 + k) = k
    end do

    ! Plastic fraction from one pass (the YIELD state variable says which points returned).
    nplastic = 0
    do ib = 1, nb
       call vumat(jblock, ndir, nshr, nstatev, nfieldv, nprops, 0, 1.0_dp, 1.0_dp, 1.0e-5_dp, cmname, &
            coord, char_length, props, density, strain_inc(:, :, ib), spin, temp, stretch, defgrad, &
            field(:, :, ib), stress_old(:, :, ib), state_old(:, :, ib), e_old, ei_old, &
            temp, stretch, defgrad, field(:, :, ib), stress_new, state_new, e_new, ei_new)
       if (trim(model_arg) /= 'ELASTIC') nplastic = nplastic + count(state_new(:, sdv_yield) > 0)
    end do

    calls = 0
    call system_clock(t0, rate)
    do
       do ib = 1, nb
          call vumat(jblock, ndir, nshr, nstatev, nfieldv, nprops, 0, 1.0_dp, 1.0_dp, 1.0e-5_dp, cmname, &
            coord, char_length, props, density, strain_inc(:, :, ib), spin, temp, stretch, defgrad, &
            field(:, :, ib), stress_old(:, :, ib), state_old(:, :, ib), e_old, ei_old, &
            temp, stretch, defgrad, field(:, :, ib), stress_new, state_new, e_new, ei_new)
       end do
       calls = calls + nb
       call system_clock(t1)
       elapsed = real(t1 - t0, dp) / real(rate, dp)
       if (elapsed >= seconds) exit
    end do
    write (output_unit, '(a10, i8, es11.3, f10.3)') merge('plane   ', '3D      ', plane), nblock, &
         real(calls, dp) * nblock / elapsed, real(nplastic, dp) / real(nb * nblock, dp)

  end subroutine run_case

  real(dp) function uniform()
    seed = ieor(seed, ishft(seed, 13))
    seed = ieor(seed, ishft(seed, -7))
    seed = ieor(seed, ishft(seed, 17))
    uniform = real(ishft(seed, -11), dp) / 9007199254740992.0_dp
  end function uniform
end program bulkflow_bench_material
