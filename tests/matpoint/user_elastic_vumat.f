C     A user's VUMAT as users write them for Abaqus/Explicit: fixed form,
C     implicit typing from vaba_param.inc, the manual's argument list.
C     Isotropic linear elasticity, props(1) = E, props(2) = nu.
C     It is built into bulkflow-matpoint-user-example to show that the
C     material-point driver runs any VUMAT compiled against the same
C     interface (tests/matpoint/CMakeLists.txt).
      subroutine vumat(
C Read only (unmodifiable) variables -
     1  nblock, ndir, nshr, nstatev, nfieldv, nprops, lanneal,
     2  stepTime, totalTime, dt, cmname, coordMp, charLength,
     3  props, density, strainInc, relSpinInc,
     4  tempOld, stretchOld, defgradOld, fieldOld,
     5  stressOld, stateOld, enerInternOld, enerInelasOld,
     6  tempNew, stretchNew, defgradNew, fieldNew,
C Write only (modifiable) variables -
     7  stressNew, stateNew, enerInternNew, enerInelasNew )
C
      include 'vaba_param.inc'
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
     8  defgradNew(nblock,ndir+nshr+nshr),
     9  fieldNew(nblock,nfieldv),
     1  stressNew(nblock,ndir+nshr), stateNew(nblock,nstatev),
     2  enerInternNew(nblock), enerInelasNew(nblock)
C
      character*80 cmname
      parameter( zero = 0.d0, one = 1.d0, two = 2.d0, half = 0.5d0 )
C
      e      = props(1)
      xnu    = props(2)
      twomu  = e / ( one + xnu )
      alamda = xnu * twomu / ( one - two * xnu )
C
      do 100 km = 1, nblock
C        trace of the strain increment (tensor shear components)
         trace = strainInc(km,1) + strainInc(km,2) + strainInc(km,3)
         do 10 i = 1, ndir
            stressNew(km,i) = stressOld(km,i)
     1         + alamda * trace + twomu * strainInc(km,i)
   10    continue
         do 20 i = ndir+1, ndir+nshr
            stressNew(km,i) = stressOld(km,i) + twomu * strainInc(km,i)
   20    continue
         do 30 i = 1, nstatev
            stateNew(km,i) = stateOld(km,i)
   30    continue
C        specific internal energy, midpoint rule, factor 2 on shears
         stressPower = zero
         do 40 i = 1, ndir
            stressPower = stressPower + half * ( stressOld(km,i)
     1         + stressNew(km,i) ) * strainInc(km,i)
   40    continue
         do 50 i = ndir+1, ndir+nshr
            stressPower = stressPower + ( stressOld(km,i)
     1         + stressNew(km,i) ) * strainInc(km,i)
   50    continue
         enerInternNew(km) = enerInternOld(km) + stressPower/density(km)
         enerInelasNew(km) = enerInelasOld(km)
  100 continue
C
      return
      end
