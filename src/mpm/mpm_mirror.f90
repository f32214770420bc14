!> Symmetry planes that lie on a grid node plane, done by mirroring the grid (a reflective
!> boundary): after P2G every node in front of the plane receives what the mirror image of the
!> material would give it (the real contributions of its image node behind the plane, reflected),
!> and the image node becomes the reflection of the node. The grid then holds exactly the fields
!> of the full (mirrored) model near the plane, so the interpolated normal velocity vanishes on
!> the plane for any symmetric shape function and particles approach the plane without crossing
!> it.
!>
!> Why not the wall projection (mpm_walls): with uGIMP a particle on or next to the plane still
!> weights the free node one cell in front, so projecting only the plane nodes (and those behind)
!> leaves it a velocity through the plane; the put-back then stacked particles on the plane (175
!> on the axis of the ch. 4 hopper at h = 0.0357 m, none at 0.035 m), which decided between two
!> different steady discharge rates (src/mpm/README.md).
!>
!> Accounting stays that of the half model: `mass_own` (the node mass before folding) weights the
!> wall forces and the damping energy, and the plane's reaction is the momentum the fold hands the
!> real material, −Σ [m_own (p + Δt f)/m − (p_own + Δt f_own)] / Δt. With two planes (a quarter
!> model) the second fold meets nodes the first has already folded: their p_own is then the own
!> share m_own/m of the node's momentum (own_share), so each plane reports its own reaction.
module mpm_mirror
  use base_kinds, only: dp
  use mpm_scene, only: mpm_wall_t, wall_symmetry
  use mpm_grid, only: grid_t, grid_node_index
  use mpm_walls, only: wall_contains, node_on_wall_tolerance
  implicit none
  private

  !> A symmetry plane x_axis = const on a node plane: its nodes, and the pairs (front, back) of
  !> nodes one and two cells in front of it and their images (farther nodes never share a
  !> particle with an image node: particles stay in front of the plane).
  type, public :: mirror_plane_t
     integer :: axis = 0
     integer, allocatable :: plane(:), front(:), back(:)
  end type mirror_plane_t

  public :: mirror_plane_setup, mirror_fold, mirror_fold_momentum

contains

  !> Is wall w a symmetry plane the grid can mirror (normal along a grid axis, on a node plane)?
  !> If so, fill mp with the nodes over which the wall extends.
  subroutine mirror_plane_setup(w, g, mp, ok)
    type(mpm_wall_t), intent(in) :: w
    type(grid_t), intent(in) :: g
    type(mirror_plane_t), intent(out) :: mp
    logical, intent(out) :: ok
    integer :: k, axis, i, np, nf, idx(3), img(3), layer
    real(dp) :: q, tol, x(3)
    integer, allocatable :: plane(:), front(:), back(:)

    ok = .false.
    if (w%kind /= wall_symmetry) return
    axis = 0
    do k = 1, g%ndim
       if (abs(abs(w%normal(k)) - 1) < 1.0e-12_dp) axis = k
    end do
    if (axis == 0) return
    q = (w%p0(axis) - g%lo(axis)) / g%h
    layer = nint(q)
    if (abs(q - layer) > node_on_wall_tolerance) return
    ! the plane's layer in this grid's numbering (a rank's held box: mpm_grid's offset)
    layer = layer - g%offset(axis)
    if (layer < 0 .or. layer > g%n(axis) - 1) return
    tol = node_on_wall_tolerance * g%h
    allocate (plane(g%nn), front(g%nn), back(g%nn))
    np = 0
    nf = 0
    do i = 1, g%nn
       idx = grid_node_index(g, i)
       ! only where the wall extends (its segment / box, as the projection walls)
       x = g%position(i)
       x(axis) = w%p0(axis)
       if (.not. wall_contains(w, g%ndim, x, tol)) cycle
       k = idx(axis) - layer
       if (w%normal(axis) < 0) k = -k              ! k: cells in front of the plane
       if (k == 0) then
          np = np + 1
          plane(np) = i
       else if (k == 1 .or. k == 2) then
          img = idx
          img(axis) = 2 * layer - idx(axis)
          if (img(axis) < 0 .or. img(axis) > g%n(axis) - 1) cycle
          nf = nf + 1
          front(nf) = i
          back(nf) = 1 + img(1) + g%n(1) * (img(2) + g%n(2) * img(3))
       end if
    end do
    mp%axis = axis
    mp%plane = plane(1:np)
    mp%front = front(1:nf)
    mp%back = back(1:nf)
    ok = .true.
  end subroutine mirror_plane_setup

  !> Fold mass, momentum and force of the P2G across the plane (the grid's mass before any fold
  !> is in g%mass_own, set by the caller). Returns the force the material exerts on the plane.
  !> With `owned` (a spatially decomposed grid, mpm_domain) the reaction counts the plane nodes
  !> and the pairs whose front node is owned here (the fold itself is done on every held pair).
  subroutine mirror_fold(mp, g, dt, reaction, owned)
    type(mirror_plane_t), intent(in) :: mp
    type(grid_t), intent(inout) :: g
    real(dp), intent(in) :: dt
    real(dp), intent(out) :: reaction(3)
    logical, intent(in), optional :: owned(:)
    ! fixed-size locals, the components 1:nd used: with (g%ndim)-sized ones and an array-valued
    ! reflect gfortran allocated temporaries on the heap for every node pair (issue 19)
    integer :: k, f, b, a, nd, j
    real(dp) :: m, p(3), fo(3), v(3), exchange(3), sf, sb

    nd = g%ndim
    a = mp%axis
    exchange = 0
    do k = 1, size(mp%plane)
       f = mp%plane(k)
       ! the image gives the same mass and tangential parts, the opposite normal parts
       if (counted(f)) exchange(a) = exchange(a) - own_share(g, f) * (g%mom(a, f) + dt * g%force(a, f))
       g%mom(a, f) = 0
       g%force(a, f) = 0
    end do
    do k = 1, size(mp%front)
       f = mp%front(k)
       b = mp%back(k)
       m = g%mass(f) + g%mass(b)
       if (m <= 0) cycle
       do j = 1, nd
          p(j) = g%mom(j, f) + reflected(g%mom(j, b), j, a)
          fo(j) = g%force(j, f) + reflected(g%force(j, b), j, a)
          v(j) = (p(j) + dt * fo(j)) / m
       end do
       if (counted(f)) then
          sf = own_share(g, f)
          sb = own_share(g, b)
          do j = 1, nd
             exchange(j) = exchange(j) + g%mass_own(f) * v(j) - sf * (g%mom(j, f) + dt * g%force(j, f)) &
                  + g%mass_own(b) * reflected(v(j), j, a) - sb * (g%mom(j, b) + dt * g%force(j, b))
          end do
       end if
       g%mass(f) = m
       g%mass(b) = m
       do j = 1, nd
          g%mom(j, f) = p(j)
          g%mom(j, b) = reflected(p(j), j, a)
          g%force(j, f) = fo(j)
          g%force(j, b) = reflected(fo(j), j, a)
       end do
    end do
    reaction = 0
    reaction(1:nd) = -exchange(1:nd) / dt
  contains
    logical function counted(node)
      integer, intent(in) :: node
      counted = .true.
      if (present(owned)) counted = owned(node)
    end function counted
  end subroutine mirror_fold

  !> Fold the remapped momentum (MUSL) across the plane; masses were folded after the P2G.
  subroutine mirror_fold_momentum(mp, g)
    type(mirror_plane_t), intent(in) :: mp
    type(grid_t), intent(inout) :: g
    integer :: k, f, b, a, j
    real(dp) :: p

    a = mp%axis
    do k = 1, size(mp%plane)
       g%mom(a, mp%plane(k)) = 0
    end do
    do k = 1, size(mp%front)
       f = mp%front(k)
       b = mp%back(k)
       do j = 1, g%ndim
          p = g%mom(j, f) + reflected(g%mom(j, b), j, a)
          g%mom(j, f) = p
          g%mom(j, b) = reflected(p, j, a)
       end do
    end do
  end subroutine mirror_fold_momentum

  !> The model's own share mass_own/mass of what a node holds before this fold: 1 (exactly) unless
  !> an earlier plane folded its image in (the edge x = z = 0 of a quarter model), then the real
  !> material's momentum there is that share of the node's, moving with the node's velocity.
  pure real(dp) function own_share(g, i)
    type(grid_t), intent(in) :: g
    integer, intent(in) :: i
    own_share = 1
    if (abs(g%mass(i) - g%mass_own(i)) <= 0) return
    own_share = 0
    if (g%mass(i) > 0) own_share = g%mass_own(i) / g%mass(i)
  end function own_share

  !> Component j of a vector reflected across the plane normal to axis: −x on the axis, else x
  !> (scalar, so no array temporary).
  pure real(dp) function reflected(x, j, axis)
    real(dp), intent(in) :: x
    integer, intent(in) :: j, axis
    reflected = x
    if (j == axis) reflected = -x
  end function reflected
end module mpm_mirror
