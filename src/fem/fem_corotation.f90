!> Corotational (Green–Naghdi) frame of one-point elements, as Abaqus/Explicit gives it to a VUMAT.
!>
!> Why Green–Naghdi (polar decomposition of the element F) and not an integrated
!> (Hughes–Winget) spin: the VUMAT contract is Green–Naghdi. Abaqus hands the VUMAT
!> relSpinInc = ΔW − ΔΩ (zero by construction for a frame that spins with W), stretch U = RᵀF and
!> F, all consistent with R from F = RU. R is recomputed from the total F every increment, so no
!> rotation error accumulates: a rigid rotation by 90° in any number of steps gives R equal to the
!> exact rotation to round-off, and an objective (frame-indifferent) stress update is automatic.
!>
!> Data layout (block of nb elements, element index first, as a VUMAT receives its arrays):
!>   f, r          (nb, ndim, ndim)   f(:, i, j) = F_ij = ∂x_i/∂X_j, r(:, i, j) = R_ij
!>   symmetric     (nb, ncomp)        2D: 11, 22, 33, 12 (ncomp 4); 3D: 11, 22, 33, 12, 23, 31
!>   spin vectors  (nb, nshr)         2D: ω3 = W21; 3D: (ω1, ω2, ω3) = (W32, W13, W21)
!> Plane strain (ndim 2): R is an in-plane rotation, R33 = 1, and the 33 component is untouched.
module fem_corotation
  use base_kinds, only: dp
  use fem_plane_frame, only: plane_defgrad, plane_rotation, plane_similarity, plane_relative_spin
  implicit none
  private

  public :: deformation_gradient, polar_rotation, identity_rotation, rotation_matrix
  public :: to_corotational, to_global, stored_to_global, relative_spin
  public :: vumat_defgrad, vumat_stretch, corotational_increment

  !> Symmetric-tensor component k of the 3-D VUMAT order is the pair (sym_i(k), sym_j(k)).
  integer, parameter :: sym_i(6) = [1, 2, 3, 1, 2, 3]
  integer, parameter :: sym_j(6) = [1, 2, 3, 2, 3, 1]
  !> Polar decomposition (3D): stop when every element's Newton update is below this (the
  !> iterate is then orthogonal to ~1e-16 after the extra final step), or after max_newton.
  real(dp), parameter :: newton_tolerance = 1.0e-10_dp
  integer, parameter :: max_newton = 60
  !> Elements per chunk of the 3D polar decomposition (polar_rotation_3d).
  integer, parameter :: polar_chunk = 32

contains

  !> The whole corotational step of a block, in the order of docs/theory/abaqus_contract.md §1.4:
  !> F_{n+½}, F_{n+1} from the reference mean gradient; R_{n+½}, R_{n+1} by polar
  !> decomposition; strainInc = R_{n+½}ᵀ Δε R_{n+½}; relSpinInc. strain_inc, spin_inc: the
  !> global increments of <el>_strain_increment. r_old = R_n (element state, identity at the
  !> start); after the VUMAT the driver rotates the stress with r_new (to_global) and keeps
  !> r_new as the next r_old. f_new feeds defgradNew/stretchNew (vumat_defgrad, vumat_stretch).
  pure subroutine corotational_increment(nb, ndim, nen, bmat_ref, xe_mid, xe_new, strain_inc, &
                                         spin_inc, r_old, r_mid, r_new, f_new, strain_inc_corot, &
                                         rel_spin)
    integer, intent(in) :: nb, ndim, nen
    real(dp), intent(in) :: bmat_ref(nb, ndim, nen)
    real(dp), intent(in) :: xe_mid(nb, ndim, nen), xe_new(nb, ndim, nen)
    real(dp), intent(in) :: strain_inc(nb, 2 * ndim), spin_inc(nb, 2 * ndim - 3)
    real(dp), intent(in) :: r_old(nb, ndim, ndim)
    real(dp), intent(out) :: r_mid(nb, ndim, ndim), r_new(nb, ndim, ndim), f_new(nb, ndim, ndim)
    real(dp), intent(out) :: strain_inc_corot(nb, 2 * ndim), rel_spin(nb, 2 * ndim - 3)
    real(dp), allocatable :: f_mid(:, :, :)

    ! The solver's CPE4R pass does this step inside fem_cpe4r's fused kernel, with the same
    ! plane-frame kernels (fem_plane_frame) as the pieces below, so both agree to the bit.
    allocate(f_mid(nb, ndim, ndim))
    call deformation_gradient(nb, ndim, nen, bmat_ref, xe_mid, f_mid)
    call polar_rotation(nb, ndim, f_mid, r_mid)
    call deformation_gradient(nb, ndim, nen, bmat_ref, xe_new, f_new)
    call polar_rotation(nb, ndim, f_new, r_new)
    call to_corotational(nb, ndim, 2 * ndim, r_mid, strain_inc, strain_inc_corot)
    call relative_spin(nb, ndim, spin_inc, r_old, r_new, r_mid, rel_spin)
  end subroutine corotational_increment

  !> Mean deformation gradient F = Σ_I x_I ⊗ B0_I of a block, B0 the mean gradient of the
  !> reference configuration (fem_cpe4r/fem_c3d8r geometry on x0). Exact for linear fields.
  !> Coordinates are taken relative to node 1 (Σ_I B0_I = 0), so large absolute coordinates do
  !> not cost digits.
  pure subroutine deformation_gradient(nb, ndim, nen, bmat_ref, xe, f)
    integer, intent(in) :: nb, ndim, nen
    real(dp), intent(in) :: bmat_ref(nb, ndim, nen)
    real(dp), intent(in) :: xe(nb, ndim, nen)
    real(dp), intent(out) :: f(nb, ndim, ndim)
    integer :: i, j, n, e

    if (ndim == 2 .and. nen == 4) then
       ! CPE4R: one pass with the sums of the general loop below in the same order (bitwise the
       ! same F), instead of zeroing F and updating it three times.
       do e = 1, nb
          call plane_defgrad(xe(e, 1, 2) - xe(e, 1, 1), xe(e, 1, 3) - xe(e, 1, 1), xe(e, 1, 4) - xe(e, 1, 1), &
               xe(e, 2, 2) - xe(e, 2, 1), xe(e, 2, 3) - xe(e, 2, 1), xe(e, 2, 4) - xe(e, 2, 1), &
               bmat_ref(e, 1, 2), bmat_ref(e, 1, 3), bmat_ref(e, 1, 4), bmat_ref(e, 2, 2), &
               bmat_ref(e, 2, 3), bmat_ref(e, 2, 4), f(e, 1, 1), f(e, 2, 1), f(e, 1, 2), f(e, 2, 2))
       end do
       return
    end if
    if (ndim == 3 .and. nen == 8) then
       ! C3D8R: each F_ij in one pass, the sum over the nodes written out in the order of the
       ! general loop below (bitwise the same F), instead of seven read-modify-write passes.
       f(:, 1, 1) = ((((((0.0_dp + (xe(:, 1, 2) - xe(:, 1, 1)) * bmat_ref(:, 1, 2)) + (xe(:, 1, 3) - xe(:, 1, 1)) * bmat_ref(:, 1, 3)) + (xe(:, 1, 4) - xe(:, 1, 1)) * bmat_ref(:, 1, 4)) + (xe(:, 1, 5) - xe(:, 1, 1)) * bmat_ref(:, 1, 5)) + (xe(:, 1, 6) - xe(:, 1, 1)) * bmat_ref(:, 1, 6)) + (xe(:, 1, 7) - xe(:, 1, 1)) * bmat_ref(:, 1, 7)) + (xe(:, 1, 8) - xe(:, 1, 1)) * bmat_ref(:, 1, 8)
       f(:, 2, 1) = ((((((0.0_dp + (xe(:, 2, 2) - xe(:, 2, 1)) * bmat_ref(:, 1, 2)) + (xe(:, 2, 3) - xe(:, 2, 1)) * bmat_ref(:, 1, 3)) + (xe(:, 2, 4) - xe(:, 2, 1)) * bmat_ref(:, 1, 4)) + (xe(:, 2, 5) - xe(:, 2, 1)) * bmat_ref(:, 1, 5)) + (xe(:, 2, 6) - xe(:, 2, 1)) * bmat_ref(:, 1, 6)) + (xe(:, 2, 7) - xe(:, 2, 1)) * bmat_ref(:, 1, 7)) + (xe(:, 2, 8) - xe(:, 2, 1)) * bmat_ref(:, 1, 8)
       f(:, 3, 1) = ((((((0.0_dp + (xe(:, 3, 2) - xe(:, 3, 1)) * bmat_ref(:, 1, 2)) + (xe(:, 3, 3) - xe(:, 3, 1)) * bmat_ref(:, 1, 3)) + (xe(:, 3, 4) - xe(:, 3, 1)) * bmat_ref(:, 1, 4)) + (xe(:, 3, 5) - xe(:, 3, 1)) * bmat_ref(:, 1, 5)) + (xe(:, 3, 6) - xe(:, 3, 1)) * bmat_ref(:, 1, 6)) + (xe(:, 3, 7) - xe(:, 3, 1)) * bmat_ref(:, 1, 7)) + (xe(:, 3, 8) - xe(:, 3, 1)) * bmat_ref(:, 1, 8)
       f(:, 1, 2) = ((((((0.0_dp + (xe(:, 1, 2) - xe(:, 1, 1)) * bmat_ref(:, 2, 2)) + (xe(:, 1, 3) - xe(:, 1, 1)) * bmat_ref(:, 2, 3)) + (xe(:, 1, 4) - xe(:, 1, 1)) * bmat_ref(:, 2, 4)) + (xe(:, 1, 5) - xe(:, 1, 1)) * bmat_ref(:, 2, 5)) + (xe(:, 1, 6) - xe(:, 1, 1)) * bmat_ref(:, 2, 6)) + (xe(:, 1, 7) - xe(:, 1, 1)) * bmat_ref(:, 2, 7)) + (xe(:, 1, 8) - xe(:, 1, 1)) * bmat_ref(:, 2, 8)
       f(:, 2, 2) = ((((((0.0_dp + (xe(:, 2, 2) - xe(:, 2, 1)) * bmat_ref(:, 2, 2)) + (xe(:, 2, 3) - xe(:, 2, 1)) * bmat_ref(:, 2, 3)) + (xe(:, 2, 4) - xe(:, 2, 1)) * bmat_ref(:, 2, 4)) + (xe(:, 2, 5) - xe(:, 2, 1)) * bmat_ref(:, 2, 5)) + (xe(:, 2, 6) - xe(:, 2, 1)) * bmat_ref(:, 2, 6)) + (xe(:, 2, 7) - xe(:, 2, 1)) * bmat_ref(:, 2, 7)) + (xe(:, 2, 8) - xe(:, 2, 1)) * bmat_ref(:, 2, 8)
       f(:, 3, 2) = ((((((0.0_dp + (xe(:, 3, 2) - xe(:, 3, 1)) * bmat_ref(:, 2, 2)) + (xe(:, 3, 3) - xe(:, 3, 1)) * bmat_ref(:, 2, 3)) + (xe(:, 3, 4) - xe(:, 3, 1)) * bmat_ref(:, 2, 4)) + (xe(:, 3, 5) - xe(:, 3, 1)) * bmat_ref(:, 2, 5)) + (xe(:, 3, 6) - xe(:, 3, 1)) * bmat_ref(:, 2, 6)) + (xe(:, 3, 7) - xe(:, 3, 1)) * bmat_ref(:, 2, 7)) + (xe(:, 3, 8) - xe(:, 3, 1)) * bmat_ref(:, 2, 8)
       f(:, 1, 3) = ((((((0.0_dp + (xe(:, 1, 2) - xe(:, 1, 1)) * bmat_ref(:, 3, 2)) + (xe(:, 1, 3) - xe(:, 1, 1)) * bmat_ref(:, 3, 3)) + (xe(:, 1, 4) - xe(:, 1, 1)) * bmat_ref(:, 3, 4)) + (xe(:, 1, 5) - xe(:, 1, 1)) * bmat_ref(:, 3, 5)) + (xe(:, 1, 6) - xe(:, 1, 1)) * bmat_ref(:, 3, 6)) + (xe(:, 1, 7) - xe(:, 1, 1)) * bmat_ref(:, 3, 7)) + (xe(:, 1, 8) - xe(:, 1, 1)) * bmat_ref(:, 3, 8)
       f(:, 2, 3) = ((((((0.0_dp + (xe(:, 2, 2) - xe(:, 2, 1)) * bmat_ref(:, 3, 2)) + (xe(:, 2, 3) - xe(:, 2, 1)) * bmat_ref(:, 3, 3)) + (xe(:, 2, 4) - xe(:, 2, 1)) * bmat_ref(:, 3, 4)) + (xe(:, 2, 5) - xe(:, 2, 1)) * bmat_ref(:, 3, 5)) + (xe(:, 2, 6) - xe(:, 2, 1)) * bmat_ref(:, 3, 6)) + (xe(:, 2, 7) - xe(:, 2, 1)) * bmat_ref(:, 3, 7)) + (xe(:, 2, 8) - xe(:, 2, 1)) * bmat_ref(:, 3, 8)
       f(:, 3, 3) = ((((((0.0_dp + (xe(:, 3, 2) - xe(:, 3, 1)) * bmat_ref(:, 3, 2)) + (xe(:, 3, 3) - xe(:, 3, 1)) * bmat_ref(:, 3, 3)) + (xe(:, 3, 4) - xe(:, 3, 1)) * bmat_ref(:, 3, 4)) + (xe(:, 3, 5) - xe(:, 3, 1)) * bmat_ref(:, 3, 5)) + (xe(:, 3, 6) - xe(:, 3, 1)) * bmat_ref(:, 3, 6)) + (xe(:, 3, 7) - xe(:, 3, 1)) * bmat_ref(:, 3, 7)) + (xe(:, 3, 8) - xe(:, 3, 1)) * bmat_ref(:, 3, 8)
       return
    end if
    f = 0.0_dp
    do n = 2, nen
       do j = 1, ndim
          do i = 1, ndim
             do e = 1, nb
                f(e, i, j) = f(e, i, j) + (xe(e, i, n) - xe(e, i, 1)) * bmat_ref(e, j, n)
             end do
          end do
       end do
    end do
  end subroutine deformation_gradient

  !> R of the polar decomposition F = R U.
  !> 2D: closed form, R = rotation by θ = atan2(F21 − F12, F11 + F22) (valid for det F > 0).
  !> 3D: Newton iteration X ← ½(γX + X⁻ᵀ/γ) with Frobenius scaling γ = (‖X⁻¹‖/‖X‖)^½ (Higham),
  !> which converges for any non-singular F (a few iterations for moderate stretches, ≲ 10 for
  !> condition numbers up to 1e12). The exit test is block-wide, so the element loop stays
  !> branch-free. An inverted element (det F < 0) gives an improper orthogonal matrix; the
  !> inversion check (fem_inversion) stops such a run anyway.
  pure subroutine polar_rotation(nb, ndim, f, r)
    integer, intent(in) :: nb, ndim
    real(dp), intent(in) :: f(nb, ndim, ndim)
    real(dp), intent(out) :: r(nb, ndim, ndim)
    integer :: e

    if (ndim == 2) then
       ! One loop with scalars: block-sized automatic arrays are heap-allocated by gfortran,
       ! a malloc/free pair each per call.
       do e = 1, nb
          call plane_rotation(f(e, 1, 1), f(e, 2, 1), f(e, 1, 2), f(e, 2, 2), r(e, 1, 1), r(e, 2, 1), &
               r(e, 1, 2), r(e, 2, 2))
       end do
    else
       call polar_rotation_3d(nb, f, r)
    end if
  end subroutine polar_rotation

  pure subroutine polar_rotation_3d(nb, f, r)
    integer, intent(in) :: nb
    real(dp), intent(in) :: f(nb, 3, 3)
    real(dp), intent(out) :: r(nb, 3, 3)
    integer :: e0

    ! Chunks of fixed size: the work arrays live on the stack (block-sized automatic arrays
    ! are heap-allocated by gfortran, seven per call here), stay in L1, and the iterations stop
    ! when the chunk has converged instead of the whole block. Each element's iterates depend
    ! on that element alone, so the result does not depend on the chunking.
    do e0 = 1, nb, polar_chunk
       call polar_rotation_3d_chunk(nb, e0, min(polar_chunk, nb - e0 + 1), f, r)
    end do
  end subroutine polar_rotation_3d

  !> polar_rotation_3d on the n elements e0..e0+n-1 of the block, with the operations of the
  !> former whole-block form in the same order (bitwise the same R). Each step is a loop over
  !> the chunk that vectorises.
  pure subroutine polar_rotation_3d_chunk(nb, e0, n, f, r)
    integer, intent(in) :: nb, e0, n
    real(dp), intent(in) :: f(nb, 3, 3)
    real(dp), intent(inout) :: r(nb, 3, 3)
    real(dp) :: x(polar_chunk, 3, 3), cof(polar_chunk, 3, 3), det(polar_chunk), gam(polar_chunk)
    real(dp) :: change(polar_chunk)
    real(dp) :: xnew, xnorm2, cnorm2, d
    integer :: it, i, j, k
    ! Per element: 0 scaled iterations, 1 the final unscaled step, 2 converged (frozen). The
    ! stopping test is each element's own, so an element's R does not depend on which other
    ! elements share its block (and results do not depend on the number of MPI ranks).
    integer :: stage(polar_chunk)

    do j = 1, 3
       do i = 1, 3
          x(1:n, i, j) = f(e0:e0 + n - 1, i, j)
       end do
    end do
    stage(1:n) = 0
    do it = 1, max_newton
       do k = 1, n
          ! cofactor matrix (cof X)_ij = ∂det X/∂X_ij and det X
          cof(k, 1, 1) = x(k, 2, 2) * x(k, 3, 3) - x(k, 2, 3) * x(k, 3, 2)
          cof(k, 1, 2) = x(k, 2, 3) * x(k, 3, 1) - x(k, 2, 1) * x(k, 3, 3)
          cof(k, 1, 3) = x(k, 2, 1) * x(k, 3, 2) - x(k, 2, 2) * x(k, 3, 1)
          cof(k, 2, 1) = x(k, 1, 3) * x(k, 3, 2) - x(k, 1, 2) * x(k, 3, 3)
          cof(k, 2, 2) = x(k, 1, 1) * x(k, 3, 3) - x(k, 1, 3) * x(k, 3, 1)
          cof(k, 2, 3) = x(k, 1, 2) * x(k, 3, 1) - x(k, 1, 1) * x(k, 3, 2)
          cof(k, 3, 1) = x(k, 1, 2) * x(k, 2, 3) - x(k, 1, 3) * x(k, 2, 2)
          cof(k, 3, 2) = x(k, 1, 3) * x(k, 2, 1) - x(k, 1, 1) * x(k, 2, 3)
          cof(k, 3, 3) = x(k, 1, 1) * x(k, 2, 2) - x(k, 1, 2) * x(k, 2, 1)
          d = x(k, 1, 1) * cof(k, 1, 1) + x(k, 1, 2) * cof(k, 1, 2) + x(k, 1, 3) * cof(k, 1, 3)
          ! Guard against an exactly singular (collapsed) element: no division by zero.
          d = sign(max(abs(d), tiny(1.0_dp)), d)
          det(k) = d
          ! Frobenius norms, column by column
          xnorm2 = ((((((((0.0_dp + x(k, 1, 1)**2) + x(k, 2, 1)**2) + x(k, 3, 1)**2) + x(k, 1, 2)**2) &
               + x(k, 2, 2)**2) + x(k, 3, 2)**2) + x(k, 1, 3)**2) + x(k, 2, 3)**2) + x(k, 3, 3)**2
          cnorm2 = ((((((((0.0_dp + cof(k, 1, 1)**2) + cof(k, 2, 1)**2) + cof(k, 3, 1)**2) &
               + cof(k, 1, 2)**2) + cof(k, 2, 2)**2) + cof(k, 3, 2)**2) + cof(k, 1, 3)**2) &
               + cof(k, 2, 3)**2) + cof(k, 3, 3)**2
          ! γ = (‖X⁻¹‖_F / ‖X‖_F)^½ with ‖X⁻¹‖_F = ‖cof X‖_F / |det X|
          gam(k) = sqrt(sqrt(cnorm2 / max(xnorm2, tiny(1.0_dp))) / abs(d))
       end do
       ! 1 for the final step. (Its own loop: in the one above the compiler moved the square
       ! roots under a branch on the stage and could no longer vectorise.)
       do k = 1, n
          gam(k) = merge(gam(k), 1.0_dp, stage(k) == 0)
       end do
       change(1:n) = 0.0_dp
       do j = 1, 3
          do i = 1, 3
             do k = 1, n
                ! X⁻ᵀ = cof(X) / det X
                xnew = 0.5_dp * (gam(k) * x(k, i, j) + cof(k, i, j) / (gam(k) * det(k)))
                change(k) = change(k) + (xnew - x(k, i, j))**2
                x(k, i, j) = merge(xnew, x(k, i, j), stage(k) < 2)
             end do
          end do
       end do
       ! Near convergence the scaling is switched off for one last plain Newton step, which
       ! restores full quadratic convergence to an orthogonal matrix.
       do k = 1, n
          stage(k) = merge(stage(k) + 1, stage(k), stage(k) == 1 .or. &
               (stage(k) == 0 .and. change(k) <= newton_tolerance**2))
       end do
       if (all(stage(1:n) == 2)) exit
    end do
    do j = 1, 3
       do i = 1, 3
          r(e0:e0 + n - 1, i, j) = x(1:n, i, j)
       end do
    end do
  end subroutine polar_rotation_3d_chunk

  !> R = I for every element (initial rotation state when the initial configuration is the
  !> reference one), stored as its first ncol columns: ncol = ndim the matrix, ncol = 1 in 2D
  !> the plane form (cos θ, sin θ) = (1, 0) (rotation_matrix).
  pure subroutine identity_rotation(nb, ndim, ncol, r)
    integer, intent(in) :: nb, ndim, ncol
    real(dp), intent(out) :: r(nb, ndim, ncol)
    integer :: i

    r = 0.0_dp
    do i = 1, ncol
       r(:, i, i) = 1.0_dp
    end do
  end subroutine identity_rotation

  !> The rotation matrices r (nb, ndim, ndim) of a block's stored rotations r_stored
  !> (nb, ndim, ncol): the matrices themselves (ncol = ndim), or in 2D with ncol = 1 the plane
  !> form, the first column (cos θ, sin θ) of R = [c −s; s c]. plane_rotation forms R12 as −s
  !> to the bit (−(a/b) = (−a)/b in IEEE arithmetic), so the matrix is the one it formed.
  pure subroutine rotation_matrix(nb, ndim, ncol, r_stored, r)
    integer, intent(in) :: nb, ndim, ncol
    real(dp), intent(in) :: r_stored(nb, ndim, ncol)
    real(dp), intent(out) :: r(nb, ndim, ndim)

    if (ncol == ndim) then
       r = r_stored
    else
       r(:, 1, 1) = r_stored(:, 1, 1)
       r(:, 2, 1) = r_stored(:, 2, 1)
       r(:, 1, 2) = -r_stored(:, 2, 1)
       r(:, 2, 2) = r_stored(:, 1, 1)
    end if
  end subroutine rotation_matrix

  !> a_c = Rᵀ a R: global → corotational components of a symmetric tensor (strain increment with
  !> R = R_{n+½}; an initial global stress with R = R_n).
  pure subroutine to_corotational(nb, ndim, ncomp, r, a, a_corot)
    integer, intent(in) :: nb, ndim, ncomp
    real(dp), intent(in) :: r(nb, ndim, ndim)
    real(dp), intent(in) :: a(nb, ncomp)
    real(dp), intent(out) :: a_corot(nb, ncomp)

    call rotate_symmetric(nb, ndim, ncomp, r, .true., a, a_corot)
  end subroutine to_corotational

  !> a = R a_c Rᵀ: corotational → global components (stress for the nodal forces, R = R_{n+1}).
  pure subroutine to_global(nb, ndim, ncomp, r, a_corot, a)
    integer, intent(in) :: nb, ndim, ncomp
    real(dp), intent(in) :: r(nb, ndim, ndim)
    real(dp), intent(in) :: a_corot(nb, ncomp)
    real(dp), intent(out) :: a(nb, ncomp)

    call rotate_symmetric(nb, ndim, ncomp, r, .false., a_corot, a)
  end subroutine to_global

  !> to_global with a block's stored rotations (rotation_matrix): output and set-up, off the
  !> increment's path.
  pure subroutine stored_to_global(nb, ndim, ncol, ncomp, r_stored, a_corot, a)
    integer, intent(in) :: nb, ndim, ncol, ncomp
    real(dp), intent(in) :: r_stored(nb, ndim, ncol)
    real(dp), intent(in) :: a_corot(nb, ncomp)
    real(dp), intent(out) :: a(nb, ncomp)
    real(dp), allocatable :: r(:, :, :)

    allocate(r(nb, ndim, ndim))
    call rotation_matrix(nb, ndim, ncol, r_stored, r)
    call rotate_symmetric(nb, ndim, ncomp, r, .false., a_corot, a)
  end subroutine stored_to_global

  !> transposed: b = Rᵀ a R, else b = R a Rᵀ. Works on the full in-plane (2D) or 3×3 matrix;
  !> in 2D the 33 component is copied (R33 = 1).
  pure subroutine rotate_symmetric(nb, ndim, ncomp, r, transposed, a, b)
    integer, intent(in) :: nb, ndim, ncomp
    real(dp), intent(in) :: r(nb, ndim, ndim)
    logical, intent(in) :: transposed
    real(dp), intent(in) :: a(nb, ncomp)
    real(dp), intent(out) :: b(nb, ncomp)

    if (ndim == 2) then
       call rotate_symmetric_2d(nb, r, transposed, a, b)
    else if (ndim == 3 .and. ncomp == 6) then
       call rotate_symmetric_3d(nb, r, transposed, a, b)
    else
       call rotate_symmetric_nd(nb, ndim, ncomp, r, transposed, a, b)
    end if
  end subroutine rotate_symmetric

  !> rotate_symmetric for ndim = 3 as one element loop on scalars (no block temporaries, one
  !> pass). The sums are those of rotate_symmetric_nd in the same order, starting from 0 as it
  !> does, so the result is the same to the bit.
  pure subroutine rotate_symmetric_3d(nb, r, transposed, a, b)
    integer, intent(in) :: nb
    real(dp), intent(in) :: r(nb, 3, 3)
    logical, intent(in) :: transposed
    real(dp), intent(in) :: a(nb, 6)
    real(dp), intent(out) :: b(nb, 6)

    ! The branch outside the element loop (inside it would keep the loop scalar): the columns
    ! of Rᵀ are the rows of R, so both forms are b = Q a Qᵀ on the columns named accordingly.
    if (transposed) then
       call rotate_symmetric_3d_columns(nb, r(:, 1, 1), r(:, 2, 1), r(:, 3, 1), r(:, 1, 2), r(:, 2, 2), &
            r(:, 3, 2), r(:, 1, 3), r(:, 2, 3), r(:, 3, 3), a, b)
    else
       call rotate_symmetric_3d_columns(nb, r(:, 1, 1), r(:, 1, 2), r(:, 1, 3), r(:, 2, 1), r(:, 2, 2), &
            r(:, 2, 3), r(:, 3, 1), r(:, 3, 2), r(:, 3, 3), a, b)
    end if
  end subroutine rotate_symmetric_3d

  !> b = Q a Qᵀ for every element, Q given by its nine components (contiguous columns of the
  !> block's R, so no copies).
  pure subroutine rotate_symmetric_3d_columns(nb, q11, q12, q13, q21, q22, q23, q31, q32, q33, a, b)
    integer, intent(in) :: nb
    real(dp), intent(in), dimension(nb) :: q11, q12, q13, q21, q22, q23, q31, q32, q33
    real(dp), intent(in) :: a(nb, 6)
    real(dp), intent(out) :: b(nb, 6)
    real(dp) :: a1, a2, a3, a4, a5, a6
    real(dp) :: t11, t12, t13, t21, t22, t23, t31, t32, t33
    real(dp) :: u11, u12, u13, u21, u22, u23, u31, u32, u33
    integer :: e

    !GCC$ ivdep
    do e = 1, nb
       a1 = a(e, 1)
       a2 = a(e, 2)
       a3 = a(e, 3)
       a4 = a(e, 4)
       a5 = a(e, 5)
       a6 = a(e, 6)
       t11 = ((0.0_dp + a1 * q11(e)) + a4 * q12(e)) + a6 * q13(e)
       t21 = ((0.0_dp + a4 * q11(e)) + a2 * q12(e)) + a5 * q13(e)
       t31 = ((0.0_dp + a6 * q11(e)) + a5 * q12(e)) + a3 * q13(e)
       t12 = ((0.0_dp + a1 * q21(e)) + a4 * q22(e)) + a6 * q23(e)
       t22 = ((0.0_dp + a4 * q21(e)) + a2 * q22(e)) + a5 * q23(e)
       t32 = ((0.0_dp + a6 * q21(e)) + a5 * q22(e)) + a3 * q23(e)
       t13 = ((0.0_dp + a1 * q31(e)) + a4 * q32(e)) + a6 * q33(e)
       t23 = ((0.0_dp + a4 * q31(e)) + a2 * q32(e)) + a5 * q33(e)
       t33 = ((0.0_dp + a6 * q31(e)) + a5 * q32(e)) + a3 * q33(e)
       u11 = ((0.0_dp + q11(e) * t11) + q12(e) * t21) + q13(e) * t31
       u21 = ((0.0_dp + q21(e) * t11) + q22(e) * t21) + q23(e) * t31
       u31 = ((0.0_dp + q31(e) * t11) + q32(e) * t21) + q33(e) * t31
       u12 = ((0.0_dp + q11(e) * t12) + q12(e) * t22) + q13(e) * t32
       u22 = ((0.0_dp + q21(e) * t12) + q22(e) * t22) + q23(e) * t32
       u32 = ((0.0_dp + q31(e) * t12) + q32(e) * t22) + q33(e) * t32
       u13 = ((0.0_dp + q11(e) * t13) + q12(e) * t23) + q13(e) * t33
       u23 = ((0.0_dp + q21(e) * t13) + q22(e) * t23) + q23(e) * t33
       u33 = ((0.0_dp + q31(e) * t13) + q32(e) * t23) + q33(e) * t33
       b(e, 1) = u11
       b(e, 2) = u22
       b(e, 3) = u33
       b(e, 4) = 0.5_dp * (u12 + u21)
       b(e, 5) = 0.5_dp * (u23 + u32)
       b(e, 6) = 0.5_dp * (u31 + u13)
    end do
  end subroutine rotate_symmetric_3d_columns

  !> rotate_symmetric on block temporaries, any ndim (the reference form of the 2D and 3D paths).
  pure subroutine rotate_symmetric_nd(nb, ndim, ncomp, r, transposed, a, b)
    integer, intent(in) :: nb, ndim, ncomp
    real(dp), intent(in) :: r(nb, ndim, ndim)
    logical, intent(in) :: transposed
    real(dp), intent(in) :: a(nb, ncomp)
    real(dp), intent(out) :: b(nb, ncomp)
    real(dp) :: full(nb, ndim, ndim), t(nb, ndim, ndim), q(nb, ndim, ndim)
    integer :: i, j, k, c
    ! q = R (b = q a qᵀ) or Rᵀ
    if (transposed) then
       do j = 1, ndim
          do i = 1, ndim
             q(:, i, j) = r(:, j, i)
          end do
       end do
    else
       q = r
    end if
    if (ndim == 2) then
       full(:, 1, 1) = a(:, 1)
       full(:, 2, 2) = a(:, 2)
       full(:, 1, 2) = a(:, 4)
       full(:, 2, 1) = a(:, 4)
    else
       do c = 1, 6
          full(:, sym_i(c), sym_j(c)) = a(:, c)
          full(:, sym_j(c), sym_i(c)) = a(:, c)
       end do
    end if
    ! t = a qᵀ, then b = q t
    t = 0.0_dp
    do j = 1, ndim
       do k = 1, ndim
          do i = 1, ndim
             t(:, i, j) = t(:, i, j) + full(:, i, k) * q(:, j, k)
          end do
       end do
    end do
    full = 0.0_dp
    do j = 1, ndim
       do k = 1, ndim
          do i = 1, ndim
             full(:, i, j) = full(:, i, j) + q(:, i, k) * t(:, k, j)
          end do
       end do
    end do
    if (ndim == 2) then
       b(:, 1) = full(:, 1, 1)
       b(:, 2) = full(:, 2, 2)
       b(:, 3) = a(:, 3)
       ! symmetrised: exact symmetry of the result whatever the round-off
       b(:, 4) = 0.5_dp * (full(:, 1, 2) + full(:, 2, 1))
    else
       do c = 1, 3
          b(:, c) = full(:, c, c)
       end do
       do c = 4, 6
          b(:, c) = 0.5_dp * (full(:, sym_i(c), sym_j(c)) + full(:, sym_j(c), sym_i(c)))
       end do
    end if
  end subroutine rotate_symmetric_nd

  !> rotate_symmetric for ndim = 2 as one loop on scalars (no block temporaries, one pass). The
  !> sums are those of the general form in the same order, starting from 0 as it does, so the
  !> result is the same to the bit.
  pure subroutine rotate_symmetric_2d(nb, r, transposed, a, b)
    integer, intent(in) :: nb
    real(dp), intent(in) :: r(nb, 2, 2)
    logical, intent(in) :: transposed
    real(dp), intent(in) :: a(nb, 4)
    real(dp), intent(out) :: b(nb, 4)
    integer :: e, i, j

    ! q = R or Rᵀ: q12 = r(:, i, j), q21 = r(:, j, i). Chosen outside the loop, which then
    ! vectorises (a branch inside kept it scalar).
    i = merge(2, 1, transposed)
    j = 3 - i
    do e = 1, nb
       call plane_similarity(r(e, 1, 1), r(e, i, j), r(e, j, i), r(e, 2, 2), a(e, 1), a(e, 2), a(e, 4), &
            b(e, 1), b(e, 2), b(e, 4))
       b(e, 3) = a(e, 3)
    end do
  end subroutine rotate_symmetric_2d

  !> relSpinInc: ΔW − ΔΩ in the corotational frame (Rᵀ_{n+½} applied to the axial vector).
  !> spin_inc is the global material spin increment of the element kinematics (axial vector of
  !> skw(∂Δu/∂x_{n+½})); ΔΩ is the frame spin increment, the Cayley (midpoint) vector of
  !> ΔR = R_{n+1} R_nᵀ: ω_Ω = 2 axial(ΔR − ΔRᵀ) / (1 + tr ΔR) = 2 tan(Δφ/2) a. The same midpoint
  !> rule gives ΔW for a rigid rotation (∂Δu/∂x_{n+½} = 2(ΔR − I)(ΔR + I)⁻¹), so a rigid rotation
  !> has relSpinInc = 0 to round-off.
  !> Order (nb, nshr): 2D ω3 (about the out-of-plane axis); 3D (ω1, ω2, ω3) = (W32, W13, W21).
  pure subroutine relative_spin(nb, ndim, spin_inc, r_old, r_new, r_mid, rel_spin)
    integer, intent(in) :: nb, ndim
    real(dp), intent(in) :: spin_inc(nb, 2 * ndim - 3)
    real(dp), intent(in) :: r_old(nb, ndim, ndim), r_new(nb, ndim, ndim), r_mid(nb, ndim, ndim)
    real(dp), intent(out) :: rel_spin(nb, 2 * ndim - 3)
    integer :: e

    if (ndim == 2) then
       ! One loop on scalars (no block temporaries): ΔR = R_new R_oldᵀ, 1 + tr ΔR of the 3-D embedding
       ! (ΔR33 = 1) and ω3 = spin − 2 (ΔR21 − ΔR12) / (1 + tr ΔR), the sums of the 3D form below.
       do e = 1, nb
          rel_spin(e, 1) = plane_relative_spin(spin_inc(e, 1), r_new(e, 1, 1), r_new(e, 2, 1), r_new(e, 1, 2), &
               r_new(e, 2, 2), r_old(e, 1, 1), r_old(e, 2, 1), r_old(e, 1, 2), r_old(e, 2, 2))
       end do
    else
       call relative_spin_3d(nb, spin_inc, r_old, r_new, r_mid, rel_spin)
    end if
  end subroutine relative_spin

  !> relative_spin for ndim = 3, one element loop on scalars. It replaces a form on block
  !> temporaries with runtime ndim (gfortran put them on the heap, malloc/free per block; issue
  !> 19) with the same sums in the same order, from 0 as there, so the result is the same to the bit.
  pure subroutine relative_spin_3d(nb, spin_inc, r_old, r_new, r_mid, rel_spin)
    integer, intent(in) :: nb
    real(dp), intent(in) :: spin_inc(nb, 3)
    real(dp), intent(in) :: r_old(nb, 3, 3), r_new(nb, 3, 3), r_mid(nb, 3, 3)
    real(dp), intent(out) :: rel_spin(nb, 3)
    real(dp) :: dr(3, 3), w(3), trace1
    integer :: e, i, j, k

    do e = 1, nb
       ! ΔR_ij = Σ_k Rnew_ik Rold_jk
       do j = 1, 3
          do i = 1, 3
             dr(i, j) = 0.0_dp
             do k = 1, 3
                dr(i, j) = dr(i, j) + r_new(e, i, k) * r_old(e, j, k)
             end do
          end do
       end do
       trace1 = 1.0_dp + dr(1, 1) + dr(2, 2) + dr(3, 3)
       w(1) = spin_inc(e, 1) - 2.0_dp * (dr(3, 2) - dr(2, 3)) / trace1
       w(2) = spin_inc(e, 2) - 2.0_dp * (dr(1, 3) - dr(3, 1)) / trace1
       w(3) = spin_inc(e, 3) - 2.0_dp * (dr(2, 1) - dr(1, 2)) / trace1
       do i = 1, 3
          rel_spin(e, i) = r_mid(e, 1, i) * w(1) + r_mid(e, 2, i) * w(2) + r_mid(e, 3, i) * w(3)
       end do
    end do
  end subroutine relative_spin_3d


  !> F in the VUMAT layout (nb, ndir + 2 nshr): 2D F11, F22, F33 (= 1), F12, F21;
  !> 3D F11, F22, F33, F12, F23, F31, F21, F32, F13.
  pure subroutine vumat_defgrad(nb, ndim, f, defgrad)
    integer, intent(in) :: nb, ndim
    real(dp), intent(in) :: f(nb, ndim, ndim)
    real(dp), intent(out) :: defgrad(nb, 4 * ndim - 3)

    if (ndim == 2) then
       defgrad(:, 1) = f(:, 1, 1)
       defgrad(:, 2) = f(:, 2, 2)
       defgrad(:, 3) = 1.0_dp
       defgrad(:, 4) = f(:, 1, 2)
       defgrad(:, 5) = f(:, 2, 1)
    else
       defgrad(:, 1) = f(:, 1, 1)
       defgrad(:, 2) = f(:, 2, 2)
       defgrad(:, 3) = f(:, 3, 3)
       defgrad(:, 4) = f(:, 1, 2)
       defgrad(:, 5) = f(:, 2, 3)
       defgrad(:, 6) = f(:, 3, 1)
       defgrad(:, 7) = f(:, 2, 1)
       defgrad(:, 8) = f(:, 3, 2)
       defgrad(:, 9) = f(:, 1, 3)
    end if
  end subroutine vumat_defgrad

  !> Right stretch U = Rᵀ F (symmetrised) in the VUMAT layout (nb, ncomp); 2D U33 = 1.
  pure subroutine vumat_stretch(nb, ndim, r, f, stretch)
    integer, intent(in) :: nb, ndim
    real(dp), intent(in) :: r(nb, ndim, ndim), f(nb, ndim, ndim)
    real(dp), intent(out) :: stretch(nb, 2 * ndim)
    real(dp) :: u12, u21
    integer :: e

    if (ndim == 2) then
       ! One loop on scalars (no block temporary); the same sums in the same order as below.
       do e = 1, nb
          stretch(e, 1) = (0.0_dp + r(e, 1, 1) * f(e, 1, 1)) + r(e, 2, 1) * f(e, 2, 1)
          stretch(e, 2) = (0.0_dp + r(e, 1, 2) * f(e, 1, 2)) + r(e, 2, 2) * f(e, 2, 2)
          stretch(e, 3) = 1.0_dp
          u12 = (0.0_dp + r(e, 1, 1) * f(e, 1, 2)) + r(e, 2, 1) * f(e, 2, 2)
          u21 = (0.0_dp + r(e, 1, 2) * f(e, 1, 1)) + r(e, 2, 2) * f(e, 2, 1)
          stretch(e, 4) = 0.5_dp * (u12 + u21)
       end do
    else
       call vumat_stretch_nd(nb, ndim, r, f, stretch)
    end if
  end subroutine vumat_stretch

  !> vumat_stretch on a block temporary, any ndim (used for 3D).
  pure subroutine vumat_stretch_nd(nb, ndim, r, f, stretch)
    integer, intent(in) :: nb, ndim
    real(dp), intent(in) :: r(nb, ndim, ndim), f(nb, ndim, ndim)
    real(dp), intent(out) :: stretch(nb, 2 * ndim)
    real(dp) :: u(nb, ndim, ndim)
    integer :: i, j, k, c

    u = 0.0_dp
    do j = 1, ndim
       do k = 1, ndim
          do i = 1, ndim
             u(:, i, j) = u(:, i, j) + r(:, k, i) * f(:, k, j)
          end do
       end do
    end do
    if (ndim == 2) then
       stretch(:, 1) = u(:, 1, 1)
       stretch(:, 2) = u(:, 2, 2)
       stretch(:, 3) = 1.0_dp
       stretch(:, 4) = 0.5_dp * (u(:, 1, 2) + u(:, 2, 1))
    else
       do c = 1, 3
          stretch(:, c) = u(:, c, c)
       end do
       do c = 4, 6
          stretch(:, c) = 0.5_dp * (u(:, sym_i(c), sym_j(c)) + u(:, sym_j(c), sym_i(c)))
       end do
    end if
  end subroutine vumat_stretch_nd
end module fem_corotation
