!DIR$ FREEFORM
! Abaqus/Standard UMAT entry point of the bulkflow materials (Abaqus's exact argument list;
! CalculiX calls it the same way for materials named ABAQUS...). The material is chosen by the
! name (umat/README.md); material_standard does the work and forms the consistent tangent.
! JSTEP is Abaqus's current form of KSTEP (step number, procedure, NLGEOM, linear perturbation).
subroutine umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
     stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, ndi, nshr, ntens, &
     nstatv, props, nprops, coords, drot, pnewdt, celent, dfgrd0, dfgrd1, noel, npt, layer, &
     kspt, jstep, kinc)
  use material_standard, only: material_umat, message_length
  include 'aba_param.inc'
  character(len=80), intent(in) :: cmname
  integer, intent(in) :: ndi, nshr, ntens, nstatv, nprops, noel, npt, layer, kspt, jstep(*), kinc
  double precision, intent(inout) :: stress(ntens), statev(nstatv), sse, spd, scd, pnewdt
  double precision, intent(out) :: ddsdde(ntens, ntens), rpl, ddsddt(ntens), drplde(ntens), drpldt
  double precision, intent(in) :: stran(ntens), dstran(ntens), time(2), dtime, temp, dtemp
  double precision, intent(in) :: predef(*), dpred(*), props(nprops), coords(3), drot(3, 3), celent
  double precision, intent(in) :: dfgrd0(3, 3), dfgrd1(3, 3)
  logical :: ok
  character(len=message_length) :: message
  integer :: intv(1)
  double precision :: realv(1)
  character(len=8) :: charv(1)

  ! No heat generation and no temperature dependence.
  rpl = 0
  ddsddt = 0
  drplde = 0
  drpldt = 0
  call material_umat(ndi, nshr, ntens, nstatv, nprops, time(2) + dtime, dtime, cmname, props, dstran, &
       stress, statev, sse, spd, ddsdde, ok, message)
  if (.not. ok) then
     intv = 0
     realv = 0
     charv = ' '
     call stdb_abqerr(-3, 'UMAT: ' // trim(message), intv, realv, charv)
     call xit()
  end if
end subroutine umat
