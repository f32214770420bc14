!> Consistent (algorithmic) tangents dσ_{n+1}/dΔε of the bulkflow stress returns, for implicit
!> hosts (the Abaqus/Standard UMAT's DDSDDE; CalculiX). Owns the tangents only: the returns
!> themselves stay in mohr_coulomb_return and drucker_prager_return, and every routine here
!> differentiates the result of those routines (docs/consistent_tangent.md derives them).
!>
!> Fourth-order tangents are held as c(3,3,3,3) with c(a,b,c,d) = ∂σ_ab/∂ε_cd for a symmetric
!> strain increment (minor symmetries in ab and cd); tangent_to_standard packs them in the
!> Abaqus/Standard component order with engineering shear strains.
!>
!> Mohr–Coulomb: σ_{n+1} = Σ_i σ_i(σ^B) n_i⊗n_i with the trial eigenvectors n_i (isotropic
!> elasticity and an isotropic yield function keep the principal axes). Its derivative has the
!> principal part J·D (J = ∂σ_i/∂σ^B_j of the principal return, D the principal elastic matrix)
!> and, for each pair i ≠ j, the shear coefficient θ_ij·2G with θ_ij = (σ_i − σ_j)/(σ^B_i − σ^B_j)
!> (the rotation of the eigenvectors; de Souza Neto, Perić & Owen 2008, Appendix A). For every
!> region J is a projection: with the active planes S (normals a_i, flow directions b_i),
!> J = I − Σ_{i,j∈S} D b_i (A⁻¹)_ij a_jᵀ, A_ij = a_iᵀ D b_j (Clausen, Damkilde & Andersen 2007),
!> and J = 0 where three planes fix the stress (apex, cut-off corners).
module material_tangent
  use material_kinds, only: dp
  use mohr_coulomb_return, only: region_elastic, region_plane, region_edge_compression, &
       region_edge_extension, region_apex, region_tension, cutoff_plane, cutoff_mc_line, cutoff_edge, &
       mc_sin_phi_min, mc_sin_phi_max
  implicit none
  private

  public :: elastic_tangent, mohr_coulomb_principal_jacobian, isotropic_function_tangent
  public :: drucker_prager_tangent, tangent_to_standard

  !> Two trial principal stresses closer than this (relative to the largest) count as equal in
  !> θ_ij: there the difference quotient would amplify round-off, and its limit is used.
  real(dp), parameter :: equal_roots = 1.0e-8_dp

contains

  !> Isotropic elasticity: c = λ δ_ab δ_cd + G (δ_ac δ_bd + δ_ad δ_bc).
  pure subroutine elastic_tangent(lam, shear, c)
    real(dp), intent(in) :: lam, shear
    real(dp), intent(out) :: c(3, 3, 3, 3)
    integer :: a, b

    c = 0
    do a = 1, 3
       do b = 1, 3
          c(a, a, b, b) = c(a, a, b, b) + lam
          c(a, b, a, b) = c(a, b, a, b) + shear
          c(a, b, b, a) = c(a, b, b, a) + shear
       end do
    end do
  end subroutine elastic_tangent

  !> J = ∂σ_i/∂σ^B_j of the principal Mohr–Coulomb return for the region (and cut-off detail)
  !> that mohr_coulomb_principal_return_detail reported, with the same clamps of sinφ and sinψ.
  !> Planes: 1 main (a = (k,0,−1), b = (m,0,−1)), 2 σ1=σ2 side (a = (0,k,−1)), 3 σ2=σ3 side
  !> (a = (k,−1,0)), 4 and 5 Rankine σ1 ≤ σt, σ2 ≤ σt (associated). ψ = 0 needs no branch.
  pure subroutine mohr_coulomb_principal_jacobian(sin_phi, sin_psi, lam, shear, region, detail, jac)
    real(dp), intent(in) :: sin_phi, sin_psi, lam, shear
    integer, intent(in) :: region, detail
    real(dp), intent(out) :: jac(3, 3)
    real(dp) :: sp, sq, k, m
    real(dp) :: a(3, 5), b(3, 5)
    integer :: i

    sp = min(max(sin_phi, mc_sin_phi_min), mc_sin_phi_max)
    sq = min(max(sin_psi, 0.0_dp), sp)
    k = (1.0_dp + sp) / (1.0_dp - sp)
    m = (1.0_dp + sq) / (1.0_dp - sq)
    a(:, 1) = [k, 0.0_dp, -1.0_dp]
    b(:, 1) = [m, 0.0_dp, -1.0_dp]
    a(:, 2) = [0.0_dp, k, -1.0_dp]
    b(:, 2) = [0.0_dp, m, -1.0_dp]
    a(:, 3) = [k, -1.0_dp, 0.0_dp]
    b(:, 3) = [m, -1.0_dp, 0.0_dp]
    a(:, 4) = [1.0_dp, 0.0_dp, 0.0_dp]
    b(:, 4) = a(:, 4)
    a(:, 5) = [0.0_dp, 1.0_dp, 0.0_dp]
    b(:, 5) = a(:, 5)

    jac = 0
    do i = 1, 3
       jac(i, i) = 1.0_dp
    end do
    select case (region)
    case (region_elastic)
    case (region_plane)
       call project_out(a(:, 1:1), b(:, 1:1), lam, shear, jac)
    case (region_edge_compression)
       call project_out(a(:, 1:2), b(:, 1:2), lam, shear, jac)
    case (region_edge_extension)
       call project_out(a(:, [1, 3]), b(:, [1, 3]), lam, shear, jac)
    case (region_tension)
       select case (detail)
       case (cutoff_plane)
          call project_out(a(:, 4:4), b(:, 4:4), lam, shear, jac)
       case (cutoff_mc_line)
          call project_out(a(:, [1, 4]), b(:, [1, 4]), lam, shear, jac)
       case (cutoff_edge)
          call project_out(a(:, 4:5), b(:, 4:5), lam, shear, jac)
       case default
          jac = 0   ! a corner or the Rankine apex: the stress is fixed
       end select
    case default
       jac = 0      ! region_apex
    end select
  end subroutine mohr_coulomb_principal_jacobian

  !> jac ← I − Σ_{i,j} D b_i (A⁻¹)_ij a_jᵀ, A_ij = a_iᵀ D b_j, for one or two active planes.
  pure subroutine project_out(a, b, lam, shear, jac)
    real(dp), intent(in) :: a(:, :), b(:, :), lam, shear
    real(dp), intent(inout) :: jac(3, 3)
    real(dp) :: db(3, 2), amat(2, 2), ainv(2, 2), det
    integer :: n, i, j, r

    n = size(a, 2)
    do j = 1, n
       db(:, j) = lam * sum(b(:, j)) + 2.0_dp * shear * b(:, j)
       do i = 1, n
          amat(i, j) = dot_product(a(:, i), db(:, j))
       end do
    end do
    ! The diagonal entries a_iᵀ D b_i are > 0 and the 2x2 systems of the edges and of the
    ! cut-off line are regular (their planes are independent); see the derivation notes.
    if (n == 1) then
       ainv(1, 1) = 1.0_dp / amat(1, 1)
    else
       det = amat(1, 1) * amat(2, 2) - amat(1, 2) * amat(2, 1)
       ainv(1, 1) = amat(2, 2) / det
       ainv(2, 2) = amat(1, 1) / det
       ainv(1, 2) = -amat(1, 2) / det
       ainv(2, 1) = -amat(2, 1) / det
    end if
    ! Δλ = A⁻¹ (a_iᵀ σ^B − ...), σ = σ^B − Σ_j Δλ_j D b_j.
    do r = 1, 3
       do j = 1, 3
          do i = 1, n
             jac(r, j) = jac(r, j) - sum(db(r, 1:n) * ainv(1:n, i)) * a(j, i)
          end do
       end do
    end do
  end subroutine project_out

  !> Tangent of σ = Σ_i σ_i(σ^B) n_i⊗n_i with σ^B = σ_n + D:Δε (isotropic D):
  !> sig_trial, vec: trial principal stresses and eigenvectors (columns); sig: returned principal
  !> values; jac = ∂σ_i/∂σ^B_j.
  pure subroutine isotropic_function_tangent(sig_trial, vec, sig, jac, lam, shear, c)
    real(dp), intent(in) :: sig_trial(3), vec(3, 3), sig(3), jac(3, 3), lam, shear
    real(dp), intent(out) :: c(3, 3, 3, 3)
    real(dp) :: jd(3, 3), theta(3, 3), scale, gap
    integer :: i, j, a, b, p, q

    ! Principal block J·D, D = λ 11ᵀ + 2G I.
    do j = 1, 3
       do i = 1, 3
          jd(i, j) = lam * sum(jac(i, :)) + 2.0_dp * shear * jac(i, j)
       end do
    end do
    ! θ_ij: difference quotient, or its limit ½(J_ii − J_ij + J_jj − J_ji) for equal roots.
    scale = maxval(abs(sig_trial)) + tiny(1.0_dp)
    theta = 0
    do j = 1, 3
       do i = 1, 3
          if (i == j) cycle
          gap = sig_trial(i) - sig_trial(j)
          if (abs(gap) > equal_roots * scale) then
             theta(i, j) = (sig(i) - sig(j)) / gap
          else
             theta(i, j) = 0.5_dp * (jac(i, i) - jac(i, j) + jac(j, j) - jac(j, i))
          end if
       end do
    end do
    ! c_abpq = Σ_ij JD_ij n_ia n_ib n_jp n_jq + Σ_{i≠j} θ_ij G n_ia n_jb (n_ip n_jq + n_jp n_iq).
    do q = 1, 3
       do p = 1, 3
          do b = 1, 3
             do a = 1, 3
                c(a, b, p, q) = 0
                do j = 1, 3
                   do i = 1, 3
                      c(a, b, p, q) = c(a, b, p, q) + jd(i, j) * vec(a, i) * vec(b, i) * vec(p, j) * vec(q, j)
                      if (i /= j) c(a, b, p, q) = c(a, b, p, q) + theta(i, j) * shear * vec(a, i) &
                           * vec(b, j) * (vec(p, i) * vec(q, j) + vec(p, j) * vec(q, i))
                   end do
                end do
             end do
          end do
       end do
    end do
  end subroutine isotropic_function_tangent

  !> Tangent of the linear Drucker–Prager return (q-form, drucker_prager_return) for the region
  !> it reported; s_trial is the trial stress tensor. On the cone, with s* the trial deviator,
  !> q* = √(3/2 s*:s*), N = (3/2) s*/q*, H = 3G + K tanβ tanψ:
  !>   dp = −K dε_v + K tanψ (2G N:dε + K tanβ dε_v)/H,  q = p tanβ + d,
  !>   σ = (q/q*) s* − p I  ⇒  c = −I⊗P + s*⊗(tanβ P)/q* − (q/q*²) s*⊗(2G N) + (q/q*) 2G I_dev.
  pure subroutine drucker_prager_tangent(s_trial, tan_beta, tan_psi, d, bulk, shear, region, c)
    real(dp), intent(in) :: s_trial(3, 3), tan_beta, tan_psi, d, bulk, shear
    integer, intent(in) :: region
    real(dp), intent(out) :: c(3, 3, 3, 3)
    real(dp) :: dev(3, 3), ptan(3, 3), n_dir(3, 3), eye(3, 3), mean, p_trial, q_trial, h, dlam
    real(dp) :: p_new, q_new
    integer :: a, b, p, q

    eye = 0
    do a = 1, 3
       eye(a, a) = 1.0_dp
    end do
    select case (region)
    case (0)
       call elastic_tangent(bulk - 2.0_dp * shear / 3.0_dp, shear, c)
       return
    case (1)
    case default
       c = 0   ! apex
       return
    end select
    mean = (s_trial(1, 1) + s_trial(2, 2) + s_trial(3, 3)) / 3.0_dp
    dev = s_trial - mean * eye
    p_trial = -mean
    q_trial = sqrt(1.5_dp * sum(dev**2))
    h = 3.0_dp * shear + bulk * tan_beta * tan_psi
    dlam = (q_trial - p_trial * tan_beta - d) / h
    p_new = p_trial + bulk * dlam * tan_psi
    q_new = max(p_new * tan_beta + d, 0.0_dp)
    n_dir = 1.5_dp * dev / q_trial
    ptan = -bulk * eye + bulk * tan_psi * (2.0_dp * shear * n_dir + bulk * tan_beta * eye) / h
    do q = 1, 3
       do p = 1, 3
          do b = 1, 3
             do a = 1, 3
                c(a, b, p, q) = -eye(a, b) * ptan(p, q) + dev(a, b) * tan_beta * ptan(p, q) / q_trial &
                     - q_new / q_trial**2 * dev(a, b) * 2.0_dp * shear * n_dir(p, q) &
                     + q_new / q_trial * shear * (eye(a, p) * eye(b, q) + eye(a, q) * eye(b, p) &
                     - 2.0_dp * eye(a, b) * eye(p, q) / 3.0_dp)
             end do
          end do
       end do
    end do
  end subroutine drucker_prager_tangent

  !> DDSDDE(I, J) = ∂σ_I/∂ε_J in the Abaqus/Standard order (11, 22, 33, 12[, 13, 23]) with
  !> engineering shear strains γ_ab = 2ε_ab: ∂σ_I/∂γ_cd = c(.., c, d) by the minor symmetry.
  pure subroutine tangent_to_standard(c, ntens, ddsdde)
    real(dp), intent(in) :: c(3, 3, 3, 3)
    integer, intent(in) :: ntens
    real(dp), intent(out) :: ddsdde(ntens, ntens)
    integer, parameter :: pair(2, 6) = reshape([1, 1, 2, 2, 3, 3, 1, 2, 1, 3, 2, 3], [2, 6])
    integer :: i, j

    do j = 1, ntens
       do i = 1, ntens
          ddsdde(i, j) = c(pair(1, i), pair(2, i), pair(1, j), pair(2, j))
       end do
    end do
  end subroutine tangent_to_standard
end module material_tangent
