!> C3D8R: 8-node hexahedron, one-point (uniform strain) quadrature with the exact
!> Flanagan–Belytschko mean gradient, for blocks of nb elements (element index first).
!>
!> Nodes (Abaqus order): 1–4 bottom face counter-clockwise seen from the top, 5–8 above
!> them; natural coordinates ξ, η, ζ = ±1 (node 1 at (−1,−1,−1), node 7 at (1,1,1)).
!> Arrays: xe, du (nb, 3, 8); bmat (nb, 3, 8) the mean gradient B_iI = (1/V)∫ ∂N_I/∂x_i dV;
!> symmetric tensors (nb, 6) in the VUMAT order 11, 22, 33, 12, 23, 31 with tensor shear;
!> spin (nb, 3) = (W32, W13, W21), the axial vector; fe (nb, 3, 8) internal nodal forces
!> (resisting sign: a = (f_ext − f_int)/m).
!>
!> Exact volume and b = ∂V/∂x from the trilinear map x(ξ) = a0 + a1 ξ + a2 η + a3 ζ
!> + a4 ξη + a5 ηζ + a6 ζξ + a7 ξηζ, a_k = ⅛ Σ_I c_kI x_I (c_kI the nodal values of the
!> monomials). Integrating det[x,ξ x,η x,ζ] over the cube (all odd moments vanish, a7 drops out):
!>   V = 8 a1·(a2×a3) + (8/3)[a4·(a2×a5) + a6·(a5×a3) + a1·(a4×a6)]
!>   b_I = Σ_{k=1..6} c_kI g_k,  g1 = a2×a3 + ⅓ a4×a6,  g2 = a3×a1 + ⅓ a5×a4,
!>   g3 = a1×a2 + ⅓ a6×a5,  g4 = ⅓(a2×a5 + a6×a1),  g5 = ⅓(a4×a2 + a3×a6),
!>   g6 = ⅓(a5×a3 + a1×a4);   B = b/V.
!> The a_k (k ≥ 1) involve only coordinate differences, so large absolute coordinates cost no
!> digits. B is exact: Σ_I x_jI B_iI = δ_ij and Σ_I B_iI = 0 (patch test).
module fem_c3d8r
  use base_kinds, only: dp
  use fem_hourglass, only: hourglass_forces
  implicit none
  private

  public :: c3d8r_geometry, c3d8r_char_length, c3d8r_strain_increment, c3d8r_kinematics
  public :: c3d8r_internal_force, c3d8r_hourglass_gamma, c3d8r_hourglass

  integer, parameter, public :: c3d8r_ndim = 3, c3d8r_nen = 8, c3d8r_ncomp = 6
  integer, parameter, public :: c3d8r_nshr = 3, c3d8r_nmode = 4

  !> cn(I, k): nodal values of the monomials ξ, η, ζ, ξη, ηζ, ζξ, ξηζ (k = 1..7) at node I.
  !> Columns 4..7 are the FB hourglass base vectors Γ1..Γ4.
  real(dp), parameter :: cn(8, 7) = reshape([ &
       -1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp, &
       -1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, &
       -1.0_dp, -1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp, &
       1.0_dp, -1.0_dp, 1.0_dp, -1.0_dp, 1.0_dp, -1.0_dp, 1.0_dp, -1.0_dp, &
       1.0_dp, 1.0_dp, -1.0_dp, -1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, &
       1.0_dp, -1.0_dp, -1.0_dp, 1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp, &
       -1.0_dp, 1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp, 1.0_dp, -1.0_dp], [8, 7])
  !> Faces (Abaqus S1..S6) for the characteristic length.
  integer, parameter :: face(4, 6) = reshape([1, 2, 3, 4, 5, 8, 7, 6, 1, 5, 6, 2, &
                                              2, 6, 7, 3, 3, 7, 8, 4, 4, 8, 5, 1], [4, 6])

contains

  !> The a_k vectors (nb, 3, 7) of the trilinear map.
  pure subroutine map_coefficients(nb, xe, a)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 3, 8)
    real(dp), intent(out) :: a(nb, 3, 7)
    ! a_k = ⅛ Σ_I c_kI x_I with c_kI = ±1 written out as additions and subtractions: the same
    ! sums in the same order as Σ_I (c_kI x_I) from 0 (c x = ±x exactly, 0 + (−x) = 0 − x), so
    ! bitwise the same a_k, in one pass per coefficient instead of eight read-modify-write
    ! passes with multiplications. (The signs are those of cn, column k.)
    a(:, 1, 1) = 0.125_dp * ((((((((0.0_dp - xe(:, 1, 1)) + xe(:, 1, 2)) + xe(:, 1, 3)) - xe(:, 1, 4)) - xe(:, 1, 5)) + xe(:, 1, 6)) + xe(:, 1, 7)) - xe(:, 1, 8))
    a(:, 2, 1) = 0.125_dp * ((((((((0.0_dp - xe(:, 2, 1)) + xe(:, 2, 2)) + xe(:, 2, 3)) - xe(:, 2, 4)) - xe(:, 2, 5)) + xe(:, 2, 6)) + xe(:, 2, 7)) - xe(:, 2, 8))
    a(:, 3, 1) = 0.125_dp * ((((((((0.0_dp - xe(:, 3, 1)) + xe(:, 3, 2)) + xe(:, 3, 3)) - xe(:, 3, 4)) - xe(:, 3, 5)) + xe(:, 3, 6)) + xe(:, 3, 7)) - xe(:, 3, 8))
    a(:, 1, 2) = 0.125_dp * ((((((((0.0_dp - xe(:, 1, 1)) - xe(:, 1, 2)) + xe(:, 1, 3)) + xe(:, 1, 4)) - xe(:, 1, 5)) - xe(:, 1, 6)) + xe(:, 1, 7)) + xe(:, 1, 8))
    a(:, 2, 2) = 0.125_dp * ((((((((0.0_dp - xe(:, 2, 1)) - xe(:, 2, 2)) + xe(:, 2, 3)) + xe(:, 2, 4)) - xe(:, 2, 5)) - xe(:, 2, 6)) + xe(:, 2, 7)) + xe(:, 2, 8))
    a(:, 3, 2) = 0.125_dp * ((((((((0.0_dp - xe(:, 3, 1)) - xe(:, 3, 2)) + xe(:, 3, 3)) + xe(:, 3, 4)) - xe(:, 3, 5)) - xe(:, 3, 6)) + xe(:, 3, 7)) + xe(:, 3, 8))
    a(:, 1, 3) = 0.125_dp * ((((((((0.0_dp - xe(:, 1, 1)) - xe(:, 1, 2)) - xe(:, 1, 3)) - xe(:, 1, 4)) + xe(:, 1, 5)) + xe(:, 1, 6)) + xe(:, 1, 7)) + xe(:, 1, 8))
    a(:, 2, 3) = 0.125_dp * ((((((((0.0_dp - xe(:, 2, 1)) - xe(:, 2, 2)) - xe(:, 2, 3)) - xe(:, 2, 4)) + xe(:, 2, 5)) + xe(:, 2, 6)) + xe(:, 2, 7)) + xe(:, 2, 8))
    a(:, 3, 3) = 0.125_dp * ((((((((0.0_dp - xe(:, 3, 1)) - xe(:, 3, 2)) - xe(:, 3, 3)) - xe(:, 3, 4)) + xe(:, 3, 5)) + xe(:, 3, 6)) + xe(:, 3, 7)) + xe(:, 3, 8))
    a(:, 1, 4) = 0.125_dp * ((((((((0.0_dp + xe(:, 1, 1)) - xe(:, 1, 2)) + xe(:, 1, 3)) - xe(:, 1, 4)) + xe(:, 1, 5)) - xe(:, 1, 6)) + xe(:, 1, 7)) - xe(:, 1, 8))
    a(:, 2, 4) = 0.125_dp * ((((((((0.0_dp + xe(:, 2, 1)) - xe(:, 2, 2)) + xe(:, 2, 3)) - xe(:, 2, 4)) + xe(:, 2, 5)) - xe(:, 2, 6)) + xe(:, 2, 7)) - xe(:, 2, 8))
    a(:, 3, 4) = 0.125_dp * ((((((((0.0_dp + xe(:, 3, 1)) - xe(:, 3, 2)) + xe(:, 3, 3)) - xe(:, 3, 4)) + xe(:, 3, 5)) - xe(:, 3, 6)) + xe(:, 3, 7)) - xe(:, 3, 8))
    a(:, 1, 5) = 0.125_dp * ((((((((0.0_dp + xe(:, 1, 1)) + xe(:, 1, 2)) - xe(:, 1, 3)) - xe(:, 1, 4)) - xe(:, 1, 5)) - xe(:, 1, 6)) + xe(:, 1, 7)) + xe(:, 1, 8))
    a(:, 2, 5) = 0.125_dp * ((((((((0.0_dp + xe(:, 2, 1)) + xe(:, 2, 2)) - xe(:, 2, 3)) - xe(:, 2, 4)) - xe(:, 2, 5)) - xe(:, 2, 6)) + xe(:, 2, 7)) + xe(:, 2, 8))
    a(:, 3, 5) = 0.125_dp * ((((((((0.0_dp + xe(:, 3, 1)) + xe(:, 3, 2)) - xe(:, 3, 3)) - xe(:, 3, 4)) - xe(:, 3, 5)) - xe(:, 3, 6)) + xe(:, 3, 7)) + xe(:, 3, 8))
    a(:, 1, 6) = 0.125_dp * ((((((((0.0_dp + xe(:, 1, 1)) - xe(:, 1, 2)) - xe(:, 1, 3)) + xe(:, 1, 4)) - xe(:, 1, 5)) + xe(:, 1, 6)) + xe(:, 1, 7)) - xe(:, 1, 8))
    a(:, 2, 6) = 0.125_dp * ((((((((0.0_dp + xe(:, 2, 1)) - xe(:, 2, 2)) - xe(:, 2, 3)) + xe(:, 2, 4)) - xe(:, 2, 5)) + xe(:, 2, 6)) + xe(:, 2, 7)) - xe(:, 2, 8))
    a(:, 3, 6) = 0.125_dp * ((((((((0.0_dp + xe(:, 3, 1)) - xe(:, 3, 2)) - xe(:, 3, 3)) + xe(:, 3, 4)) - xe(:, 3, 5)) + xe(:, 3, 6)) + xe(:, 3, 7)) - xe(:, 3, 8))
    a(:, 1, 7) = 0.125_dp * ((((((((0.0_dp - xe(:, 1, 1)) + xe(:, 1, 2)) - xe(:, 1, 3)) + xe(:, 1, 4)) + xe(:, 1, 5)) - xe(:, 1, 6)) + xe(:, 1, 7)) - xe(:, 1, 8))
    a(:, 2, 7) = 0.125_dp * ((((((((0.0_dp - xe(:, 2, 1)) + xe(:, 2, 2)) - xe(:, 2, 3)) + xe(:, 2, 4)) + xe(:, 2, 5)) - xe(:, 2, 6)) + xe(:, 2, 7)) - xe(:, 2, 8))
    a(:, 3, 7) = 0.125_dp * ((((((((0.0_dp - xe(:, 3, 1)) + xe(:, 3, 2)) - xe(:, 3, 3)) + xe(:, 3, 4)) + xe(:, 3, 5)) - xe(:, 3, 6)) + xe(:, 3, 7)) - xe(:, 3, 8))
  end subroutine map_coefficients

  !> p × q for blocks of vectors (nb, 3).
  pure function cross(nb, p, q) result(r)
    integer, intent(in) :: nb
    real(dp), intent(in) :: p(nb, 3), q(nb, 3)
    real(dp) :: r(nb, 3)

    r(:, 1) = p(:, 2) * q(:, 3) - p(:, 3) * q(:, 2)
    r(:, 2) = p(:, 3) * q(:, 1) - p(:, 1) * q(:, 3)
    r(:, 3) = p(:, 1) * q(:, 2) - p(:, 2) * q(:, 1)
  end function cross

  !> Exact volume and mean gradient B of a block at the configuration xe.
  pure subroutine c3d8r_geometry(nb, xe, volume, bmat)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 3, 8)
    real(dp), intent(out) :: volume(nb)
    real(dp), intent(out) :: bmat(nb, 3, 8)
    real(dp) :: a(nb, 3, 7), g(nb, 3, 6), rv(nb)
    real(dp), parameter :: third = 1.0_dp / 3.0_dp
    integer :: k, i

    call map_coefficients(nb, xe, a)
    g(:, :, 1) = cross(nb, a(:, :, 2), a(:, :, 3)) + third * cross(nb, a(:, :, 4), a(:, :, 6))
    g(:, :, 2) = cross(nb, a(:, :, 3), a(:, :, 1)) + third * cross(nb, a(:, :, 5), a(:, :, 4))
    g(:, :, 3) = cross(nb, a(:, :, 1), a(:, :, 2)) + third * cross(nb, a(:, :, 6), a(:, :, 5))
    g(:, :, 4) = third * (cross(nb, a(:, :, 2), a(:, :, 5)) + cross(nb, a(:, :, 6), a(:, :, 1)))
    g(:, :, 5) = third * (cross(nb, a(:, :, 4), a(:, :, 2)) + cross(nb, a(:, :, 3), a(:, :, 6)))
    g(:, :, 6) = third * (cross(nb, a(:, :, 5), a(:, :, 3)) + cross(nb, a(:, :, 1), a(:, :, 4)))
    ! V = Σ_k a_k·∂V/∂a_k / 3 = (8/3) Σ_k a_k·g_k (Euler: V is cubic in the a_k)
    volume = 0.0_dp
    do k = 1, 6
       do i = 1, 3
          volume = volume + a(:, i, k) * g(:, i, k)
       end do
    end do
    volume = (8.0_dp / 3.0_dp) * volume
    ! A degenerate element (V = 0) is caught by the inversion check; avoid 1/0 here.
    rv = 1.0_dp / sign(max(abs(volume), tiny(1.0_dp)), volume)
    ! B_iI = (Σ_k c_kI g_ik) / V with c_kI = ±1 written out (as in map_coefficients: the same
    ! sums in the same order, bitwise the same B, one pass per entry).
    bmat(:, 1, 1) = ((((((0.0_dp - g(:, 1, 1)) - g(:, 1, 2)) - g(:, 1, 3)) + g(:, 1, 4)) + g(:, 1, 5)) + g(:, 1, 6)) * rv
    bmat(:, 2, 1) = ((((((0.0_dp - g(:, 2, 1)) - g(:, 2, 2)) - g(:, 2, 3)) + g(:, 2, 4)) + g(:, 2, 5)) + g(:, 2, 6)) * rv
    bmat(:, 3, 1) = ((((((0.0_dp - g(:, 3, 1)) - g(:, 3, 2)) - g(:, 3, 3)) + g(:, 3, 4)) + g(:, 3, 5)) + g(:, 3, 6)) * rv
    bmat(:, 1, 2) = ((((((0.0_dp + g(:, 1, 1)) - g(:, 1, 2)) - g(:, 1, 3)) - g(:, 1, 4)) + g(:, 1, 5)) - g(:, 1, 6)) * rv
    bmat(:, 2, 2) = ((((((0.0_dp + g(:, 2, 1)) - g(:, 2, 2)) - g(:, 2, 3)) - g(:, 2, 4)) + g(:, 2, 5)) - g(:, 2, 6)) * rv
    bmat(:, 3, 2) = ((((((0.0_dp + g(:, 3, 1)) - g(:, 3, 2)) - g(:, 3, 3)) - g(:, 3, 4)) + g(:, 3, 5)) - g(:, 3, 6)) * rv
    bmat(:, 1, 3) = ((((((0.0_dp + g(:, 1, 1)) + g(:, 1, 2)) - g(:, 1, 3)) + g(:, 1, 4)) - g(:, 1, 5)) - g(:, 1, 6)) * rv
    bmat(:, 2, 3) = ((((((0.0_dp + g(:, 2, 1)) + g(:, 2, 2)) - g(:, 2, 3)) + g(:, 2, 4)) - g(:, 2, 5)) - g(:, 2, 6)) * rv
    bmat(:, 3, 3) = ((((((0.0_dp + g(:, 3, 1)) + g(:, 3, 2)) - g(:, 3, 3)) + g(:, 3, 4)) - g(:, 3, 5)) - g(:, 3, 6)) * rv
    bmat(:, 1, 4) = ((((((0.0_dp - g(:, 1, 1)) + g(:, 1, 2)) - g(:, 1, 3)) - g(:, 1, 4)) - g(:, 1, 5)) + g(:, 1, 6)) * rv
    bmat(:, 2, 4) = ((((((0.0_dp - g(:, 2, 1)) + g(:, 2, 2)) - g(:, 2, 3)) - g(:, 2, 4)) - g(:, 2, 5)) + g(:, 2, 6)) * rv
    bmat(:, 3, 4) = ((((((0.0_dp - g(:, 3, 1)) + g(:, 3, 2)) - g(:, 3, 3)) - g(:, 3, 4)) - g(:, 3, 5)) + g(:, 3, 6)) * rv
    bmat(:, 1, 5) = ((((((0.0_dp - g(:, 1, 1)) - g(:, 1, 2)) + g(:, 1, 3)) + g(:, 1, 4)) - g(:, 1, 5)) - g(:, 1, 6)) * rv
    bmat(:, 2, 5) = ((((((0.0_dp - g(:, 2, 1)) - g(:, 2, 2)) + g(:, 2, 3)) + g(:, 2, 4)) - g(:, 2, 5)) - g(:, 2, 6)) * rv
    bmat(:, 3, 5) = ((((((0.0_dp - g(:, 3, 1)) - g(:, 3, 2)) + g(:, 3, 3)) + g(:, 3, 4)) - g(:, 3, 5)) - g(:, 3, 6)) * rv
    bmat(:, 1, 6) = ((((((0.0_dp + g(:, 1, 1)) - g(:, 1, 2)) + g(:, 1, 3)) - g(:, 1, 4)) - g(:, 1, 5)) + g(:, 1, 6)) * rv
    bmat(:, 2, 6) = ((((((0.0_dp + g(:, 2, 1)) - g(:, 2, 2)) + g(:, 2, 3)) - g(:, 2, 4)) - g(:, 2, 5)) + g(:, 2, 6)) * rv
    bmat(:, 3, 6) = ((((((0.0_dp + g(:, 3, 1)) - g(:, 3, 2)) + g(:, 3, 3)) - g(:, 3, 4)) - g(:, 3, 5)) + g(:, 3, 6)) * rv
    bmat(:, 1, 7) = ((((((0.0_dp + g(:, 1, 1)) + g(:, 1, 2)) + g(:, 1, 3)) + g(:, 1, 4)) + g(:, 1, 5)) + g(:, 1, 6)) * rv
    bmat(:, 2, 7) = ((((((0.0_dp + g(:, 2, 1)) + g(:, 2, 2)) + g(:, 2, 3)) + g(:, 2, 4)) + g(:, 2, 5)) + g(:, 2, 6)) * rv
    bmat(:, 3, 7) = ((((((0.0_dp + g(:, 3, 1)) + g(:, 3, 2)) + g(:, 3, 3)) + g(:, 3, 4)) + g(:, 3, 5)) + g(:, 3, 6)) * rv
    bmat(:, 1, 8) = ((((((0.0_dp - g(:, 1, 1)) + g(:, 1, 2)) + g(:, 1, 3)) - g(:, 1, 4)) + g(:, 1, 5)) - g(:, 1, 6)) * rv
    bmat(:, 2, 8) = ((((((0.0_dp - g(:, 2, 1)) + g(:, 2, 2)) + g(:, 2, 3)) - g(:, 2, 4)) + g(:, 2, 5)) - g(:, 2, 6)) * rv
    bmat(:, 3, 8) = ((((((0.0_dp - g(:, 3, 1)) + g(:, 3, 2)) + g(:, 3, 3)) - g(:, 3, 4)) + g(:, 3, 5)) - g(:, 3, 6)) * rv
  end subroutine c3d8r_geometry

  !> Characteristic length L_e = V / (largest face area) (LS-DYNA's choice for hexahedra),
  !> face area = ½|d1 × d2| from the face diagonals (exact for planar faces). L_e = h for a
  !> cube of side h, for which a uniform mesh of one-point elements has ω_max = 2c/h exactly
  !> (docs/theory/elements.md §3.6); a thin plate gives its thickness.
  pure subroutine c3d8r_char_length(nb, xe, volume, char_length)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 3, 8)
    real(dp), intent(in) :: volume(nb)
    real(dp), intent(out) :: char_length(nb)
    real(dp) :: d1(nb, 3), d2(nb, 3), n(nb, 3), a2max(nb)
    integer :: f

    a2max = 0.0_dp
    do f = 1, 6
       d1 = xe(:, :, face(3, f)) - xe(:, :, face(1, f))
       d2 = xe(:, :, face(4, f)) - xe(:, :, face(2, f))
       n = cross(nb, d1, d2)
       a2max = max(a2max, 0.25_dp * (n(:, 1)**2 + n(:, 2)**2 + n(:, 3)**2))
    end do
    char_length = abs(volume) / sqrt(max(a2max, tiny(1.0_dp)))
  end subroutine c3d8r_char_length

  !> Global strain and spin increments from du = Δt v_{n+½} with B at the mid-increment
  !> configuration: ΔL_ij = Σ_I du_iI B_jI, strain_inc = sym ΔL (11, 22, 33, 12, 23, 31,
  !> tensor shear), spin_inc = axial vector of skw ΔL = (ΔW32, ΔW13, ΔW21).
  pure subroutine c3d8r_strain_increment(nb, bmat_mid, du, strain_inc, spin_inc)
    integer, intent(in) :: nb
    real(dp), intent(in) :: bmat_mid(nb, 3, 8)
    real(dp), intent(in) :: du(nb, 3, 8)
    real(dp), intent(out) :: strain_inc(nb, 6)
    real(dp), intent(out) :: spin_inc(nb, 3)
    real(dp) :: dl(nb, 3, 3)

    ! ΔL_ij = Σ_I du_iI B_jI, each in one pass with the sum over the nodes in node order from 0
    ! (the order of the former node loop: bitwise the same).
    dl(:, 1, 1) = (((((((0.0_dp + du(:, 1, 1) * bmat_mid(:, 1, 1)) + du(:, 1, 2) * bmat_mid(:, 1, 2)) + du(:, 1, 3) * bmat_mid(:, 1, 3)) + du(:, 1, 4) * bmat_mid(:, 1, 4)) + du(:, 1, 5) * bmat_mid(:, 1, 5)) + du(:, 1, 6) * bmat_mid(:, 1, 6)) + du(:, 1, 7) * bmat_mid(:, 1, 7)) + du(:, 1, 8) * bmat_mid(:, 1, 8)
    dl(:, 2, 1) = (((((((0.0_dp + du(:, 2, 1) * bmat_mid(:, 1, 1)) + du(:, 2, 2) * bmat_mid(:, 1, 2)) + du(:, 2, 3) * bmat_mid(:, 1, 3)) + du(:, 2, 4) * bmat_mid(:, 1, 4)) + du(:, 2, 5) * bmat_mid(:, 1, 5)) + du(:, 2, 6) * bmat_mid(:, 1, 6)) + du(:, 2, 7) * bmat_mid(:, 1, 7)) + du(:, 2, 8) * bmat_mid(:, 1, 8)
    dl(:, 3, 1) = (((((((0.0_dp + du(:, 3, 1) * bmat_mid(:, 1, 1)) + du(:, 3, 2) * bmat_mid(:, 1, 2)) + du(:, 3, 3) * bmat_mid(:, 1, 3)) + du(:, 3, 4) * bmat_mid(:, 1, 4)) + du(:, 3, 5) * bmat_mid(:, 1, 5)) + du(:, 3, 6) * bmat_mid(:, 1, 6)) + du(:, 3, 7) * bmat_mid(:, 1, 7)) + du(:, 3, 8) * bmat_mid(:, 1, 8)
    dl(:, 1, 2) = (((((((0.0_dp + du(:, 1, 1) * bmat_mid(:, 2, 1)) + du(:, 1, 2) * bmat_mid(:, 2, 2)) + du(:, 1, 3) * bmat_mid(:, 2, 3)) + du(:, 1, 4) * bmat_mid(:, 2, 4)) + du(:, 1, 5) * bmat_mid(:, 2, 5)) + du(:, 1, 6) * bmat_mid(:, 2, 6)) + du(:, 1, 7) * bmat_mid(:, 2, 7)) + du(:, 1, 8) * bmat_mid(:, 2, 8)
    dl(:, 2, 2) = (((((((0.0_dp + du(:, 2, 1) * bmat_mid(:, 2, 1)) + du(:, 2, 2) * bmat_mid(:, 2, 2)) + du(:, 2, 3) * bmat_mid(:, 2, 3)) + du(:, 2, 4) * bmat_mid(:, 2, 4)) + du(:, 2, 5) * bmat_mid(:, 2, 5)) + du(:, 2, 6) * bmat_mid(:, 2, 6)) + du(:, 2, 7) * bmat_mid(:, 2, 7)) + du(:, 2, 8) * bmat_mid(:, 2, 8)
    dl(:, 3, 2) = (((((((0.0_dp + du(:, 3, 1) * bmat_mid(:, 2, 1)) + du(:, 3, 2) * bmat_mid(:, 2, 2)) + du(:, 3, 3) * bmat_mid(:, 2, 3)) + du(:, 3, 4) * bmat_mid(:, 2, 4)) + du(:, 3, 5) * bmat_mid(:, 2, 5)) + du(:, 3, 6) * bmat_mid(:, 2, 6)) + du(:, 3, 7) * bmat_mid(:, 2, 7)) + du(:, 3, 8) * bmat_mid(:, 2, 8)
    dl(:, 1, 3) = (((((((0.0_dp + du(:, 1, 1) * bmat_mid(:, 3, 1)) + du(:, 1, 2) * bmat_mid(:, 3, 2)) + du(:, 1, 3) * bmat_mid(:, 3, 3)) + du(:, 1, 4) * bmat_mid(:, 3, 4)) + du(:, 1, 5) * bmat_mid(:, 3, 5)) + du(:, 1, 6) * bmat_mid(:, 3, 6)) + du(:, 1, 7) * bmat_mid(:, 3, 7)) + du(:, 1, 8) * bmat_mid(:, 3, 8)
    dl(:, 2, 3) = (((((((0.0_dp + du(:, 2, 1) * bmat_mid(:, 3, 1)) + du(:, 2, 2) * bmat_mid(:, 3, 2)) + du(:, 2, 3) * bmat_mid(:, 3, 3)) + du(:, 2, 4) * bmat_mid(:, 3, 4)) + du(:, 2, 5) * bmat_mid(:, 3, 5)) + du(:, 2, 6) * bmat_mid(:, 3, 6)) + du(:, 2, 7) * bmat_mid(:, 3, 7)) + du(:, 2, 8) * bmat_mid(:, 3, 8)
    dl(:, 3, 3) = (((((((0.0_dp + du(:, 3, 1) * bmat_mid(:, 3, 1)) + du(:, 3, 2) * bmat_mid(:, 3, 2)) + du(:, 3, 3) * bmat_mid(:, 3, 3)) + du(:, 3, 4) * bmat_mid(:, 3, 4)) + du(:, 3, 5) * bmat_mid(:, 3, 5)) + du(:, 3, 6) * bmat_mid(:, 3, 6)) + du(:, 3, 7) * bmat_mid(:, 3, 7)) + du(:, 3, 8) * bmat_mid(:, 3, 8)
    strain_inc(:, 1) = dl(:, 1, 1)
    strain_inc(:, 2) = dl(:, 2, 2)
    strain_inc(:, 3) = dl(:, 3, 3)
    strain_inc(:, 4) = 0.5_dp * (dl(:, 1, 2) + dl(:, 2, 1))
    strain_inc(:, 5) = 0.5_dp * (dl(:, 2, 3) + dl(:, 3, 2))
    strain_inc(:, 6) = 0.5_dp * (dl(:, 3, 1) + dl(:, 1, 3))
    spin_inc(:, 1) = 0.5_dp * (dl(:, 3, 2) - dl(:, 2, 3))
    spin_inc(:, 2) = 0.5_dp * (dl(:, 1, 3) - dl(:, 3, 1))
    spin_inc(:, 3) = 0.5_dp * (dl(:, 2, 1) - dl(:, 1, 2))
  end subroutine c3d8r_strain_increment

  !> Everything an increment needs from the geometry, in one call:
  !> mid-increment volume and B (strain, spin, hourglass), end-of-increment volume, B (nodal
  !> forces) and characteristic length (stable increment).
  pure subroutine c3d8r_kinematics(nb, xe_mid, du, xe_new, volume_mid, bmat_mid, strain_inc, &
                                   spin_inc, volume_new, bmat_new, char_length)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe_mid(nb, 3, 8), du(nb, 3, 8), xe_new(nb, 3, 8)
    real(dp), intent(out) :: volume_mid(nb), bmat_mid(nb, 3, 8)
    real(dp), intent(out) :: strain_inc(nb, 6), spin_inc(nb, 3)
    real(dp), intent(out) :: volume_new(nb), bmat_new(nb, 3, 8), char_length(nb)

    call c3d8r_geometry(nb, xe_mid, volume_mid, bmat_mid)
    call c3d8r_strain_increment(nb, bmat_mid, du, strain_inc, spin_inc)
    call c3d8r_geometry(nb, xe_new, volume_new, bmat_new)
    call c3d8r_char_length(nb, xe_new, volume_new, char_length)
  end subroutine c3d8r_kinematics

  !> f_iI = V Σ_j σ_ij B_jI with the global stress. Overwrites fe; hourglass and
  !> bulk-viscosity routines add to it.
  pure subroutine c3d8r_internal_force(nb, volume, bmat, stress, fe)
    integer, intent(in) :: nb
    real(dp), intent(in) :: volume(nb)
    real(dp), intent(in) :: bmat(nb, 3, 8)
    real(dp), intent(in) :: stress(nb, 6)
    real(dp), intent(out) :: fe(nb, 3, 8)
    integer :: e, n

    do n = 1, 8
       do e = 1, nb
          fe(e, 1, n) = volume(e) * (stress(e, 1) * bmat(e, 1, n) + stress(e, 4) * bmat(e, 2, n) &
                                     + stress(e, 6) * bmat(e, 3, n))
          fe(e, 2, n) = volume(e) * (stress(e, 4) * bmat(e, 1, n) + stress(e, 2) * bmat(e, 2, n) &
                                     + stress(e, 5) * bmat(e, 3, n))
          fe(e, 3, n) = volume(e) * (stress(e, 6) * bmat(e, 1, n) + stress(e, 5) * bmat(e, 2, n) &
                                     + stress(e, 3) * bmat(e, 3, n))
       end do
    end do
  end subroutine c3d8r_internal_force

  !> FB hourglass vectors γ_αI = Γ_αI − (Γ_α·x_j) B_jI for the four modes Γ = ξη, ηζ, ζξ, ξηζ
  !> (unnormalised, γ = Γ on a parallelepiped); Γ_α·x = 8 a_{α+3}. gamma (nb, 8 nodes, 4 modes).
  pure subroutine c3d8r_hourglass_gamma(nb, xe, bmat, gamma)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 3, 8), bmat(nb, 3, 8)
    real(dp), intent(out) :: gamma(nb, 8, 4)
    real(dp) :: a(nb, 3, 7)
    integer :: m, n

    call map_coefficients(nb, xe, a)
    do m = 1, 4
       do n = 1, 8
          gamma(:, n, m) = cn(n, m + 3) - 8.0_dp * (a(:, 1, m + 3) * bmat(:, 1, n) &
                           + a(:, 2, m + 3) * bmat(:, 2, n) + a(:, 3, m + 3) * bmat(:, 3, n))
       end do
    end do
  end subroutine c3d8r_hourglass_gamma

  !> Hourglass forces of a block, added to fe, and the hourglass energy increment (ALLAE).
  !> kind/coefficient: fem_hourglass (hourglass_viscous with Q_v, hourglass_stiffness with κ).
  !> Scalings: viscous C = Q_v ρ c_d V^{2/3}/4; stiffness K = κ (λ+2μ) V Σ_iI B_iI² / 8.
  !> Evaluated on the mid-increment configuration, with density ρ and p-wave modulus λ+2μ per
  !> element. hg_state (nb, 3, 4): corotational hourglass generalised forces of the stiffness
  !> form (zero at the start). rot_mid, rot_new: R_{n+½}, R_{n+1} (fem_corotation).
  pure subroutine c3d8r_hourglass(nb, xe_mid, volume_mid, bmat_mid, du, dt, density, modulus, &
                                  kind, coefficient, rot_mid, rot_new, hg_state, fe, energy_inc)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe_mid(nb, 3, 8), volume_mid(nb), bmat_mid(nb, 3, 8)
    real(dp), intent(in) :: du(nb, 3, 8), dt
    real(dp), intent(in) :: density(nb), modulus(nb)
    integer, intent(in) :: kind
    real(dp), intent(in) :: coefficient
    real(dp), intent(in) :: rot_mid(nb, 3, 3), rot_new(nb, 3, 3)
    real(dp), intent(inout) :: hg_state(nb, 3, 4)
    real(dp), intent(inout) :: fe(nb, 3, 8)
    real(dp), intent(out) :: energy_inc(nb)
    real(dp) :: gamma(nb, 8, 4), visc(nb), stiff(nb)
    integer :: i, n

    call c3d8r_hourglass_gamma(nb, xe_mid, bmat_mid, gamma)
    visc = 0.25_dp * sqrt(density * modulus) * abs(volume_mid)**(2.0_dp / 3.0_dp)
    ! Σ_iI B_iI² accumulated in place (a sum(sum(B**2)) expression would build a block temporary)
    stiff = 0.0_dp
    do n = 1, 8
       do i = 1, 3
          stiff = stiff + bmat_mid(:, i, n)**2
       end do
    end do
    stiff = 0.125_dp * modulus * volume_mid * stiff
    call hourglass_forces(nb, 3, 8, 4, gamma, du, dt, kind, coefficient, visc, stiff, &
                          rot_mid, rot_new, hg_state, fe, energy_inc)
  end subroutine c3d8r_hourglass
end module fem_c3d8r
