!> Shape functions of the background grid for a block of particles: the standard linear hat
!> functions (2 nodes per direction) and uGIMP (Bardenhagen & Kober 2004; 3 nodes per direction),
!> as tensor products S_Ip = Π_k N(x_pk − x_Ik) with gradients ∇S_Ip = (N_x' N_y [N_z], ...).
!>
!> uGIMP keeps the particle half-length l fixed at its initial value h/(2 ppc) (the "u" of
!> uGIMP): no domain update with F, so no domain can outgrow the 3-node stencil, and the
!> kernel is the same for every particle of a block. docs/theory/mpm.md §4.2 has the 1D formulas.
!>
!> Layout (block of nb particles, particle index first so the loops over a block vectorize):
!> the 1D factors, not their products. corner(nb) is the global index (1-based) of the stencil's
!> first node, w1(nb, nsup, ndim) and dw1(nb, nsup, ndim) the weights N and derivatives N' of
!> the nsup = 2 (linear) or 3 (uGIMP) nodes in each direction. Stencil node s = a + nsup (b − 1)
!> [+ nsup² (c − 1)] is the global node corner + (a − 1) + n1 (b − 1) [+ n1 n2 (c − 1)], and its
!> weight and gradient are, in exactly this order of the products (every kernel of mpm_transfer
!> forms them so, and stencil_expand is the reference):
!>   2D  S = N_a N_b          ∇S = (N'_a N_b, N_a N'_b)
!>   3D  S = (N_a N_b) N_c    ∇S = ((N'_a N_b) N_c, (N_a N'_b) N_c, (N_a N_b) N'_c)
!> Why: the products were stored per particle before (9 × node, S, ∇S in 2D uGIMP: 252 bytes a
!> particle, written every increment and read by four kernels); the factors are 2.4× less data
!> and the kernels' few multiplications replace the loads.
module mpm_shape
  use base_kinds, only: dp
  use mpm_scene, only: shape_linear
  implicit none
  private

  public :: stencil_nodes_per_direction, block_stencil, stencil_expand

contains

  pure integer function stencil_nodes_per_direction(shape)
    integer, intent(in) :: shape
    stencil_nodes_per_direction = 3
    if (shape == shape_linear) stencil_nodes_per_direction = 2
  end function stencil_nodes_per_direction

  !> Stencil factors of nb particles at x(nb, ndim) on the grid with origin lo, spacing h and
  !> n(3) nodes per direction. half = l (uGIMP particle half-length; unused for linear).
  !> `outside` returns the first particle whose stencil leaves the grid (0: none; corner is
  !> then undefined).
  pure subroutine block_stencil(nb, ndim, nsup, shape, lo, h, n, half, x, corner, w1, dw1, outside)
    integer, intent(in) :: nb, ndim, nsup, shape
    real(dp), intent(in) :: lo(3), h, half
    integer, intent(in) :: n(3)
    real(dp), intent(in) :: x(nb, ndim)
    integer, intent(out) :: corner(nb)
    real(dp), intent(out) :: w1(nb, nsup, ndim), dw1(nb, nsup, ndim)
    integer, intent(out) :: outside
    integer :: base(nb, 3), p, k

    outside = 0
    do k = 1, ndim
       call weights_1d(nb, nsup, shape, lo(k), h, half, x(:, k), base(:, k), w1(:, :, k), dw1(:, :, k))
    end do
    do p = 1, nb
       do k = 1, ndim
          if (base(p, k) < 0 .or. base(p, k) + nsup - 1 > n(k) - 1) then
             if (outside == 0) outside = p
          end if
       end do
    end do
    if (outside /= 0) return
    if (ndim == 2) then
       do p = 1, nb
          corner(p) = 1 + base(p, 1) + n(1) * base(p, 2)
       end do
    else
       do p = 1, nb
          corner(p) = 1 + base(p, 1) + n(1) * (base(p, 2) + n(2) * base(p, 3))
       end do
    end if
  end subroutine block_stencil

  !> The full stencil of the factors (the module header's products, stencil order): node(nb, ns)
  !> global node index, w(nb, ns) weights, dw(nb, ns * ndim) gradients (component k at
  !> (k − 1) ns + s), ns = nsup**ndim. The reference the kernels' products are checked against
  !> (tests/mpm/test_mpm_shape.pf); not used in the time loop.
  pure subroutine stencil_expand(nb, ndim, nsup, n, corner, w1, dw1, node, w, dw)
    integer, intent(in) :: nb, ndim, nsup
    integer, intent(in) :: n(3)
    integer, intent(in) :: corner(nb)
    real(dp), intent(in) :: w1(nb, nsup, ndim), dw1(nb, nsup, ndim)
    integer, intent(out) :: node(nb, *)
    real(dp), intent(out) :: w(nb, *), dw(nb, *)
    integer :: ns, p, a, b, c, s

    ns = nsup**ndim
    if (ndim == 2) then
       s = 0
       do b = 1, nsup
          do a = 1, nsup
             s = s + 1
             do p = 1, nb
                node(p, s) = corner(p) + (a - 1) + n(1) * (b - 1)
                w(p, s) = w1(p, a, 1) * w1(p, b, 2)
                dw(p, s) = dw1(p, a, 1) * w1(p, b, 2)
                dw(p, ns + s) = w1(p, a, 1) * dw1(p, b, 2)
             end do
          end do
       end do
    else
       s = 0
       do c = 1, nsup
          do b = 1, nsup
             do a = 1, nsup
                s = s + 1
                do p = 1, nb
                   node(p, s) = corner(p) + (a - 1) + n(1) * ((b - 1) + n(2) * (c - 1))
                   w(p, s) = w1(p, a, 1) * w1(p, b, 2) * w1(p, c, 3)
                   dw(p, s) = dw1(p, a, 1) * w1(p, b, 2) * w1(p, c, 3)
                   dw(p, ns + s) = w1(p, a, 1) * dw1(p, b, 2) * w1(p, c, 3)
                   dw(p, 2 * ns + s) = w1(p, a, 1) * w1(p, b, 2) * dw1(p, c, 3)
                end do
             end do
          end do
       end do
    end if
  end subroutine stencil_expand

  !> 1D weights of the nodes base, base+1[, base+2] (0-based node numbers along the axis).
  pure subroutine weights_1d(nb, nsup, shape, lo, h, l, x, base, n1, d1)
    integer, intent(in) :: nb, nsup, shape
    real(dp), intent(in) :: lo, h, l, x(nb)
    integer, intent(out) :: base(nb)
    real(dp), intent(out) :: n1(nb, nsup), d1(nb, nsup)
    integer :: p, a, k
    real(dp) :: xi, r, ar, sg, t, num, den
    logical :: centre, linear, tail

    if (shape == shape_linear) then
       do p = 1, nb
          xi = (x(p) - lo) / h
          base(p) = floor(xi)
          r = xi - base(p)
          n1(p, 1) = 1 - r
          n1(p, 2) = r
          d1(p, 1) = -1 / h
          d1(p, 2) = 1 / h
       end do
    else
       ! Branch-free, so the loop vectorises (the branches on the zone of each node were
       ! mispredicted at random: the stencil was 11 % of a hopper run) — in optimised builds
       ! this file is compiled with -fno-trapping-math (src/CMakeLists.txt), without which
       ! gfortran 12 kept the merges as branches and the loop scalar. Each zone's value is
       ! num/den with that zone's own numerator and denominator, selected before the one
       ! division, so every weight and gradient is the same double as the branched form's:
       !   |r| < l          N = 1 − (r² + l²)/(2hl)     N' = −r/(hl)
       !   l ≤ |r| ≤ h − l  N = 1 − |r|/h               N' = −sgn(r)/h
       !   h − l < |r| < h + l  N = (h + l − |r|)²/(4hl)  N' = −sgn(r)(h + l − |r|)/(2hl)
       !   else             N = 0 (0/1)                 N' = 0 (0/1)
       do p = 1, nb
          xi = (x(p) - lo) / h
          ! nint(xi) − 1 without nint's libm call (lround), which kept the loops scalar: the
          ! same integer for xi ≥ 0 (xi − int(xi) is exact), negative (outside) for xi < 0.
          k = int(xi)
          base(p) = k - 1 + merge(1, 0, xi - k >= 0.5_dp)
       end do
       do a = 1, nsup
          do p = 1, nb
             ! r = x_p − x_I (signed distance to node base + a − 1)
             r = x(p) - (lo + (base(p) + a - 1) * h)
             ar = abs(r)
             sg = sign(1.0_dp, r)
             centre = ar < l
             linear = ar <= h - l
             tail = ar < h + l
             t = h + l - ar
             num = merge(r * r + l * l, merge(ar, merge(t**2, 0.0_dp, tail), linear), centre)
             den = merge(2 * h * l, merge(h, merge(4 * h * l, 1.0_dp, tail), linear), centre)
             n1(p, a) = merge(1 - num / den, num / den, centre .or. linear)
             num = merge(-r, merge(-sg, merge(-sg * t, 0.0_dp, tail), linear), centre)
             den = merge(h * l, merge(h, merge(2 * h * l, 1.0_dp, tail), linear), centre)
             d1(p, a) = num / den
          end do
       end do
    end if
  end subroutine weights_1d
end module mpm_shape
