!DIR$ FREEFORM
! Abaqus/Explicit VUSDFLD entry point of the bulkflow materials (Abaqus's exact argument list).
! Two modes, chosen by the constants of `*USER DEFINED FIELD, PROPERTIES=3` (umat/README.md):
!
! * volumetric strain (no properties, or any other constants): field 1 = tr(LE), dilation
!   positive, so that friction and dilation angles tabulated against field 1 soften with
!   dilation (thesis eq. 4.1, 5.4); the state variables pass through unchanged.
! * flow function (exactly three properties: 1, t_freeze, record): field 1 = the recorded major
!   principal consolidation stress sigma1 = -(most compressive principal stress of S), COMPRESSION
!   POSITIVE and never below 0, so that `*MOHR COULOMB HARDENING, DEPENDENCIES=1` tabulates the
!   cohesion c(sigma1) = fc(sigma1)(1 - sin phi)/(2 cos phi) (thesis eq. 6.9, §6.2: the cohesion
!   follows the consolidation stress until the end of filling and is frozen after). The record is
!   the current value (record = 0) or the running maximum (record = 1) while the time of the
!   start-of-increment stress, totalTime - dt, is at most t_freeze (t_freeze <= 0: never frozen),
!   and held after. It lives in the LAST state variable (SDV nstatev, *DEPVAR >= 1; with our MC or
!   DP VUMAT, whose SDVs 1-8 are its own, *DEPVAR >= 9). Field 2, when the material has two field
!   variables, is tr(LE) as in the other mode.
!
! Only the vgetvrm keys Abaqus provides are read ('S', 'LE'), so the routine runs in Abaqus/Explicit
! unchanged; vgetvrm returns start-of-increment values (the stress the VUMAT gets as stressOld).
subroutine vusdfld(nblock, nstatev, nfieldv, nprops, ndir, nshr, &
     jElem, kIntPt, kLayer, kSecPt, &
     stepTime, totalTime, dt, cmname, &
     coordMp, direct, T, charLength, props, &
     stateOld, &
     stateNew, field)
  use principal_stress, only: principal_plane, principal_3d
  use material_props, only: model_from_name, model_mohr_coulomb, model_drucker_prager
  use material_state, only: n_state_plastic
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
  ! The stress of the start of the increment belongs to time totalTime - dt; this fraction of dt
  ! absorbs the round-off of that difference, so a freeze time at a step end keeps the stress
  ! of the step's last increment (and nothing later: the next one is a whole dt away).
  double precision, parameter :: time_round_off = 1.0d-9
  double precision :: rData(maxblk * max_components)
  integer :: jData(maxblk * max_components), k, j, ncomp, izz, model
  character(len=3) :: cData(maxblk * max_components)
  double precision :: s(6), sig(3), vec(3, 3), c, sn, sigma1, recorded
  logical :: flow_function, recording, record_maximum

  stateNew = stateOld
  if (nfieldv < 1) return
  flow_function = .false.
  if (nprops == 3) flow_function = nint(props(1)) == 1
  if (.not. flow_function) then
     call get_variable('LE', rData, jData, cData, cmname)
     do k = 1, nblock
        field(k, 1) = rData(k) + rData(nblock + k) + rData(2 * nblock + k)
     end do
     return
  end if

  model = model_from_name(cmname)
  if (nstatev < 1 .or. ((model == model_mohr_coulomb .or. model == model_drucker_prager) &
       .and. nstatev <= n_state_plastic)) then
     call stop_with('VUSDFLD (flow-function mode) keeps the consolidation stress in the last ' // &
          'state variable: declare *DEPVAR >= 1, or >= 9 with the MC/DP VUMAT, for material ' // trim(cmname))
  end if
  recording = props(2) <= 0 .or. totalTime - dt <= props(2) + time_round_off * dt
  record_maximum = nint(props(3)) == 1
  ncomp = ndir + nshr
  call get_variable('S', rData, jData, cData, cmname)
  s = 0
  do k = 1, nblock
     do j = 1, ncomp
        s(j) = rData((j - 1) * nblock + k)
     end do
     if (ncomp == 4) then
        call principal_plane(s(1:4), sig, c, sn, izz)
     else
        call principal_3d(s, sig, vec)
     end if
     sigma1 = max(0.0d0, -sig(3))
     recorded = stateOld(k, nstatev)
     if (recording) then
        if (record_maximum) then
           recorded = max(recorded, sigma1)
        else
           recorded = sigma1
        end if
     end if
     stateNew(k, nstatev) = recorded
     field(k, 1) = recorded
  end do
  if (nfieldv >= 2) then
     call get_variable('LE', rData, jData, cData, cmname)
     do k = 1, nblock
        field(k, 2) = rData(k) + rData(nblock + k) + rData(2 * nblock + k)
     end do
  end if

contains

  ! vgetvrm, stopping the analysis when the key is not available.
  subroutine get_variable(key, values, flags, texts, material)
    character(len=*), intent(in) :: key
    double precision, intent(out) :: values(*)
    integer, intent(out) :: flags(*)
    character(len=3), intent(out) :: texts(*)
    character(len=80), intent(in) :: material
    integer :: status

    status = 1
    call vgetvrm(key, values, flags, texts, status)
    if (status /= 0) call stop_with('VUSDFLD: vgetvrm could not provide ' // key // ' for material ' // &
         trim(material))
  end subroutine get_variable

  subroutine stop_with(text)
    character(len=*), intent(in) :: text
    integer :: intv(1)
    double precision :: realv(1)
    character(len=8) :: charv(1)

    intv = 0
    realv = 0
    charv = ' '
    call xplb_abqerr(-2, text, intv, realv, charv)
    call xplb_exit()
  end subroutine stop_with
end subroutine vusdfld
