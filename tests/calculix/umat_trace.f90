! Test-only UMAT for CalculiX: calls bulkflow's umat (renamed bulkflow_umat_traced by objcopy in
! check_ccx_matpoint.py) and appends each call's end-of-increment stress and state with 17
! significant digits to umat_trace.txt (CalculiX prints 7). The last call of an increment at a
! point is the converged one.
subroutine umat(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
     stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, ndi, nshr, ntens, &
     nstatv, props, nprops, coords, drot, pnewdt, celent, dfgrd0, dfgrd1, noel, npt, layer, &
     kspt, jstep, kinc)
  implicit none
  character(len=80) :: cmname
  integer :: ndi, nshr, ntens, nstatv, nprops, noel, npt, layer, kspt, jstep(*), kinc
  double precision :: stress(ntens), statev(nstatv), sse, spd, scd, pnewdt
  double precision :: ddsdde(ntens, ntens), rpl, ddsddt(ntens), drplde(ntens), drpldt
  double precision :: stran(ntens), dstran(ntens), time(2), dtime, temp, dtemp
  double precision :: predef(*), dpred(*), props(nprops), coords(3), drot(3, 3), celent
  double precision :: dfgrd0(3, 3), dfgrd1(3, 3)
  integer :: unit
  logical :: opened

  call bulkflow_umat_traced(stress, statev, ddsdde, sse, spd, scd, rpl, ddsddt, drplde, drpldt, &
       stran, dstran, time, dtime, temp, dtemp, predef, dpred, cmname, ndi, nshr, ntens, &
       nstatv, props, nprops, coords, drot, pnewdt, celent, dfgrd0, dfgrd1, noel, npt, layer, &
       kspt, jstep, kinc)
  ! Asked every call instead of a saved unit number: CalculiX may call from other threads.
  inquire (file='umat_trace.txt', opened=opened, number=unit)
  if (.not. opened) open (newunit=unit, file='umat_trace.txt', status='unknown', position='append', &
       action='write')
  write (unit, '(i0,1x,i0,*(1x,es25.17))') noel, npt, time(2) + dtime, stress, statev
  flush (unit)
end subroutine umat
