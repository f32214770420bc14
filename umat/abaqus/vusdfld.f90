!DIR$ FREEFORM
! Abaqus/Explicit VUSDFLD entry point of the bulkflow materials (Abaqus's exact argument list).
! Field variable 1 becomes the current volumetric strain tr(LE) (dilation positive), read with
! vgetvrm, so that friction and dilation angles tabulated against field 1 soften with dilation
! (thesis eq. 4.1, 5.4). The state variables pass through unchanged.
subroutine vusdfld(nblock, nstatev, nfieldv, nprops, ndir, nshr, &
     jElem, kIntPt, kLayer, kSecPt, &
     stepTime, totalTime, dt, cmname, &
     coordMp, direct, T, charLength, props, &
     stateOld, &
     stateNew, field)
  include 'vaba_param.inc'
  integer, intent(in) :: nblock, nstatev, nfieldv, nprops, ndir, nshr
  integer, intent(in) :: jElem(nblock), kIntPt, kLayer, kSecPt
  double precision, intent(in) :: stepTime, totalTime, dt
  character(len=80), intent(in) :: cmname
  double precision, intent(in) :: coordMp(nblock, *), direct(nblock, 3, 3), T(nblock, 3, 3)
  double precision, intent(in) :: charLength(nblock), props(nprops), stateOld(nblock, nstatev)
  double precision, intent(out) :: stateNew(nblock, nstatev)
  double precision, intent(inout) :: field(nblock, nfieldv)
  ! vgetvrm fills arrays dimensioned for the largest block (Abaqus's documented convention).
  integer, parameter :: max_components = 6
  double precision :: rData(maxblk * max_components)
  integer :: jData(maxblk * max_components), jStatus, k, intv(1)
  character(len=3) :: cData(maxblk * max_components)
  double precision :: realv(1)
  character(len=8) :: charv(1)

  stateNew = stateOld
  if (nfieldv < 1) return
  jStatus = 1
  call vgetvrm('LE', rData, jData, cData, jStatus)
  if (jStatus /= 0) then
     intv = 0
     realv = 0
     charv = ' '
     call xplb_abqerr(-2, 'VUSDFLD: vgetvrm could not provide LE for material ' // trim(cmname), &
          intv, realv, charv)
     call xplb_exit()
  end if
  do k = 1, nblock
     field(k, 1) = rData(k) + rData(nblock + k) + rData(2 * nblock + k)
  end do
end subroutine vusdfld
