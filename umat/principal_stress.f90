!> Spectral decomposition of symmetric stress (or strain) tensors for the principal-space
!> material returns, and the inverse rotation back to the component basis.
!>
!> This module owns:
!>   * principal_plane / rebuild_plane  — plane strain (components 11,22,33,12; 33 is principal);
!>   * principal_3d    / rebuild_3d     — 3D (components 11,22,33,12,23,31, the VUMAT order);
!>   * *_block versions of all four    — the same on up to block_points points at once, one
!>     branch-free loop over the points that gfortran vectorises (see "Block versions" below),
!>     with the same results bit for bit.
!> Principal values come out sorted σ1 ≥ σ2 ≥ σ3 (tension positive, σ3 most compressive).
!> The rebuild routines accept *any* diagonal values in the stored basis, so they also rotate
!> principal plastic strains back (tensor shear components, like the stresses).
!>
!> Everything is pure, branch-light (merge() selections, no sort loops, no acos/cos) and has
!> explicit-shape dummies only, so that gfortran -O3 can inline it into a block loop over
!> material points. No routine divides by zero: zero, isotropic and repeated-root tensors are
!> handled explicitly, and magnitudes far from 1 (|s| < 1e-100 or > 1e100 in 3D, deviator
!> outside [1e-150, 1e150] in the plane) are scaled by exact powers of two first.
!>
!> Accuracy: rebuild(principal(s)) reproduces s to a few ulp of max|s_ij| (≤ ~2e-15 relative
!> over 2·10^6 random tensors incl. double, triple and nearly repeated roots and magnitudes
!> 1e-150..1e150; unit tests ask for 1e-13), eigenvectors are orthonormal to ~1.5e-15.
!> Cost (gfortran 12 -O3, not inlined, one AMD EPYC core): principal_plane ≈ 10 ns,
!> principal_3d ≈ 95 ns; the 3D time is the latency of its sqrt/div chain. The block versions
!> work on two points per SSE2 instruction and overlap the chains of successive points:
!> principal_3d_block costs about half of principal_3d per point, principal_plane_block a
!> few ns (measured on a busy machine, so indicative only).
module principal_stress
  use, intrinsic :: iso_fortran_env, only: int64
  use material_kinds, only: dp
  implicit none
  private

  public :: principal_plane, rebuild_plane, principal_3d, rebuild_3d
  public :: principal_plane_block, rebuild_plane_block, principal_3d_block, rebuild_3d_block

  !> Rows of the work arrays of the block routines: they take n ≤ block_points points in
  !> arrays dimensioned (block_points, ...). A constant leading dimension lets the compiler see
  !> that the columns never overlap; with a run-time one it would need more alias checks than
  !> it allows and would not vectorise. 64 points keep a chunk's work arrays in L1.
  integer, parameter, public :: block_points = 64

  !> Absolute floor of the deviator size p in principal_3d_core: below it the tensor is treated
  !> as isotropic, which keeps 1/p finite (inputs there are pre-scaled to max|s_ij| ≥ 1e-100, so
  !> only an exactly or nearly isotropic tensor can get this low).
  real(dp), parameter :: radius_floor = sqrt(tiny(1.0_dp))

contains

  !> Principal stresses of a plane-strain tensor s = (11, 22, 33, 12).
  !> sig   : sorted descending (σ1 ≥ σ2 ≥ σ3);
  !> c, sn : cosine and sine of the angle θ from x to the major *in-plane* principal direction
  !>         (eigenvector (c, sn, 0) belongs to the larger in-plane value σa);
  !> izz   : slot of the out-of-plane value s33 in sig (1, 2 or 3). The in-plane values σa ≥ σb
  !>         fill the other two slots in that order.
  pure subroutine principal_plane(s, sig, c, sn, izz)
    real(dp), intent(in) :: s(4)
    real(dp), intent(out) :: sig(3)
    real(dp), intent(out) :: c, sn
    integer, intent(out) :: izz
    real(dp) :: sa, sb, szz

    call sym2_eigen(s(1), s(2), s(4), sa, sb, c, sn)
    szz = s(3)
    ! Three values with sa >= sb already known: two compares place szz.
    if (szz >= sa) then
       sig(1) = szz
       sig(2) = sa
       sig(3) = sb
       izz = 1
    else if (szz >= sb) then
       sig(1) = sa
       sig(2) = szz
       sig(3) = sb
       izz = 2
    else
       sig(1) = sa
       sig(2) = sb
       sig(3) = szz
       izz = 3
    end if
  end subroutine principal_plane

  !> Inverse of principal_plane: s = σa e_a⊗e_a + σb e_b⊗e_b + σzz e_z⊗e_z with the stored
  !> angle (c, sn) and slot izz. Works for any three values in that basis (e.g. principal plastic
  !> strains), not only for sorted ones; s(4) is the tensor shear component.
  pure subroutine rebuild_plane(sig, c, sn, izz, s)
    real(dp), intent(in) :: sig(3)
    real(dp), intent(in) :: c, sn
    integer, intent(in) :: izz
    real(dp), intent(out) :: s(4)
    real(dp) :: sa, sb, szz, cc, ss

    select case (izz)
    case (1)
       szz = sig(1)
       sa = sig(2)
       sb = sig(3)
    case (2)
       sa = sig(1)
       szz = sig(2)
       sb = sig(3)
    case default
       sa = sig(1)
       sb = sig(2)
       szz = sig(3)
    end select
    cc = c * c
    ss = sn * sn
    s(1) = sa * cc + sb * ss
    s(2) = sa * ss + sb * cc
    s(3) = szz
    s(4) = (sa - sb) * c * sn
  end subroutine rebuild_plane

  !> Principal values and unit eigenvectors of a symmetric 3x3 tensor s = (11,22,33,12,23,31).
  !> sig sorted descending; vec(:, i) is the unit eigenvector of sig(i); the triad is
  !> orthonormal (its handedness is not fixed).
  !>
  !> Method (non-iterative apart from one fixed Newton step, robust for repeated roots):
  !>  1. shift by the mean q and scale the deviator by p = sqrt(tr(B²)/6): the scaled deviator
  !>     C has eigenvalues 2cos(·) in [-2, 2] and no overflow/underflow can occur;
  !>  2. the root of μ³ − 3μ − 2r = 0 (r = det C / 2) that is *separated* from the other two —
  !>     the largest for r ≥ 0, the smallest for r < 0 — lies at least √3 away from both others.
  !>     It is the trigonometric root ±2cos(acos|r|/3), evaluated here without acos/cos: a
  !>     degree-8 fit in |r| (error < 1e-8) and one Newton step give it to an ulp (f' ≥ 6);
  !>  3. its eigenvector is the largest cross product of two rows of C − μI (squared norm ≥ 3
  !>     in exact arithmetic), accurate to ~ulp whatever the other two roots do;
  !>  4. C is projected exactly onto the plane orthogonal to that vector and the 2x2 problem is
  !>     solved in closed form (exact for double roots); the separated value follows from the
  !>     trace. Because C is projected onto the computed triad, the reconstruction error stays at
  !>     rounding level even when two roots nearly coincide, where the cubic formula alone would
  !>     lose half the digits of the close pair.
  !> Isotropic tensors (deviator at rounding level of the mean) return the identity triad.
  !> The selections use merge() so that gfortran emits blends instead of unpredictable branches.
  !> Tensors with max|s_ij| outside [1e-100, 1e100] are first scaled by an exact power of two,
  !> so squares and cubes of their components can neither underflow nor overflow.
  pure subroutine principal_3d(s, sig, vec)
    real(dp), intent(in) :: s(6)
    real(dp), intent(out) :: sig(3)
    real(dp), intent(out) :: vec(3, 3)
    real(dp) :: amax, sc(6)
    integer :: e

    ! One call site, so that an inlining caller gets one copy of the core; scale() is exact and
    ! only runs on the rare path.
    amax = max(abs(s(1)), abs(s(2)), abs(s(3)), abs(s(4)), abs(s(5)), abs(s(6)))
    sc = s
    e = 0
    if (.not. (amax > 1.0e-100_dp .and. amax < 1.0e100_dp)) then
       e = exponent(amax)
       sc = scale(s, -e)
    end if
    call principal_3d_core(sc, sig, vec)
    if (e /= 0) sig = scale(sig, e)
  end subroutine principal_3d

  !> principal_3d for max|s_ij| in [1e-100, 1e100] (see principal_3d).
  pure subroutine principal_3d_core(s, sig, vec)
    real(dp), intent(in) :: s(6)
    real(dp), intent(out) :: sig(3)
    real(dp), intent(out) :: vec(3, 3)
    ! Degree-8 fit of 2cos(acos(ρ)/3) on [0, 1] (Chebyshev least squares, max error 8.6e-9;
    ! one Newton step then lands within an ulp).
    real(dp), parameter :: f0 = 1.7320508160829569_dp, f1 = 0.33333253539506985_dp
    real(dp), parameter :: f2 = -0.09620655020681854_dp, f3 = 0.04919767526830958_dp
    real(dp), parameter :: f4 = -0.030190554045480565_dp, f5 = 0.01874415728341634_dp
    real(dp), parameter :: f6 = -0.009859042862492647_dp, f7 = 0.0035427520895337217_dp
    real(dp), parameter :: f8 = -0.0006117952499170653_dp
    real(dp), parameter :: third = 1.0_dp / 3.0_dp
    real(dp) :: q, b11, b22, b33, p2, p, ip
    real(dp) :: c11, c22, c33, c12, c23, c13, r, rho, rho2, rho4, mu, mm
    real(dp) :: x01(3), x02(3), x12(3), n01, n02, n12, x(3), nx, inv_x, inv_u, v(3), u(3), w(3)
    real(dp) :: cu(3), cw(3), a11, a22, a12, mu_a, mu_b, cs, sn, mu_s, ea(3), eb(3)
    logical :: top

    q = (s(1) + s(2) + s(3)) * third
    b11 = s(1) - q
    b22 = s(2) - q
    b33 = s(3) - q
    p2 = (b11 * b11 + b22 * b22 + b33 * b33 &
         + 2.0_dp * (s(4) * s(4) + s(5) * s(5) + s(6) * s(6))) * (1.0_dp / 6.0_dp)
    ! Isotropic (incl. zero) tensor: every triad is a valid eigenbasis. The threshold is
    ! ulp-level relative to the mean plus an absolute floor that keeps 1/p finite.
    if (p2 <= max(radius_floor**2, (4.0_dp * epsilon(1.0_dp) * q)**2)) then
       sig = q
       vec = 0.0_dp
       vec(1, 1) = 1.0_dp
       vec(2, 2) = 1.0_dp
       vec(3, 3) = 1.0_dp
       return
    end if
    p = sqrt(p2)
    ip = 1.0_dp / p
    c11 = b11 * ip
    c22 = b22 * ip
    c33 = b33 * ip
    c12 = s(4) * ip
    c23 = s(5) * ip
    c13 = s(6) * ip

    ! r = det(C)/2 = cos(3φ); clamp the rounding excursions beyond ±1.
    r = 0.5_dp * (c11 * (c22 * c33 - c23 * c23) - c12 * (c12 * c33 - c23 * c13) &
         + c13 * (c12 * c23 - c22 * c13))
    rho = min(abs(r), 1.0_dp)
    ! Estrin's scheme keeps the polynomial's dependency chain short.
    rho2 = rho * rho
    rho4 = rho2 * rho2
    mu = ((f0 + f1 * rho) + (f2 + f3 * rho) * rho2) &
         + ((f4 + f5 * rho) + (f6 + f7 * rho) * rho2) * rho4 + f8 * (rho4 * rho4)
    mm = mu * mu
    mu = mu - (mu * (mm - 3.0_dp) - 2.0_dp * rho) / (3.0_dp * (mm - 1.0_dp))
    ! The smallest root for r < 0 is the mirror image of the largest root for |r|.
    top = r >= 0.0_dp
    mu = merge(mu, -mu, top)

    ! Rows of C − μI and their cross products; the largest is the separated eigenvector.
    x01 = cross(c11 - mu, c12, c13, c12, c22 - mu, c23)
    x02 = cross(c11 - mu, c12, c13, c13, c23, c33 - mu)
    x12 = cross(c12, c22 - mu, c23, c13, c23, c33 - mu)
    n01 = dot_product(x01, x01)
    n02 = dot_product(x02, x02)
    n12 = dot_product(x12, x12)
    x = merge(x01, merge(x02, x12, n02 >= n12), n01 >= max(n02, n12))
    nx = max(n01, n02, n12)
    if (.not. nx > 1.0e-6_dp) then
       ! Unreachable for finite input (nx ≥ 3 in exact arithmetic); no path divides by zero.
       x = [1.0_dp, 0.0_dp, 0.0_dp]
       nx = 1.0_dp
    end if
    ! Orthonormal triad (v, u, w). u is built from the unnormalised x (its larger pair of
    ! components keeps |u|² ≥ |x|²/2), so the two normalisations run in parallel.
    u = merge([-x(3), 0.0_dp, x(1)], [0.0_dp, x(3), -x(2)], abs(x(1)) > abs(x(2)))
    w = cross(x(1), x(2), x(3), u(1), u(2), u(3))
    inv_x = 1.0_dp / sqrt(nx)
    inv_u = 1.0_dp / sqrt(dot_product(u, u))
    v = x * inv_x
    w = w * (inv_x * inv_u)
    u = u * inv_u

    ! Exact projection of C on (u, w); the separated value from the trace.
    cu = matvec(c11, c22, c33, c12, c23, c13, u)
    cw = matvec(c11, c22, c33, c12, c23, c13, w)
    a11 = dot_product(u, cu)
    a22 = dot_product(w, cw)
    a12 = dot_product(u, cw)
    mu_s = (c11 + c22 + c33) - a11 - a22
    call sym2_eigen(a11, a22, a12, mu_a, mu_b, cs, sn)
    ea = cs * u + sn * w
    eb = cs * w - sn * u

    ! The separated root is the largest (r ≥ 0) or the smallest (r < 0) with a gap ≥ √3 to the
    ! others, so its position needs no comparison.
    sig(1) = q + p * merge(mu_s, mu_a, top)
    sig(2) = q + p * merge(mu_a, mu_b, top)
    sig(3) = q + p * merge(mu_b, mu_s, top)
    vec(:, 1) = merge(v, ea, top)
    vec(:, 2) = merge(ea, eb, top)
    vec(:, 3) = merge(eb, v, top)
  end subroutine principal_3d_core

  !> Inverse of principal_3d: s = Σ_i sig(i) vec(:,i)⊗vec(:,i), components (11,22,33,12,23,31).
  !> Any diagonal values in the basis vec are accepted (principal plastic strains included).
  pure subroutine rebuild_3d(sig, vec, s)
    real(dp), intent(in) :: sig(3)
    real(dp), intent(in) :: vec(3, 3)
    real(dp), intent(out) :: s(6)
    real(dp) :: a(3), b(3), cc(3)

    a = sig(1) * vec(:, 1)
    b = sig(2) * vec(:, 2)
    cc = sig(3) * vec(:, 3)
    s(1) = a(1) * vec(1, 1) + b(1) * vec(1, 2) + cc(1) * vec(1, 3)
    s(2) = a(2) * vec(2, 1) + b(2) * vec(2, 2) + cc(2) * vec(2, 3)
    s(3) = a(3) * vec(3, 1) + b(3) * vec(3, 2) + cc(3) * vec(3, 3)
    s(4) = a(1) * vec(2, 1) + b(1) * vec(2, 2) + cc(1) * vec(2, 3)
    s(5) = a(2) * vec(3, 1) + b(2) * vec(3, 2) + cc(2) * vec(3, 3)
    s(6) = a(3) * vec(1, 1) + b(3) * vec(1, 2) + cc(3) * vec(1, 3)
  end subroutine rebuild_3d

  !> Closed-form eigen-pair of the symmetric 2x2 matrix [[a11, a12], [a12, a22]]:
  !> mu_a ≥ mu_b, (c, sn) the unit eigenvector of mu_a. With d = (a11 − a22)/2 and
  !> ρ = sqrt(d² + a12²) that eigenvector is (d + ρ, a12) for d ≥ 0 and (a12, ρ − d) for d < 0;
  !> both are written with t = |d| + ρ, whose squared norm t² + a12² = 2ρ(ρ + |d|) suffers no
  !> cancellation, so c² + sn² = 1 to rounding without atan2/cos/sin. A double root keeps the
  !> current axes. Deviators outside [1e-150, 1e150] are scaled by an exact power of two first
  !> (rare, predictable branch), so d² + a12² never underflows or overflows.
  pure subroutine sym2_eigen(a11, a22, a12, mu_a, mu_b, c, sn)
    real(dp), intent(in) :: a11, a22, a12
    real(dp), intent(out) :: mu_a, mu_b, c, sn
    real(dp) :: mid, d, o, amax, rho, rs, t, inv
    integer :: e
    logical :: pos
    mid = 0.5_dp * (a11 + a22)
    d = 0.5_dp * (a11 - a22)
    o = a12
    amax = max(abs(d), abs(o))
    if (amax > 1.0e-150_dp .and. amax < 1.0e150_dp) then
       rho = sqrt(d * d + o * o)
       t = abs(d) + rho
    else if (amax > 0.0_dp) then
       e = exponent(amax)
       t = scale(abs(d), -e)
       o = scale(o, -e)
       rs = sqrt(t * t + o * o)
       rho = scale(rs, e)
       t = t + rs
    else
       rho = 0.0_dp
       t = 1.0_dp
    end if
    mu_a = mid + rho
    mu_b = mid - rho
    inv = 1.0_dp / sqrt(t * t + o * o)
    pos = d >= 0.0_dp
    c = merge(t, o, pos) * inv
    sn = merge(o, t, pos) * inv
  end subroutine sym2_eigen

  ! ---------------------------------------------------------------------------------------------
  ! Block versions: the same algorithms on n points at once, in the layout of the VUMAT arrays
  ! (point index first, unit stride), with the same results bit for bit (same operations in the
  ! same order; no FMA: -ffp-contract=off). Each routine is one loop over the points without
  ! any branch, so that gfortran -O3 vectorises it across points:
  !  * selections are bitwise (sign_mask, bit_select): the sign bit of a difference decides,
  !    and integer masks pick the bits. merge() would also be branch-free in the source, but
  !    the optimiser turns merges back into branches and moves the arithmetic that follows
  !    them into those branches; under the default -ftrapping-math a floating-point operation
  !    under a branch stops the vectoriser. (rebuild_plane_block keeps merge() for its
  !    selections by slot number: they pick loaded values, which is safe, and vectorises.)
  !  * every point evaluates every case (the special cases too), so the operands of sqrt and of
  !    the divisions are guarded (a floor, or a substitute value for the case that is not
  !    taken) and no lane, used or not, can trap in the debug build.
  ! Two-dimensional arrays have block_points rows, of which the first n ≤ block_points are used,
  ! so that a caller keeps fixed-size work arrays and passes a shorter last chunk without a copy.
  ! The only results that may differ from the scalar routines, in the last bits, are those of
  ! tensors whose size is outside [1e-100, 1e100] (3D), whose in-plane deviator is outside
  ! [1e-150, 1e150], or (3D) whose close pair of roots differs by less than 1e-150 of the
  ! deviator without being equal: the block routines scale these by fixed powers of two instead
  ! of exponent-dependent ones, which can change a result only where a square underflows.
  ! ---------------------------------------------------------------------------------------------

  !> principal_plane on n points: s(k, 1:4) = (11, 22, 33, 12) of point k; sig(k, :) sorted
  !> descending, (c(k), sn(k)) the in-plane angle, izz(k) the slot of s33 (see principal_plane).
  pure subroutine principal_plane_block(n, s, sig, c, sn, izz)
    integer, intent(in) :: n
    real(dp), intent(in) :: s(block_points, 4)
    real(dp), intent(out) :: sig(block_points, 3)
    real(dp), intent(out) :: c(n), sn(n)
    integer, intent(out) :: izz(n)
    real(dp), parameter :: up = 2.0_dp**600, down = 2.0_dp**(-600), t_floor = 2.0_dp**(-504)
    real(dp) :: sa, sb, szz, mid, d, o, amax, f, g, rs, rho, t, inv
    integer(int64) :: small, large, pos, above_a, above_b
    integer :: k

    do k = 1, n
       ! In-plane eigen-pair: the operations of sym2_eigen, without branch (see above); the
       ! deviator is scaled by 2 (exact) or, outside [1e-150, 1e150], by 2^±600 (into
       ! [1e-143, 1e128]); t_floor, below every non-zero t, makes a double root keep the axes.
       mid = 0.5_dp * (s(k, 1) + s(k, 2))
       d = 0.5_dp * (s(k, 1) - s(k, 2))
       amax = max(abs(d), abs(s(k, 4)))
       small = not(sign_mask(1.0e-150_dp - amax))     ! amax ≤ 1e-150
       large = not(sign_mask(amax - 1.0e150_dp))      ! amax ≥ 1e150
       f = bit_select(small, up, bit_select(large, down, 2.0_dp))
       g = bit_select(small, down, bit_select(large, up, 0.5_dp))
       t = abs(d) * f
       o = s(k, 4) * f
       rs = sqrt(t * t + o * o)
       rho = rs * g
       t = max(t + rs, t_floor)
       sa = mid + rho
       sb = mid - rho
       inv = 1.0_dp / sqrt(t * t + o * o)
       t = t * inv
       o = o * inv
       pos = not(sign_mask(d + 0.0_dp))               ! d ≥ 0 (−0 included)
       c(k) = bit_select(pos, t, o)
       sn(k) = bit_select(pos, o, t)

       szz = s(k, 3)
       ! szz ≥ sa, szz ≥ sb (the second follows from the first, sa ≥ sb).
       above_a = not(sign_mask(szz - sa))
       above_b = not(sign_mask(szz - sb))
       sig(k, 1) = bit_select(above_a, szz, sa)
       sig(k, 2) = bit_select(above_a, sa, bit_select(above_b, szz, sb))
       sig(k, 3) = bit_select(above_b, sb, szz)
       ! 1, 2 or 3 (the masks are −1 or 0).
       izz(k) = int(3_int64 + above_a + above_b)
    end do
  end subroutine principal_plane_block

  !> rebuild_plane on n points (any three values per point in the stored basis).
  pure subroutine rebuild_plane_block(n, sig, c, sn, izz, s)
    integer, intent(in) :: n
    real(dp), intent(in) :: sig(block_points, 3)
    real(dp), intent(in) :: c(n), sn(n)
    integer, intent(in) :: izz(n)
    real(dp), intent(out) :: s(block_points, 4)
    real(dp) :: s1, s2, s3, sa, sb, szz, cc, ss
    integer :: k

    do k = 1, n
       ! Unconditional loads, then selections of the loaded values only.
       s1 = sig(k, 1)
       s2 = sig(k, 2)
       s3 = sig(k, 3)
       szz = merge(s1, merge(s2, s3, izz(k) == 2), izz(k) == 1)
       sa = merge(s2, s1, izz(k) == 1)
       sb = merge(s2, s3, izz(k) == 3)
       cc = c(k) * c(k)
       ss = sn(k) * sn(k)
       s(k, 1) = sa * cc + sb * ss
       s(k, 2) = sa * ss + sb * cc
       s(k, 3) = szz
       s(k, 4) = (sa - sb) * c(k) * sn(k)
    end do
  end subroutine rebuild_plane_block

  !> principal_3d on n points: s(k, 1:6) = (11,22,33,12,23,31) of point k; sig(k, :) sorted
  !> descending; vec(k, :, i) the unit eigenvector of sig(k, i). The method and the results
  !> are those of principal_3d (see principal_3d_core); its special cases become:
  !>  * size: max|s_ij| outside [1e-100, 1e100] is scaled by a fixed power of two (2^704
  !>    below, 2^-678 above) into [1e-112, 1e112], where no square under- or overflows, and
  !>    the values scaled back at the end; sizes inside are scaled by 2, which is exact and
  !>    changes no result bit (it keeps 1.0 out of the selection);
  !>  * isotropic tensors: C = 0 meanwhile (finite throughout), then sig = q and the identity;
  !>  * the (unreachable) tiny cross product: x = (1, 0, 0), as in principal_3d_core.
  pure subroutine principal_3d_block(n, s, sig, vec)
    integer, intent(in) :: n
    real(dp), intent(in) :: s(block_points, 6)
    real(dp), intent(out) :: sig(block_points, 3)
    real(dp), intent(out) :: vec(block_points, 3, 3)
    ! Degree-8 fit of 2cos(acos(ρ)/3) on [0, 1] (as in principal_3d_core).
    real(dp), parameter :: f0 = 1.7320508160829569_dp, f1 = 0.33333253539506985_dp
    real(dp), parameter :: f2 = -0.09620655020681854_dp, f3 = 0.04919767526830958_dp
    real(dp), parameter :: f4 = -0.030190554045480565_dp, f5 = 0.01874415728341634_dp
    real(dp), parameter :: f6 = -0.009859042862492647_dp, f7 = 0.0035427520895337217_dp
    real(dp), parameter :: f8 = -0.0006117952499170653_dp
    real(dp), parameter :: third = 1.0_dp / 3.0_dp
    real(dp), parameter :: scale_up = 2.0_dp**704, scale_down = 2.0_dp**(-678)
    real(dp), parameter :: up2 = 2.0_dp**600, down2 = 2.0_dp**(-600), t_floor = 2.0_dp**(-504)
    real(dp) :: s1, s2, s3, s4, s5, s6, amax, sf, isf, q, b11, b22, b33, p2, p, ip
    real(dp) :: c11, c22, c33, c12, c23, c13, r, rho, rho2, rho4, mu, mm
    real(dp) :: x01_1, x01_2, x01_3, x02_1, x02_2, x02_3, x12_1, x12_2, x12_3, n01, n02, n12
    real(dp) :: x1, x2, x3, nx, u1, u2, u3, w1, w2, w3, v1, v2, v3, inv_x, inv_u
    real(dp) :: cu1, cu2, cu3, cw1, cw2, cw3, a11, a22, a12, mu_a, mu_b, cs, sn, mu_s
    real(dp) :: ea1, ea2, ea3, eb1, eb2, eb3, mid, d, o, f, g, rs, t, inv
    integer(int64) :: small, large, iso, top, pick01, pick02, big, first, pos
    integer :: k

    do k = 1, n
       amax = max(abs(s(k, 1)), abs(s(k, 2)), abs(s(k, 3)), abs(s(k, 4)), abs(s(k, 5)), &
            abs(s(k, 6)))
       small = not(sign_mask(1.0e-100_dp - amax))     ! amax ≤ 1e-100
       large = not(sign_mask(amax - 1.0e100_dp))      ! amax ≥ 1e100
       sf = bit_select(small, scale_up, bit_select(large, scale_down, 2.0_dp))
       isf = bit_select(small, 1.0_dp / scale_up, bit_select(large, 1.0_dp / scale_down, 0.5_dp))
       s1 = s(k, 1) * sf
       s2 = s(k, 2) * sf
       s3 = s(k, 3) * sf
       s4 = s(k, 4) * sf
       s5 = s(k, 5) * sf
       s6 = s(k, 6) * sf

       q = (s1 + s2 + s3) * third
       b11 = s1 - q
       b22 = s2 - q
       b33 = s3 - q
       p2 = (b11 * b11 + b22 * b22 + b33 * b33 &
            + 2.0_dp * (s4 * s4 + s5 * s5 + s6 * s6)) * (1.0_dp / 6.0_dp)
       iso = not(sign_mask(max(radius_floor**2, (4.0_dp * epsilon(1.0_dp) * q)**2) - p2))
       p = sqrt(p2)
       ip = bit_select(iso, 0.0_dp, 1.0_dp / max(p, radius_floor))
       c11 = b11 * ip
       c22 = b22 * ip
       c33 = b33 * ip
       c12 = s4 * ip
       c23 = s5 * ip
       c13 = s6 * ip

       r = 0.5_dp * (c11 * (c22 * c33 - c23 * c23) - c12 * (c12 * c33 - c23 * c13) &
            + c13 * (c12 * c23 - c22 * c13))
       rho = min(abs(r), 1.0_dp)
       rho2 = rho * rho
       rho4 = rho2 * rho2
       mu = ((f0 + f1 * rho) + (f2 + f3 * rho) * rho2) &
            + ((f4 + f5 * rho) + (f6 + f7 * rho) * rho2) * rho4 + f8 * (rho4 * rho4)
       mm = mu * mu
       mu = mu - (mu * (mm - 3.0_dp) - 2.0_dp * rho) / (3.0_dp * (mm - 1.0_dp))
       top = not(sign_mask(r + 0.0_dp))               ! r ≥ 0 (−0 included)
       mu = bit_select(top, mu, -mu)

       ! Cross products of the rows of C − μI; the largest is the separated eigenvector.
       x01_1 = c12 * c23 - c13 * (c22 - mu)
       x01_2 = c13 * c12 - (c11 - mu) * c23
       x01_3 = (c11 - mu) * (c22 - mu) - c12 * c12
       x02_1 = c12 * (c33 - mu) - c13 * c23
       x02_2 = c13 * c13 - (c11 - mu) * (c33 - mu)
       x02_3 = (c11 - mu) * c23 - c12 * c13
       x12_1 = (c22 - mu) * (c33 - mu) - c23 * c23
       x12_2 = c23 * c13 - c12 * (c33 - mu)
       x12_3 = c12 * c23 - (c22 - mu) * c13
       n01 = x01_1 * x01_1 + x01_2 * x01_2 + x01_3 * x01_3
       n02 = x02_1 * x02_1 + x02_2 * x02_2 + x02_3 * x02_3
       n12 = x12_1 * x12_1 + x12_2 * x12_2 + x12_3 * x12_3
       pick01 = not(sign_mask(n01 - max(n02, n12)))   ! n01 ≥ max(n02, n12)
       pick02 = not(sign_mask(n02 - n12))             ! n02 ≥ n12
       x1 = bit_select(pick01, x01_1, bit_select(pick02, x02_1, x12_1))
       x2 = bit_select(pick01, x01_2, bit_select(pick02, x02_2, x12_2))
       x3 = bit_select(pick01, x01_3, bit_select(pick02, x02_3, x12_3))
       nx = max(n01, n02, n12)
       ! Unreachable for finite input (nx ≥ 3 in exact arithmetic), as in principal_3d_core.
       big = sign_mask(1.0e-6_dp - nx)                ! nx > 1e-6
       x1 = bit_select(big, x1, 1.0_dp)
       x2 = bit_select(big, x2, 0.0_dp)
       x3 = bit_select(big, x3, 0.0_dp)
       nx = bit_select(big, nx, 1.0_dp)

       ! Orthonormal triad (v, u, w) as in principal_3d_core: u = (−x3, 0, x1) if
       ! |x1| > |x2|, else (0, x3, −x2).
       first = sign_mask(abs(x2) - abs(x1))           ! |x1| > |x2|
       u1 = bit_select(first, -x3, 0.0_dp)
       u2 = bit_select(first, 0.0_dp, x3)
       u3 = bit_select(first, x1, -x2)
       w1 = x2 * u3 - x3 * u2
       w2 = x3 * u1 - x1 * u3
       w3 = x1 * u2 - x2 * u1
       inv_x = 1.0_dp / sqrt(nx)
       inv_u = 1.0_dp / sqrt(u1 * u1 + u2 * u2 + u3 * u3)
       v1 = x1 * inv_x
       v2 = x2 * inv_x
       v3 = x3 * inv_x
       w1 = w1 * (inv_x * inv_u)
       w2 = w2 * (inv_x * inv_u)
       w3 = w3 * (inv_x * inv_u)
       u1 = u1 * inv_u
       u2 = u2 * inv_u
       u3 = u3 * inv_u

       ! Exact projection of C on (u, w); the separated value from the trace.
       cu1 = c11 * u1 + c12 * u2 + c13 * u3
       cu2 = c12 * u1 + c22 * u2 + c23 * u3
       cu3 = c13 * u1 + c23 * u2 + c33 * u3
       cw1 = c11 * w1 + c12 * w2 + c13 * w3
       cw2 = c12 * w1 + c22 * w2 + c23 * w3
       cw3 = c13 * w1 + c23 * w2 + c33 * w3
       a11 = u1 * cu1 + u2 * cu2 + u3 * cu3
       a22 = w1 * cw1 + w2 * cw2 + w3 * cw3
       a12 = u1 * cw1 + u2 * cw2 + u3 * cw3
       mu_s = (c11 + c22 + c33) - a11 - a22
       ! 2x2 eigen-pair (the operations of sym2_eigen; written out, like the plane block's,
       ! so that the loop body needs no call whatever the inliner decides).
       mid = 0.5_dp * (a11 + a22)
       d = 0.5_dp * (a11 - a22)
       amax = max(abs(d), abs(a12))
       small = not(sign_mask(1.0e-150_dp - amax))     ! amax ≤ 1e-150
       large = not(sign_mask(amax - 1.0e150_dp))      ! amax ≥ 1e150
       f = bit_select(small, up2, bit_select(large, down2, 2.0_dp))
       g = bit_select(small, down2, bit_select(large, up2, 0.5_dp))
       t = abs(d) * f
       o = a12 * f
       rs = sqrt(t * t + o * o)
       rho = rs * g
       t = max(t + rs, t_floor)
       mu_a = mid + rho
       mu_b = mid - rho
       inv = 1.0_dp / sqrt(t * t + o * o)
       t = t * inv
       o = o * inv
       pos = not(sign_mask(d + 0.0_dp))               ! d ≥ 0 (−0 included)
       cs = bit_select(pos, t, o)
       sn = bit_select(pos, o, t)
       ea1 = cs * u1 + sn * w1
       ea2 = cs * u2 + sn * w2
       ea3 = cs * u3 + sn * w3
       eb1 = cs * w1 - sn * u1
       eb2 = cs * w2 - sn * u2
       eb3 = cs * w3 - sn * u3

       ! The separated root is the largest (r ≥ 0) or the smallest (r < 0); isotropic: q
       ! (p = 0) and the identity.
       p = bit_select(iso, 0.0_dp, p)
       mu_s = (q + p * mu_s) * isf
       mu_a = (q + p * mu_a) * isf
       mu_b = (q + p * mu_b) * isf
       sig(k, 1) = bit_select(top, mu_s, mu_a)
       sig(k, 2) = bit_select(top, mu_a, mu_b)
       sig(k, 3) = bit_select(top, mu_b, mu_s)
       vec(k, 1, 1) = bit_select(iso, 1.0_dp, bit_select(top, v1, ea1))
       vec(k, 2, 1) = bit_select(iso, 0.0_dp, bit_select(top, v2, ea2))
       vec(k, 3, 1) = bit_select(iso, 0.0_dp, bit_select(top, v3, ea3))
       vec(k, 1, 2) = bit_select(iso, 0.0_dp, bit_select(top, ea1, eb1))
       vec(k, 2, 2) = bit_select(iso, 1.0_dp, bit_select(top, ea2, eb2))
       vec(k, 3, 2) = bit_select(iso, 0.0_dp, bit_select(top, ea3, eb3))
       vec(k, 1, 3) = bit_select(iso, 0.0_dp, bit_select(top, eb1, v1))
       vec(k, 2, 3) = bit_select(iso, 0.0_dp, bit_select(top, eb2, v2))
       vec(k, 3, 3) = bit_select(iso, 1.0_dp, bit_select(top, eb3, v3))
    end do
  end subroutine principal_3d_block

  !> rebuild_3d on n points (any three values per point in the basis vec(k, :, :)).
  pure subroutine rebuild_3d_block(n, sig, vec, s)
    integer, intent(in) :: n
    real(dp), intent(in) :: sig(block_points, 3)
    real(dp), intent(in) :: vec(block_points, 3, 3)
    real(dp), intent(out) :: s(block_points, 6)
    real(dp) :: a1, a2, a3, b1, b2, b3, c1, c2, c3
    integer :: k

    do k = 1, n
       a1 = sig(k, 1) * vec(k, 1, 1)
       a2 = sig(k, 1) * vec(k, 2, 1)
       a3 = sig(k, 1) * vec(k, 3, 1)
       b1 = sig(k, 2) * vec(k, 1, 2)
       b2 = sig(k, 2) * vec(k, 2, 2)
       b3 = sig(k, 2) * vec(k, 3, 2)
       c1 = sig(k, 3) * vec(k, 1, 3)
       c2 = sig(k, 3) * vec(k, 2, 3)
       c3 = sig(k, 3) * vec(k, 3, 3)
       s(k, 1) = a1 * vec(k, 1, 1) + b1 * vec(k, 1, 2) + c1 * vec(k, 1, 3)
       s(k, 2) = a2 * vec(k, 2, 1) + b2 * vec(k, 2, 2) + c2 * vec(k, 2, 3)
       s(k, 3) = a3 * vec(k, 3, 1) + b3 * vec(k, 3, 2) + c3 * vec(k, 3, 3)
       s(k, 4) = a1 * vec(k, 2, 1) + b1 * vec(k, 2, 2) + c1 * vec(k, 2, 3)
       s(k, 5) = a2 * vec(k, 3, 1) + b2 * vec(k, 3, 2) + c2 * vec(k, 3, 3)
       s(k, 6) = a3 * vec(k, 1, 1) + b3 * vec(k, 1, 2) + c3 * vec(k, 1, 3)
    end do
  end subroutine rebuild_3d_block

  !> All ones where x has its sign bit set (x < 0 or x = −0), zeros elsewhere: with a
  !> difference a − b, which is +0 for a = b, it turns a comparison into a bit mask
  !> (a < b ⇔ sign_mask(a − b) set; a ≥ b ⇔ clear).
  elemental integer(int64) function sign_mask(x)
    real(dp), intent(in) :: x
    sign_mask = -ishft(transfer(x, 0_int64), -63)
  end function sign_mask

  !> a where mask is all ones, b where it is zero: a bitwise selection, exact and branch-free.
  elemental real(dp) function bit_select(mask, a, b)
    integer(int64), intent(in) :: mask
    real(dp), intent(in) :: a, b
    bit_select = transfer(ior(iand(transfer(a, 0_int64), mask), iand(transfer(b, 0_int64), &
         not(mask))), a)
  end function bit_select

  pure function cross(a1, a2, a3, b1, b2, b3) result(x)
    real(dp), intent(in) :: a1, a2, a3, b1, b2, b3
    real(dp) :: x(3)
    x(1) = a2 * b3 - a3 * b2
    x(2) = a3 * b1 - a1 * b3
    x(3) = a1 * b2 - a2 * b1
  end function cross

  pure function matvec(c11, c22, c33, c12, c23, c13, x) result(y)
    real(dp), intent(in) :: c11, c22, c33, c12, c23, c13
    real(dp), intent(in) :: x(3)
    real(dp) :: y(3)
    y(1) = c11 * x(1) + c12 * x(2) + c13 * x(3)
    y(2) = c12 * x(1) + c22 * x(2) + c23 * x(3)
    y(3) = c13 * x(1) + c23 * x(2) + c33 * x(3)
  end function matvec


end module principal_stress
