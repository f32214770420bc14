!> CPE4R: 4-node plane-strain quadrilateral, one-point (uniform strain) quadrature with the
!> Flanagan–Belytschko mean gradient, for blocks of nb elements (element index first).
!>
!> Nodes 1–4 counter-clockwise, natural coordinates (ξ, η) = (−1,−1), (1,−1), (1,1), (−1,1).
!> Arrays: xe, du (nb, 2, 4) nodal coordinates / displacement increments; bmat (nb, 2, 4) the
!> mean gradient B_iI = (1/A)∫ ∂N_I/∂x_i dA; symmetric tensors (nb, 4) in the order
!> 11, 22, 33, 12 with tensor shear; fe (nb, 2, 4) internal nodal forces (resisting sign:
!> a = (f_ext − f_int)/m). "volume" is always A·t (thickness t per element), so masses,
!> forces and energies are those of the real slab.
!>
!> Exact formulas (d = x3 − x1, e = x4 − x2 the diagonals):
!>   A = ½ (d × e),  B_x = [−e_y, d_y, e_y, −d_y]/(2A),  B_y = [e_x, −d_x, −e_x, d_x]/(2A)
!> B is the exact mean gradient, so Σ_I x_jI B_iI = δ_ij, Σ_I B_iI = 0: linear fields give
!> exactly uniform strain and uniform stress gives self-equilibrated interior forces.
module fem_cpe4r
  use material_kinds, only: dp
  use fem_hourglass, only: hourglass_forces
  implicit none
  private

  public :: cpe4r_geometry, cpe4r_char_length, cpe4r_strain_increment, cpe4r_kinematics
  public :: cpe4r_internal_force, cpe4r_hourglass_gamma, cpe4r_hourglass

  integer, parameter, public :: cpe4r_ndim = 2, cpe4r_nen = 4, cpe4r_ncomp = 4
  integer, parameter, public :: cpe4r_nshr = 1, cpe4r_nmode = 1

  !> Hourglass base vector h = ξη at the nodes.
  real(dp), parameter :: hg_base(4) = [1.0_dp, -1.0_dp, 1.0_dp, -1.0_dp]

contains

  !> volume = t·A and the mean gradient B of a block at the configuration xe.
  pure subroutine cpe4r_geometry(nb, xe, thickness, volume, bmat)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 2, 4)
    real(dp), intent(in) :: thickness(nb)
    real(dp), intent(out) :: volume(nb)
    real(dp), intent(out) :: bmat(nb, 2, 4)
    real(dp) :: dx, dy, ex, ey, area, r2a
    integer :: e

    ! One loop on scalars. (Whole-block array statements on local copies vectorised, but the
    ! five block-sized automatic arrays are heap-allocated by gfortran: five malloc/free pairs
    ! per call, and five extra passes, cost more than the loop's scalar code.)
    do e = 1, nb
       dx = xe(e, 1, 3) - xe(e, 1, 1)
       dy = xe(e, 2, 3) - xe(e, 2, 1)
       ex = xe(e, 1, 4) - xe(e, 1, 2)
       ey = xe(e, 2, 4) - xe(e, 2, 2)
       area = 0.5_dp * (dx * ey - dy * ex)
       volume(e) = thickness(e) * area
       ! A degenerate element (A = 0) is caught by the inversion check; avoid 1/0 here.
       r2a = 1.0_dp / sign(max(abs(2.0_dp * area), tiny(1.0_dp)), area)
       bmat(e, 1, 1) = -ey * r2a
       bmat(e, 1, 2) = dy * r2a
       bmat(e, 1, 3) = ey * r2a
       bmat(e, 1, 4) = -dy * r2a
       bmat(e, 2, 1) = ex * r2a
       bmat(e, 2, 2) = -dx * r2a
       bmat(e, 2, 3) = -ex * r2a
       bmat(e, 2, 4) = dx * r2a
    end do
  end subroutine cpe4r_geometry

  !> Characteristic length L_e = A / (longest edge): the element height across its longest
  !> side (LS-DYNA's choice for quadrilaterals). L_e = h for a square of side h, for which a
  !> uniform mesh of one-point elements has ω_max = 2c/h exactly (numerics.md §3.6), so
  !> Δt = L_e/c is the exact limit there; a thin a×b rectangle gives min(a, b).
  pure subroutine cpe4r_char_length(nb, xe, char_length)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 2, 4)
    real(dp), intent(out) :: char_length(nb)
    real(dp) :: area, l2max
    integer :: e

    do e = 1, nb
       area = 0.5_dp * ((xe(e, 1, 3) - xe(e, 1, 1)) * (xe(e, 2, 4) - xe(e, 2, 2)) &
                        - (xe(e, 2, 3) - xe(e, 2, 1)) * (xe(e, 1, 4) - xe(e, 1, 2)))
       l2max = max((xe(e, 1, 2) - xe(e, 1, 1))**2 + (xe(e, 2, 2) - xe(e, 2, 1))**2, &
                   (xe(e, 1, 3) - xe(e, 1, 2))**2 + (xe(e, 2, 3) - xe(e, 2, 2))**2, &
                   (xe(e, 1, 4) - xe(e, 1, 3))**2 + (xe(e, 2, 4) - xe(e, 2, 3))**2, &
                   (xe(e, 1, 1) - xe(e, 1, 4))**2 + (xe(e, 2, 1) - xe(e, 2, 4))**2)
       char_length(e) = abs(area) / sqrt(max(l2max, tiny(1.0_dp)))
    end do
  end subroutine cpe4r_char_length

  !> Global strain and spin increments from the displacement increment du = Δt v_{n+½}, with
  !> B taken at the mid-increment configuration x_{n+½} (Abaqus: strains are measured on the
  !> mid-increment configuration; a rigid rotation then gives exactly zero strain).
  !> ΔL_ij = Σ_I du_iI B_jI; strain_inc = sym ΔL (11, 22, 33 = 0, 12 tensor shear);
  !> spin_inc(:, 1) = ΔW21 = ½(ΔL21 − ΔL12).
  pure subroutine cpe4r_strain_increment(nb, bmat_mid, du, strain_inc, spin_inc)
    integer, intent(in) :: nb
    real(dp), intent(in) :: bmat_mid(nb, 2, 4)
    real(dp), intent(in) :: du(nb, 2, 4)
    real(dp), intent(out) :: strain_inc(nb, 4)
    real(dp), intent(out) :: spin_inc(nb, 1)
    real(dp) :: l11, l12, l21, l22
    integer :: e, n

    do e = 1, nb
       l11 = 0.0_dp
       l12 = 0.0_dp
       l21 = 0.0_dp
       l22 = 0.0_dp
       do n = 1, 4
          l11 = l11 + du(e, 1, n) * bmat_mid(e, 1, n)
          l12 = l12 + du(e, 1, n) * bmat_mid(e, 2, n)
          l21 = l21 + du(e, 2, n) * bmat_mid(e, 1, n)
          l22 = l22 + du(e, 2, n) * bmat_mid(e, 2, n)
       end do
       strain_inc(e, 1) = l11
       strain_inc(e, 2) = l22
       strain_inc(e, 3) = 0.0_dp
       strain_inc(e, 4) = 0.5_dp * (l12 + l21)
       spin_inc(e, 1) = 0.5_dp * (l21 - l12)
    end do
  end subroutine cpe4r_strain_increment

  !> Everything an increment needs from the geometry, in one call:
  !> mid-increment volume and B (strain, spin, hourglass), end-of-increment volume, B (nodal
  !> forces) and characteristic length (stable increment).
  pure subroutine cpe4r_kinematics(nb, thickness, xe_mid, du, xe_new, volume_mid, bmat_mid, &
                                   strain_inc, spin_inc, volume_new, bmat_new, char_length)
    integer, intent(in) :: nb
    real(dp), intent(in) :: thickness(nb)
    real(dp), intent(in) :: xe_mid(nb, 2, 4), du(nb, 2, 4), xe_new(nb, 2, 4)
    real(dp), intent(out) :: volume_mid(nb), bmat_mid(nb, 2, 4)
    real(dp), intent(out) :: strain_inc(nb, 4), spin_inc(nb, 1)
    real(dp), intent(out) :: volume_new(nb), bmat_new(nb, 2, 4), char_length(nb)

    call cpe4r_geometry(nb, xe_mid, thickness, volume_mid, bmat_mid)
    call cpe4r_strain_increment(nb, bmat_mid, du, strain_inc, spin_inc)
    call cpe4r_geometry(nb, xe_new, thickness, volume_new, bmat_new)
    call cpe4r_char_length(nb, xe_new, char_length)
  end subroutine cpe4r_kinematics

  !> f_iI = V Σ_j σ_ij B_jI with the global stress (σ33 does no work in plane strain).
  !> Overwrites fe; hourglass and bulk-viscosity routines add to it.
  pure subroutine cpe4r_internal_force(nb, volume, bmat, stress, fe)
    integer, intent(in) :: nb
    real(dp), intent(in) :: volume(nb)
    real(dp), intent(in) :: bmat(nb, 2, 4)
    real(dp), intent(in) :: stress(nb, 4)
    real(dp), intent(out) :: fe(nb, 2, 4)
    integer :: e, n

    do n = 1, 4
       do e = 1, nb
          fe(e, 1, n) = volume(e) * (stress(e, 1) * bmat(e, 1, n) + stress(e, 4) * bmat(e, 2, n))
          fe(e, 2, n) = volume(e) * (stress(e, 4) * bmat(e, 1, n) + stress(e, 2) * bmat(e, 2, n))
       end do
    end do
  end subroutine cpe4r_internal_force

  !> Flanagan–Belytschko hourglass shape vector γ_I = h_I − (h·x) B_xI − (h·y) B_yI
  !> (unnormalised: γ = h = (1, −1, 1, −1) for a parallelogram). Orthogonal to every linear
  !> field: Σ_I γ_I = 0, Σ_I γ_I x_jI = 0. gamma (nb, 4 nodes, 1 mode).
  pure subroutine cpe4r_hourglass_gamma(nb, xe, bmat, gamma)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 2, 4), bmat(nb, 2, 4)
    real(dp), intent(out) :: gamma(nb, 4, 1)
    real(dp) :: hx(nb), hy(nb)
    integer :: n

    hx = xe(:, 1, 1) - xe(:, 1, 2) + xe(:, 1, 3) - xe(:, 1, 4)
    hy = xe(:, 2, 1) - xe(:, 2, 2) + xe(:, 2, 3) - xe(:, 2, 4)
    do n = 1, 4
       gamma(:, n, 1) = hg_base(n) - hx * bmat(:, 1, n) - hy * bmat(:, 2, n)
    end do
  end subroutine cpe4r_hourglass_gamma

  !> Hourglass forces of a block, added to fe, and the hourglass energy increment (ALLAE).
  !> kind/coefficient: fem_hourglass (hourglass_viscous with Q_v, hourglass_stiffness with κ).
  !> Per-unit-thickness scalings of fem_hourglass, times t:
  !>   viscous   C = Q_v ρ c_d t √A / 4
  !>   stiffness K = κ (λ+2μ) V Σ_iI B_iI² / 4
  !> Evaluated on the mid-increment configuration (xe_mid, volume_mid, bmat_mid), with
  !> density ρ and p-wave modulus λ+2μ per element. hg_state (nb, 2, 1): corotational
  !> hourglass generalised force of the stiffness form (zero it at the start; untouched by
  !> the viscous form). rot_mid, rot_new: R_{n+½}, R_{n+1} (fem_corotation).
  pure subroutine cpe4r_hourglass(nb, thickness, xe_mid, volume_mid, bmat_mid, du, dt, density, &
                                  modulus, kind, coefficient, rot_mid, rot_new, hg_state, fe, &
                                  energy_inc)
    integer, intent(in) :: nb
    real(dp), intent(in) :: thickness(nb)
    real(dp), intent(in) :: xe_mid(nb, 2, 4), volume_mid(nb), bmat_mid(nb, 2, 4)
    real(dp), intent(in) :: du(nb, 2, 4), dt
    real(dp), intent(in) :: density(nb), modulus(nb)
    integer, intent(in) :: kind
    real(dp), intent(in) :: coefficient
    real(dp), intent(in) :: rot_mid(nb, 2, 2), rot_new(nb, 2, 2)
    real(dp), intent(inout) :: hg_state(nb, 2, 1)
    real(dp), intent(inout) :: fe(nb, 2, 4)
    real(dp), intent(out) :: energy_inc(nb)
    real(dp) :: gamma(nb, 4, 1), visc(nb), stiff(nb), area(nb)
    integer :: i, n

    call cpe4r_hourglass_gamma(nb, xe_mid, bmat_mid, gamma)
    area = abs(volume_mid) / thickness
    ! ρ c_d = sqrt(ρ (λ+2μ))
    visc = 0.25_dp * sqrt(density * modulus) * thickness * sqrt(area)
    ! Σ_iI B_iI² accumulated in place (a sum(sum(B**2)) expression would build a block temporary)
    stiff = 0.0_dp
    do n = 1, 4
       do i = 1, 2
          stiff = stiff + bmat_mid(:, i, n)**2
       end do
    end do
    stiff = 0.25_dp * modulus * volume_mid * stiff
    call hourglass_forces(nb, 2, 4, 1, gamma, du, dt, kind, coefficient, visc, stiff, &
                          rot_mid, rot_new, hg_state, fe, energy_inc)
  end subroutine cpe4r_hourglass
end module fem_cpe4r
