!> CAX4R: 4-node axisymmetric quadrilateral (x = r, y = z), one-point (uniform strain)
!> quadrature, for blocks of nb elements (element index first), the sibling of fem_cpe4r.
!>
!> The element is the full 360° ring: volume V = 2π ∫ r dA, so masses, internal forces and
!> energies are those of the whole ring (Abaqus's convention for concentrated loads and
!> reaction forces on axisymmetric models; docs/theory/elements.md §3.10).
!>
!> Uniform strain: B̄ = (1/V) ∫_V B dV, every integral exact (2×2 Gauss is exact for these
!> polynomials of the bilinear map), with S = ∫ r dA:
!>   B_rI = (1/S) ∫ r ∂N_I/∂r dA,  B_zI = (1/S) ∫ r ∂N_I/∂z dA,  B_θI = (1/S) ∫ N_I dA.
!> Σ_I B_rI r_I = Σ_I B_zI z_I = 1, Σ_I B_rI z_I = Σ_I B_zI r_I = 0, Σ_I B_θI r_I = 1: the field
!> u_r = a r, u_z = c z (+ a z translation) gives exactly Δε = (a, c, a, 0). On a rectangle
!> aligned with the axes the r row is the plane mean gradient and the hoop row is N_I(0)/r̄ (the
!> hoop row at the centroid radius r̄); the z row weights the nodes by their radius. With
!> S = ∫ r dA: S B_zI = ∂S/∂z_I and S (B_rI + B_θI) = ∂S/∂r_I, so uniform stress with
!> σ_rr = σ_θθ leaves every interior node balanced, whatever the distortion.
!> Nodal masses: m_I = ρ 2π ∫ N_I r dA (share_I = ∫ N_I r dA / S), the row sum of the
!> consistent ring mass; gravity loads m_I g are then the consistent ones.
!> Stable increment: L_e = 1/√(1/L_p² + 3 Σ_I B_θI²), L_p = A / longest edge (CPE4R's);
!> the hoop term keeps ω_max L_e at most that of the plane-strain element of the same shape
!> (docs/theory/elements.md §3.10).
!> Components (nb, 4): 11 = rr, 22 = zz, 33 = θθ, 12 = rz (tensor shear), as Abaqus passes them.
module fem_cax4r
  use base_kinds, only: dp
  use fem_hourglass, only: hourglass_viscous, hourglass_stiffness
  use fem_plane_frame, only: plane_corotational_step
  use fem_inversion, only: inversion_none, inversion_centre, inversion_corner, inversion_collapse, &
       inversion_axis
  use fem_cpe4r, only: quad_char_length, quad_displacement_gradient, add_mode_forces, stiffness_mode_force
  implicit none
  private

  public :: cax4r_geometry, cax4r_char_length, cax4r_increment_kinematics, cax4r_internal_force
  public :: cax4r_hourglass_update, cax4r_hoop_stretch

  real(dp), parameter :: two_pi = 6.283185307179586476925286766559_dp
  !> 1/√3, the 2×2 Gauss abscissa
  real(dp), parameter :: gauss = 0.57735026918962576450914878050196_dp
  real(dp), parameter :: xi_node(4) = [-1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp]
  real(dp), parameter :: eta_node(4) = [-1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp]
  real(dp), parameter :: hg_base(4) = [1.0_dp, -1.0_dp, 1.0_dp, -1.0_dp]
  !> weight of Σ B_θ² in L_e (chosen with the element eigenvalues, docs/theory/elements.md §3.10)
  real(dp), parameter :: hoop_dt_weight = 3.0_dp

contains

  !> Area A, ring volume V = 2π ∫ r dA, the rows B_r, B_z, B_θ of B̄ and the mass shares of one
  !> element (module header). r, z: node coordinates. A degenerate ring (∫ r dA = 0) is caught
  !> by the inversion check; the guard only avoids 1/0.
  pure subroutine ring_geometry(r, z, area, volume, br, bz, bt, share)
    real(dp), intent(in) :: r(4), z(4)
    real(dp), intent(out) :: area, volume, br(4), bz(4), bt(4), share(4)
    real(dp) :: xi, eta, n(4), nxi(4), neta(4), rxi, zxi, reta, zeta, jac, rg, ring, inv
    integer :: k

    area = 0
    ring = 0
    br = 0
    bz = 0
    bt = 0
    share = 0
    do k = 1, 4
       xi = gauss * xi_node(k)
       eta = gauss * eta_node(k)
       n = 0.25_dp * (1 + xi_node * xi) * (1 + eta_node * eta)
       nxi = 0.25_dp * xi_node * (1 + eta_node * eta)
       neta = 0.25_dp * eta_node * (1 + xi_node * xi)
       rxi = sum(nxi * r)
       zxi = sum(nxi * (z - z(1)))
       reta = sum(neta * r)
       zeta = sum(neta * (z - z(1)))
       jac = rxi * zeta - zxi * reta
       rg = sum(n * r)
       area = area + jac
       ring = ring + rg * jac
       ! r ∂N/∂r det J and r ∂N/∂z det J (det J cancels: no division per point)
       br = br + rg * (zeta * nxi - zxi * neta)
       bz = bz + rg * (rxi * neta - reta * nxi)
       bt = bt + n * jac
       share = share + n * rg * jac
    end do
    volume = two_pi * ring
    inv = 1.0_dp / sign(max(abs(ring), tiny(1.0_dp)), ring)
    br = br * inv
    bz = bz * inv
    bt = bt * inv
    share = share * inv
  end subroutine ring_geometry

  !> V (ring volume), B̄ (nb, 2, 4) rows r, z, the hoop row (nb, 4) and the nodal mass shares
  !> (nb, 4) of a block at the configuration xe.
  pure subroutine cax4r_geometry(nb, xe, volume, bmat, bhoop, share)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 2, 4)
    real(dp), intent(out) :: volume(nb), bmat(nb, 2, 4), bhoop(nb, 4), share(nb, 4)
    real(dp) :: area, br(4), bz(4), bt(4), sh(4)
    integer :: e

    do e = 1, nb
       call ring_geometry(xe(e, 1, :), xe(e, 2, :), area, volume(e), br, bz, bt, sh)
       bmat(e, 1, :) = br
       bmat(e, 2, :) = bz
       bhoop(e, :) = bt
       share(e, :) = sh
    end do
  end subroutine cax4r_geometry

  !> L_e = 1/√(1/L_p² + 3 Σ B_θ²) with L_p = A / longest edge (module header).
  pure subroutine cax4r_char_length(nb, xe, char_length)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe(nb, 2, 4)
    real(dp), intent(out) :: char_length(nb)
    real(dp) :: area, volume, br(4), bz(4), bt(4), sh(4)
    integer :: e

    do e = 1, nb
       call ring_geometry(xe(e, 1, :), xe(e, 2, :), area, volume, br, bz, bt, sh)
       char_length(e) = ring_char_length(xe(e, 1, :), xe(e, 2, :), area, bt)
    end do
  end subroutine cax4r_char_length

  pure real(dp) function ring_char_length(r, z, area, bt) result(char_length)
    real(dp), intent(in) :: r(4), z(4), area, bt(4)
    real(dp) :: lp

    lp = quad_char_length(r(1), r(2), r(3), r(4), z(1), z(2), z(3), z(4), area)
    char_length = 1.0_dp / sqrt(1.0_dp / max(lp, tiny(1.0_dp))**2 + hoop_dt_weight * sum(bt**2))
  end function ring_char_length

  !> Hoop stretch r̄/R̄ of each element (ratio of the mean nodal radii of x and X): F33 and U33
  !> of the VUMAT's defgrad and stretch (plane F33 = 1 otherwise).
  pure subroutine cax4r_hoop_stretch(nb, xe_ref, xe, stretch)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe_ref(nb, 2, 4), xe(nb, 2, 4)
    real(dp), intent(out) :: stretch(nb)
    integer :: e

    do e = 1, nb
       stretch(e) = sum(xe(e, 1, :)) / max(sum(xe_ref(e, 1, :)), tiny(1.0_dp))
    end do
  end subroutine cax4r_hoop_stretch

  !> The whole pre-material pass of a CAX4R block in one element loop (cpe4r_increment_kinematics'
  !> sibling): x_{n+½} = x_n + ½du and x_{n+1} = x_n + du; on x_{n+½} the volume, density
  !> ρ0 V0 / |V|, hourglass γ, Σ(B_r² + B_z²), the global strain increment (rr, zz, θθ = Σ du_r B_θ,
  !> rz) and spin; on x_{n+1} the volume, B̄ rows and L_e; the inversion check (centre, corner,
  !> collapse, and a node crossing the axis r < 0); the Green–Naghdi frame in the r–z plane
  !> (θ is a principal direction: the hoop component is not rotated), strainInc and relSpinInc.
  !> bmat_ref, volume_ref: the set-up's B̄ and V of X (F = Σ (x_I − x_1) ⊗ B0_I is exact for
  !> affine motions in the plane).
  pure subroutine cax4r_increment_kinematics(nb, xe_old, du, bmat_ref, volume_ref, min_volume_ratio, &
       density0, r_old, volume_mid, volume_abs, area_mid, density, gamma, bsq, strain_inc, volume_new, &
       bmat_new, bhoop_new, char_length, reason, r_mid, r_new, r_plane, f_new, strain_inc_corot, rel_spin)
    integer, intent(in) :: nb
    real(dp), intent(in) :: xe_old(nb, 2, 4), du(nb, 2, 4), bmat_ref(nb, 2, 4), volume_ref(nb)
    real(dp), intent(in) :: min_volume_ratio, density0, r_old(nb, 2, 1)
    real(dp), intent(out) :: volume_mid(nb), volume_abs(nb), area_mid(nb), density(nb), gamma(nb, 4)
    real(dp), intent(out) :: bsq(nb), strain_inc(nb, 4), volume_new(nb), bmat_new(nb, 2, 4)
    real(dp), intent(out) :: bhoop_new(nb, 4), char_length(nb)
    integer, intent(out) :: reason(nb)
    real(dp), intent(out) :: r_mid(nb, 2, 2), r_new(nb, 2, 2), r_plane(nb, 2, 1), f_new(nb, 2, 2)
    real(dp), intent(out) :: strain_inc_corot(nb, 4), rel_spin(nb, 1)
    real(dp) :: mr(4), mz(4), nr(4), nz(4), br(4), bz(4), bt(4), sh(4), area, vol, hx, hy, jmin
    real(dp) :: l11, l12, l21, l22, hoop, spin
    integer :: e, k

    do e = 1, nb
       mr = xe_old(e, 1, :) + 0.5_dp * du(e, 1, :)
       mz = xe_old(e, 2, :) + 0.5_dp * du(e, 2, :)
       nr = xe_old(e, 1, :) + du(e, 1, :)
       nz = xe_old(e, 2, :) + du(e, 2, :)

       ! x_{n+½}
       call ring_geometry(mr, mz, area, vol, br, bz, bt, sh)
       volume_mid(e) = vol
       volume_abs(e) = abs(vol)
       area_mid(e) = abs(area)
       density(e) = (density0 * volume_ref(e)) / max(abs(vol), tiny(1.0_dp))
       hx = mr(1) - mr(2) + mr(3) - mr(4)
       hy = mz(1) - mz(2) + mz(3) - mz(4)
       do k = 1, 4
          gamma(e, k) = hg_base(k) - hx * br(k) - hy * bz(k)
       end do
       bsq(e) = sum(br**2) + sum(bz**2)
       call quad_displacement_gradient(du(e, 1, 1), du(e, 1, 2), du(e, 1, 3), du(e, 1, 4), du(e, 2, 1), &
            du(e, 2, 2), du(e, 2, 3), du(e, 2, 4), br(1), br(2), br(3), br(4), bz(1), bz(2), bz(3), bz(4), &
            l11, l12, l21, l22)
       hoop = (((0.0_dp + du(e, 1, 1) * bt(1)) + du(e, 1, 2) * bt(2)) + du(e, 1, 3) * bt(3)) + du(e, 1, 4) * bt(4)
       strain_inc(e, 1) = l11
       strain_inc(e, 2) = l22
       strain_inc(e, 3) = hoop
       strain_inc(e, 4) = 0.5_dp * (l12 + l21)
       spin = 0.5_dp * (l21 - l12)

       ! x_{n+1}
       call ring_geometry(nr, nz, area, vol, br, bz, bt, sh)
       volume_new(e) = vol
       bmat_new(e, 1, :) = br
       bmat_new(e, 2, :) = bz
       bhoop_new(e, :) = bt
       char_length(e) = ring_char_length(nr, nz, area, bt)

       ! corner Jacobians in node order (fem_inversion's 2D test)
       jmin = huge(1.0_dp)
       jmin = min(jmin, 1.0_dp * ((nr(2) - nr(1)) * (nz(4) - nz(1)) - (nz(2) - nz(1)) * (nr(4) - nr(1))))
       jmin = min(jmin, -1.0_dp * ((nr(1) - nr(2)) * (nz(3) - nz(2)) - (nz(1) - nz(2)) * (nr(3) - nr(2))))
       jmin = min(jmin, 1.0_dp * ((nr(4) - nr(3)) * (nz(2) - nz(3)) - (nz(4) - nz(3)) * (nr(2) - nr(3))))
       jmin = min(jmin, -1.0_dp * ((nr(3) - nr(4)) * (nz(1) - nz(4)) - (nz(3) - nz(4)) * (nr(1) - nr(4))))
       k = inversion_none
       if (vol < min_volume_ratio * volume_ref(e)) k = inversion_collapse
       if (jmin <= 0.0_dp) k = inversion_corner
       if (vol <= 0.0_dp) k = inversion_centre
       ! a node on the far side of the axis (nodes on it, r = 0, are valid)
       if (minval(nr) < 0.0_dp) k = inversion_axis
       reason(e) = k

       ! Green–Naghdi R in the r–z plane from the reference B̄ (fem_plane_frame); θθ is not rotated
       call plane_corotational_step(mr(2) - mr(1), mr(3) - mr(1), mr(4) - mr(1), mz(2) - mz(1), &
            mz(3) - mz(1), mz(4) - mz(1), nr(2) - nr(1), nr(3) - nr(1), nr(4) - nr(1), nz(2) - nz(1), &
            nz(3) - nz(1), nz(4) - nz(1), bmat_ref(e, 1, 2), bmat_ref(e, 1, 3), bmat_ref(e, 1, 4), &
            bmat_ref(e, 2, 2), bmat_ref(e, 2, 3), bmat_ref(e, 2, 4), l11, l22, 0.5_dp * (l12 + l21), spin, &
            r_old(e, 1, 1), r_old(e, 2, 1), r_mid(e, 1, 1), r_mid(e, 2, 1), r_mid(e, 1, 2), r_mid(e, 2, 2), &
            f_new(e, 1, 1), f_new(e, 2, 1), f_new(e, 1, 2), f_new(e, 2, 2), &
            r_new(e, 1, 1), r_new(e, 2, 1), r_new(e, 1, 2), r_new(e, 2, 2), &
            strain_inc_corot(e, 1), strain_inc_corot(e, 2), strain_inc_corot(e, 4), rel_spin(e, 1))
       strain_inc_corot(e, 3) = hoop
       r_plane(e, 1, 1) = r_new(e, 1, 1)
       r_plane(e, 2, 1) = r_new(e, 2, 1)
    end do
  end subroutine cax4r_increment_kinematics

  !> f_rI = V (σ_rr B_rI + σ_rz B_zI + σ_θθ B_θI), f_zI = V (σ_rz B_rI + σ_zz B_zI), with the
  !> isotropic bulk-viscosity stress σ_bv added to rr, zz and θθ (pass zeros without it).
  !> Overwrites fe; the hourglass kernel adds to it.
  pure subroutine cax4r_internal_force(nb, volume, bmat, bhoop, stress, sigma_bv, fe)
    integer, intent(in) :: nb
    real(dp), intent(in) :: volume(nb), bmat(nb, 2, 4), bhoop(nb, 4), stress(nb, 4), sigma_bv(nb)
    real(dp), intent(out) :: fe(nb, 2, 4)
    real(dp) :: s11, s22, s33
    integer :: e, n

    do n = 1, 4
       do e = 1, nb
          s11 = stress(e, 1) + sigma_bv(e)
          s22 = stress(e, 2) + sigma_bv(e)
          s33 = stress(e, 3) + sigma_bv(e)
          fe(e, 1, n) = volume(e) * (s11 * bmat(e, 1, n) + stress(e, 4) * bmat(e, 2, n) + s33 * bhoop(e, n))
          fe(e, 2, n) = volume(e) * (stress(e, 4) * bmat(e, 1, n) + s22 * bmat(e, 2, n))
       end do
    end do
  end subroutine cax4r_internal_force

  !> Hourglass forces (added to fe), the kernel's energy and the trapezoidal work, as
  !> cpe4r_hourglass_update with the ring's own "thickness" V/A per element:
  !>   viscous   C = Q_v ρ c_d (V/A) √A / 4,   stiffness K = κ (λ+2μ) V Σ(B_r² + B_z²) / 4.
  !> γ and bsq from cax4r_increment_kinematics; area_mid = |A| of x_{n+½}.
  pure subroutine cax4r_hourglass_update(nb, gamma, bsq, volume_mid, area_mid, du, dt, density, &
       modulus, kind, coefficient, rot_mid, rot_new, hg_state, fe, force_hg, energy_inc, work)
    integer, intent(in) :: nb
    real(dp), intent(in) :: gamma(nb, 4), bsq(nb), volume_mid(nb), area_mid(nb), du(nb, 2, 4), dt
    real(dp), intent(in) :: density(nb), modulus(nb)
    integer, intent(in) :: kind
    real(dp), intent(in) :: coefficient, rot_mid(nb, 2, 2), rot_new(nb, 2, 2)
    real(dp), intent(inout) :: hg_state(nb, 2, 1), fe(nb, 2, 4), force_hg(nb, 2, 1)
    real(dp), intent(out) :: energy_inc(nb), work(nb)
    real(dp) :: q1, q2, qg1, qg2, c, dtm, area
    integer :: e

    dtm = max(dt, tiny(1.0_dp))
    do e = 1, nb
       ! the mode's amplitudes q_i = Σ_I γ_I du_iI
       q1 = sum(gamma(e, :) * du(e, 1, :))
       q2 = sum(gamma(e, :) * du(e, 2, :))
       ! no hourglass control (kind none): no force, no energy
       qg1 = 0.0_dp
       qg2 = 0.0_dp
       energy_inc(e) = 0.0_dp
       if (kind == hourglass_viscous) then
          area = max(area_mid(e), tiny(1.0_dp))
          c = coefficient * 0.25_dp * sqrt(density(e) * modulus(e)) * (abs(volume_mid(e)) / area) &
               * sqrt(area) / dtm
          qg1 = c * q1
          qg2 = c * q2
          energy_inc(e) = (0.0_dp + qg1 * q1) + qg2 * q2
       else if (kind == hourglass_stiffness) then
          c = coefficient * 0.25_dp * modulus(e) * volume_mid(e) * bsq(e)
          call stiffness_mode_force(c, q1, q2, rot_mid(e, 1, 1), rot_mid(e, 2, 1), rot_mid(e, 1, 2), &
               rot_mid(e, 2, 2), rot_new(e, 1, 1), rot_new(e, 2, 1), rot_new(e, 1, 2), rot_new(e, 2, 2), &
               hg_state(e, 1, 1), hg_state(e, 2, 1), qg1, qg2, energy_inc(e))
       end if
       call add_mode_forces(gamma(e, 1), gamma(e, 2), gamma(e, 3), gamma(e, 4), q1, q2, qg1, qg2, fe(e, 1, 1), fe(e, 2, 1), fe(e, 1, 2), &
            fe(e, 2, 2), fe(e, 1, 3), fe(e, 2, 3), fe(e, 1, 4), fe(e, 2, 4), force_hg(e, 1, 1), &
            force_hg(e, 2, 1), work(e))
    end do
  end subroutine cax4r_hourglass_update
end module fem_cax4r
