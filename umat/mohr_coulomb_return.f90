!> Exact (non-iterative) return of a trial stress onto the Mohr–Coulomb surface in principal
!> stress space, with non-associated flow and an optional associated Rankine tension cut-off.
!>
!> This module owns the return-region logic of Clausen, Damkilde & Andersen (Comput. Struct. 85,
!> 2007; docs/theory/return_mapping.md §1.2): plane, edge σ1=σ2 (compression meridian, l1 = (1,1,k)), edge σ2=σ3
!> (extension meridian, l2 = (1,k,k)) and apex, and the cut-off regions (Rankine plane σ1 = σt,
!> Rankine edge σ1=σ2=σt, MC∩Rankine line and its two corners, Rankine apex σ = σt(1,1,1)).
!>
!> Conventions: tension positive; principal values sorted σ1 ≥ σ2 ≥ σ3 on input and output;
!> f = kσ1 − σ3 − σc ≤ 0, g = mσ1 − σ3, k = (1+sinφ)/(1−sinφ), m = (1+sinψ)/(1−sinψ),
!> σc = 2c√k, apex σa = c·cotφ. Isotropic linear elasticity (λ, G) gives the principal D.
!>
!> Guards (so that no input in the documented ranges divides by zero, and no NaN/Inf is made):
!>  * φ is clamped to [0.5°, 89.5°] inside the kernel (mc_sin_phi_min/max). φ → 0 is the Tresca
!>    limit where the apex σa = c·cotφ runs off to infinity; the material input layer rejects
!>    φ < 0.5°, the clamp only keeps the kernel finite if it is called directly.
!>  * ψ is clamped to [0, φ]; ψ = 0 is exact (m = 1 exactly, see below).
!>  * c = 0 is exact (apex at the origin).
!>  * A relative yield tolerance f ≤ tol·(k|σB1| + |σB3| + σc), tol = 1e-12, keeps stress-free
!>    and near-zero states from flipping regions on round-off. It is measured on the terms of f
!>    rather than on max|σB| + σc because f itself rounds at eps·k|σ1| (k ≈ 1.3e4 at φ = 89°);
!>    for φ ≤ 55° the two differ by less than a factor 10.
!>
!> ψ = 0: with m = 1 the dilatancy term g_d = λ(m−1) is exactly zero, and every general formula
!> below reduces *identically* to the closed forms of docs/theory/return_mapping.md §1.3 (r ∝ (1,0,−1),
!> t1 ∝ 3(p−σa)/(2+k), t2 ∝ 3(p−σa)/(1+2k)); all denominators are sums of positive terms for
!> every ψ in [0, φ] and every λ > −2G/3 (bulk modulus > 0), so no ψ = 0 branch is needed.
!>
!> Apex: the region test is Clausen's (t1 > 0 and t2 > 0). For ψ > 0 and trial states in the
!> cone of the corrector directions this is the KKT apex return; for ψ = 0 (and for small ψ with
!> trial states far on the tensile side) no plastic corrector of the flow rule can reach the
!> surface, and the apex is taken by definition ("tensile separation", docs/theory/return_mapping.md §1.3), with a
!> volumetric plastic strain even for ψ = 0.
!>
!> The plain Mohr–Coulomb path is closed form (about 10-20 ns per call) and small enough to
!> inline into a block loop. The cut-off is entered only when the Mohr–Coulomb result violates
!> σ1 ≤ σt: the Rankine return alone in closed form (about 25 ns), and only where Mohr–Coulomb is
!> active as well an active-set solve over the candidate plane sets (docs/theory/return_mapping.md §1.7).
!> mohr_coulomb_return_block is the same return on up to block_points points at once, in one
!> branch-free loop that gfortran vectorises, with the same results bit for bit (the cut-off,
!> where active, goes through the scalar routine in a second pass).
module mohr_coulomb_return
  use, intrinsic :: iso_fortran_env, only: int64
  use material_kinds, only: dp
  use principal_stress, only: block_points
  implicit none
  private

  !> Return regions (stored in SDV5 YIELD by the material layer).
  integer, parameter, public :: region_elastic = 0
  integer, parameter, public :: region_plane = 1
  integer, parameter, public :: region_edge_compression = 2   !< σ1 = σ2 (l1 = (1,1,k))
  integer, parameter, public :: region_edge_extension = 3     !< σ2 = σ3 (l2 = (1,k,k))
  integer, parameter, public :: region_apex = 4
  integer, parameter, public :: region_tension = 5            !< any set with the cut-off active

  !> Sub-regions of region_tension (output of mohr_coulomb_principal_return_detail only).
  integer, parameter, public :: cutoff_none = 0
  integer, parameter, public :: cutoff_plane = 1        !< σ1 = σt
  integer, parameter, public :: cutoff_mc_line = 2      !< σ1 = σt and kσ1 − σ3 = σc
  integer, parameter, public :: cutoff_edge = 3         !< σ1 = σ2 = σt
  integer, parameter, public :: cutoff_corner_extension = 4   !< (σt, kσt−σc, kσt−σc)
  integer, parameter, public :: cutoff_corner_compression = 5 !< (σt, σt, kσt−σc)
  integer, parameter, public :: cutoff_apex = 6         !< σ = σt(1,1,1)

  !> Relative yield tolerance: f > tol·(k|σB1| + |σB3| + σc) is plastic (the size of the terms
  !> of f; within a factor k of tol·(max|σB| + σc)), σ1 − σt > tol·max(max|σB| + σc, |σt|) for
  !> the cut-off.
  real(dp), parameter, public :: mc_yield_tolerance = 1.0e-12_dp
  !> sin(0.5°) and sin(89.5°): kernel clamp of the friction angle (Tresca / vertical limits).
  real(dp), parameter, public :: mc_sin_phi_min = 8.7265354983739347e-3_dp
  real(dp), parameter, public :: mc_sin_phi_max = 0.99996192306417131_dp

  public :: mohr_coulomb_principal_return, mohr_coulomb_principal_return_detail
  public :: mohr_coulomb_return_block

  !> Acceptance tolerance (relative to the stress scale) of a candidate active set of the
  !> cut-off solve: looser than the yield tolerance because it absorbs the round-off of a
  !> 3x3 solve, far tighter than any genuine violation.
  real(dp), parameter :: set_tolerance = 1.0e-11_dp

contains

  !> Principal-space return (the agreed API, docs/team_notes_issue2.md).
  !> sig_trial : elastic trial principal stresses, sorted descending;
  !> sin_phi, sin_psi, cohesion : current strength parameters (ψ ≤ φ);
  !> lam, shear : Lamé λ and G;
  !> tension_cutoff, sigma_t : optional Rankine cut-off σ1 ≤ σt (ignored when σt ≥ c·cotφ);
  !> sig : returned principal stresses, sorted descending; region : region_* above.
  pure subroutine mohr_coulomb_principal_return(sig_trial, sin_phi, sin_psi, cohesion, lam, &
       shear, tension_cutoff, sigma_t, sig, region)
    real(dp), intent(in) :: sig_trial(3)
    real(dp), intent(in) :: sin_phi, sin_psi, cohesion, lam, shear
    logical, intent(in) :: tension_cutoff
    real(dp), intent(in) :: sigma_t
    real(dp), intent(out) :: sig(3)
    integer, intent(out) :: region
    integer :: detail

    call mohr_coulomb_principal_return_detail(sig_trial, sin_phi, sin_psi, cohesion, lam, &
         shear, tension_cutoff, sigma_t, sig, region, detail)
  end subroutine mohr_coulomb_principal_return

  !> Same as mohr_coulomb_principal_return, plus the cut-off sub-region (cutoff_* above,
  !> cutoff_none unless region == region_tension). For tests and post-processing.
  pure subroutine mohr_coulomb_principal_return_detail(sig_trial, sin_phi, sin_psi, cohesion, &
       lam, shear, tension_cutoff, sigma_t, sig, region, detail)
    real(dp), intent(in) :: sig_trial(3)
    real(dp), intent(in) :: sin_phi, sin_psi, cohesion, lam, shear
    logical, intent(in) :: tension_cutoff
    real(dp), intent(in) :: sigma_t
    real(dp), intent(out) :: sig(3)
    integer, intent(out) :: region, detail
    real(dp) :: sp, sq, cos_phi, omk, ik, k, m, sigc, siga, scale, f, tol_f
    real(dp) :: ge, gh, gd, gdk, s1, s2, s3, n1s, n2s, q1s, q2s, t, step

    sp = min(max(sin_phi, mc_sin_phi_min), mc_sin_phi_max)
    sq = min(max(sin_psi, 0.0_dp), sp)
    cos_phi = sqrt((1.0_dp - sp) * (1.0_dp + sp))
    omk = 1.0_dp / (1.0_dp - sp)
    k = (1.0_dp + sp) * omk
    ik = (1.0_dp - sp) / (1.0_dp + sp)
    ! σc = 2c√k = 2c·cosφ/(1−sinφ); σa = σc/(k−1) = c·cosφ/sinφ (no k−1 cancellation).
    sigc = 2.0_dp * cohesion * cos_phi * omk
    siga = cohesion * cos_phi / sp
    scale = max(abs(sig_trial(1)), abs(sig_trial(3))) + sigc
    ! Tolerance on f relative to the size of its terms: evaluating kσ1 − σ3 − σc rounds at
    ! ~eps·(k|σ1| + |σ3| + σc), which for φ → 89° (k ≈ 1.3e4) is far above eps·scale.
    tol_f = mc_yield_tolerance * (k * abs(sig_trial(1)) + abs(sig_trial(3)) + sigc)
    detail = cutoff_none

    f = k * sig_trial(1) - sig_trial(3) - sigc
    if (f <= tol_f) then
       sig = sig_trial
       region = region_elastic
    else
       ! Plastic corrector directions, written with ge = 2G, gh = 2Gm, gd = λ(m−1):
       !   D b   = (gd+gh, gd, gd−ge)            (main plane, b = (m,0,−1))
       !   aᵀD b = gd(k−1) + k·gh + ge > 0
       ! Normals of the region boundaries (docs/theory/return_mapping.md §1.2, scaled by positive factors, which
       ! changes no sign and no ratio):
       !   n1 ∝ r × r2 = (ge−gd, ge−gd, 2gd+gh),   t1 = n1·s / n1·l1
       !   n2 ∝ −r × r3 = (ge−2gd, gd+gh, gd+gh),  t2 = n2·s / n2·l2
       !   q1 ∝ r × l1 = (gd(k−1)+ge, −(gd(k−1)+ge+k·gh), gh)
       !   q2 ∝ r × l2 = (k·ge, gd−ge−k(gd+gh), k(gd+gh)−gd)
       ! n1·l1 = 2ge + 2gd(k−1) + k·gh and n2·l2 = ge + 2gd(k−1) + 2k·gh are > 0 for
       ! λ > −2G/3, so the signs of t1, t2 are those of n1·s, n2·s (no division needed to
       ! choose the region).
       m = (1.0_dp + sq) / (1.0_dp - sq)
       ge = 2.0_dp * shear
       gh = ge * m
       gd = lam * (m - 1.0_dp)
       gdk = gd * (k - 1.0_dp)
       s1 = sig_trial(1) - siga
       s2 = sig_trial(2) - siga
       s3 = sig_trial(3) - siga
       n1s = (ge - gd) * (s1 + s2) + (2.0_dp * gd + gh) * s3
       n2s = (ge - 2.0_dp * gd) * s1 + (gd + gh) * (s2 + s3)
       if (n1s > 0.0_dp .and. n2s > 0.0_dp) then
          sig = siga
          region = region_apex
       else
          q1s = (gdk + ge) * s1 - (gdk + ge + k * gh) * s2 + gh * s3
          ! In the three non-apex returns σ1 is finally taken from the plane, σ1 = (σ3 + σc)/k:
          ! exact in exact arithmetic, and it puts the result on f = 0 to an ulp of σ3 instead
          ! of k ulps of σB1 (the cancellation σB1 − Δσ1 times k ≈ 1e4 at φ = 89°), so a
          ! returned stress is found elastic when it is returned again.
          if (q1s < 0.0_dp) then
             t = n1s / (2.0_dp * ge + 2.0_dp * gdk + k * gh)
             sig(3) = siga + k * t
             sig(1) = (sig(3) + sigc) * ik
             sig(2) = sig(1)
             region = region_edge_compression
          else
             q2s = k * ge * s1 + (gd - ge - k * (gd + gh)) * s2 + (k * (gd + gh) - gd) * s3
             if (q2s <= 0.0_dp) then
                step = f / (gdk + k * gh + ge)
                sig(3) = sig_trial(3) - step * (gd - ge)
                sig(1) = (sig(3) + sigc) * ik
                ! The plane return keeps the order inside its region; the clamp only absorbs
                ! a last-ulp crossing next to the edges.
                sig(2) = min(max(sig_trial(2) - step * gd, sig(3)), sig(1))
                region = region_plane
             else
                t = n2s / (ge + 2.0_dp * gdk + 2.0_dp * k * gh)
                sig(3) = siga + k * t
                sig(2) = sig(3)
                sig(1) = (sig(3) + sigc) * ik
                region = region_edge_extension
             end if
          end if
       end if
    end if

    ! Rankine cut-off: only where σt is below the apex (otherwise it can never be active) and the
    ! Mohr–Coulomb result still exceeds it. A Mohr–Coulomb KKT point that satisfies σ1 ≤ σt is
    ! also a KKT point of the combined surface, so it is kept.
    if (tension_cutoff) then
       if (sigma_t < siga .and. sig(1) - sigma_t > mc_yield_tolerance * max(scale, abs(sigma_t))) then
          ! The scale also covers σt so that it is > 0 whenever this branch is reached.
          call tension_cutoff_return(sig_trial, k, m_of(sq), sigc, sigma_t, lam, shear, &
               max(scale, abs(sigma_t), tiny(1.0_dp)), sig, detail)
          region = region_tension
       end if
    end if
  end subroutine mohr_coulomb_principal_return_detail

  !> mohr_coulomb_principal_return on n ≤ block_points points, with the same results bit for bit.
  !> sig_trial(k, :) sorted descending; sin_phi(k), sin_psi(k), cohesion(k) the strength of
  !> point k; sig(k, :), region(k) as in the scalar routine. Arrays of two dimensions have
  !> block_points rows (see principal_stress).
  !>
  !> One loop over the points without any branch, vectorised by gfortran -O3: every point
  !> evaluates the three closed forms (edge σ1=σ2, plane, edge σ2=σ3) with the scalar routine's
  !> operations, and the result of its region (or the trial state, or the apex) is selected
  !> bitwise (sign_mask, bit_select; see principal_stress): with merge() the optimiser turns the
  !> selections back into branches and moves each closed form into its own branch, and a loop
  !> with floating-point operations under a branch is not vectorised (-ftrapping-math). All divisors are positive for λ > −2G/3 (positive bulk
  !> modulus), so the closed forms that are not selected cannot trap either.
  !> The tension cut-off is a second pass: where the Mohr–Coulomb result exceeds σt, the point
  !> is returned again by the scalar routine (which applies the cut-off exactly as there).
  pure subroutine mohr_coulomb_return_block(n, sig_trial, sin_phi, sin_psi, cohesion, lam, &
       shear, tension_cutoff, sigma_t, sig, region)
    integer, intent(in) :: n
    real(dp), intent(in) :: sig_trial(block_points, 3)
    real(dp), intent(in) :: sin_phi(n), sin_psi(n), cohesion(n)
    real(dp), intent(in) :: lam, shear
    logical, intent(in) :: tension_cutoff
    real(dp), intent(in) :: sigma_t
    real(dp), intent(out) :: sig(block_points, 3)
    integer, intent(out) :: region(n)
    real(dp) :: sp, sq, cos_phi, omk, ik, k, m, sigc, siga, f, tol_f
    real(dp) :: ge, gh, gd, gdk, st1, st2, st3, s1, s2, s3, n1s, n2s, q1s, q2s
    real(dp) :: t, step, c1, c3, p1, p2, p3, e1, e3, r1, r2, r3
    integer(int64) :: plastic, apex, edge1, plane, extension
    real(dp) :: trial(3), sig3(3)
    integer :: i

    do i = 1, n
       sp = min(max(sin_phi(i), mc_sin_phi_min), mc_sin_phi_max)
       sq = min(max(sin_psi(i), 0.0_dp), sp)
       cos_phi = sqrt((1.0_dp - sp) * (1.0_dp + sp))
       omk = 1.0_dp / (1.0_dp - sp)
       k = (1.0_dp + sp) * omk
       ik = (1.0_dp - sp) / (1.0_dp + sp)
       sigc = 2.0_dp * cohesion(i) * cos_phi * omk
       siga = cohesion(i) * cos_phi / sp
       st1 = sig_trial(i, 1)
       st2 = sig_trial(i, 2)
       st3 = sig_trial(i, 3)
       tol_f = mc_yield_tolerance * (k * abs(st1) + abs(st3) + sigc)
       f = k * st1 - st3 - sigc

       m = (1.0_dp + sq) / (1.0_dp - sq)
       ge = 2.0_dp * shear
       gh = ge * m
       gd = lam * (m - 1.0_dp)
       gdk = gd * (k - 1.0_dp)
       s1 = st1 - siga
       s2 = st2 - siga
       s3 = st3 - siga
       n1s = (ge - gd) * (s1 + s2) + (2.0_dp * gd + gh) * s3
       n2s = (ge - 2.0_dp * gd) * s1 + (gd + gh) * (s2 + s3)
       q1s = (gdk + ge) * s1 - (gdk + ge + k * gh) * s2 + gh * s3
       q2s = k * ge * s1 + (gd - ge - k * (gd + gh)) * s2 + (k * (gd + gh) - gd) * s3

       ! The scalar routine's tests, exactly (a − b ≥ 0 ⇔ a ≥ b; 0 − x < 0 ⇔ x > 0;
       ! x + 0 < 0 ⇔ x < 0, −0 included):
       plastic = sign_mask(tol_f - f)                                  ! f > tol_f
       apex = iand(sign_mask(0.0_dp - n1s), sign_mask(0.0_dp - n2s))   ! n1s > 0, n2s > 0
       edge1 = sign_mask(q1s + 0.0_dp)                                 ! q1s < 0
       plane = iand(not(edge1), not(sign_mask(0.0_dp - q2s)))          ! q1s ≥ 0, q2s ≤ 0
       extension = iand(not(edge1), not(plane))

       ! The three closed forms, each with the scalar routine's operations.
       t = n1s / (2.0_dp * ge + 2.0_dp * gdk + k * gh)
       c3 = siga + k * t
       c1 = (c3 + sigc) * ik
       step = f / (gdk + k * gh + ge)
       p3 = st3 - step * (gd - ge)
       p1 = (p3 + sigc) * ik
       p2 = min(max(st2 - step * gd, p3), p1)
       t = n2s / (ge + 2.0_dp * gdk + 2.0_dp * k * gh)
       e3 = siga + k * t
       e1 = (e3 + sigc) * ik

       r1 = bit_select(edge1, c1, bit_select(plane, p1, e1))
       r2 = bit_select(edge1, c1, bit_select(plane, p2, e3))
       r3 = bit_select(edge1, c3, bit_select(plane, p3, e3))
       sig(i, 1) = bit_select(plastic, bit_select(apex, siga, r1), st1)
       sig(i, 2) = bit_select(plastic, bit_select(apex, siga, r2), st2)
       sig(i, 3) = bit_select(plastic, bit_select(apex, siga, r3), st3)
       region(i) = int(iand(plastic, ior(iand(apex, int(region_apex, int64)), iand(not(apex), &
            ior(ior(iand(edge1, int(region_edge_compression, int64)), &
            iand(plane, int(region_plane, int64))), &
            iand(extension, int(region_edge_extension, int64)))))))
    end do

    ! Rankine cut-off: a result above σt is a candidate (the scalar routine decides).
    if (.not. tension_cutoff) return
    do i = 1, n
       if (.not. sig(i, 1) > sigma_t) cycle
       trial = sig_trial(i, :)
       call mohr_coulomb_principal_return(trial, sin_phi(i), sin_psi(i), cohesion(i), lam, &
            shear, tension_cutoff, sigma_t, sig3, region(i))
       sig(i, :) = sig3
    end do
  end subroutine mohr_coulomb_return_block

  !> All ones where x has its sign bit set, zeros elsewhere (see principal_stress). A private
  !> copy, so that it is inlined into the block loop without link-time optimisation.
  elemental integer(int64) function sign_mask(x)
    real(dp), intent(in) :: x
    sign_mask = -ishft(transfer(x, 0_int64), -63)
  end function sign_mask

  !> a where mask is all ones, b where it is zero (see principal_stress; private copy).
  elemental real(dp) function bit_select(mask, a, b)
    integer(int64), intent(in) :: mask
    real(dp), intent(in) :: a, b
    bit_select = transfer(ior(iand(transfer(a, 0_int64), mask), iand(transfer(b, 0_int64), &
         not(mask))), a)
  end function bit_select

  pure real(dp) function m_of(sin_psi)
    real(dp), intent(in) :: sin_psi
    m_of = (1.0_dp + sin_psi) / (1.0_dp - sin_psi)
  end function m_of

  !> Combined Mohr–Coulomb + Rankine return in the sorted sextant (docs/theory/return_mapping.md §1.7).
  !> Planes: 1 MC main (a = (k,0,−1), b = (m,0,−1)), 2 MC σ1=σ2 side (a = (0,k,−1)),
  !> 3 MC σ2=σ3 side (a = (k,−1,0)), 4..6 Rankine σ1, σ2, σ3 ≤ σt (associated, a = b = e_i).
  !>
  !> 1. The Rankine return alone, in closed form (plane: Δλ1 = (σB1−σt)/(λ+2G); edge: the 2x2
  !>    system with determinant 4G(λ+G) > 0; else apex σt(1,1,1)). If its result satisfies
  !>    Mohr–Coulomb it is a KKT point of the combined surface and is taken: this is the usual
  !>    case (material pulled apart), and it costs a few flops.
  !> 2. Otherwise Mohr–Coulomb is active too: candidate active sets S are tried in order,
  !>    {MC,R1} (line), {MC,MC3,R1} (extension corner), the four non-singular triples of
  !>    {MC,MC2,R1,R2} (compression corner, where four planes meet), then the Rankine-only sets.
  !>    For each, Σ_j (a_iᵀ D b_j) Δλ_j = f_i(σB), i ∈ S, is solved by Cramer's rule and the set
  !>    is accepted when all Δλ_j ≥ 0 and every plane holds at the result. If round-off rejects
  !>    every set, the candidate with the smallest violation is used.
  !> Finally the active coordinates are set exactly and the result is clamped into the admissible
  !> set, so a second call finds it elastic.
  pure subroutine tension_cutoff_return(sig_trial, k, m, sigc, sigma_t, lam, shear, scale, &
       sig, detail)
    real(dp), intent(in) :: sig_trial(3), k, m, sigc, sigma_t, lam, shear, scale
    real(dp), intent(out) :: sig(3)
    integer, intent(out) :: detail
    integer, parameter :: ncand = 9
    ! Plane indices of each candidate (0 = unused) and its reported sub-region.
    integer, parameter :: sets(3, ncand) = reshape([ &
         1, 4, 0, &
         1, 3, 4, &
         1, 2, 4, &
         1, 4, 5, &
         2, 4, 5, &
         1, 2, 5, &
         4, 0, 0, &
         4, 5, 0, &
         4, 5, 6], [3, ncand])
    integer, parameter :: set_detail(ncand) = [cutoff_mc_line, cutoff_corner_extension, &
         cutoff_corner_compression, cutoff_corner_compression, cutoff_corner_compression, &
         cutoff_corner_compression, cutoff_plane, cutoff_edge, cutoff_apex]
    real(dp) :: a(3, 6), db(3, 6), rhs(6), trial_sig(3), viol, best_viol
    real(dp) :: mp, e1, e2, d1, det, dl1, dl2, s3
    integer :: ic

    ! 1. Rankine alone.
    mp = lam + 2.0_dp * shear
    e1 = sig_trial(1) - sigma_t
    e2 = sig_trial(2) - sigma_t
    d1 = e1 / mp
    if (e2 - lam * d1 <= 0.0_dp) then
       sig = [sigma_t, sig_trial(2) - lam * d1, sig_trial(3) - lam * d1]
       detail = cutoff_plane
    else
       det = 4.0_dp * shear * (lam + shear)
       dl1 = (mp * e1 - lam * e2) / det
       dl2 = (mp * e2 - lam * e1) / det
       s3 = sig_trial(3) - lam * (dl1 + dl2)
       if (s3 <= sigma_t) then
          sig = [sigma_t, sigma_t, s3]
          detail = cutoff_edge
       else
          sig = sigma_t
          detail = cutoff_apex
       end if
    end if

    ! 2. Mohr–Coulomb violated there: active-set search including the Mohr–Coulomb planes.
    if (k * sig(1) - sig(3) - sigc > set_tolerance * scale) then
       a(:, 1) = [k, 0.0_dp, -1.0_dp]
       a(:, 2) = [0.0_dp, k, -1.0_dp]
       a(:, 3) = [k, -1.0_dp, 0.0_dp]
       a(:, 4) = [1.0_dp, 0.0_dp, 0.0_dp]
       a(:, 5) = [0.0_dp, 1.0_dp, 0.0_dp]
       a(:, 6) = [0.0_dp, 0.0_dp, 1.0_dp]
       db(:, 1) = elastic_principal(lam, shear, [m, 0.0_dp, -1.0_dp])
       db(:, 2) = elastic_principal(lam, shear, [0.0_dp, m, -1.0_dp])
       db(:, 3) = elastic_principal(lam, shear, [m, -1.0_dp, 0.0_dp])
       db(:, 4) = elastic_principal(lam, shear, a(:, 4))
       db(:, 5) = elastic_principal(lam, shear, a(:, 5))
       db(:, 6) = elastic_principal(lam, shear, a(:, 6))
       rhs(1:3) = sigc
       rhs(4:6) = sigma_t
       best_viol = huge(1.0_dp)
       do ic = 1, ncand
          call try_active_set(sets(:, ic), a, db, rhs, sig_trial, scale, trial_sig, viol)
          if (viol < best_viol) then
             best_viol = viol
             sig = trial_sig
             detail = set_detail(ic)
          end if
          if (viol <= set_tolerance) exit
       end do
    end if

    ! Exact coordinates of the active planes (the solves reproduce them to rounding only).
    sig(1) = sigma_t
    select case (detail)
    case (cutoff_mc_line)
       sig(3) = k * sigma_t - sigc
    case (cutoff_edge)
       sig(2) = sigma_t
    case (cutoff_corner_extension)
       sig(3) = k * sigma_t - sigc
       sig(2) = sig(3)
    case (cutoff_corner_compression)
       sig(2) = sigma_t
       sig(3) = k * sigma_t - sigc
    case (cutoff_apex)
       sig(2) = sigma_t
       sig(3) = sigma_t
    end select
    ! Make the result admissible to the last bit, whatever set was accepted within
    ! set_tolerance: with σ1 = σt, kσ1 − σ3 ≤ σc is σ3 ≥ kσt − σc, and σt ≥ σ2 ≥ σ3 then
    ! satisfies the other five planes. A second call therefore finds the point elastic.
    sig(3) = min(max(sig(3), k * sigma_t - sigc), sigma_t)
    sig(2) = min(max(sig(2), sig(3)), sig(1))
  end subroutine tension_cutoff_return

  !> Solve one candidate active set; viol = largest relative violation of (Δλ ≥ 0, f ≤ 0), ≤ 0
  !> for an acceptable set, huge for a singular system.
  pure subroutine try_active_set(set, a, db, rhs, sig_trial, scale, sig, viol)
    integer, intent(in) :: set(3)
    real(dp), intent(in) :: a(3, 6), db(3, 6), rhs(6), sig_trial(3), scale
    real(dp), intent(out) :: sig(3), viol
    real(dp) :: mat(3, 3), f(3), dl(3), det
    integer :: n, i, j

    n = count(set > 0)
    mat = 0.0_dp
    do j = 1, 3
       mat(j, j) = 1.0_dp
    end do
    f = 0.0_dp
    do i = 1, n
       f(i) = dot_product(a(:, set(i)), sig_trial) - rhs(set(i))
       do j = 1, n
          mat(i, j) = dot_product(a(:, set(i)), db(:, set(j)))
       end do
    end do
    ! Cramer's rule on the padded 3x3 system (identity outside the active block).
    ! Singular (or nearly so) relative to the row sizes: not a usable set.
    det = det3(mat)
    if (abs(det) <= 1.0e-12_dp * maxval(abs(mat(1, :))) * maxval(abs(mat(2, :))) &
         * maxval(abs(mat(3, :)))) then
       sig = sig_trial
       viol = huge(1.0_dp)
       return
    end if
    dl(1) = det3(reshape([f, mat(:, 2), mat(:, 3)], [3, 3])) / det
    dl(2) = det3(reshape([mat(:, 1), f, mat(:, 3)], [3, 3])) / det
    dl(3) = det3(reshape([mat(:, 1), mat(:, 2), f], [3, 3])) / det
    sig = sig_trial
    viol = -huge(1.0_dp)
    do j = 1, n
       sig = sig - dl(j) * db(:, set(j))
       ! Multiplier sign, measured as the stress it moves (so it compares with scale).
       viol = max(viol, -dl(j) * maxval(abs(db(:, set(j)))) / scale)
    end do
    do i = 1, 6
       viol = max(viol, (dot_product(a(:, i), sig) - rhs(i)) / scale)
    end do
  end subroutine try_active_set

  pure function elastic_principal(lam, shear, b) result(db)
    real(dp), intent(in) :: lam, shear, b(3)
    real(dp) :: db(3)
    db = lam * (b(1) + b(2) + b(3)) + 2.0_dp * shear * b
  end function elastic_principal

  pure real(dp) function det3(x)
    real(dp), intent(in) :: x(3, 3)
    det3 = x(1, 1) * (x(2, 2) * x(3, 3) - x(2, 3) * x(3, 2)) &
         - x(1, 2) * (x(2, 1) * x(3, 3) - x(2, 3) * x(3, 1)) &
         + x(1, 3) * (x(2, 1) * x(3, 2) - x(2, 2) * x(3, 1))
  end function det3

end module mohr_coulomb_return
