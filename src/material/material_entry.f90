!> Which VUMAT/VUSDFLD a material calls: ours (linked in) or the user's (loaded with --user).
!> Elements, particles and the material-point driver take their entry points here, so the
!> choice is made in one place (name resolution: docs/user_subroutines.md).
module material_entry
  use user_library, only: user_vumat, user_vusdfld, user_library_use_linked
  implicit none
  private

  external :: vumat, vusdfld

  public :: vumat_entry, vusdfld_entry, use_linked_entries

contains

  !> --user-linked: *USER MATERIALs take the user's path with the vumat/vusdfld linked in.
  subroutine use_linked_entries()
    call user_library_use_linked(vumat, vusdfld, 'the linked-in subroutines')
  end subroutine use_linked_entries

  !> `user`: the material is a *USER MATERIAL and a user file is loaded.
  function vumat_entry(user) result(entry)
    logical, intent(in) :: user
    procedure(), pointer :: entry

    if (user) then
       entry => user_vumat
    else
       entry => vumat
    end if
  end function vumat_entry

  !> `user`: the material has *USER DEFINED FIELD and the loaded user file defines VUSDFLD.
  function vusdfld_entry(user) result(entry)
    logical, intent(in) :: user
    procedure(), pointer :: entry

    if (user) then
       entry => user_vusdfld
    else
       entry => vusdfld
    end if
  end function vusdfld_entry
end module material_entry

!> Our materials, callable from a user's VUMAT (docs/user_subroutines.md): the same argument
!> list as VUMAT; `cmname` selects our model as in umat/README.md (ELASTIC-..., MC-..., DP-...).
!> A user's file that defines its own `vumat` reaches ours through this name.
subroutine bulkflow_vumat(nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal, stepTime, totalTime, &
     dt, cmname, coordMp, charLength, props, density, strainInc, relSpinInc, tempOld, stretchOld, &
     defgradOld, fieldOld, stressOld, stateOld, enerInternOld, enerInelasOld, tempNew, stretchNew, &
     defgradNew, fieldNew, stressNew, stateNew, enerInternNew, enerInelasNew)
  use base_kinds, only: dp
  implicit none
  integer, intent(in) :: nblock(*), ndir, nshr, nstatev, nfieldv, nprops, lanneal
  real(dp), intent(in) :: stepTime, totalTime, dt
  character(len=80), intent(in) :: cmname
  real(dp), intent(in) :: coordMp(*), charLength(*), props(*), density(*), strainInc(*), relSpinInc(*)
  real(dp), intent(in) :: tempOld(*), stretchOld(*), defgradOld(*), fieldOld(*), stressOld(*), stateOld(*)
  real(dp), intent(in) :: enerInternOld(*), enerInelasOld(*), tempNew(*), stretchNew(*), defgradNew(*)
  real(dp), intent(in) :: fieldNew(*)
  real(dp), intent(inout) :: stressNew(*), stateNew(*), enerInternNew(*), enerInelasNew(*)
  external :: vumat

  call vumat(nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal, stepTime, totalTime, dt, cmname, &
       coordMp, charLength, props, density, strainInc, relSpinInc, tempOld, stretchOld, defgradOld, &
       fieldOld, stressOld, stateOld, enerInternOld, enerInelasOld, tempNew, stretchNew, defgradNew, &
       fieldNew, stressNew, stateNew, enerInternNew, enerInelasNew)
end subroutine bulkflow_vumat
