!> Flanagan–Belytschko hourglass control of one-point elements (viscous and stiffness forms),
!> generic over the element: the element modules supply the γ vectors and the scalings.
!>
!> With γ_αI the FB hourglass vectors (unnormalised, entries ±1 on a parallelogram/
!> parallelepiped; orthogonal to all linear fields) and du = Δt v_{n+½}:
!>   hourglass displacement increment   q_iα = Σ_I γ_αI du_iI     (zero for linear fields)
!>   viscous    f_iI = C q_iα/Δt γ_αI,            ΔE = C Σ q²/Δt ≥ 0
!>              C = Q_v ρ c_d V^{2/3}/4 (3D, LS-DYNA form), Q_v ρ c_d t √A/4 (2D)
!>   stiffness  Q^c_iα ← Q^c_iα + K (R_{n+½}ᵀ q)_iα  (corotational generalised force, state)
!>              f_iI = (R_{n+1} Q^c)_iα γ_αI,         ΔE = ½ (Q^c_old + Q^c_new)·(R_{n+½}ᵀ q)
!>              K = κ (λ+2μ) V Σ_iI B_iI² / nen   (per mode). On a square/cube this is
!>              6κ M/(M+μ) (2D) or 9κ M/(M+μ) (3D) times the hourglass-mode stiffness of the
!>              fully integrated element, (M+μ)t/12 resp. (M+μ)h/48 (M = λ+2μ): about 20–30 %
!>              of it at κ = 0.05.
!> f is the internal-force sign (added to f_int; its power C q̇² is dissipated / stored).
!> ΔE is the hourglass energy increment of the element (J; ALLAE).
!> Defaults: Q_v = 0.1 (LS-DYNA/OptiStruct viscous default), κ = 0.05 (stiffness default).
!> Storing the stiffness force in the corotational frame keeps it objective: a rigid rotation
!> turns the hourglass force with the element and does no work.
module fem_hourglass
  use base_kinds, only: dp
  ! The codes are the model's (a section owns its hourglass control); re-exported for the kernels' callers.
  use model_materials, only: hourglass_none, hourglass_viscous, hourglass_stiffness, &
       default_hourglass_viscous_coefficient, default_hourglass_stiffness_coefficient
  implicit none
  private

  public :: hourglass_forces
  public :: hourglass_none, hourglass_viscous, hourglass_stiffness
  public :: default_hourglass_viscous_coefficient, default_hourglass_stiffness_coefficient

contains

  !> gamma (nb, nen, nmode); du (nb, ndim, nen); visc_scale = C/Q_v, stiff_scale = K/κ (nb);
  !> rot_mid, rot_new (nb, ndim, ndim); hg_state (nb, ndim, nmode) corotational Q (stiffness
  !> form only); fe (nb, ndim, nen) incremented; energy_inc (nb) set.
  !> dt > 0 (the viscous form divides by it).
  pure subroutine hourglass_forces(nb, ndim, nen, nmode, gamma, du, dt, kind, coefficient, &
                                   visc_scale, stiff_scale, rot_mid, rot_new, hg_state, fe, &
                                   energy_inc)
    integer, intent(in) :: nb, ndim, nen, nmode
    real(dp), intent(in) :: gamma(nb, nen, nmode)
    real(dp), intent(in) :: du(nb, ndim, nen)
    real(dp), intent(in) :: dt
    integer, intent(in) :: kind
    real(dp), intent(in) :: coefficient
    real(dp), intent(in) :: visc_scale(nb), stiff_scale(nb)
    real(dp), intent(in) :: rot_mid(nb, ndim, ndim), rot_new(nb, ndim, ndim)
    real(dp), intent(inout) :: hg_state(nb, ndim, nmode)
    real(dp), intent(inout) :: fe(nb, ndim, nen)
    real(dp), intent(out) :: energy_inc(nb)
    real(dp) :: q(nb, ndim, nmode), qc(nb, ndim, nmode), qg(nb, ndim, nmode), c(nb)
    integer :: i, k, n, m

    energy_inc = 0.0_dp
    if (kind /= hourglass_viscous .and. kind /= hourglass_stiffness) return

    ! q_iα = Σ_I γ_αI du_iI
    q = 0.0_dp
    do m = 1, nmode
       do n = 1, nen
          do i = 1, ndim
             q(:, i, m) = q(:, i, m) + gamma(:, n, m) * du(:, i, n)
          end do
       end do
    end do

    if (kind == hourglass_viscous) then
       c = coefficient * visc_scale / max(dt, tiny(1.0_dp))
       ! generalised force C q/Δt; energy C q²/Δt
       do m = 1, nmode
          do i = 1, ndim
             qg(:, i, m) = c * q(:, i, m)
             energy_inc = energy_inc + qg(:, i, m) * q(:, i, m)
          end do
       end do
    else
       c = coefficient * stiff_scale
       ! qc = R_midᵀ q (corotational increment); Q^c += K qc; qg = R_new Q^c
       qc = 0.0_dp
       do m = 1, nmode
          do k = 1, ndim
             do i = 1, ndim
                qc(:, i, m) = qc(:, i, m) + rot_mid(:, k, i) * q(:, k, m)
             end do
          end do
       end do
       do m = 1, nmode
          do i = 1, ndim
             energy_inc = energy_inc + (hg_state(:, i, m) + 0.5_dp * c * qc(:, i, m)) * qc(:, i, m)
             hg_state(:, i, m) = hg_state(:, i, m) + c * qc(:, i, m)
          end do
       end do
       qg = 0.0_dp
       do m = 1, nmode
          do k = 1, ndim
             do i = 1, ndim
                qg(:, i, m) = qg(:, i, m) + rot_new(:, i, k) * hg_state(:, k, m)
             end do
          end do
       end do
    end if

    ! f_iI += Σ_α qg_iα γ_αI
    do m = 1, nmode
       do n = 1, nen
          do i = 1, ndim
             fe(:, i, n) = fe(:, i, n) + qg(:, i, m) * gamma(:, n, m)
          end do
       end do
    end do
  end subroutine hourglass_forces
end module fem_hourglass
