C     Test user file in users' style with no VUMAT: only a VUSDFLD, for one of
C     bulkflow's built-in materials (*MOHR COULOMB with an angle table on
C     field 1). Field 1 = 0.5 everywhere (our own VUSDFLD would give the
C     volumetric strain), field 2 = tr(PE) and field 3 = PE22 read with
C     vgetvrm('PE') at the start of the increment.
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
      parameter( nrData=6 )
      character*3 cData(maxblk*nrData)
      dimension rData(maxblk*nrData), jData(maxblk*nrData)
C
      jStatus = 1
      call vgetvrm( 'PE', rData, jData, cData, jStatus )
      if( jStatus .ne. 0 ) then
         call xplb_abqerr(-3,'vgetvrm PE failed',0,0.d0,' ')
      end if
      do k = 1, nblock
        field(k,1) = 0.5d0
        field(k,2) = rData(k) + rData(nblock+k) + rData(2*nblock+k)
        field(k,3) = rData(nblock+k)
        do i = 1, nstatev
          stateNew(k,i) = stateOld(k,i)
        end do
      end do
      return
      end
