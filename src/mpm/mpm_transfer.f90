!> Particle–grid transfer kernels of one block (mpm_shape's (nb, ns) stencil layout): the P2G
!> scatter of mass, momentum and force, the G2P gather of the grid velocities, the MUSL momentum
!> remap and the gather of the velocity gradient.
!>
!> Explicit-shape dummies throughout: on allocatable components the compiler reloaded the
!> array descriptors at every store (the P2G loop is store-bound; it was 40 % slower).
!>
!> Why each gather/remap kernel is instantiated twice from one body (mpm_transfer_*.inc): once
!> with ndim = 2 and ns = 9 (2D uGIMP, the hopper) as named constants, so the compiler unrolls
!> the node and component loops and keeps a particle's sums in registers, and once with both
!> as arguments (linear shapes, 3D). Calls with literal sizes to one runtime-sized routine were
!> not specialised by gfortran 12 (no clone), and the runtime-sized gradient gather alone was
!> a fifth of the instructions of a hopper run.
!>
!> Order of the sums (bitwise reproducibility): a gather sums a particle's stencil nodes in
!> stencil order from zero, whatever the loop nesting; a scatter adds to a node the blocks'
!> particles stencil node by stencil node (s outer, p inner), the order of the earlier code.
module mpm_transfer
  use material_kinds, only: dp
  implicit none
  private

  public :: scatter_p2g, gather_velocity, scatter_momentum, gather_gradient

contains

  !> P2G of a block: gmass += Σ S m, gmom += Σ S m v, gforce += Σ (S m g − V σ·∇S).
  !> vs(nb, ncomp): V σ in VUMAT order (2D 11, 22, 33, 12; 3D 11, 22, 33, 12, 23, 31).
  pure subroutine scatter_p2g(nb, ns, nd, ncomp, nn, node, w, dw, mp, mv, vs, mg, gmass, gmom, gforce)
    integer, intent(in) :: nb, ns, nd, ncomp, nn
    integer, intent(in) :: node(nb, ns)
    real(dp), intent(in) :: w(nb, ns), dw(nb, nd * ns), mp(nb), mv(nb, nd), vs(nb, ncomp), mg(nb, nd)
    real(dp), intent(inout) :: gmass(nn), gmom(nd, nn), gforce(nd, nn)

    if (nd == 2) then
       if (ns == 9) then
          call scatter_2d(nb, 9, nn, node, w, dw, mp, mv, vs, mg, gmass, gmom, gforce)
       else
          call scatter_2d(nb, ns, nn, node, w, dw, mp, mv, vs, mg, gmass, gmom, gforce)
       end if
    else
       call scatter_3d(nb, ns, nn, node, w, dw, mp, mv, vs, mg, gmass, gmom, gforce)
    end if
  end subroutine scatter_p2g

  pure subroutine scatter_2d(nb, ns, nn, node, w, dw, mp, mv, vs, mg, gmass, gmom, gforce)
    integer, intent(in) :: nb, ns, nn
    integer, intent(in) :: node(nb, ns)
    real(dp), intent(in) :: w(nb, ns), dw(nb, 2 * ns), mp(nb), mv(nb, 2), vs(nb, 4), mg(nb, 2)
    real(dp), intent(inout) :: gmass(nn), gmom(2, nn), gforce(2, nn)
    integer :: s, p, i
    real(dp) :: wp, dx, dy

    do s = 1, ns
       do p = 1, nb
          i = node(p, s)
          wp = w(p, s)
          dx = dw(p, s)
          dy = dw(p, ns + s)
          gmass(i) = gmass(i) + wp * mp(p)
          gmom(1, i) = gmom(1, i) + wp * mv(p, 1)
          gmom(2, i) = gmom(2, i) + wp * mv(p, 2)
          gforce(1, i) = gforce(1, i) + (wp * mg(p, 1) - (vs(p, 1) * dx + vs(p, 4) * dy))
          gforce(2, i) = gforce(2, i) + (wp * mg(p, 2) - (vs(p, 4) * dx + vs(p, 2) * dy))
       end do
    end do
  end subroutine scatter_2d

  pure subroutine scatter_3d(nb, ns, nn, node, w, dw, mp, mv, vs, mg, gmass, gmom, gforce)
    integer, intent(in) :: nb, ns, nn
    integer, intent(in) :: node(nb, ns)
    real(dp), intent(in) :: w(nb, ns), dw(nb, 3 * ns), mp(nb), mv(nb, 3), vs(nb, 6), mg(nb, 3)
    real(dp), intent(inout) :: gmass(nn), gmom(3, nn), gforce(3, nn)
    integer :: s, p, i
    real(dp) :: wp, dx, dy, dz

    do s = 1, ns
       do p = 1, nb
          i = node(p, s)
          wp = w(p, s)
          dx = dw(p, s)
          dy = dw(p, ns + s)
          dz = dw(p, 2 * ns + s)
          gmass(i) = gmass(i) + wp * mp(p)
          gmom(1, i) = gmom(1, i) + wp * mv(p, 1)
          gmom(2, i) = gmom(2, i) + wp * mv(p, 2)
          gmom(3, i) = gmom(3, i) + wp * mv(p, 3)
          gforce(1, i) = gforce(1, i) + (wp * mg(p, 1) - (vs(p, 1) * dx + vs(p, 4) * dy + vs(p, 6) * dz))
          gforce(2, i) = gforce(2, i) + (wp * mg(p, 2) - (vs(p, 4) * dx + vs(p, 2) * dy + vs(p, 5) * dz))
          gforce(3, i) = gforce(3, i) + (wp * mg(p, 3) - (vs(p, 6) * dx + vs(p, 5) * dy + vs(p, 3) * dz))
       end do
    end do
  end subroutine scatter_3d

  !> G2P gather: vpic = Σ_s S v_new, dv = Σ_s S (v_new − v_old) at the particles of a block.
  pure subroutine gather_velocity(nb, ns, nd, nn, node, w, v_new, v_old, vpic, dv)
    integer, intent(in) :: nb, ns, nd, nn
    integer, intent(in) :: node(nb, ns)
    real(dp), intent(in) :: w(nb, ns), v_new(nd, nn), v_old(nd, nn)
    real(dp), intent(out) :: vpic(nb, nd), dv(nb, nd)

    if (nd == 2 .and. ns == 9) then
       call gather_velocity_2d9(nb, nn, node, w, v_new, v_old, vpic, dv)
    else
       call gather_velocity_any(nb, ns, nd, nn, node, w, v_new, v_old, vpic, dv)
    end if
  end subroutine gather_velocity

  pure subroutine gather_velocity_2d9(nb, nn, node, w, v_new, v_old, vpic, dv)
    integer, parameter :: nd = 2, ns = 9
    include 'mpm_transfer_gather_velocity.inc'
  end subroutine gather_velocity_2d9

  pure subroutine gather_velocity_any(nb, ns, nd, nn, node, w, v_new, v_old, vpic, dv)
    integer, intent(in) :: ns, nd
    include 'mpm_transfer_gather_velocity.inc'
  end subroutine gather_velocity_any

  !> MUSL remap of a block: gmom += Σ_s S (m v)_p.
  pure subroutine scatter_momentum(nb, ns, nd, nn, node, w, mv, gmom)
    integer, intent(in) :: nb, ns, nd, nn
    integer, intent(in) :: node(nb, ns)
    real(dp), intent(in) :: w(nb, ns), mv(nb, nd)
    real(dp), intent(inout) :: gmom(nd, nn)

    if (nd == 2 .and. ns == 9) then
       call scatter_momentum_2d9(nb, nn, node, w, mv, gmom)
    else
       call scatter_momentum_any(nb, ns, nd, nn, node, w, mv, gmom)
    end if
  end subroutine scatter_momentum

  pure subroutine scatter_momentum_2d9(nb, nn, node, w, mv, gmom)
    integer, parameter :: nd = 2, ns = 9
    include 'mpm_transfer_scatter_momentum.inc'
  end subroutine scatter_momentum_2d9

  pure subroutine scatter_momentum_any(nb, ns, nd, nn, node, w, mv, gmom)
    integer, intent(in) :: ns, nd
    include 'mpm_transfer_scatter_momentum.inc'
  end subroutine scatter_momentum_any

  !> Velocity gradient L(p, a, c) = Σ_s v_a(node) ∂S/∂x_c of a block.
  pure subroutine gather_gradient(nb, ns, nd, nn, node, dw, v, l)
    integer, intent(in) :: nb, ns, nd, nn
    integer, intent(in) :: node(nb, ns)
    real(dp), intent(in) :: dw(nb, nd * ns), v(nd, nn)
    real(dp), intent(out) :: l(nb, nd, nd)

    if (nd == 2 .and. ns == 9) then
       call gather_gradient_2d9(nb, nn, node, dw, v, l)
    else
       call gather_gradient_any(nb, ns, nd, nn, node, dw, v, l)
    end if
  end subroutine gather_gradient

  pure subroutine gather_gradient_2d9(nb, nn, node, dw, v, l)
    integer, parameter :: nd = 2, ns = 9
    include 'mpm_transfer_gather_gradient.inc'
  end subroutine gather_gradient_2d9

  pure subroutine gather_gradient_any(nb, ns, nd, nn, node, dw, v, l)
    integer, intent(in) :: ns, nd
    include 'mpm_transfer_gather_gradient.inc'
  end subroutine gather_gradient_any
end module mpm_transfer
