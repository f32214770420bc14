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
  public :: scatter_particles_3d_packed, gather_velocity_3d_packed, gather_gradient_3d_packed
  public :: remap_particles_3d_packed, unpack_momentum, pack_velocities, unpack_grid_sums, stencil_span, clear_records
  public :: scatter_p2g_3d_packed, gather_velocity_3d_packed_pic, scatter_momentum_3d_packed

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

  ! ------------------------------------------------- 3D uGIMP on packed node records (issue 19)
  !
  ! Why packed records: in 3D the per-node work of the transfers is the same operation on the
  ! three components (and on the mass with the momentum), but gcc 12 does not SLP-vectorise it
  ! from the (3, nn) arrays (three-lane groups; parenthesised sums; factors hoisted into
  ! scalars). With a node's values as 4-lane records — (mass, m v1, m v2, m v3), (f1, f2, f3, 0),
  ! (v1, v2, v3, 0) — and the lane loops kept as loops (`unroll 1`, so the loop vectoriser, not
  ! the SLP pass, sees them), each lane loop is one AVX2 operation. Every lane does the scalar
  ! kernel's operations in its order (no reassociation: -ffp-contract=off, no fast-math), so
  ! every value is the scalar kernel's bit for bit; the fourth lane of a force or velocity
  ! record is 0 and nothing reads it.

  !> scatter_particles for 3D uGIMP (nsup = 3) into packed records gs(8, nn): gs(1:4, i) the
  !> mass and momentum, gs(5:7, i) the force of node i (gs(8, i) pad). The expressions of
  !> mpm_transfer_scatter_particles.inc in their order.
  pure subroutine scatter_particles_3d_packed(nb, nn, nx, nxy, corner, w1, dw1, mp, vol0, f, v, sg, gravity, gs)
    integer, parameter :: nsup = 3, nd = 3
    integer, intent(in) :: nb, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), dw1(nb, nsup, nd), mp(nb), vol0(nb), f(nb, nd, nd), v(nb, nd)
    real(dp), intent(in) :: sg(nb, 2 * nd), gravity(3)
    real(dp), intent(inout) :: gs(8, nn)
    ! fac(:, 1) (m, m v), fac(:, 2) m g, fac(:, 3:5) the columns of V σ (lane 4: 0)
    real(dp) :: fac(4, 5), g1, g2, g3, wp, vol, t, u
    integer :: a, b, c, p, i, k

    do p = 1, nb
       vol = vol0(p) * (f(p, 1, 1) * (f(p, 2, 2) * f(p, 3, 3) - f(p, 2, 3) * f(p, 3, 2)) &
            - f(p, 1, 2) * (f(p, 2, 1) * f(p, 3, 3) - f(p, 2, 3) * f(p, 3, 1)) &
            + f(p, 1, 3) * (f(p, 2, 1) * f(p, 3, 2) - f(p, 2, 2) * f(p, 3, 1)))
       fac(1, 1) = mp(p)
       do k = 1, nd
          fac(k + 1, 1) = mp(p) * v(p, k)
          fac(k, 2) = mp(p) * gravity(k)
       end do
       fac(4, 2) = 0
       fac(:, 3) = [vol * sg(p, 1), vol * sg(p, 4), vol * sg(p, 6), 0.0_dp]
       fac(:, 4) = [vol * sg(p, 4), vol * sg(p, 2), vol * sg(p, 5), 0.0_dp]
       fac(:, 5) = [vol * sg(p, 6), vol * sg(p, 5), vol * sg(p, 3), 0.0_dp]
       do c = 1, nsup
          do b = 1, nsup
             do a = 1, nsup
                i = corner(p) + (a - 1) + nx * (b - 1) + nxy * (c - 1)
                wp = w1(p, a, 1) * w1(p, b, 2)
                g1 = dw1(p, a, 1) * w1(p, b, 2)
                g2 = w1(p, a, 1) * dw1(p, b, 2)
                wp = wp * w1(p, c, 3)
                g1 = g1 * w1(p, c, 3)
                g2 = g2 * w1(p, c, 3)
                g3 = w1(p, a, 1) * w1(p, b, 2) * dw1(p, c, 3)
                !GCC$ unroll 1
                do k = 1, 4
                   gs(k, i) = gs(k, i) + wp * fac(k, 1)
                end do
                ! gforce(k) + (wp mg(k) − (vs_k1 g1 + vs_k2 g2 + vs_k3 g3)), as the scalar kernel
                !GCC$ unroll 1
                do k = 1, 4
                   t = fac(k, 3) * g1 + fac(k, 4) * g2 + fac(k, 5) * g3
                   u = wp * fac(k, 2) - t
                   gs(4 + k, i) = gs(4 + k, i) + u
                end do
             end do
          end do
       end do
    end do
  end subroutine scatter_particles_3d_packed

  !> scatter_p2g for 3D uGIMP (node-major, SORT = 0) into packed records gs(8, nn) as
  !> scatter_particles_3d_packed: the particle factors packed first into fac(4, 5, nb) (work), then
  !> the sums of mpm_transfer_scatter_3d.inc, s outer and p inner, each lane in its order.
  pure subroutine scatter_p2g_3d_packed(nb, nn, nx, nxy, corner, w1, dw1, mp, mv, vs, mg, fac, gs)
    integer, parameter :: nsup = 3
    integer, intent(in) :: nb, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, 3), dw1(nb, nsup, 3), mp(nb), mv(nb, 3), vs(nb, 6), mg(nb, 3)
    real(dp), intent(out) :: fac(4, 5, nb)
    real(dp), intent(inout) :: gs(8, nn)
    real(dp) :: wp, dx, dy, dz, t, u
    integer :: a, b, c, off, p, i, k

    do p = 1, nb
       fac(1, 1, p) = mp(p)
       do k = 1, 3
          fac(k + 1, 1, p) = mv(p, k)
          fac(k, 2, p) = mg(p, k)
       end do
       fac(4, 2, p) = 0
       fac(:, 3, p) = [vs(p, 1), vs(p, 4), vs(p, 6), 0.0_dp]
       fac(:, 4, p) = [vs(p, 4), vs(p, 2), vs(p, 5), 0.0_dp]
       fac(:, 5, p) = [vs(p, 6), vs(p, 5), vs(p, 3), 0.0_dp]
    end do
    do c = 1, nsup
       do b = 1, nsup
          do a = 1, nsup
             off = (a - 1) + nx * (b - 1) + nxy * (c - 1)
             do p = 1, nb
                i = corner(p) + off
                wp = w1(p, a, 1) * w1(p, b, 2) * w1(p, c, 3)
                dx = dw1(p, a, 1) * w1(p, b, 2) * w1(p, c, 3)
                dy = w1(p, a, 1) * dw1(p, b, 2) * w1(p, c, 3)
                dz = w1(p, a, 1) * w1(p, b, 2) * dw1(p, c, 3)
                !GCC$ unroll 1
                do k = 1, 4
                   gs(k, i) = gs(k, i) + wp * fac(k, 1, p)
                end do
                !GCC$ unroll 1
                do k = 1, 4
                   t = fac(k, 3, p) * dx + fac(k, 4, p) * dy + fac(k, 5, p) * dz
                   u = wp * fac(k, 2, p) - t
                   gs(4 + k, i) = gs(4 + k, i) + u
                end do
             end do
          end do
       end do
    end do
  end subroutine scatter_p2g_3d_packed

  !> gather_velocity for 3D uGIMP on packed records gv(8, nn) (v_new lanes 1:4, v_old 5:8):
  !> vpic = Σ S v_new, dv = Σ S (v_new − v_old), the sums of mpm_transfer_gather_velocity.inc.
  pure subroutine gather_velocity_3d_packed_pic(nb, nn, nx, nxy, corner, w1, gv, vpic, dv)
    integer, parameter :: nsup = 3
    integer, intent(in) :: nb, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, 3), gv(8, nn)
    real(dp), intent(out) :: vpic(nb, 3), dv(nb, 3)
    real(dp) :: sv(4), sd(4), ws
    integer :: a, b, c, p, i, k

    do p = 1, nb
       sv = 0
       sd = 0
       do c = 1, nsup
          do b = 1, nsup
             do a = 1, nsup
                i = corner(p) + (a - 1) + nx * (b - 1) + nxy * (c - 1)
                ws = w1(p, a, 1) * w1(p, b, 2)
                ws = ws * w1(p, c, 3)
                !GCC$ unroll 1
                do k = 1, 4
                   sv(k) = sv(k) + ws * gv(k, i)
                   sd(k) = sd(k) + ws * (gv(k, i) - gv(4 + k, i))
                end do
             end do
          end do
       end do
       do k = 1, 3
          vpic(p, k) = sv(k)
          dv(p, k) = sd(k)
       end do
    end do
  end subroutine gather_velocity_3d_packed_pic

  !> scatter_momentum for 3D uGIMP (node-major, SORT = 0) into packed records gm(4, nn): the
  !> momentum m v packed into mv4(4, nb) (work), then the sums of
  !> mpm_transfer_scatter_momentum.inc, s outer and p inner.
  pure subroutine scatter_momentum_3d_packed(nb, nn, nx, nxy, corner, w1, mp, v, mv4, gm)
    integer, parameter :: nsup = 3
    integer, intent(in) :: nb, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, 3), mp(nb), v(nb, 3)
    real(dp), intent(out) :: mv4(4, nb)
    real(dp), intent(inout) :: gm(4, nn)
    real(dp) :: ws
    integer :: a, b, c, off, p, i, k

    do p = 1, nb
       do k = 1, 3
          mv4(k, p) = mp(p) * v(p, k)
       end do
       mv4(4, p) = 0
    end do
    do c = 1, nsup
       do b = 1, nsup
          do a = 1, nsup
             off = (a - 1) + nx * (b - 1) + nxy * (c - 1)
             do p = 1, nb
                i = corner(p) + off
                ws = w1(p, a, 1) * w1(p, b, 2)
                ws = ws * w1(p, c, 3)
                !GCC$ unroll 1
                do k = 1, 4
                   gm(k, i) = gm(k, i) + ws * mv4(k, p)
                end do
             end do
          end do
       end do
    end do
  end subroutine scatter_momentum_3d_packed

  !> Nodes ilo..ihi (1-based; empty when ilo > ihi) hold every stencil of the blocks whose
  !> corners are corner(1:nb) (3D uGIMP): the span in memory order of the nodes the packed
  !> kernels touch, widened by one block's corners (the caller starts from ilo = huge, ihi = 0).
  pure subroutine stencil_span(nb, nx, nxy, corner, ilo, ihi)
    integer, intent(in) :: nb, nx, nxy
    integer, intent(in) :: corner(nb)
    integer, intent(inout) :: ilo, ihi
    integer :: p

    do p = 1, nb
       ilo = min(ilo, corner(p))
       ihi = max(ihi, corner(p) + 2 + 2 * nx + 2 * nxy)
    end do
  end subroutine stencil_span

  !> The grid sums from the packed records: mass, mom, force of nodes 1..nn, gs(:, ilo:ihi)
  !> there, zero elsewhere (no particle's stencil reaches beyond: stencil_span).
  pure subroutine unpack_grid_sums(nn, ilo, ihi, gs, gmass, gmom, gforce)
    integer, intent(in) :: nn, ilo, ihi
    real(dp), intent(in) :: gs(8, nn)
    real(dp), intent(out) :: gmass(nn), gmom(3, nn), gforce(3, nn)
    integer :: i

    do i = 1, nn
       if (i < ilo .or. i > ihi) then
          gmass(i) = 0
          gmom(1, i) = 0
          gmom(2, i) = 0
          gmom(3, i) = 0
          gforce(1, i) = 0
          gforce(2, i) = 0
          gforce(3, i) = 0
       else
          gmass(i) = gs(1, i)
          gmom(1, i) = gs(2, i)
          gmom(2, i) = gs(3, i)
          gmom(3, i) = gs(4, i)
          gforce(1, i) = gs(5, i)
          gforce(2, i) = gs(6, i)
          gforce(3, i) = gs(7, i)
       end if
    end do
  end subroutine unpack_grid_sums

  !> Velocities into packed records of nodes ilo..ihi: gv(1:3, i) = a(:, i), gv(4, i) = 0
  !> [, gv(5:7, i) = b(:, i), gv(8, i) = 0 when the records have 8 lanes].
  pure subroutine pack_velocities(nn, ilo, ihi, nlane, a, b, gv)
    integer, intent(in) :: nn, ilo, ihi, nlane
    real(dp), intent(in) :: a(3, nn), b(3, nn)
    real(dp), intent(inout) :: gv(nlane, nn)
    integer :: i

    do i = ilo, ihi
       gv(1, i) = a(1, i)
       gv(2, i) = a(2, i)
       gv(3, i) = a(3, i)
       gv(4, i) = 0
       if (nlane == 8) then
          gv(5, i) = b(1, i)
          gv(6, i) = b(2, i)
          gv(7, i) = b(3, i)
          gv(8, i) = 0
       end if
    end do
  end subroutine pack_velocities

  !> Zero the packed records of nodes ilo..ihi (nlane lanes each).
  pure subroutine clear_records(nn, ilo, ihi, nlane, gv)
    integer, intent(in) :: nn, ilo, ihi, nlane
    real(dp), intent(inout) :: gv(nlane, nn)

    if (ihi >= ilo) gv(:, ilo:ihi) = 0
  end subroutine clear_records

  !> The gather pass of g2p_particles for 3D uGIMP on packed records gv(8, nn) (v_new in lanes
  !> 1:4, v_old in 5:8): vpic = Σ S v_new, then v, x and wk as mpm_transfer_g2p_particles.inc.
  pure subroutine gather_velocity_3d_packed(nb, nn, nx, nxy, corner, w1, gv, mp, gravity, alpha, dt, v, x, wk)
    integer, parameter :: nsup = 3, nd = 3
    integer, intent(in) :: nb, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), gv(8, nn), mp(nb), gravity(3), alpha, dt
    real(dp), intent(inout) :: v(nb, nd), x(nb, nd), wk
    real(dp) :: sv(4), sd(4), ws
    integer(int64) :: row
    integer :: a, b, c, p, k

    do p = 1, nb
       sv = 0
       sd = 0
       do c = 1, nsup
          do b = 1, nsup
             row = int(corner(p), int64) + int(nx, int64) * (b - 1) + int(nxy, int64) * (c - 1)
             do a = 1, nsup
                ws = w1(p, a, 1) * w1(p, b, 2)
                ws = ws * w1(p, c, 3)
                !GCC$ unroll 1
                do k = 1, 4
                   sv(k) = sv(k) + ws * gv(k, row + (a - 1))
                   sd(k) = sd(k) + ws * (gv(k, row + (a - 1)) - gv(4 + k, row + (a - 1)))
                end do
             end do
          end do
       end do
       do k = 1, nd
          v(p, k) = alpha * (v(p, k) + sd(k)) + (1 - alpha) * sv(k)
          x(p, k) = x(p, k) + dt * sv(k)
          wk = wk + mp(p) * gravity(k) * dt * sv(k)
       end do
    end do
  end subroutine gather_velocity_3d_packed

  !> The remap pass of g2p_particles for 3D uGIMP (mpm_transfer_g2p_particles.inc's second loop)
  !> into packed momentum records gm(4, nn) (lane 4: 0): gm += Σ S m v, particle by particle.
  pure subroutine remap_particles_3d_packed(nb, nn, nx, nxy, corner, w1, mp, v, gm)
    integer, parameter :: nsup = 3, nd = 3
    integer, intent(in) :: nb, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), mp(nb), v(nb, nd)
    real(dp), intent(inout) :: gm(4, nn)
    real(dp) :: mv(4), ws
    integer(int64) :: row
    integer :: a, b, c, p, k

    do p = 1, nb
       do k = 1, nd
          mv(k) = mp(p) * v(p, k)
       end do
       mv(4) = 0
       do c = 1, nsup
          do b = 1, nsup
             row = int(corner(p), int64) + int(nx, int64) * (b - 1) + int(nxy, int64) * (c - 1)
             do a = 1, nsup
                ws = w1(p, a, 1) * w1(p, b, 2)
                ws = ws * w1(p, c, 3)
                !GCC$ unroll 1
                do k = 1, 4
                   gm(k, row + (a - 1)) = gm(k, row + (a - 1)) + ws * mv(k)
                end do
             end do
          end do
       end do
    end do
  end subroutine remap_particles_3d_packed

  !> The momentum from packed records: mom(:, i) = gm(1:3, i) for nodes ilo..ihi, zero elsewhere
  !> (as unpack_grid_sums).
  pure subroutine unpack_momentum(nn, ilo, ihi, gm, gmom)
    integer, intent(in) :: nn, ilo, ihi
    real(dp), intent(in) :: gm(4, nn)
    real(dp), intent(out) :: gmom(3, nn)
    integer :: i

    do i = 1, nn
       if (i < ilo .or. i > ihi) then
          gmom(1, i) = 0
          gmom(2, i) = 0
          gmom(3, i) = 0
       else
          gmom(1, i) = gm(1, i)
          gmom(2, i) = gm(2, i)
          gmom(3, i) = gm(3, i)
       end if
    end do
  end subroutine unpack_momentum

  !> gather_gradient for 3D uGIMP on packed velocity records gv(4, nn) (lane 4: 0).
  pure subroutine gather_gradient_3d_packed(nb, nn, nx, nxy, corner, w1, dw1, gv, l)
    integer, parameter :: nsup = 3, nd = 3
    integer, intent(in) :: nb, nn, nx, nxy
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, nd), dw1(nb, nsup, nd), gv(4, nn)
    real(dp), intent(out) :: l(nb, nd, nd)
    real(dp) :: sl(4, 3), g1, g2, g3
    integer :: a, b, c, p, i, j, k

    do p = 1, nb
       sl = 0
       do c = 1, nsup
          do b = 1, nsup
             do a = 1, nsup
                i = corner(p) + (a - 1) + nx * (b - 1) + nxy * (c - 1)
                g1 = dw1(p, a, 1) * w1(p, b, 2)
                g2 = w1(p, a, 1) * dw1(p, b, 2)
                g1 = g1 * w1(p, c, 3)
                g2 = g2 * w1(p, c, 3)
                g3 = w1(p, a, 1) * w1(p, b, 2) * dw1(p, c, 3)
                !GCC$ unroll 1
                do j = 1, 4
                   sl(j, 1) = sl(j, 1) + gv(j, i) * g1
                   sl(j, 2) = sl(j, 2) + gv(j, i) * g2
                   sl(j, 3) = sl(j, 3) + gv(j, i) * g3
                end do
             end do
          end do
       end do
       do k = 1, nd
          do j = 1, nd
             l(p, j, k) = sl(j, k)
          end do
       end do
    end do
  end subroutine gather_gradient_3d_packed

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
