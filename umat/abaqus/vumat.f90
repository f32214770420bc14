!DIR$ FREEFORM
! Abaqus/Explicit VUMAT entry point of the bulkflow materials (Abaqus's exact argument list).
! The material is chosen by the name (umat/README.md); the work is done by material_dispatch.
! `use` precedes the include because Fortran requires USE statements before IMPLICIT ones.
subroutine vumat(nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal, &
     stepTime, totalTime, dt, cmname, coordMp, charLength, &
     props, density, strainInc, relSpinInc, &
     tempOld, stretchOld, defgradOld, fieldOld, &
     stressOld, stateOld, enerInternOld, enerInelasOld, &
     tempNew, stretchNew, defgradNew, fieldNew, &
     stressNew, stateNew, enerInternNew, enerInelasNew)
  use material_dispatch, only: material_vumat, message_length
  include 'vaba_param.inc'
  integer, intent(in) :: nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal
  double precision, intent(in) :: stepTime, totalTime, dt
  character(len=80), intent(in) :: cmname
  double precision, intent(in) :: coordMp(nblock, *), charLength(nblock), props(nprops)
  double precision, intent(in) :: density(nblock), strainInc(nblock, ndir + nshr), relSpinInc(nblock, nshr)
  double precision, intent(in) :: tempOld(nblock), stretchOld(nblock, ndir + nshr)
  double precision, intent(in) :: defgradOld(nblock, ndir + nshr + nshr), fieldOld(nblock, nfieldv)
  double precision, intent(in) :: stressOld(nblock, ndir + nshr), stateOld(nblock, nstatev)
  double precision, intent(in) :: enerInternOld(nblock), enerInelasOld(nblock)
  double precision, intent(in) :: tempNew(nblock), stretchNew(nblock, ndir + nshr)
  double precision, intent(in) :: defgradNew(nblock, ndir + nshr + nshr), fieldNew(nblock, nfieldv)
  double precision, intent(out) :: stressNew(nblock, ndir + nshr), stateNew(nblock, nstatev)
  double precision, intent(inout) :: enerInternNew(nblock), enerInelasNew(nblock)
  logical :: ok
  character(len=message_length) :: message
  integer :: intv(1)
  double precision :: realv(1)
  character(len=8) :: charv(1)

  call material_vumat(nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal, stepTime, totalTime, &
       dt, cmname, props, density, strainInc, fieldNew, stressOld, stateOld, enerInternOld, enerInelasOld, &
       stressNew, stateNew, enerInternNew, enerInelasNew, ok, message)
  if (.not. ok) then
     intv = 0
     realv = 0
     charv = ' '
     call xplb_abqerr(-2, 'VUMAT: ' // trim(message), intv, realv, charv)
     call xplb_exit()
  end if
end subroutine vumat
