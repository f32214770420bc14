C     Test user file in users' style: an elastic VUMAT and a VUSDFLD that writes two field
C     variables, field 1 = pressure of the start-of-increment stress (vgetvrm 'S'), field 2 =
C     the point's current height (coordMp), and keeps them in SDV1 and SDV2;
C     SDV4 (when declared) = the nblock of its call, which must not exceed
C     n_vec_Length (136; the run stops through xplb_abqerr -3 otherwise).
      subroutine vumat(
     1 nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal,
     2 stepTime, totalTime, dt, cmname, coordMp, charLength,
     3 props, density, strainInc, relSpinInc,
     4 tempOld, stretchOld, defgradOld, fieldOld,
     5 stressOld, stateOld, enerInternOld, enerInelasOld,
     6 tempNew, stretchNew, defgradNew, fieldNew,
     7 stressNew, stateNew, enerInternNew, enerInelasNew )
      INCLUDE 'VABA_PARAM.INC'
      dimension props(nprops), density(nblock), coordMp(nblock,*),
     1 charLength(nblock), strainInc(nblock,ndir+nshr),
     2 relSpinInc(nblock,nshr), tempOld(nblock),
     3 stretchOld(nblock,ndir+nshr), defgradOld(nblock,ndir+nshr+nshr),
     4 fieldOld(nblock,nfieldv), stressOld(nblock,ndir+nshr),
     5 stateOld(nblock,nstatev), enerInternOld(nblock),
     6 enerInelasOld(nblock), tempNew(nblock),
     7 stretchNew(nblock,ndir+nshr), defgradNew(nblock,ndir+nshr+nshr),
     8 fieldNew(nblock,nfieldv), stressNew(nblock,ndir+nshr),
     9 stateNew(nblock,nstatev), enerInternNew(nblock),
     1 enerInelasNew(nblock)
      character*80 cmname
      twomu = props(1) / (1.d0 + props(2))
      alam = twomu * props(2) / (1.d0 - 2.d0 * props(2))
      do k = 1, nblock
        tr = strainInc(k,1) + strainInc(k,2) + strainInc(k,3)
        do i = 1, ndir
          stressNew(k,i) = stressOld(k,i) + alam*tr + twomu*strainInc(k,i)
        end do
        do i = ndir+1, ndir+nshr
          stressNew(k,i) = stressOld(k,i) + twomu*strainInc(k,i)
        end do
        stateNew(k,1) = stateOld(k,1)
        stateNew(k,2) = stateOld(k,2)
        stateNew(k,3) = fieldNew(k,2)
      end do
      return
      end
C
      subroutine vusdfld(
     1 nblock, nstatev, nfieldv, nprops, ndir, nshr,
     2 jElem, kIntPt, kLayer, kSecPt,
     3 stepTime, totalTime, dt, cmname,
     4 coordMp, direct, T, charLength, props,
     5 stateOld,
     6 stateNew, field )
      INCLUDE 'VABA_PARAM.INC'
      dimension jElem(nblock), coordMp(nblock,*),
     1 direct(nblock,3,3), T(nblock,3,3),
     2 charLength(nblock), props(nprops),
     3 stateOld(nblock,nstatev),
     4 stateNew(nblock,nstatev),
     5 field(nblock,nfieldv)
      character*80 cmname
      character*3 cData(maxblk*6)
      dimension rData(maxblk*6), jData(maxblk*6)
      if (nblock .gt. n_vec_Length) then
        call xplb_abqerr(-2, 'VUSDFLD: nblock above n_vec_Length',
     1    0, zero, ' ')
        call xplb_exit
      end if
      jStatus = 1
      call vgetvrm('S', rData, jData, cData, jStatus)
      if (jStatus .ne. 0) then
        call xplb_abqerr(-2, 'vgetvrm S failed', 0, zero, ' ')
        call xplb_exit
      end if
      do k = 1, nblock
        field(k,1) = -(rData(k) + rData(nblock+k) + rData(2*nblock+k))
     1               / 3.d0
        field(k,2) = coordMp(k,2)
        stateNew(k,1) = field(k,1)
        stateNew(k,2) = field(k,2)
        if (nstatev .ge. 4) stateNew(k,4) = nblock
      end do
      if (props(3) .gt. 0.d0) then
C       asks for PEEQ, which a user VUMAT does not have: the host must stop
        call vgetvrm('PEEQ', rData, jData, cData, jStatus)
      end if
      return
      end
