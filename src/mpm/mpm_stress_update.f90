!> The stress update of a particle block: the velocity gradient from the remapped grid velocity,
!> F ← (I + LΔt) F, the Green–Naghdi frame R of F (fem_corotation, the elements' code), the
!> corotational strain increment and relative spin, the density at mid-increment, and the
!> material call through the element blocks' VUMAT door (VUSDFLD + VUMAT); σ back to the
!> global frame, LE accumulated; *MPM CONTROLS, MAX DILATION holds J = det F at most j
!> (hold_dilation). Owns the VUMAT work sets of the particle blocks.
!>
!> Why Green–Naghdi and not Jaumann/Hughes–Winget: the VUMAT contract (and our elements) hand
!> the material stresses in the frame R of F = RU; a particle carries F, so the same frame, the
!> same relSpinInc and the same code serve both (a user VUMAT sees one convention).
module mpm_stress_update
  use, intrinsic :: iso_fortran_env, only: int64
  use base_kinds, only: dp
  use error_report, only: raise_error
  use model, only: model_t
  use mpm_state, only: mpm_state_t, fx_kinematics, fx_material, fx_dilation, det_f
  use mpm_particles, only: particle_block_t, particle_block_size
  use mpm_transfer, only: gather_gradient, gather_gradient_3d_packed
  use model_particle_fields, only: particle_temperature
  use material_door, only: vumat_work_t, vumat_work_init, vumat_work_rows, call_material, call_field
  use fem_corotation, only: polar_rotation, to_corotational, to_global, relative_spin, vumat_defgrad, &
       vumat_stretch
  use output_effects, only: effects_t
  implicit none
  private

  public :: stress_update, field_update, material_work_init, block_kinematics

contains

  !> Velocity gradient from the remapped grid velocities, F, the corotational increments, and
  !> the material call on the block (the element blocks' door).
  !> With field_given (*NONLOCAL: field_update ran the VUSDFLD, mpm_nonlocal averaged its
  !> variable) the VUMAT gets field_given as fieldNew and the VUSDFLD is not called again.
  subroutine stress_update(m, st, fx, b, field_given)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(effects_t), intent(inout) :: fx
    type(particle_block_t), intent(inout) :: b
    real(dp), intent(in), optional :: field_given(:, :)
    integer :: nb, nd, p, iw
    real(dp) :: dt
    real(dp) :: l(b%count, st%nd, st%nd), f_mid(b%count, st%nd, st%nd), f_new(b%count, st%nd, st%nd)
    real(dp) :: r_mid(b%count, st%nd, st%nd), r_new(b%count, st%nd, st%nd)
    real(dp) :: strain(b%count, st%nc), spin(b%count, st%nshr), strain_corot(b%count, st%nc)
    real(dp) :: rel_spin(b%count, st%nshr), density(b%count), char_length(b%count)

    call fx%start(fx_kinematics)
    nb = b%count
    nd = st%nd
    dt = st%dt
    if (nd == 3 .and. st%nsup == 3) then
       ! 3D uGIMP: v_new as packed records (musl_transfer packed it), the same sums vectorised
       call gather_gradient_3d_packed(nb, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, b%dw1, &
            st%gpack, l)
    else
       call gather_gradient(nb, st%nsup, nd, st%g%nn, st%g%n(1), st%g%n(1) * st%g%n(2), b%corner, b%w1, b%dw1, &
            st%g%v_new, l)
    end if
    call block_kinematics(nb, nd, st%nc, dt, l, b%f, f_mid, f_new, strain, spin)
    call polar_rotation(nb, nd, f_mid, r_mid)
    call polar_rotation(nb, nd, f_new, r_new)
    call to_corotational(nb, nd, st%nc, r_mid, strain, strain_corot)
    call relative_spin(nb, nd, spin, b%rot, r_new, r_mid, rel_spin)
    call block_work_set(m, st, b, iw)
    if (st%needs_kinematics(b%material)) then
       call vumat_defgrad(nb, nd, b%f, st%work(iw)%defgrad_old)
       call vumat_defgrad(nb, nd, f_new, st%work(iw)%defgrad_new)
       call vumat_stretch(nb, nd, b%rot, b%f, st%work(iw)%stretch_old)
       call vumat_stretch(nb, nd, r_new, f_new, st%work(iw)%stretch_new)
    end if
    do p = 1, nb
       if (nd == 2) then
          density(p) = f_mid(p, 1, 1) * f_mid(p, 2, 2) - f_mid(p, 1, 2) * f_mid(p, 2, 1)
       else
          density(p) = f_mid(p, 1, 1) * (f_mid(p, 2, 2) * f_mid(p, 3, 3) - f_mid(p, 2, 3) * f_mid(p, 3, 2)) &
               - f_mid(p, 1, 2) * (f_mid(p, 2, 1) * f_mid(p, 3, 3) - f_mid(p, 2, 3) * f_mid(p, 3, 1)) &
               + f_mid(p, 1, 3) * (f_mid(p, 2, 1) * f_mid(p, 3, 2) - f_mid(p, 2, 2) * f_mid(p, 3, 1))
       end if
       if (.not. (density(p) > 0)) call inverted(m, st, b, p)
       density(p) = b%mass(p) / (b%vol0(p) * density(p))
    end do
    ! the particle size: CELL/PPC
    char_length = 2 * b%half
    call fx%stop(fx_kinematics)

    call fx%start(fx_material)
    call call_material(m%materials(b%material), nb, st%nc, st%nshr, b%number, st%step_time + dt, &
         st%total_time + dt, dt, char_length, density, strain_corot, rel_spin, st%work(iw)%stretch_old, &
         st%work(iw)%stretch_new, st%work(iw)%defgrad_old, st%work(iw)%defgrad_new, &
         b%log_strain, b%stress, b%state, b%field, b%e_int, b%e_inel, st%work(iw), field_given)
    call fx%stop(fx_material)

    call fx%start(fx_kinematics)
    ! LE: what vgetvrm hands the next VUSDFLD and what the output shows
    b%log_strain = b%log_strain + strain_corot
    b%f = f_new
    b%rot = r_new
    if (fx%active(fx_dilation)) then
       if (m%mpm%steps(st%step)%max_dilation > 0) call hold_dilation(nb, nd, m%mpm%steps(st%step)%max_dilation, &
            b%f, st%n_dilation_held)
    end if
    call to_global(nb, nd, st%nc, r_new, b%stress, b%stress_global)
    call fx%stop(fx_kinematics)
  end subroutine stress_update

  !> The VUSDFLD alone on block b (*NONLOCAL, before the averaging): its state becomes the block's,
  !> its fields go to field_new (nb, nfieldv); the same point data as inside stress_update.
  subroutine field_update(m, st, b, field_new)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), intent(inout) :: b
    real(dp), intent(out) :: field_new(:, :)
    integer :: iw
    real(dp) :: char_length(b%count)

    call block_work_set(m, st, b, iw)
    char_length = 2 * b%half
    call call_field(m%materials(b%material), b%count, st%nc, st%nshr, b%number, st%step_time + st%dt, &
         st%total_time + st%dt, st%dt, char_length, b%stress, b%log_strain, b%state, b%field, field_new, &
         st%work(iw))
  end subroutine field_update

  !> The work set of block b, with exactly its count of rows, and the point data the VUSDFLD
  !> and the VUMAT read from it: coordMp (the particle's position, third column 0 in 2D; only
  !> for the materials that read it) and tempOld, tempNew (the material's particle temperature
  !> at t_n and t_n+1, driver_temperature).
  !> A partial block takes the set that has its count; when none has it, an unmade set (made for
  !> a full block's count once), or else the sets in turn, which then take the block's count
  !> (vumat_work_rows: views of their storage, no allocation but the four swapped arrays'). Which
  !> set serves a block does not change its results: what the
  !> material reads from a set is written before the call (here, stress_update, the door) or is
  !> the same in every set of that count (U = F = I and zero coordinates where not written).
  subroutine block_work_set(m, st, b, iw)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(inout) :: st
    type(particle_block_t), intent(in) :: b
    integer, intent(out) :: iw
    integer :: nb, k
    real(dp) :: dt

    nb = b%count
    dt = st%dt
    iw = 1
    if (nb /= particle_block_size) then
       iw = 0
       do k = 2, size(st%work)
          if (st%work(k)%rows == nb .or. st%work(k)%rows == 0) then
             iw = k
             exit
          end if
       end do
       if (iw == 0) then
          st%work_replace = 1 + mod(st%work_replace, size(st%work) - 1)
          iw = 1 + st%work_replace
       end if
       if (st%work(iw)%capacity == 0) call material_work_init(st, st%work(iw), particle_block_size)
       if (st%work(iw)%rows /= nb) then
          call vumat_work_rows(st%work(iw), nb)
          call unit_kinematics(st%work(iw))
       end if
    end if
    if (st%needs_kinematics(b%material)) st%work(iw)%coord(1:nb, 1:st%nd) = b%x(1:nb, 1:st%nd)
    st%work(iw)%temp(1:nb) = particle_temperature(m, st%step, b%material, st%step_time, st%total_time)
    st%work(iw)%temp_new(1:nb) = particle_temperature(m, st%step, b%material, st%step_time + dt, &
         st%total_time + dt)
  end subroutine block_work_set

  !> F_{n+1} = (I + L Δt) F_n, F_{n+½} = (I + ½ L Δt) F_n, the strain increment sym(L)Δt
  !> (tensor shears, Abaqus order 11 22 33 12 [23 31]) and the spin increment skw(L)Δt
  !> (2D: w21; 3D: w32, w13, w21) of nb particles.
  pure subroutine block_kinematics(nb, nd, nc, dt, l, f, f_mid, f_new, strain, spin)
    integer, intent(in) :: nb, nd, nc
    real(dp), intent(in) :: dt, l(nb, nd, nd), f(nb, nd, nd)
    real(dp), intent(out) :: f_mid(nb, nd, nd), f_new(nb, nd, nd), strain(nb, nc), spin(nb, 2 * nd - 3)
    integer :: a, c, k

    f_new = f
    f_mid = f
    do c = 1, nd
       do a = 1, nd
          do k = 1, nd
             f_new(:, a, c) = f_new(:, a, c) + dt * l(:, a, k) * f(:, k, c)
             f_mid(:, a, c) = f_mid(:, a, c) + 0.5_dp * dt * l(:, a, k) * f(:, k, c)
          end do
       end do
    end do
    strain(:, 1) = dt * l(:, 1, 1)
    strain(:, 2) = dt * l(:, 2, 2)
    if (nd == 2) then
       strain(:, 3) = 0
       strain(:, 4) = 0.5_dp * dt * (l(:, 1, 2) + l(:, 2, 1))
       spin(:, 1) = 0.5_dp * dt * (l(:, 2, 1) - l(:, 1, 2))
    else
       strain(:, 3) = dt * l(:, 3, 3)
       strain(:, 4) = 0.5_dp * dt * (l(:, 1, 2) + l(:, 2, 1))
       strain(:, 5) = 0.5_dp * dt * (l(:, 2, 3) + l(:, 3, 2))
       strain(:, 6) = 0.5_dp * dt * (l(:, 3, 1) + l(:, 1, 3))
       spin(:, 1) = 0.5_dp * dt * (l(:, 3, 2) - l(:, 2, 3))
       spin(:, 2) = 0.5_dp * dt * (l(:, 1, 3) - l(:, 3, 1))
       spin(:, 3) = 0.5_dp * dt * (l(:, 2, 1) - l(:, 1, 2))
    end if
  end subroutine block_kinematics

  !> *MPM CONTROLS, MAX DILATION=jmax: every particle of the block with J = det F > jmax gets
  !> F ← (jmax/J)^(1/nd) F, so J = jmax (2D: the in-plane F; F33 = 1 in plane strain). R of F = RU
  !> does not change; the stress is the material's. Why: a granular particle cannot be looser than
  !> its loosest packing — beyond it the grains separate, which one particle cannot show — and
  !> its volume J V0 sets its wave speed √(M J/ρ0), hence the stable increment of the whole run
  !> (a particle hanging at an outlet's edge stretched to J ≈ 21 made it 4.6 times shorter:
  !> docs/bins.md). `held` counts the particles so treated.
  pure subroutine hold_dilation(nb, nd, jmax, f, held)
    integer, intent(in) :: nb, nd
    real(dp), intent(in) :: jmax
    real(dp), intent(inout) :: f(nb, nd, nd)
    integer(int64), intent(inout) :: held
    real(dp) :: detf
    integer :: p

    do p = 1, nb
       detf = det_f(f, p, nd)
       if (detf > jmax) then
          f(p, :, :) = (jmax / detf)**(1.0_dp / nd) * f(p, :, :)
          held = held + 1
       end if
    end do
  end subroutine hold_dilation

  !> A VUMAT work set of `rows` rows; U = F = I, which stay for the materials that do not read
  !> them (needs_kinematics false: stress_update does not write them).
  subroutine material_work_init(st, w, rows)
    type(mpm_state_t), intent(in) :: st
    type(vumat_work_t), intent(inout) :: w
    integer, intent(in) :: rows

    call vumat_work_init(w, rows, st%nc, st%nshr, st%work_statev, st%work_fieldv)
    w%point_kind = 'particle'
    call unit_kinematics(w)
  end subroutine material_work_init

  !> U = F = I in the set's rows (stay so for the materials that do not read them).
  subroutine unit_kinematics(w)
    type(vumat_work_t), intent(inout) :: w
    w%stretch_old = 0
    w%stretch_old(:, 1:3) = 1
    w%defgrad_old = 0
    w%defgrad_old(:, 1:3) = 1
    w%stretch_new = w%stretch_old
    w%defgrad_new = w%defgrad_old
  end subroutine unit_kinematics

  subroutine inverted(m, st, b, p)
    type(model_t), intent(in) :: m
    type(mpm_state_t), intent(in) :: st
    type(particle_block_t), intent(in) :: b
    integer, intent(in) :: p
    character(len=160) :: text

    write (text, '(a,i0,a,3es12.4,a,es12.5)') 'particle ', b%number(p), ' at ', b%x(p, :), &
         ' inverted (det F <= 0) at t = ', st%total_time
    call raise_error(trim(m%input_file), 0, trim(text) // '; expected a smaller CFL or a finer grid')
  end subroutine inverted
end module mpm_stress_update
