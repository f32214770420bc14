!> Particle–grid transfer kernels of one block (mpm_shape's compact stencil: corner node and 1D
!> factors): the P2G scatter of mass, momentum and force, the G2P gather of the grid velocities,
!> the MUSL momentum remap and the gather of the velocity gradient. Each kernel forms a stencil
!> node's weight S and gradient ∇S from the 1D factors with mpm_shape's products in their order
!> (2D S = N_a N_b, ∇S = (N'_a N_b, N_a N'_b); 3D S = (N_a N_b) N_c, ...), so every S and ∇S is
!> the double the stored stencil held before, and node corner + (a − 1) + nx (b − 1)
!> [+ nxy (c − 1)] (nx = n1, nxy = n1 n2 grid nodes).
!>
!> Explicit-shape dummies throughout: on allocatable components the compiler reloaded the
!> array descriptors at every store (the P2G loop is store-bound; it was 40 % slower).
!>
!> Why each gather/remap kernel is instantiated three times from one body (mpm_transfer_*.inc):
!> with nd = 2 and nsup = 3 (2D uGIMP, the hopper) and with nd = 3, nsup = 3 (3D uGIMP) as
!> named constants, so the compiler unrolls the node and component loops and keeps a
!> particle's sums in registers, and once with both as arguments (linear shapes). The 3D
!> scatter likewise (mpm_transfer_scatter_3d.inc; the runtime-sized 3D kernels were 2/3 of
!> the instructions of a 3D hopper increment). Calls with literal sizes to one runtime-sized routine were
!> not specialised by gfortran 12 (no clone), and the runtime-sized gradient gather alone was
!> a fifth of the instructions of a hopper run.
!>
!> Order of the sums (bitwise reproducibility): a gather sums a particle's stencil nodes in
!> stencil order from zero, whatever the loop nesting; a scatter adds to a node the blocks'
!> particles stencil node by stencil node (s outer, p inner), the order of the earlier code.
module mpm_transfer
  use, intrinsic :: iso_fortran_env, only: int64
  use base_kinds, only: dp
  implicit none
  private

  public :: scatter_p2g, gather_velocity, scatter_momentum, gather_gradient
  public :: scatter_particles, g2p_particles

contains

  !> P2G of a block: gmass += Σ S m, gmom += Σ S m v, gforce += Σ (S m g − V σ·∇S).
  !> vs(nb, ncomp): V σ in VUMAT order (2D 11, 22, 33, 12; 3D 11, 22, 33, 12, 23, 31).
  pure subroutine scatter_p2g(nb, nsup, nd, ncomp, nn, nx, nxy, corner, w1, dw1, mp, mv, vs, mg, gmass, gmom, &
       gforce)
    integer, intent(in) :: nb, nsup, nd, ncomp, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), dw1(nb, nsup, nd), mp(nb), mv(nb, nd), vs(nb, ncomp), mg(nb, nd)
    real(dp), intent(inout) :: gmass(nn), gmom(nd, nn), gforce(nd, nn)

    if (nd == 2) then
       if (nsup == 3) then
          call scatter_2d(nb, 3, nn, nx, corner, w1, dw1, mp, mv, vs, mg, gmass, gmom, gforce)
       else
          call scatter_2d(nb, nsup, nn, nx, corner, w1, dw1, mp, mv, vs, mg, gmass, gmom, gforce)
       end if
    else if (nsup == 3) then
       call scatter_3d3(nb, nn, nx, nxy, corner, w1, dw1, mp, mv, vs, mg, gmass, gmom, gforce)
    else
       call scatter_3d_any(nb, nsup, nn, nx, nxy, corner, w1, dw1, mp, mv, vs, mg, gmass, gmom, gforce)
    end if
  end subroutine scatter_p2g

  pure subroutine scatter_2d(nb, nsup, nn, nx, corner, w1, dw1, mp, mv, vs, mg, gmass, gmom, gforce)
    integer, intent(in) :: nb, nsup, nn, nx
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, 2), dw1(nb, nsup, 2), mp(nb), mv(nb, 2), vs(nb, 4), mg(nb, 2)
    real(dp), intent(inout) :: gmass(nn), gmom(2, nn), gforce(2, nn)
    integer :: a, b, off, p, i
    real(dp) :: wp, dx, dy

    do b = 1, nsup
       do a = 1, nsup
          off = (a - 1) + nx * (b - 1)
          do p = 1, nb
             i = corner(p) + off
             wp = w1(p, a, 1) * w1(p, b, 2)
             dx = dw1(p, a, 1) * w1(p, b, 2)
             dy = w1(p, a, 1) * dw1(p, b, 2)
             gmass(i) = gmass(i) + wp * mp(p)
             gmom(1, i) = gmom(1, i) + wp * mv(p, 1)
             gmom(2, i) = gmom(2, i) + wp * mv(p, 2)
             gforce(1, i) = gforce(1, i) + (wp * mg(p, 1) - (vs(p, 1) * dx + vs(p, 4) * dy))
             gforce(2, i) = gforce(2, i) + (wp * mg(p, 2) - (vs(p, 4) * dx + vs(p, 2) * dy))
          end do
       end do
    end do
  end subroutine scatter_2d

  pure subroutine scatter_3d3(nb, nn, nx, nxy, corner, w1, dw1, mp, mv, vs, mg, gmass, gmom, gforce)
    integer, parameter :: nsup = 3
    include 'mpm_transfer_scatter_3d.inc'
  end subroutine scatter_3d3

  pure subroutine scatter_3d_any(nb, nsup, nn, nx, nxy, corner, w1, dw1, mp, mv, vs, mg, gmass, gmom, gforce)
    integer, intent(in) :: nsup
    include 'mpm_transfer_scatter_3d.inc'
  end subroutine scatter_3d_any

  !> G2P gather: vpic = Σ_s S v_new, dv = Σ_s S (v_new − v_old) at the particles of a block.
  pure subroutine gather_velocity(nb, nsup, nd, nn, nx, nxy, corner, w1, v_new, v_old, vpic, dv)
    integer, intent(in) :: nb, nsup, nd, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), v_new(nd, nn), v_old(nd, nn)
    real(dp), intent(out) :: vpic(nb, nd), dv(nb, nd)

    if (nd == 2 .and. nsup == 3) then
       call gather_velocity_2d3(nb, nn, nx, nxy, corner, w1, v_new, v_old, vpic, dv)
    else if (nd == 3 .and. nsup == 3) then
       call gather_velocity_3d3(nb, nn, nx, nxy, corner, w1, v_new, v_old, vpic, dv)
    else
       call gather_velocity_any(nb, nsup, nd, nn, nx, nxy, corner, w1, v_new, v_old, vpic, dv)
    end if
  end subroutine gather_velocity

  pure subroutine gather_velocity_2d3(nb, nn, nx, nxy, corner, w1, v_new, v_old, vpic, dv)
    integer, parameter :: nd = 2, nsup = 3
    include 'mpm_transfer_gather_velocity.inc'
  end subroutine gather_velocity_2d3

  pure subroutine gather_velocity_3d3(nb, nn, nx, nxy, corner, w1, v_new, v_old, vpic, dv)
    integer, parameter :: nd = 3, nsup = 3
    include 'mpm_transfer_gather_velocity.inc'
  end subroutine gather_velocity_3d3

  pure subroutine gather_velocity_any(nb, nsup, nd, nn, nx, nxy, corner, w1, v_new, v_old, vpic, dv)
    integer, intent(in) :: nsup, nd
    include 'mpm_transfer_gather_velocity.inc'
  end subroutine gather_velocity_any

  !> MUSL remap of a block: gmom += Σ_s S (m v)_p.
  pure subroutine scatter_momentum(nb, nsup, nd, nn, nx, nxy, corner, w1, mv, gmom)
    integer, intent(in) :: nb, nsup, nd, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), mv(nb, nd)
    real(dp), intent(inout) :: gmom(nd, nn)

    if (nd == 2 .and. nsup == 3) then
       call scatter_momentum_2d3(nb, nn, nx, nxy, corner, w1, mv, gmom)
    else if (nd == 3 .and. nsup == 3) then
       call scatter_momentum_3d3(nb, nn, nx, nxy, corner, w1, mv, gmom)
    else
       call scatter_momentum_any(nb, nsup, nd, nn, nx, nxy, corner, w1, mv, gmom)
    end if
  end subroutine scatter_momentum

  pure subroutine scatter_momentum_2d3(nb, nn, nx, nxy, corner, w1, mv, gmom)
    integer, parameter :: nd = 2, nsup = 3
    include 'mpm_transfer_scatter_momentum.inc'
  end subroutine scatter_momentum_2d3

  pure subroutine scatter_momentum_3d3(nb, nn, nx, nxy, corner, w1, mv, gmom)
    integer, parameter :: nd = 3, nsup = 3
    include 'mpm_transfer_scatter_momentum.inc'
  end subroutine scatter_momentum_3d3

  pure subroutine scatter_momentum_any(nb, nsup, nd, nn, nx, nxy, corner, w1, mv, gmom)
    integer, intent(in) :: nsup, nd
    include 'mpm_transfer_scatter_momentum.inc'
  end subroutine scatter_momentum_any

  !> Velocity gradient L(p, a, c) = Σ_s v_a(node) ∂S/∂x_c of a block.
  pure subroutine gather_gradient(nb, nsup, nd, nn, nx, nxy, corner, w1, dw1, v, l)
    integer, intent(in) :: nb, nsup, nd, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), dw1(nb, nsup, nd), v(nd, nn)
    real(dp), intent(out) :: l(nb, nd, nd)

    if (nd == 2 .and. nsup == 3) then
       call gather_gradient_2d3(nb, nn, nx, nxy, corner, w1, dw1, v, l)
    else if (nd == 3 .and. nsup == 3) then
       call gather_gradient_3d3(nb, nn, nx, nxy, corner, w1, dw1, v, l)
    else
       call gather_gradient_any(nb, nsup, nd, nn, nx, nxy, corner, w1, dw1, v, l)
    end if
  end subroutine gather_gradient

  pure subroutine gather_gradient_2d3(nb, nn, nx, nxy, corner, w1, dw1, v, l)
    integer, parameter :: nd = 2, nsup = 3
    include 'mpm_transfer_gather_gradient.inc'
  end subroutine gather_gradient_2d3

  pure subroutine gather_gradient_3d3(nb, nn, nx, nxy, corner, w1, dw1, v, l)
    integer, parameter :: nd = 3, nsup = 3
    include 'mpm_transfer_gather_gradient.inc'
  end subroutine gather_gradient_3d3

  pure subroutine gather_gradient_any(nb, nsup, nd, nn, nx, nxy, corner, w1, dw1, v, l)
    integer, intent(in) :: nsup, nd
    include 'mpm_transfer_gather_gradient.inc'
  end subroutine gather_gradient_any

  ! ---------------------------------------------------------------- particle-major (cell order)

  !> P2G of a block particle by particle (*MPM CONTROLS, SORT > 0: the particles are in cell
  !> order, mpm_sort): gmass += Σ S m, gmom += Σ S m v, gforce += Σ (S m g − V σ·∇S) with
  !> V = V0 det F; the same products as scatter_p2g, the sums of a node in particle order.
  pure subroutine scatter_particles(nb, nsup, nd, nn, nx, nxy, corner, w1, dw1, mp, vol0, f, v, sg, gravity, &
       gmass, gmom, gforce)
    integer, intent(in) :: nb, nsup, nd, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), dw1(nb, nsup, nd), mp(nb), vol0(nb), f(nb, nd, nd), v(nb, nd)
    real(dp), intent(in) :: sg(nb, 2 * nd), gravity(3)
    real(dp), intent(inout) :: gmass(nn), gmom(nd, nn), gforce(nd, nn)

    if (nd == 2 .and. nsup == 3) then
       call scatter_particles_2d3(nb, nn, nx, nxy, corner, w1, dw1, mp, vol0, f, v, sg, gravity, gmass, gmom, gforce)
    else if (nd == 3 .and. nsup == 3) then
       call scatter_particles_3d3(nb, nn, nx, nxy, corner, w1, dw1, mp, vol0, f, v, sg, gravity, gmass, gmom, gforce)
    else
       call scatter_particles_any(nb, nsup, nd, nn, nx, nxy, corner, w1, dw1, mp, vol0, f, v, sg, gravity, gmass, &
            gmom, gforce)
    end if
  end subroutine scatter_particles

  pure subroutine scatter_particles_2d3(nb, nn, nx, nxy, corner, w1, dw1, mp, vol0, f, v, sg, gravity, gmass, gmom, &
       gforce)
    integer, parameter :: nd = 2, nsup = 3
    include 'mpm_transfer_scatter_particles.inc'
  end subroutine scatter_particles_2d3

  pure subroutine scatter_particles_3d3(nb, nn, nx, nxy, corner, w1, dw1, mp, vol0, f, v, sg, gravity, gmass, gmom, &
       gforce)
    integer, parameter :: nd = 3, nsup = 3
    include 'mpm_transfer_scatter_particles.inc'
  end subroutine scatter_particles_3d3

  pure subroutine scatter_particles_any(nb, nsup, nd, nn, nx, nxy, corner, w1, dw1, mp, vol0, f, v, sg, gravity, &
       gmass, gmom, gforce)
    integer, intent(in) :: nsup, nd
    include 'mpm_transfer_scatter_particles.inc'
  end subroutine scatter_particles_any

  !> G2P and the MUSL remap of a block particle by particle (SORT > 0): v ← α(v + Σ S Δv) +
  !> (1 − α) Σ S v_new, x += Δt Σ S v_new, wk += m g·Δt Σ S v_new, then gmom += Σ S m v.
  pure subroutine g2p_particles(nb, nsup, nd, nn, nx, nxy, corner, w1, v_new, v_old, mp, gravity, alpha, dt, v, x, &
       gmom, wk)
    integer, intent(in) :: nb, nsup, nd, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), v_new(nd, nn), v_old(nd, nn), mp(nb), gravity(3), alpha, dt
    real(dp), intent(inout) :: v(nb, nd), x(nb, nd), gmom(nd, nn), wk

    if (nd == 2 .and. nsup == 3) then
       call g2p_particles_2d3(nb, nn, nx, nxy, corner, w1, v_new, v_old, mp, gravity, alpha, dt, v, x, gmom, wk)
    else if (nd == 3 .and. nsup == 3) then
       call g2p_particles_3d3(nb, nn, nx, nxy, corner, w1, v_new, v_old, mp, gravity, alpha, dt, v, x, gmom, wk)
    else
       call g2p_particles_any(nb, nsup, nd, nn, nx, nxy, corner, w1, v_new, v_old, mp, gravity, alpha, dt, v, x, &
            gmom, wk)
    end if
  end subroutine g2p_particles

  pure subroutine g2p_particles_2d3(nb, nn, nx, nxy, corner, w1, v_new, v_old, mp, gravity, alpha, dt, v, x, gmom, wk)
    integer, parameter :: nd = 2, nsup = 3
    include 'mpm_transfer_g2p_particles.inc'
  end subroutine g2p_particles_2d3

  pure subroutine g2p_particles_3d3(nb, nn, nx, nxy, corner, w1, v_new, v_old, mp, gravity, alpha, dt, v, x, gmom, wk)
    integer, parameter :: nd = 3, nsup = 3
    include 'mpm_transfer_g2p_particles.inc'
  end subroutine g2p_particles_3d3

  pure subroutine g2p_particles_any(nb, nsup, nd, nn, nx, nxy, corner, w1, v_new, v_old, mp, gravity, alpha, dt, v, &
       x, gmom, wk)
    integer, intent(in) :: nsup, nd
    include 'mpm_transfer_g2p_particles.inc'
  end subroutine g2p_particles_any
end module mpm_transfer
