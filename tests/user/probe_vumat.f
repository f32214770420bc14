C     A probe VUMAT written the way users write them for Abaqus/Explicit (fixed form,
C     INCLUDE 'VABA_PARAM.INC', local arrays of n_vec_Length = 136): a compressible
C     neo-Hookean solid whose stress comes from defgradNew, and on every call a check of
C     the arguments the host passes against what they must be (tests/user/README.md).
C     Any failed check stops the run through xplb_abqerr(-3, ...).
C
C     props: 1 E, 2 nu, 3 rho0, 4 expected temperature at t = 0, 5 field 1, 6 field 2,
C            7-9 reference centroid X of the probed point (checked when props(10) = 1:
C            coordMp = F X for a homogeneous motion that keeps the origin), 11 nfieldv
C            expected, 12 (optional) dT/dt of the scene's temperature (0: constant).
C     SDVs:  1 J, 2-4 coordMp, 5 charLength, 6 tempNew, 7 field 1, 8 field 2, 9 nblock,
C            10 number of increments seen.
      subroutine vumat(
     1  nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal,
     2  stepTime, totalTime, dt, cmname, coordMp, charLength,
     3  props, density, strainInc, relSpinInc,
     4  tempOld, stretchOld, defgradOld, fieldOld,
     5  stressOld, stateOld, enerInternOld, enerInelasOld,
     6  tempNew, stretchNew, defgradNew, fieldNew,
     7  stressNew, stateNew, enerInternNew, enerInelasNew )
C
      include 'VABA_PARAM.INC'
C
      dimension props(nprops), density(nblock), coordMp(nblock,*),
     1  charLength(nblock), strainInc(nblock,ndir+nshr),
     2  relSpinInc(nblock,nshr), tempOld(nblock),
     3  stretchOld(nblock,ndir+nshr),
     4  defgradOld(nblock,ndir+nshr+nshr),
     5  fieldOld(nblock,nfieldv), stressOld(nblock,ndir+nshr),
     6  stateOld(nblock,nstatev), enerInternOld(nblock),
     7  enerInelasOld(nblock), tempNew(nblock),
     8  stretchNew(nblock,ndir+nshr),
     9  defgradNew(nblock,ndir+nshr+nshr),
     1  fieldNew(nblock,nfieldv),
     2  stressNew(nblock,ndir+nshr), stateNew(nblock,nstatev),
     3  enerInternNew(nblock), enerInelasNew(nblock)
C
      character*80 cmname
      dimension f(3,3), c(3,3), u(3,3), fo(3,3), uo(3,3)
      dimension ajnew(n_vec_Length), ajold(n_vec_Length)
      dimension intv(2), realv(2)
      character*8 charv(1)
      parameter (tol = 1.d-9)
C
      e = props(1)
      xnu = props(2)
      g = e / (2.d0 * (1.d0 + xnu))
      alam = e * xnu / ((1.d0 + xnu) * (1.d0 - 2.d0 * xnu))
      intv(1) = 0
      intv(2) = 0
      realv(1) = 0.d0
      realv(2) = 0.d0
      charv(1) = ' '
C
      if (nblock .gt. n_vec_Length) call fail('nblock above 136', nblock)
      if (ndir .ne. 3) call fail('ndir is not 3', ndir)
      if (nshr .ne. 1 .and. nshr .ne. 3) call fail('nshr not 1 or 3', nshr)
      if (cmname(1:5) .ne. 'PROBE') call fail('cmname not PROBE...', 0)
      do i = 1, 80
         ic = ichar(cmname(i:i))
         if (ic .ge. ichar('a') .and. ic .le. ichar('z'))
     1      call fail('cmname not upper case', i)
      end do
C
      if (totalTime .eq. 0.d0 .and. stepTime .eq. 0.d0) then
C        The packaging call: elastic response to the trial strain.
         do k = 1, nblock
            tr = strainInc(k,1) + strainInc(k,2) + strainInc(k,3)
            do j = 1, ndir + nshr
               stressNew(k,j) = 2.d0 * g * strainInc(k,j)
            end do
            do j = 1, ndir
               stressNew(k,j) = stressNew(k,j) + alam * tr
            end do
         end do
         return
      end if
C
      if (dt .le. 0.d0) call fail('dt not positive', 0)
      if (stepTime .gt. totalTime * (1.d0 + tol)) call fail(
     1   'stepTime above totalTime', 0)
      if (nint(props(11)) .ne. nfieldv) call fail(
     1   'nfieldv differs from the scene''s field count', nfieldv)
C
      do k = 1, nblock
C        The outputs hold the old values on entry.
         do j = 1, ndir + nshr
            if (stressNew(k,j) .ne. stressOld(k,j)) call fail(
     1         'stressNew does not hold stressOld on entry', k)
         end do
         do j = 1, nstatev
            if (stateNew(k,j) .ne. stateOld(k,j)) call fail(
     1         'stateNew does not hold stateOld on entry', k)
         end do
         if (enerInternNew(k) .ne. enerInternOld(k)) call fail(
     1      'enerInternNew does not hold enerInternOld on entry', k)
         if (enerInelasNew(k) .ne. enerInelasOld(k)) call fail(
     1      'enerInelasNew does not hold enerInelasOld on entry', k)
C        Temperature: props(4) + rate * t at the start (totalTime - dt)
C        and the end (totalTime) of the increment, rate = props(12) when
C        given (the scene's *TEMPERATURE amplitude), else constant.
         rate = 0.d0
         if (nprops .ge. 12) rate = props(12)
         t0 = props(4) + rate * (totalTime - dt)
         t1 = props(4) + rate * totalTime
         if (abs(tempOld(k) - t0) .gt. tol * (1+abs(t0)))
     1      call fail('tempOld is not the temperature at t_n', k)
         if (abs(tempNew(k) - t1) .gt. tol * (1+abs(t1)))
     1      call fail('tempNew is not the temperature at t_n+1', k)
         if (abs(tempNew(k) - tempOld(k) - rate * dt) .gt.
     1      tol * (1+abs(t1)))
     2      call fail('tempNew - tempOld is not rate * dt', k)
         if (nfieldv .ge. 1) then
            if (abs(fieldNew(k,1) - props(5)) .gt. tol) call fail(
     1         'field 1 differs from the initial field 1', k)
         end if
         if (nfieldv .ge. 2) then
            if (abs(fieldNew(k,2) - props(6)) .gt. tol) call fail(
     1         'field 2 differs from the initial field 2', k)
         end if
         if (charLength(k) .le. 0.d0) call fail('charLength <= 0', k)
C        F and U at both ends of the increment: U symmetric with U U = F^T F.
         call unpack(nblock, k, nshr, defgradNew, stretchNew, f, u)
         call unpack(nblock, k, nshr, defgradOld, stretchOld, fo, uo)
         call checkstretch(f, u, 'new')
         call checkstretch(fo, uo, 'old')
         ajnew(k) = det3(f)
         ajold(k) = det3(fo)
         if (ajnew(k) .le. 0.d0) call fail('det defgradNew <= 0', k)
C        Mass conservation: density is rho0/J at a time inside the
C        increment (the mid-increment configuration of a rotation is
C        smaller by O(dtheta**2): 0.2 % allowed).
         d1 = density(k) * ajnew(k) - props(3)
         d0 = density(k) * ajold(k) - props(3)
         if (d1 * d0 .gt. 0.d0 .and. min(abs(d1), abs(d0)) .gt.
     1      2.d-3 * props(3)) call fail('density is not rho0/J', k)
C        Volume change: tr(strainInc) = ln(J_new/J_old) to second order.
         tr = strainInc(k,1) + strainInc(k,2) + strainInc(k,3)
         dv = log(ajnew(k) / ajold(k))
         if (abs(tr - dv) .gt. 1.d-3 * abs(dv) + 1.d-12) call fail(
     1      'trace of strainInc is not ln(J_new/J_old)', k)
C        coordMp of a homogeneous motion keeping the origin: x = F X.
         if (nint(props(10)) .eq. 1) then
            do i = 1, 3
               x = f(i,1)*props(7) + f(i,2)*props(8) + f(i,3)*props(9)
               if (abs(coordMp(k,i) - x) .gt. 1.d-9 * (1 + abs(x)))
     1            call fail('coordMp is not F X', i)
            end do
         end if
C        Neo-Hooke in the corotational frame: (G/J)(C - I) + lam ln J / J I.
         do i = 1, 3
            do j = 1, 3
               c(i,j) = f(1,i)*f(1,j) + f(2,i)*f(2,j) + f(3,i)*f(3,j)
            end do
         end do
         aj = ajnew(k)
         p = alam * log(aj) / aj
         stressNew(k,1) = g / aj * (c(1,1) - 1.d0) + p
         stressNew(k,2) = g / aj * (c(2,2) - 1.d0) + p
         stressNew(k,3) = g / aj * (c(3,3) - 1.d0) + p
         stressNew(k,4) = g / aj * c(1,2)
         if (nshr .eq. 3) then
            stressNew(k,5) = g / aj * c(2,3)
            stressNew(k,6) = g / aj * c(3,1)
         end if
         if (nstatev .ge. 10) then
            stateNew(k,1) = aj
            stateNew(k,2) = coordMp(k,1)
            stateNew(k,3) = coordMp(k,2)
            stateNew(k,4) = coordMp(k,3)
            stateNew(k,5) = charLength(k)
            stateNew(k,6) = tempNew(k)
            if (nfieldv .ge. 1) stateNew(k,7) = fieldNew(k,1)
            if (nfieldv .ge. 2) stateNew(k,8) = fieldNew(k,2)
            stateNew(k,9) = nblock
            stateNew(k,10) = stateOld(k,10) + 1.d0
         end if
      end do
      return
      end
C
C     F (3x3) and U (symmetric) of point k from the VUMAT layouts.
      subroutine unpack(nblock, k, nshr, defgrad, stretch, f, u)
      include 'VABA_PARAM.INC'
      dimension defgrad(nblock,*), stretch(nblock,*), f(3,3), u(3,3)
      do i = 1, 3
         do j = 1, 3
            f(i,j) = 0.d0
            u(i,j) = 0.d0
         end do
         f(i,i) = defgrad(k,i)
         u(i,i) = stretch(k,i)
      end do
      f(1,2) = defgrad(k,4)
      u(1,2) = stretch(k,4)
      u(2,1) = stretch(k,4)
      if (nshr .eq. 1) then
         f(2,1) = defgrad(k,5)
      else
         f(2,3) = defgrad(k,5)
         f(3,1) = defgrad(k,6)
         f(2,1) = defgrad(k,7)
         f(3,2) = defgrad(k,8)
         f(1,3) = defgrad(k,9)
         u(2,3) = stretch(k,5)
         u(3,2) = stretch(k,5)
         u(3,1) = stretch(k,6)
         u(1,3) = stretch(k,6)
      end if
      return
      end
C
C     U U = F^T F, to round-off.
      subroutine checkstretch(f, u, which)
      include 'VABA_PARAM.INC'
      dimension f(3,3), u(3,3)
      character*(*) which
      do i = 1, 3
         do j = 1, 3
            uu = u(i,1)*u(1,j) + u(i,2)*u(2,j) + u(i,3)*u(3,j)
            ftf = f(1,i)*f(1,j) + f(2,i)*f(2,j) + f(3,i)*f(3,j)
            if (abs(uu - ftf) .gt. 1.d-10) then
               call fail('stretch'//which//' squared is not F^T F', 0)
            end if
         end do
      end do
      return
      end
C
      function det3(a)
      include 'VABA_PARAM.INC'
      dimension a(3,3)
      det3 = a(1,1)*(a(2,2)*a(3,3) - a(2,3)*a(3,2))
     1     - a(1,2)*(a(2,1)*a(3,3) - a(2,3)*a(3,1))
     2     + a(1,3)*(a(2,1)*a(3,2) - a(2,2)*a(3,1))
      return
      end
C
      subroutine fail(text, n)
      include 'VABA_PARAM.INC'
      character*(*) text
      dimension intv(1), realv(1)
      character*8 charv(1)
      intv(1) = n
      realv(1) = 0.d0
      charv(1) = ' '
      call xplb_abqerr(-3, 'PROBE: '//text//' (%I)', intv, realv, charv)
      return
      end
