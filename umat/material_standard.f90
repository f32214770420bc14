!> What happens inside one Abaqus/Standard UMAT call (one material point): translate the
!> Standard conventions to the VUMAT ones our kernels use, update the point through the same
!> model update as the VUMAT (material_dispatch), and form the consistent tangent DDSDDE
!> (material_tangent). Kept apart from the entry point so that every argument has a type
!> and an intent.
!>
!> Standard vs Explicit: components 11, 22, 33, 12, 13, 23 (Explicit: 12, 23, 31); shear
!> strains are engineering strains γ = 2ε; one point per call; SSE and SPD are energies per
!> unit volume. The model's field variable 1 (the angle tables' usual driver) is the
!> volumetric strain at the start of the increment, SDV3, which is what our VUSDFLD gives the
!> VUMAT; Standard has no VUSDFLD.
module material_standard
  use material_kinds, only: dp, deg_to_rad
  use material_props, only: model_mohr_coulomb, model_drucker_prager, message_length
  use material_state, only: sdv_ev, sdv_cohesion, sdv_phi, sdv_psi
  use material_dispatch, only: material_choice_t, decode_material, update_material
  use elasticity, only: elastic_increment
  use principal_stress, only: principal_3d
  use mohr_coulomb_return, only: mohr_coulomb_principal_return_detail
  use drucker_prager_return, only: drucker_prager_stress_return
  use material_tangent, only: elastic_tangent, mohr_coulomb_principal_jacobian, &
       isotropic_function_tangent, drucker_prager_tangent, tangent_to_standard
  implicit none
  private

  public :: material_umat, message_length

  !> A name containing this token (e.g. MC-SAND-ELASTICTANGENT) gets the elastic matrix as
  !> DDSDDE instead of the consistent tangent: the same stresses, for comparing Newton rates or
  !> as a robust fallback. Not a model option: the stress update does not change.
  character(len=*), parameter :: elastic_tangent_token = '-ELASTICTANGENT'

  !> Explicit (VUMAT) slot of each Standard component: 13 ↔ 31 and 23 change places.
  integer, parameter :: explicit_slot(6) = [1, 2, 3, 4, 6, 5]

contains

  !> One UMAT call. time_end: total time at the end of the increment (TIME(2) + DTIME), dtime
  !> the time increment (the μ(I) option's rate);
  !> stress, statev, sse, spd: start-of-increment values in, end values out. On failure `ok`
  !> is false and `message` says why (the entry point stops the analysis with it).
  subroutine material_umat(ndi, nshr, ntens, nstatv, nprops, time_end, dtime, cmname, props, &
       dstran, stress, statev, sse, spd, ddsdde, ok, message)
    integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops
    real(dp), intent(in) :: time_end, dtime
    character(len=*), intent(in) :: cmname
    real(dp), intent(in) :: props(nprops), dstran(ntens)
    real(dp), intent(inout) :: stress(ntens), statev(nstatv), sse, spd
    real(dp), intent(out) :: ddsdde(ntens, ntens)
    logical, intent(out) :: ok
    character(len=message_length), intent(out) :: message
    type(material_choice_t) :: choice
    character(len=len(cmname)) :: name
    real(dp) :: strain_inc(1, ntens), stress_old(1, ntens), stress_new(1, ntens)
    real(dp) :: state_old(1, nstatv), state_new(1, nstatv), field(1, 1), one(1)
    real(dp) :: e_int_old(1), e_int_new(1), e_inel_old(1), e_inel_new(1)
    real(dp) :: c(3, 3, 3, 3)
    integer :: i, j, first

    ok = .false.
    ddsdde = 0
    if (ndi /= 3 .or. (nshr /= 1 .and. nshr /= 3) .or. ntens /= ndi + nshr) then
       write (message, '(a,3(a,i0),a)') 'material ' // trim(cmname), ': ndi = ', ndi, ', nshr = ', nshr, &
            ', ntens = ', ntens, ' is not supported (plane strain/axisymmetric 3,1 or 3D 3,3; no plane stress)'
       return
    end if
    ! CalculiX hands over the name after its "ABAQUS" prefix ("ABAQUS_MC-SAND" -> "_MC-SAND").
    first = verify(cmname, '-_. ')
    name = ''
    if (first > 0) name = cmname(first:)
    call decode_material(name, props, nprops, nstatv, 1, choice, ok, message)
    if (.not. ok) return

    do i = 1, ntens
       j = explicit_slot(i)
       stress_old(1, j) = stress(i)
       strain_inc(1, j) = dstran(i)
       if (i > 3) strain_inc(1, j) = 0.5_dp * dstran(i)
    end do
    state_old(1, :) = statev
    field = 0
    if (nstatv >= sdv_ev) field(1, 1) = statev(sdv_ev)
    one = 1
    e_inel_old = spd
    e_int_old = sse + spd
    call update_material(choice, 1, ntens, nstatv, 1, nprops, props, time_end, dtime, one, strain_inc, field, &
         stress_old, state_old, stress_new, state_new, e_int_old, e_int_new, e_inel_old, e_inel_new)
    do i = 1, ntens
       stress(i) = stress_new(1, explicit_slot(i))
    end do
    statev = state_new(1, :)
    spd = e_inel_new(1)
    sse = e_int_new(1) - e_inel_new(1)

    if (index(name, elastic_tangent_token) > 0) then
       call elastic_tangent(choice%lam, choice%shear, c)
    else
       call point_tangent(choice, ntens, stress_old(1, :), strain_inc(1, :), state_new(1, :), c)
    end if
    call tangent_to_standard(c, ntens, ddsdde)
    ok = .true.
  end subroutine material_umat

  !> Consistent tangent at one point: the derivative of the model's update at this increment,
  !> with the strength parameters it used (start-of-increment state, as in the update).
  pure subroutine point_tangent(choice, ntens, stress_old, strain_inc, state_new, c)
    type(material_choice_t), intent(in) :: choice
    integer, intent(in) :: ntens
    real(dp), intent(in) :: stress_old(ntens), strain_inc(ntens), state_new(:)
    real(dp), intent(out) :: c(3, 3, 3, 3)
    real(dp) :: trial(6), sig_trial(3), vec(3, 3), sig(3), jac(3, 3), tensor(3, 3)
    real(dp) :: phi, psi, cohesion, s_new(6), deps_p(6)
    integer :: region, detail

    trial = 0
    trial(1:ntens) = stress_old
    call elastic_increment(ntens, choice%lam, choice%shear, strain_inc, trial(1:ntens))
    select case (choice%model)
    case (model_mohr_coulomb)
       phi = choice%mc%phi
       psi = choice%mc%psi
       cohesion = state_new(sdv_cohesion)
       ! The angle the update used: from the table, or raised by μ(I) (its tangent holds φ
       ! fixed, the rate term is not differentiated).
       if (choice%mc%n_ang > 0 .or. choice%mc%mu_of_i) then
          phi = state_new(sdv_phi) * deg_to_rad
          psi = state_new(sdv_psi) * deg_to_rad
       end if
       call principal_3d(trial, sig_trial, vec)
       call mohr_coulomb_principal_return_detail(sig_trial, sin(phi), sin(psi), cohesion, choice%lam, &
            choice%shear, choice%mc%tension_cutoff, choice%mc%sigma_t, sig, region, detail)
       call mohr_coulomb_principal_jacobian(sin(phi), sin(psi), choice%lam, choice%shear, region, &
            detail, jac)
       call isotropic_function_tangent(sig_trial, vec, sig, jac, choice%lam, choice%shear, c)
    case (model_drucker_prager)
       call drucker_prager_stress_return(6, trial, choice%dpp%tan_beta, choice%dpp%tan_psi, choice%dpp%d, &
            choice%dpp%bulk, choice%dpp%shear, s_new, deps_p, region)
       tensor = reshape([trial(1), trial(4), trial(6), trial(4), trial(2), trial(5), trial(6), trial(5), &
            trial(3)], [3, 3])
       call drucker_prager_tangent(tensor, choice%dpp%tan_beta, choice%dpp%tan_psi, choice%dpp%d, &
            choice%dpp%bulk, choice%dpp%shear, region, c)
    case default
       call elastic_tangent(choice%lam, choice%shear, c)
    end select
  end subroutine point_tangent
end module material_standard
