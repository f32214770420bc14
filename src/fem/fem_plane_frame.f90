!> Scalar kernels of the plane-strain (4-node) corotational frame: the mean deformation gradient,
!> its polar rotation, the rotation of a symmetric in-plane tensor and the relative spin.
!>
!> Why scalar elemental kernels: the block routines of fem_corotation (one quantity per pass) and
!> the fused CPE4R pass of fem_cpe4r (all quantities in one element loop, values kept in
!> registers) need the same expressions; written once here, both call them inside their element
!> loops, the compiler inlines them (LTO across modules) and the loops still vectorise. Each sum
!> starts from 0 and runs in the order of the general nd loops of fem_corotation, so every caller
!> gets the same result to the bit.
module fem_plane_frame
  use base_kinds, only: dp
  implicit none
  private

  public :: plane_defgrad, plane_rotation, plane_similarity, plane_relative_spin, plane_corotational_step

contains

  !> F = Σ_I (x_I − x_1) ⊗ B0_I of a 4-node element (Σ_I B0_I = 0, so node 1 drops out):
  !> xI, yI = offsets of node I from node 1 (I = 2..4), b1I, b2I = the reference mean gradient.
  elemental subroutine plane_defgrad(x2, x3, x4, y2, y3, y4, b12, b13, b14, b22, b23, b24, &
                                     f11, f21, f12, f22)
    real(dp), intent(in) :: x2, x3, x4, y2, y3, y4, b12, b13, b14, b22, b23, b24
    real(dp), intent(out) :: f11, f21, f12, f22

    f11 = ((0.0_dp + x2 * b12) + x3 * b13) + x4 * b14
    f21 = ((0.0_dp + y2 * b12) + y3 * b13) + y4 * b14
    f12 = ((0.0_dp + x2 * b22) + x3 * b23) + x4 * b24
    f22 = ((0.0_dp + y2 * b22) + y3 * b23) + y4 * b24
  end subroutine plane_defgrad

  !> R of F = RU in the plane: the rotation by atan2(F21 − F12, F11 + F22), valid for det F > 0.
  !> ‖(c, s)‖² = ‖F‖² + 2 det F > 0 for a non-inverted element; the guard only avoids 0/0 (an
  !> inverted element is stopped by the inversion check of the same pass).
  elemental subroutine plane_rotation(f11, f21, f12, f22, r11, r21, r12, r22)
    real(dp), intent(in) :: f11, f21, f12, f22
    real(dp), intent(out) :: r11, r21, r12, r22
    real(dp) :: c, s, nrm

    c = f11 + f22
    s = f21 - f12
    nrm = max(sqrt(c * c + s * s), tiny(1.0_dp))
    r11 = c / nrm
    r21 = s / nrm
    r12 = -s / nrm
    r22 = c / nrm
  end subroutine plane_rotation

  !> b = q a qᵀ for a symmetric in-plane tensor a (a11, a22, a12 as tensor components); the 33
  !> component is untouched by an in-plane rotation. b12 is the mean of the two off-diagonal
  !> products, so b is symmetric to the bit.
  elemental subroutine plane_similarity(q11, q12, q21, q22, a11, a22, a12, b11, b22, b12)
    real(dp), intent(in) :: q11, q12, q21, q22, a11, a22, a12
    real(dp), intent(out) :: b11, b22, b12
    real(dp) :: t11, t12, t21, t22, u12, u21

    ! t = a qᵀ, then b = q t
    t11 = (0.0_dp + a11 * q11) + a12 * q12
    t12 = (0.0_dp + a11 * q21) + a12 * q22
    t21 = (0.0_dp + a12 * q11) + a22 * q12
    t22 = (0.0_dp + a12 * q21) + a22 * q22
    b11 = (0.0_dp + q11 * t11) + q12 * t21
    b22 = (0.0_dp + q21 * t12) + q22 * t22
    u12 = (0.0_dp + q11 * t12) + q12 * t22
    u21 = (0.0_dp + q21 * t11) + q22 * t21
    b12 = 0.5_dp * (u12 + u21)
  end subroutine plane_similarity

  !> relSpinInc ω3 = ΔW21 − ΔΩ21 in the plane: spin = the material spin increment, ΔΩ the Cayley
  !> vector of ΔR = R_{n+1} R_nᵀ (fem_corotation's relative_spin), n = R_{n+1}, o = R_n. 1 + tr ΔR
  !> of the 3-D embedding is 2 + ΔR11 + ΔR22 > 0 for any rotation below 180° in one increment;
  !> guarded like the rotation.
  elemental real(dp) function plane_relative_spin(spin, n11, n21, n12, n22, o11, o21, o12, o22) &
       result(rel_spin)
    real(dp), intent(in) :: spin, n11, n21, n12, n22, o11, o21, o12, o22
    real(dp) :: d11, d22, d12, d21

    d11 = (0.0_dp + n11 * o11) + n12 * o12
    d22 = (0.0_dp + n21 * o21) + n22 * o22
    d12 = (0.0_dp + n11 * o21) + n12 * o22
    d21 = (0.0_dp + n21 * o11) + n22 * o12
    rel_spin = spin - 2.0_dp * (d21 - d12) / max(2.0_dp + d11 + d22, tiny(1.0_dp))
  end function plane_relative_spin

  !> The whole Green–Naghdi step of a 4-node plane element (CPE4R, and CAX4R in its r–z plane):
  !> F_{n+½}, R_{n+½} (q) from the mid-increment node offsets dm (nodes 2–4 from node 1), F_{n+1}
  !> (f), R_{n+1} (n) from dn, with the reference mean gradient b; strainInc = R_{n+½}ᵀ Δε R_{n+½}
  !> of the in-plane global increment (e11, e22, e12 tensor shear) -> (c11, c22, c12); relSpinInc
  !> from the spin ΔW21 and R_n = [co −so; so co].
  elemental subroutine plane_corotational_step(dmx2, dmx3, dmx4, dmy2, dmy3, dmy4, dnx2, dnx3, dnx4, &
       dny2, dny3, dny4, b12, b13, b14, b22, b23, b24, e11, e22, e12, spin, co, so, q11, q21, q12, q22, &
       f11, f21, f12, f22, n11, n21, n12, n22, c11, c22, c12, rel_spin)
    real(dp), intent(in) :: dmx2, dmx3, dmx4, dmy2, dmy3, dmy4, dnx2, dnx3, dnx4, dny2, dny3, dny4
    real(dp), intent(in) :: b12, b13, b14, b22, b23, b24, e11, e22, e12, spin, co, so
    real(dp), intent(out) :: q11, q21, q12, q22, f11, f21, f12, f22, n11, n21, n12, n22, c11, c22, c12
    real(dp), intent(out) :: rel_spin
    real(dp) :: g11, g21, g12, g22

    call plane_defgrad(dmx2, dmx3, dmx4, dmy2, dmy3, dmy4, b12, b13, b14, b22, b23, b24, g11, g21, g12, g22)
    call plane_rotation(g11, g21, g12, g22, q11, q21, q12, q22)
    call plane_defgrad(dnx2, dnx3, dnx4, dny2, dny3, dny4, b12, b13, b14, b22, b23, b24, f11, f21, f12, f22)
    call plane_rotation(f11, f21, f12, f22, n11, n21, n12, n22)
    call plane_similarity(q11, q21, q12, q22, e11, e22, e12, c11, c22, c12)
    rel_spin = plane_relative_spin(spin, n11, n21, n12, n22, co, so, -so, co)
  end subroutine plane_corotational_step
end module fem_plane_frame
