!> What happens inside one VUMAT call: pick the model from the material name, decode and
!> check `props`, and update the block. Kept apart from the Abaqus-style entry point so that
!> every argument here has an explicit type and intent.
module material_dispatch
  use material_kinds, only: dp
  use material_props, only: model_from_name, model_names_help, model_unknown, model_elastic, &
       model_mohr_coulomb, model_drucker_prager, message_length, mohr_coulomb_props_t, &
       drucker_prager_props_t, decode_elastic, decode_mohr_coulomb, decode_drucker_prager
  use material_update, only: update_elastic_block, update_mohr_coulomb_block, update_drucker_prager_block
  implicit none
  private

  public :: material_vumat, message_length
  public :: decode_material, update_material

  !> A model chosen by name with its decoded constants (the tables stay in `props`).
  type, public :: material_choice_t
     integer :: model = model_unknown
     real(dp) :: lam = 0, shear = 0
     type(mohr_coulomb_props_t) :: mc
     type(drucker_prager_props_t) :: dpp
  end type material_choice_t

contains

  !> One VUMAT call. On failure `ok` is false and `message` says why; the entry point
  !> reports it through the host's error utilities (xplb_abqerr / xplb_exit).
  subroutine material_vumat(nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal, step_time, &
       total_time, dt, cmname, props, density, strain_inc, field_new, stress_old, state_old, &
       e_int_old, e_inel_old, stress_new, state_new, e_int_new, e_inel_new, ok, message)
    integer, intent(in) :: nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal
    real(dp), intent(in) :: step_time, total_time, dt
    character(len=*), intent(in) :: cmname
    real(dp), intent(in) :: props(nprops), density(nblock)
    real(dp), intent(in) :: strain_inc(nblock, ndir + nshr), field_new(nblock, nfieldv)
    real(dp), intent(in) :: stress_old(nblock, ndir + nshr), state_old(nblock, nstatev)
    real(dp), intent(in) :: e_int_old(nblock), e_inel_old(nblock)
    real(dp), intent(out) :: stress_new(nblock, ndir + nshr), state_new(nblock, nstatev)
    real(dp), intent(out) :: e_int_new(nblock), e_inel_new(nblock)
    logical, intent(out) :: ok
    character(len=message_length), intent(out) :: message
    integer :: ncomp
    type(material_choice_t) :: choice

    ok = .false.
    ncomp = ndir + nshr
    if (ndir /= 3 .or. (nshr /= 1 .and. nshr /= 3)) then
       write (message, '(a,i0,a,i0,a)') 'material ' // trim(cmname) // ': ndir = ', ndir, ', nshr = ', nshr, &
            ' is not supported (plane strain/axisymmetric 3,1 or 3D 3,3; no plane stress)'
       return
    end if
    ! Validate first, whatever the call: bad props must stop the data check, not increment 1.
    call decode_material(cmname, props, nprops, nstatev, nfieldv, choice, ok, message)
    if (.not. ok) return

    e_inel_new = e_inel_old
    if (lanneal == 1) then
       ! Annealing: Abaqus zeroes stresses; the plastic history goes with them.
       stress_new = 0
       state_new = 0
       e_int_new = e_int_old
       return
    end if
    if (max(abs(step_time), abs(total_time)) < tiny(1.0_dp)) then
       ! Packaging call: the host only wants the elastic response to size the wave speed.
       call update_elastic_block(nblock, ncomp, choice%lam, choice%shear, density, strain_inc, stress_old, &
            stress_new, e_int_old, e_int_new)
       state_new = state_old
       return
    end if
    call update_material(choice, nblock, ncomp, nstatev, nfieldv, nprops, props, total_time, dt, density, &
         strain_inc, field_new, stress_old, state_old, stress_new, state_new, e_int_old, e_int_new, &
         e_inel_old, e_inel_new)
  end subroutine material_vumat

  !> The model named by `cmname` (upper case, umat/README.md) with its checked constants.
  !> On failure `ok` is false and `message` names the material and what is wrong.
  pure subroutine decode_material(cmname, props, nprops, nstatev, nfieldv, choice, ok, message)
    character(len=*), intent(in) :: cmname
    integer, intent(in) :: nprops, nstatev, nfieldv
    real(dp), intent(in) :: props(nprops)
    type(material_choice_t), intent(out) :: choice
    logical, intent(out) :: ok
    character(len=message_length), intent(out) :: message

    ok = .false.
    choice%model = model_from_name(cmname)
    select case (choice%model)
    case (model_elastic)
       call decode_elastic(props, nprops, choice%lam, choice%shear, ok, message)
    case (model_mohr_coulomb)
       call decode_mohr_coulomb(props, nprops, nstatev, nfieldv, choice%mc, ok, message)
       choice%lam = choice%mc%lam; choice%shear = choice%mc%shear
    case (model_drucker_prager)
       call decode_drucker_prager(props, nprops, nstatev, choice%dpp, ok, message)
       choice%lam = choice%dpp%lam; choice%shear = choice%dpp%shear
    case default
       message = 'unknown material name "' // trim(cmname) // '": ' // model_names_help()
       return
    end select
    if (.not. ok) message = 'material ' // trim(cmname) // ': ' // trim(message)
  end subroutine decode_material

  !> Stress update of a block of points by the chosen model (not the packaging call); dt is
  !> the time increment (used by the μ(I) option of Mohr-Coulomb only).
  pure subroutine update_material(choice, nblock, ncomp, nstatev, nfieldv, nprops, props, total_time, dt, &
       density, strain_inc, field_new, stress_old, state_old, stress_new, state_new, e_int_old, &
       e_int_new, e_inel_old, e_inel_new)
    type(material_choice_t), intent(in) :: choice
    integer, intent(in) :: nblock, ncomp, nstatev, nfieldv, nprops
    real(dp), intent(in) :: props(nprops), total_time, dt
    real(dp), intent(in) :: density(nblock), strain_inc(nblock, ncomp), field_new(nblock, nfieldv)
    real(dp), intent(in) :: stress_old(nblock, ncomp), state_old(nblock, nstatev)
    real(dp), intent(out) :: stress_new(nblock, ncomp), state_new(nblock, nstatev)
    real(dp), intent(in) :: e_int_old(nblock), e_inel_old(nblock)
    real(dp), intent(out) :: e_int_new(nblock), e_inel_new(nblock)

    select case (choice%model)
    case (model_mohr_coulomb)
       call update_mohr_coulomb_block(nblock, ncomp, nstatev, nfieldv, nprops, props, choice%mc, &
            total_time, dt, density, strain_inc, field_new, stress_old, state_old, stress_new, state_new, &
            e_int_old, e_int_new, e_inel_old, e_inel_new)
    case (model_drucker_prager)
       call update_drucker_prager_block(nblock, ncomp, nstatev, choice%dpp, density, strain_inc, &
            stress_old, state_old, stress_new, state_new, e_int_old, e_int_new, e_inel_old, e_inel_new)
    case default
       call update_elastic_block(nblock, ncomp, choice%lam, choice%shear, density, strain_inc, &
            stress_old, stress_new, e_int_old, e_int_new)
       state_new = state_old
       e_inel_new = e_inel_old
    end select
  end subroutine update_material
end module material_dispatch
