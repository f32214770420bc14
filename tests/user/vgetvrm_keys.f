C     Test user file in users' style with no VUMAT: a VUSDFLD for one of
C     bulkflow's built-in materials (*MOHR COULOMB with an angle table on
C     field 1) that reads every vgetvrm key the host documents: S, LE, PE,
C     PEEQ, SDV and TEMP. It stops the run (xplb_abqerr -3) when nblock is
C     above n_vec_Length, when nstatev is not the *DEPVAR count props(2)
C     (Abaqus gives a VUSDFLD on a built-in material its *DEPVAR state
C     variables only) or when vgetvrm('SDV') differs from stateOld. Its own
C     state: SDV1 counts its calls, SDV2 keeps PEEQ. The rest goes to the
C     fields, checked against the frames:
C       field 1 = 0.5 (phi of the angle table), 2 = TEMP, 3 = PEEQ,
C       4 = LE22, 5 = S22, 6 = PE22.
C     props (*USER DEFINED FIELD, PROPERTIES=2): props(1) = 1 asks for the
C     key 'SP', which the host does not provide: the run must stop naming
C     it; props(2) = the expected nstatev.
      subroutine vusdfld(
     1   nblock, nstatev, nfieldv, nprops, ndir, nshr,
     2   jElem, kIntPt, kLayer, kSecPt,
     3   stepTime, totalTime, dt, cmname,
     4   coordMp, direct, T, charLength, props,
     5   stateOld,
     6   stateNew, field )
      INCLUDE 'VABA_PARAM.INC'
      dimension jElem(nblock), coordMp(nblock,*),
     1   direct(nblock,3,3), T(nblock,3,3),
     2   charLength(nblock), props(nprops),
     3   stateOld(nblock,nstatev), stateNew(nblock,nstatev),
     4   field(nblock,nfieldv)
      character*80 cmname
      parameter( nrData=6, nsdv=16 )
      character*3 cData(maxblk*nsdv)
      dimension rs(maxblk*nrData), rle(maxblk*nrData),
     1   rpe(maxblk*nrData), rpeeq(maxblk), rtemp(maxblk),
     2   rsdv(maxblk*nsdv), jData(maxblk*nsdv)
C
      if (nblock .gt. n_vec_Length) call stopkey('nblock above 136',
     1   nblock)
      if (nfieldv .lt. 6) call stopkey('FIELDS=6 expected', nfieldv)
      if (nstatev .gt. nsdv) call stopkey('more than 16 SDVs', nstatev)
      if (nprops .lt. 2) call stopkey('PROPERTIES=2 expected', nprops)
      if (nstatev .ne. nint(props(2))) call stopkey(
     1   'nstatev is not the *DEPVAR count', nstatev)
      call getkey('S', rs, jData, cData)
      call getkey('LE', rle, jData, cData)
      call getkey('PE', rpe, jData, cData)
      call getkey('PEEQ', rpeeq, jData, cData)
      call getkey('SDV', rsdv, jData, cData)
      call getkey('TEMP', rtemp, jData, cData)
      if (props(1) .eq. 1.d0) call getkey('SP', rs, jData, cData)
      do k = 1, nblock
        do i = 1, nstatev
          if (rsdv((i-1)*nblock+k) .ne. stateOld(k,i))
     1       call stopkey('vgetvrm SDV is not stateOld', i)
        end do
        stateNew(k,1) = stateOld(k,1) + 1.d0
        stateNew(k,2) = rpeeq(k)
        field(k,1) = 0.5d0
        field(k,2) = rtemp(k)
        field(k,3) = rpeeq(k)
        field(k,4) = rle(nblock+k)
        field(k,5) = rs(nblock+k)
        field(k,6) = rpe(nblock+k)
      end do
      return
      end
C
      subroutine getkey(key, rData, jData, cData)
      INCLUDE 'VABA_PARAM.INC'
      character*(*) key
      character*3 cData(*)
      dimension rData(*), jData(*)
      jStatus = 1
      call vgetvrm(key, rData, jData, cData, jStatus)
      if (jStatus .ne. 0) call stopkey('vgetvrm failed', jStatus)
      return
      end
C
      subroutine stopkey(text, n)
      INCLUDE 'VABA_PARAM.INC'
      character*(*) text
      dimension intv(1), realv(1)
      character*8 charv(1)
      intv(1) = n
      realv(1) = 0.d0
      charv(1) = ' '
      call xplb_abqerr(-3, 'KEYS: '//text//' (%I)', intv, realv, charv)
      return
      end
