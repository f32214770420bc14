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
  use base_kinds, only: dp
  use fem_hourglass, only: hourglass_viscous, hourglass_stiffness
  use fem_plane_frame, only: plane_corotational_step
  use fem_inversion, only: inversion_none, inversion_centre, inversion_corner, inversion_collapse
  implicit none
  private

  public :: cpe4r_geometry, cpe4r_char_length, cpe4r_strain_increment
  public :: cpe4r_internal_force, cpe4r_hourglass_gamma, cpe4r_hourglass, cpe4r_hourglass_update
  public :: cpe4r_increment_kinematics, cpe4r_internal_force_bv
  ! the per-element scalar kernels, shared with fem_cax4r
  public :: quad_char_length, quad_displacement_gradient, add_mode_forces, stiffness_mode_force

  integer, parameter, public :: cpe4r_ndim = 2, cpe4r_nen = 4, cpe4r_ncomp = 4
  integer, parameter, public :: cpe4r_nshr = 1, cpe4r_nmode = 1

  !> Hourglass base vector h = ξη at the nodes.
  real(dp), parameter :: hg_base(4) = [1.0_dp, -1.0_dp, 1.0_dp, -1.0_dp]

contains

  !> volume = t·A and the mean gradient B of a block at the configuration xe; t the block's
  !> section thickness (one section per block, as every CPE4R kernel takes it).
  pure subroutine cpe4r_geometry(nb, xe, thickness, volume, bmat)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 2, 4)
    real(dp), intent(in) :: thickness
    real(dp), intent(out) :: volume(nb)
    real(dp), intent(out) :: bmat(nb, 2, 4)
    real(dp) :: area
    integer :: e

    ! One loop on scalars. (Whole-block array statements on local copies vectorised, but the
    ! five block-sized automatic arrays are heap-allocated by gfortran: five malloc/free pairs
    ! per call, and five extra passes, cost more than the loop's scalar code.)
    do e = 1, nb
       call quad_geometry(xe(e, 1, 1), xe(e, 1, 2), xe(e, 1, 3), xe(e, 1, 4), xe(e, 2, 1), xe(e, 2, 2), &
            xe(e, 2, 3), xe(e, 2, 4), thickness, area, volume(e), bmat(e, 1, 1), bmat(e, 1, 2), &
            bmat(e, 1, 3), bmat(e, 1, 4), bmat(e, 2, 1), bmat(e, 2, 2), bmat(e, 2, 3), bmat(e, 2, 4))
    end do
  end subroutine cpe4r_geometry

  !> Characteristic length L_e = A / (longest edge): the element height across its longest
  !> side (LS-DYNA's choice for quadrilaterals). L_e = h for a square of side h, for which a
  !> uniform mesh of one-point elements has ω_max = 2c/h exactly (docs/theory/elements.md §3.6), so
  !> Δt = L_e/c is the exact limit there; a thin a×b rectangle gives min(a, b).
  pure subroutine cpe4r_char_length(nb, xe, char_length)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 2, 4)
    real(dp), intent(out) :: char_length(nb)
    real(dp) :: area
    integer :: e

    do e = 1, nb
       area = 0.5_dp * ((xe(e, 1, 3) - xe(e, 1, 1)) * (xe(e, 2, 4) - xe(e, 2, 2)) &
                        - (xe(e, 2, 3) - xe(e, 2, 1)) * (xe(e, 1, 4) - xe(e, 1, 2)))
       char_length(e) = quad_char_length(xe(e, 1, 1), xe(e, 1, 2), xe(e, 1, 3), xe(e, 1, 4), xe(e, 2, 1), &
            xe(e, 2, 2), xe(e, 2, 3), xe(e, 2, 4), area)
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
    integer :: e

    do e = 1, nb
       call quad_displacement_gradient(du(e, 1, 1), du(e, 1, 2), du(e, 1, 3), du(e, 1, 4), du(e, 2, 1), &
            du(e, 2, 2), du(e, 2, 3), du(e, 2, 4), bmat_mid(e, 1, 1), bmat_mid(e, 1, 2), bmat_mid(e, 1, 3), &
            bmat_mid(e, 1, 4), bmat_mid(e, 2, 1), bmat_mid(e, 2, 2), bmat_mid(e, 2, 3), bmat_mid(e, 2, 4), &
            l11, l12, l21, l22)
       strain_inc(e, 1) = l11
       strain_inc(e, 2) = l22
       strain_inc(e, 3) = 0.0_dp
       strain_inc(e, 4) = 0.5_dp * (l12 + l21)
       spin_inc(e, 1) = 0.5_dp * (l21 - l12)
    end do
  end subroutine cpe4r_strain_increment

  !> The solver's whole pre-material pass of a CPE4R block in one element loop: the work of
  !> cpe4r_geometry on x_{n+½} and x_{n+1}, cpe4r_strain_increment, cpe4r_char_length,
  !> fem_inversion's check_inversion (2D), fem_corotation's
  !> corotational_increment (2D), the current density and the hourglass shape vector γ.
  !> Why one loop: each of those passes streamed the block's coordinates, B matrices and
  !> rotations through the cache again (the block's (nb, 2, 4) arrays do not fit in L1), and
  !> the gather wrote x_{n+½} and x_{n+1} only for them to read back; here they are formed in
  !> registers from x_n and du with the gather's expressions. Every quantity is the same
  !> expression, in the same order, as in those routines, so the results are the same to the bit.
  !> xe_old = x_n, du = Δt v_{n+½} (the gather); x_{n+½} = x_n + ½du, x_{n+1} = x_n + du.
  !> xe_ref = the reference coordinates X, from which the reference mean gradient B0 and volume
  !> are formed again with cpe4r_geometry's expressions (the same bits as the set-up's): the
  !> gather reads X anyway, and 72 bytes per element and increment of stored B0 and V0 were a
  !> fifth of what the pass read from memory. The element mass is ρ0 V0 formed as the set-up
  !> forms it (density0 × the same V0: the same bits as the block's mass); r_old = R_n in the plane
  !> form (cos θ, sin θ) (fem_corotation's rotation_matrix); r_plane: R_{n+1} in that form.
  !> Out: volume_mid, strain_inc (global), volume_new, bmat_new, char_length,
  !> volume_abs = |volume_mid|, density = mass/|volume_mid|, reason (fem_inversion codes,
  !> check_inversion's order of tests), as corotational_increment r_mid, r_new, f_new,
  !> strain_inc_corot, rel_spin, and for cpe4r_hourglass_update, in place of B_{n+½}: gamma
  !> (nb, 4), γ of x_{n+½} (cpe4r_hourglass_gamma), and bsq = Σ_iI B_iI² of B_{n+½} (the
  !> stiffness form's scale, summed in its order).
  pure subroutine cpe4r_increment_kinematics(nb, thickness, xe_old, du, xe_ref, &
       min_volume_ratio, density0, r_old, volume_mid, volume_abs, density, gamma, bsq, &
       strain_inc, volume_new, bmat_new, char_length, reason, r_mid, r_new, r_plane, f_new, &
       strain_inc_corot, rel_spin)
    integer, intent(in) :: nb
    ! thickness, density0: the block's section thickness and material density (one section
    ! and one material per block: two scalars, not two arrays read per element)
    real(dp), intent(in) :: thickness, xe_old(nb, 2, 4), du(nb, 2, 4), xe_ref(nb, 2, 4)
    real(dp), intent(in) :: min_volume_ratio, density0, r_old(nb, 2, 1)
    real(dp), intent(out) :: volume_mid(nb), volume_abs(nb), density(nb), gamma(nb, 4), bsq(nb)
    real(dp), intent(out) :: strain_inc(nb, 4), volume_new(nb), bmat_new(nb, 2, 4)
    real(dp), intent(out) :: char_length(nb)
    integer, intent(out) :: reason(nb)
    real(dp), intent(out) :: r_mid(nb, 2, 2), r_new(nb, 2, 2), r_plane(nb, 2, 1), f_new(nb, 2, 2)
    real(dp), intent(out) :: strain_inc_corot(nb, 4), rel_spin(nb, 1)
    ! x_{n+½} (m) and x_{n+1} (n) of the four nodes
    real(dp) :: mx1, mx2, mx3, mx4, my1, my2, my3, my4, nx1, nx2, nx3, nx4, ny1, ny2, ny3, ny4
    real(dp) :: area, vol, jmin, hx, hy
    real(dp) :: b11, b12, b13, b14, b21, b22, b23, b24, l11, l12, l21, l22, spin
    real(dp) :: r11, r12, r13, r14, r21, r22, r23, r24, vol_ref
    integer :: e, r

    ! ivdep: the dummies do not alias (Fortran); the compiler's run-time alias checks for this
    ! many arrays exceed its limit and it would leave the loop scalar.
    !GCC$ ivdep
    do e = 1, nb
       ! the gather's x_{n+½} = x_n + ½ du and x_{n+1} = x_n + du
       mx1 = xe_old(e, 1, 1) + 0.5_dp * du(e, 1, 1)
       mx2 = xe_old(e, 1, 2) + 0.5_dp * du(e, 1, 2)
       mx3 = xe_old(e, 1, 3) + 0.5_dp * du(e, 1, 3)
       mx4 = xe_old(e, 1, 4) + 0.5_dp * du(e, 1, 4)
       my1 = xe_old(e, 2, 1) + 0.5_dp * du(e, 2, 1)
       my2 = xe_old(e, 2, 2) + 0.5_dp * du(e, 2, 2)
       my3 = xe_old(e, 2, 3) + 0.5_dp * du(e, 2, 3)
       my4 = xe_old(e, 2, 4) + 0.5_dp * du(e, 2, 4)
       nx1 = xe_old(e, 1, 1) + du(e, 1, 1)
       nx2 = xe_old(e, 1, 2) + du(e, 1, 2)
       nx3 = xe_old(e, 1, 3) + du(e, 1, 3)
       nx4 = xe_old(e, 1, 4) + du(e, 1, 4)
       ny1 = xe_old(e, 2, 1) + du(e, 2, 1)
       ny2 = xe_old(e, 2, 2) + du(e, 2, 2)
       ny3 = xe_old(e, 2, 3) + du(e, 2, 3)
       ny4 = xe_old(e, 2, 4) + du(e, 2, 4)

       ! reference B0 and V0 (cpe4r_geometry on X, as the set-up formed them)
       call quad_geometry(xe_ref(e, 1, 1), xe_ref(e, 1, 2), xe_ref(e, 1, 3), xe_ref(e, 1, 4), &
            xe_ref(e, 2, 1), xe_ref(e, 2, 2), xe_ref(e, 2, 3), xe_ref(e, 2, 4), thickness, area, &
            vol_ref, r11, r12, r13, r14, r21, r22, r23, r24)

       ! x_{n+½}: volume and B (cpe4r_geometry), density, γ and Σ B² (cpe4r_hourglass_gamma,
       ! cpe4r_hourglass_update)
       call quad_geometry(mx1, mx2, mx3, mx4, my1, my2, my3, my4, thickness, area, vol, &
            b11, b12, b13, b14, b21, b22, b23, b24)
       volume_mid(e) = vol
       volume_abs(e) = abs(vol)
       ! Guarded (the max changes nothing for any valid element): the inversion check now runs
       ! in this same loop, after which the driver stops, so an inverted or collapsed element
       ! must not trap here (the debug build traps on 1/0 and 0/0).
       density(e) = (density0 * vol_ref) / max(abs(vol), tiny(1.0_dp))
       hx = mx1 - mx2 + mx3 - mx4
       hy = my1 - my2 + my3 - my4
       gamma(e, 1) = hg_base(1) - hx * b11 - hy * b21
       gamma(e, 2) = hg_base(2) - hx * b12 - hy * b22
       gamma(e, 3) = hg_base(3) - hx * b13 - hy * b23
       gamma(e, 4) = hg_base(4) - hx * b14 - hy * b24
       bsq(e) = ((((((((0.0_dp + b11**2) + b21**2) + b12**2) + b22**2) + b13**2) + b23**2) &
            + b14**2) + b24**2)
       ! strain and spin increments (cpe4r_strain_increment)
       call quad_displacement_gradient(du(e, 1, 1), du(e, 1, 2), du(e, 1, 3), du(e, 1, 4), du(e, 2, 1), &
            du(e, 2, 2), du(e, 2, 3), du(e, 2, 4), b11, b12, b13, b14, b21, b22, b23, b24, &
            l11, l12, l21, l22)
       strain_inc(e, 1) = l11
       strain_inc(e, 2) = l22
       strain_inc(e, 3) = 0.0_dp
       strain_inc(e, 4) = 0.5_dp * (l12 + l21)
       spin = 0.5_dp * (l21 - l12)

       ! x_{n+1}: volume and B (cpe4r_geometry), L_e (cpe4r_char_length)
       call quad_geometry(nx1, nx2, nx3, nx4, ny1, ny2, ny3, ny4, thickness, area, vol, &
            bmat_new(e, 1, 1), bmat_new(e, 1, 2), bmat_new(e, 1, 3), bmat_new(e, 1, 4), &
            bmat_new(e, 2, 1), bmat_new(e, 2, 2), bmat_new(e, 2, 3), bmat_new(e, 2, 4))
       volume_new(e) = vol
       char_length(e) = quad_char_length(nx1, nx2, nx3, nx4, ny1, ny2, ny3, ny4, area)

       ! check_inversion_2d on x_{n+1}: corner values ξ_I η_I (x_nξ − x_I) × (x_nη − x_I) in
       ! node order (neighbours 2,4 / 1,3 / 4,2 / 3,1; sign +, −, +, −), their running minimum
       jmin = huge(1.0_dp)
       jmin = min(jmin, 1.0_dp * ((nx2 - nx1) * (ny4 - ny1) - (ny2 - ny1) * (nx4 - nx1)))
       jmin = min(jmin, -1.0_dp * ((nx1 - nx2) * (ny3 - ny2) - (ny1 - ny2) * (nx3 - nx2)))
       jmin = min(jmin, 1.0_dp * ((nx4 - nx3) * (ny2 - ny3) - (ny4 - ny3) * (nx2 - nx3)))
       jmin = min(jmin, -1.0_dp * ((nx3 - nx4) * (ny1 - ny4) - (ny3 - ny4) * (nx1 - nx4)))
       r = inversion_none
       if (vol < min_volume_ratio * vol_ref) r = inversion_collapse
       if (jmin <= 0.0_dp) r = inversion_corner
       if (vol <= 0.0_dp) r = inversion_centre
       reason(e) = r

       ! corotational_increment_2d: F_{n+½} and R_{n+½}, F_{n+1} and R_{n+1}, strainInc =
       ! R_{n+½}ᵀ Δε R_{n+½}, relSpinInc with ΔR = R_{n+1} R_nᵀ, R_n = [c −s; s c] (plane form)
       call plane_corotational_step(mx2 - mx1, mx3 - mx1, mx4 - mx1, my2 - my1, my3 - my1, my4 - my1, &
            nx2 - nx1, nx3 - nx1, nx4 - nx1, ny2 - ny1, ny3 - ny1, ny4 - ny1, r12, r13, r14, r22, r23, r24, &
            l11, l22, 0.5_dp * (l12 + l21), spin, r_old(e, 1, 1), r_old(e, 2, 1), &
            r_mid(e, 1, 1), r_mid(e, 2, 1), r_mid(e, 1, 2), r_mid(e, 2, 2), &
            f_new(e, 1, 1), f_new(e, 2, 1), f_new(e, 1, 2), f_new(e, 2, 2), &
            r_new(e, 1, 1), r_new(e, 2, 1), r_new(e, 1, 2), r_new(e, 2, 2), &
            strain_inc_corot(e, 1), strain_inc_corot(e, 2), strain_inc_corot(e, 4), rel_spin(e, 1))
       strain_inc_corot(e, 3) = 0.0_dp
       r_plane(e, 1, 1) = r_new(e, 1, 1)
       r_plane(e, 2, 1) = r_new(e, 2, 1)
    end do
  end subroutine cpe4r_increment_kinematics

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

  !> cpe4r_internal_force of the stress plus the isotropic bulk-viscosity stress σ_bv (added to
  !> 11 and 22 here, with the sums the solver formed in a copy of the stress before: bitwise the
  !> same forces, without that copy and its passes). Overwrites fe.
  pure subroutine cpe4r_internal_force_bv(nb, volume, bmat, stress, sigma_bv, fe)
    integer, intent(in) :: nb
    real(dp), intent(in) :: volume(nb)
    real(dp), intent(in) :: bmat(nb, 2, 4)
    real(dp), intent(in) :: stress(nb, 4), sigma_bv(nb)
    real(dp), intent(out) :: fe(nb, 2, 4)
    real(dp) :: s11, s22
    integer :: e, n

    do n = 1, 4
       do e = 1, nb
          s11 = stress(e, 1) + sigma_bv(e)
          s22 = stress(e, 2) + sigma_bv(e)
          fe(e, 1, n) = volume(e) * (s11 * bmat(e, 1, n) + stress(e, 4) * bmat(e, 2, n))
          fe(e, 2, n) = volume(e) * (stress(e, 4) * bmat(e, 1, n) + s22 * bmat(e, 2, n))
       end do
    end do
  end subroutine cpe4r_internal_force_bv

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
  !> energy_inc is the kernel's own increment (C q²/Δt, resp. ½ (Q^c_old + Q^c_new)·qc); the
  !> solver books the trapezoidal work of cpe4r_hourglass_update instead.
  pure subroutine cpe4r_hourglass(nb, thickness, xe_mid, volume_mid, bmat_mid, du, dt, density, &
                                  modulus, kind, coefficient, rot_mid, rot_new, hg_state, fe, &
                                  energy_inc)
    integer, intent(in) :: nb
    real(dp), intent(in) :: thickness
    real(dp), intent(in) :: xe_mid(nb, 2, 4), volume_mid(nb), bmat_mid(nb, 2, 4)
    real(dp), intent(in) :: du(nb, 2, 4), dt
    real(dp), intent(in) :: density(nb), modulus(nb)
    integer, intent(in) :: kind
    real(dp), intent(in) :: coefficient
    real(dp), intent(in) :: rot_mid(nb, 2, 2), rot_new(nb, 2, 2)
    real(dp), intent(inout) :: hg_state(nb, 2, 1)
    real(dp), intent(inout) :: fe(nb, 2, 4)
    real(dp), intent(out) :: energy_inc(nb)
    real(dp), allocatable :: force_hg(:, :, :), work(:), gamma(:, :, :), bsq(:)
    integer :: n, i

    ! Not on the solver's path (tests, single elements): the extra arrays may be allocated.
    allocate(force_hg(nb, 2, 1), work(nb), gamma(nb, 4, 1), bsq(nb))
    force_hg = 0.0_dp
    ! γ and Σ B² as cpe4r_increment_kinematics forms them
    call cpe4r_hourglass_gamma(nb, xe_mid, bmat_mid, gamma)
    bsq = 0.0_dp
    do n = 1, 4
       do i = 1, 2
          bsq = bsq + bmat_mid(:, i, n)**2
       end do
    end do
    call cpe4r_hourglass_update(nb, thickness, gamma(:, :, 1), bsq, volume_mid, du, dt, density, &
         modulus, kind, coefficient, rot_mid, rot_new, hg_state, fe, force_hg, energy_inc, work)
  end subroutine cpe4r_hourglass

  !> cpe4r_hourglass as the solver uses it: one element loop on scalars (no block temporaries,
  !> every element read once), which also books the hourglass work.
  !> gamma (nb, 4): γ of x_{n+½}; bsq (nb): Σ_iI B_iI² of B_{n+½} (read by the stiffness form
  !> only); both from cpe4r_increment_kinematics, in place of x_{n+½} and B_{n+½}.
  !> fe (nb, 2, 4): in, the block's forces without hourglass; out, with the hourglass forces.
  !> force_hg (nb, 2, 1): in, the generalised hourglass force Q_n of t_n (the nodal forces are
  !> f_iI = Q_i γ_I); out, Q_{n+1}.
  !> work (nb): ½ (Q_n + Q_{n+1})·q with q_i = Σ_I γ_I du_iI: the trapezoidal work
  !> ½ Σ_iI (f_n + f_{n+1})_iI du_iI of the hourglass forces over the increment, as the energy
  !> balance charges it (ALLAE), with f_n taken on this increment's γ — which moves by the order
  !> of a strain increment per increment. (The eight nodal forces of t_n, kept before, were
  !> 8 values read and 8 written per element and increment: a sixth of the element loop's
  !> memory traffic, for a difference in ALLAE at round-off level.)
  !> The forces and their sums are those of cpe4r_hourglass_gamma and fem_hourglass's
  !> hourglass_forces, so the forces are bitwise the same.
  pure subroutine cpe4r_hourglass_update(nb, thickness, gamma, bsq, volume_mid, du, dt, density, &
                                         modulus, kind, coefficient, rot_mid, rot_new, hg_state, &
                                         fe, force_hg, energy_inc, work)
    integer, intent(in) :: nb
    real(dp), intent(in) :: thickness                !< the block's section thickness
    real(dp), intent(in) :: gamma(nb, 4), bsq(nb), volume_mid(nb)
    real(dp), intent(in) :: du(nb, 2, 4), dt
    real(dp), intent(in) :: density(nb), modulus(nb)
    integer, intent(in) :: kind
    real(dp), intent(in) :: coefficient
    real(dp), intent(in) :: rot_mid(nb, 2, 2), rot_new(nb, 2, 2)
    real(dp), intent(inout) :: hg_state(nb, 2, 1)
    real(dp), intent(inout) :: fe(nb, 2, 4)
    real(dp), intent(inout) :: force_hg(nb, 2, 1)
    real(dp), intent(out) :: energy_inc(nb), work(nb)
    real(dp) :: g1, g2, g3, g4, q1, q2, qg1, qg2, area, scale, c, dtm
    integer :: e

    dtm = max(dt, tiny(1.0_dp))
    if (kind == hourglass_viscous) then
       ! The usual form, on its own loop: without the branch on kind it vectorises. (The
       ! dummies cannot alias, which ivdep tells the compiler: its run-time alias checks for
       ! this many arrays exceed its limit, and it then left the loop scalar.)
       !GCC$ ivdep
       do e = 1, nb
          ! γ_I = h_I − (h·x) B_xI − (h·y) B_yI (cpe4r_hourglass_gamma)
          g1 = gamma(e, 1)
          g2 = gamma(e, 2)
          g3 = gamma(e, 3)
          g4 = gamma(e, 4)
          ! q_i = Σ_I γ_I du_iI
          q1 = (((0.0_dp + g1 * du(e, 1, 1)) + g2 * du(e, 1, 2)) + g3 * du(e, 1, 3)) + g4 * du(e, 1, 4)
          q2 = (((0.0_dp + g1 * du(e, 2, 1)) + g2 * du(e, 2, 2)) + g3 * du(e, 2, 3)) + g4 * du(e, 2, 4)
          ! generalised force C q/Δt and energy C q²/Δt
          area = abs(volume_mid(e)) / thickness
          scale = 0.25_dp * sqrt(density(e) * modulus(e)) * thickness * sqrt(area)
          c = coefficient * scale / dtm
          qg1 = c * q1
          qg2 = c * q2
          energy_inc(e) = (0.0_dp + qg1 * q1) + qg2 * q2
          ! f_iI += qg_i γ_I; the trapezoidal work with the generalised forces
          call add_mode_forces(g1, g2, g3, g4, q1, q2, qg1, qg2, fe(e, 1, 1), fe(e, 2, 1), fe(e, 1, 2), &
               fe(e, 2, 2), fe(e, 1, 3), fe(e, 2, 3), fe(e, 1, 4), fe(e, 2, 4), force_hg(e, 1, 1), &
               force_hg(e, 2, 1), work(e))
       end do
       return
    end if

    ! Stiffness form, or none: the same steps with the generalised force of that form.
    do e = 1, nb
       g1 = gamma(e, 1)
       g2 = gamma(e, 2)
       g3 = gamma(e, 3)
       g4 = gamma(e, 4)
       q1 = (((0.0_dp + g1 * du(e, 1, 1)) + g2 * du(e, 1, 2)) + g3 * du(e, 1, 3)) + g4 * du(e, 1, 4)
       q2 = (((0.0_dp + g1 * du(e, 2, 1)) + g2 * du(e, 2, 2)) + g3 * du(e, 2, 3)) + g4 * du(e, 2, 4)
       if (kind == hourglass_stiffness) then
          ! Σ_iI B_iI² (in the order of the node loop)
          scale = 0.25_dp * modulus(e) * volume_mid(e) * bsq(e)
          c = coefficient * scale
          call stiffness_mode_force(c, q1, q2, rot_mid(e, 1, 1), rot_mid(e, 2, 1), rot_mid(e, 1, 2), &
               rot_mid(e, 2, 2), rot_new(e, 1, 1), rot_new(e, 2, 1), rot_new(e, 1, 2), rot_new(e, 2, 2), &
               hg_state(e, 1, 1), hg_state(e, 2, 1), qg1, qg2, energy_inc(e))
       else
          ! no hourglass control: no force (fe + 0 = fe below), no energy
          qg1 = 0.0_dp
          qg2 = 0.0_dp
          energy_inc(e) = 0.0_dp
       end if
       call add_mode_forces(g1, g2, g3, g4, q1, q2, qg1, qg2, fe(e, 1, 1), fe(e, 2, 1), fe(e, 1, 2), &
            fe(e, 2, 2), fe(e, 1, 3), fe(e, 2, 3), fe(e, 1, 4), fe(e, 2, 4), force_hg(e, 1, 1), &
            force_hg(e, 2, 1), work(e))
    end do
  end subroutine cpe4r_hourglass_update

  !> The stiffness form's generalised force of one element (stiffness c = κ K): qc = R_{n+½}ᵀ q,
  !> Q^c += c qc (h, the corotational state, in and out), qg = R_{n+1} Q^c, and its energy
  !> ½ (Q^c_old + Q^c_new)·qc. r_ij: R_{n+½}, n_ij: R_{n+1}.
  elemental subroutine stiffness_mode_force(c, q1, q2, r11, r21, r12, r22, n11, n21, n12, n22, h1, h2, &
                                            qg1, qg2, energy)
    real(dp), intent(in) :: c, q1, q2, r11, r21, r12, r22, n11, n21, n12, n22
    real(dp), intent(inout) :: h1, h2
    real(dp), intent(out) :: qg1, qg2, energy
    real(dp) :: qc1, qc2

    qc1 = (0.0_dp + r11 * q1) + r21 * q2
    qc2 = (0.0_dp + r12 * q1) + r22 * q2
    energy = (0.0_dp + (h1 + 0.5_dp * c * qc1) * qc1) + (h2 + 0.5_dp * c * qc2) * qc2
    h1 = h1 + c * qc1
    h2 = h2 + c * qc2
    qg1 = (0.0_dp + n11 * h1) + n12 * h2
    qg2 = (0.0_dp + n21 * h1) + n22 * h2
  end subroutine stiffness_mode_force

  !> One element's hourglass mode in both loops of cpe4r_hourglass_update: f_iI += Q_i γ_I,
  !> work = ½ (Q_n + Q_{n+1})·q, and Q_{n+1} = Q kept (q_old in, out).
  elemental subroutine add_mode_forces(g1, g2, g3, g4, q1, q2, qg1, qg2, f11, f21, f12, f22, f13, f23, &
                                       f14, f24, q_old1, q_old2, work)
    real(dp), intent(in) :: g1, g2, g3, g4, q1, q2, qg1, qg2
    real(dp), intent(inout) :: f11, f21, f12, f22, f13, f23, f14, f24, q_old1, q_old2
    real(dp), intent(out) :: work

    f11 = f11 + qg1 * g1
    f21 = f21 + qg2 * g1
    f12 = f12 + qg1 * g2
    f22 = f22 + qg2 * g2
    f13 = f13 + qg1 * g3
    f23 = f23 + qg2 * g3
    f14 = f14 + qg1 * g4
    f24 = f24 + qg2 * g4
    work = 0.5_dp * (q_old1 + qg1) * q1 + 0.5_dp * (q_old2 + qg2) * q2
    q_old1 = qg1
    q_old2 = qg2
  end subroutine add_mode_forces
  !> Area A, volume t·A and mean gradient B of one element from its node coordinates (the
  !> formulas of the module header). A degenerate element (A = 0) is caught by the inversion
  !> check; the guard only avoids 1/0 here.
  elemental subroutine quad_geometry(x1, x2, x3, x4, y1, y2, y3, y4, thickness, area, volume, &
                                     b11, b12, b13, b14, b21, b22, b23, b24)
    real(dp), intent(in) :: x1, x2, x3, x4, y1, y2, y3, y4, thickness
    real(dp), intent(out) :: area, volume, b11, b12, b13, b14, b21, b22, b23, b24
    real(dp) :: dx, dy, ex, ey, r2a

    dx = x3 - x1
    dy = y3 - y1
    ex = x4 - x2
    ey = y4 - y2
    area = 0.5_dp * (dx * ey - dy * ex)
    volume = thickness * area
    r2a = 1.0_dp / sign(max(abs(2.0_dp * area), tiny(1.0_dp)), area)
    b11 = -ey * r2a
    b12 = dy * r2a
    b13 = ey * r2a
    b14 = -dy * r2a
    b21 = ex * r2a
    b22 = -dx * r2a
    b23 = -ex * r2a
    b24 = dx * r2a
  end subroutine quad_geometry

  !> L_e = |A| / (longest edge) of one element (cpe4r_char_length).
  elemental real(dp) function quad_char_length(x1, x2, x3, x4, y1, y2, y3, y4, area) result(char_length)
    real(dp), intent(in) :: x1, x2, x3, x4, y1, y2, y3, y4, area
    real(dp) :: l2max

    l2max = max((x2 - x1)**2 + (y2 - y1)**2, (x3 - x2)**2 + (y3 - y2)**2, &
                (x4 - x3)**2 + (y4 - y3)**2, (x1 - x4)**2 + (y1 - y4)**2)
    char_length = abs(area) / sqrt(max(l2max, tiny(1.0_dp)))
  end function quad_char_length

  !> ΔL_ij = Σ_I du_iI B_jI of one element, summed from 0 in node order (cpe4r_strain_increment).
  elemental subroutine quad_displacement_gradient(u1, u2, u3, u4, v1, v2, v3, v4, b11, b12, b13, b14, &
                                                  b21, b22, b23, b24, l11, l12, l21, l22)
    real(dp), intent(in) :: u1, u2, u3, u4, v1, v2, v3, v4
    real(dp), intent(in) :: b11, b12, b13, b14, b21, b22, b23, b24
    real(dp), intent(out) :: l11, l12, l21, l22

    l11 = (((0.0_dp + u1 * b11) + u2 * b12) + u3 * b13) + u4 * b14
    l12 = (((0.0_dp + u1 * b21) + u2 * b22) + u3 * b23) + u4 * b24
    l21 = (((0.0_dp + v1 * b11) + v2 * b12) + v3 * b13) + v4 * b14
    l22 = (((0.0_dp + v1 * b21) + v2 * b22) + v3 * b23) + v4 * b24
  end subroutine quad_displacement_gradient
end module fem_cpe4r
