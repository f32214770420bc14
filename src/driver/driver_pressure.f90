!> *DSLOAD pressures of the current step on this rank: the loaded faces of this rank's elements
!> and their nodal forces on the current geometry (a follower load, as Abaqus/Explicit applies
!> pressure), assembled like element forces (collective over the neighbouring ranks).
!>
!> Consistent nodal forces f_I = p ∫ N_I n_in dA of a face, n_in the inward unit normal
!> (positive pressure pushes into the material):
!> * CPE4R edge a→b (element counter-clockwise, so the left normal points in): f_a = f_b =
!>   ½ p t (−Δy, Δx), t the section thickness;
!> * CAX4R edge: the full ring, 2π r along the edge: f_a = 2π p (−Δz, Δr)(2 r_a + r_b)/6,
!>   f_b = 2π p (−Δz, Δr)(r_a + 2 r_b)/6 (exact for r linear along the edge);
!> * C3D8R face: f_I = p ∫ N_I (x_ξ × x_η) dξ dη over the bilinear face, 2×2 Gauss (exact).
module driver_pressure
  use base_kinds, only: dp
  use model, only: model_t
  use model_mesh, only: element_cax4r
  use model_surfaces, only: cpe4r_faces, c3d8r_faces
  use model_time_variation, only: time_variation_t, variation_factor
  use parallel_partition, only: local_elem_index
  use parallel_assembly, only: assemble_element_vectors
  use driver_solver, only: solver_t
  implicit none
  private

  real(dp), parameter :: two_pi = 6.283185307179586476925286766559_dp
  real(dp), parameter :: gauss = 0.57735026918962576450914878050196_dp

  type :: loaded_face_t
     integer :: le = 0, face = 0, load = 0     !< local element, face number, index of its load
  end type loaded_face_t

  type, public :: step_pressures_t
     integer :: n_loads = 0
     real(dp), allocatable :: magnitude(:)
     type(time_variation_t), allocatable :: variation(:)
     type(loaded_face_t), allocatable :: faces(:)
     real(dp), allocatable :: thickness(:)      !< per face: its element's section thickness (2D)
  end type step_pressures_t

  public :: prepare_pressures, add_pressure_forces

contains

  !> The faces of the step's pressure loads that belong to this rank's elements.
  subroutine prepare_pressures(m, istep, solver, pressures)
    type(model_t), intent(in) :: m
    integer, intent(in) :: istep
    type(solver_t), intent(in) :: solver
    type(step_pressures_t), intent(out) :: pressures
    integer :: k, j, n, le

    pressures%n_loads = 0
    allocate (pressures%magnitude(0), pressures%variation(0), pressures%faces(0), pressures%thickness(0))
    if (.not. allocated(m%steps(istep)%pressures)) return
    associate (loads => m%steps(istep)%pressures)
      pressures%n_loads = size(loads)
      pressures%magnitude = loads%magnitude
      pressures%variation = loads%variation
      n = 0
      do k = 1, size(loads)
         n = n + size(m%element_surfaces(loads(k)%surface)%elems)
      end do
      deallocate (pressures%faces, pressures%thickness)
      allocate (pressures%faces(n), pressures%thickness(n))
      n = 0
      do k = 1, size(loads)
         associate (surf => m%element_surfaces(loads(k)%surface))
           do j = 1, size(surf%elems)
              le = local_elem_index(solver%part, surf%elems(j))
              if (le == 0) cycle
              n = n + 1
              pressures%faces(n) = loaded_face_t(le, surf%faces(j), k)
              pressures%thickness(n) = m%sections(m%mesh%elem_section(surf%elems(j)))%thickness
           end do
         end associate
      end do
      pressures%faces = pressures%faces(1:n)
      pressures%thickness = pressures%thickness(1:n)
    end associate
  end subroutine prepare_pressures

  !> f_ext += the pressure forces at step_time on x = x0 + u + ahead·v (ahead = Δt: the
  !> geometry of t_{n+1} in the increment loop; 0 at a step start). Collective.
  subroutine add_pressure_forces(m, pressures, solver, step_time, ahead, f_ext)
    type(model_t), intent(in) :: m
    type(step_pressures_t), intent(in) :: pressures
    type(solver_t), intent(in) :: solver
    real(dp), intent(in) :: step_time, ahead
    real(dp), intent(inout) :: f_ext(:, :)
    real(dp), allocatable :: fe(:, :, :), f(:, :)
    real(dp) :: amp(pressures%n_loads), x(3, 4), fl(3, 4)
    integer :: k, a, nd, nf, node
    integer :: local(4)

    nd = solver%ndim
    do k = 1, pressures%n_loads
       amp(k) = pressures%magnitude(k) * variation_factor(pressures%variation(k), m%amplitudes, step_time, &
            solver%step_start + step_time)
    end do
    allocate (fe(solver%part%n_local_elems, nd, solver%nen), f(nd, solver%n_nodes))
    fe = 0
    nf = merge(2, 4, nd == 2)
    do k = 1, size(pressures%faces)
       associate (lf => pressures%faces(k))
         do a = 1, nf
            if (nd == 2) then
               local(a) = cpe4r_faces(a, lf%face)
            else
               local(a) = c3d8r_faces(a, lf%face)
            end if
            node = solver%part%conn(local(a), lf%le)
            x(1:nd, a) = solver%x0(:, node) + solver%u(:, node) + ahead * solver%v(:, node)
         end do
         if (nd == 3) then
            call face_forces_3d(x, amp(lf%load), fl)
         else if (m%mesh%element_type == element_cax4r) then
            call edge_forces_ring(x, amp(lf%load), fl)
         else
            call edge_forces_plane(x, amp(lf%load), pressures%thickness(k), fl)
         end if
         do a = 1, nf
            fe(lf%le, :, local(a)) = fe(lf%le, :, local(a)) + fl(1:nd, a)
         end do
       end associate
    end do
    call assemble_element_vectors(solver%part, nd, fe, f)
    f_ext = f_ext + f
  end subroutine add_pressure_forces

  pure subroutine edge_forces_plane(x, p, thickness, f)
    real(dp), intent(in) :: x(3, 4), p, thickness
    real(dp), intent(out) :: f(3, 4)

    f = 0
    f(1, 1) = -0.5_dp * p * thickness * (x(2, 2) - x(2, 1))
    f(2, 1) = 0.5_dp * p * thickness * (x(1, 2) - x(1, 1))
    f(:, 2) = f(:, 1)
  end subroutine edge_forces_plane

  pure subroutine edge_forces_ring(x, p, f)
    real(dp), intent(in) :: x(3, 4), p
    real(dp), intent(out) :: f(3, 4)
    real(dp) :: nr, nz

    f = 0
    nr = -two_pi * p * (x(2, 2) - x(2, 1))
    nz = two_pi * p * (x(1, 2) - x(1, 1))
    f(1:2, 1) = [nr, nz] * (2 * x(1, 1) + x(1, 2)) / 6
    f(1:2, 2) = [nr, nz] * (x(1, 1) + 2 * x(1, 2)) / 6
  end subroutine edge_forces_ring

  pure subroutine face_forces_3d(x, p, f)
    real(dp), intent(in) :: x(3, 4), p
    real(dp), intent(out) :: f(3, 4)
    real(dp), parameter :: xi_node(4) = [-1.0_dp, 1.0_dp, 1.0_dp, -1.0_dp]
    real(dp), parameter :: eta_node(4) = [-1.0_dp, -1.0_dp, 1.0_dp, 1.0_dp]
    real(dp) :: xi, eta, n(4), tx(3), te(3), area_vector(3)
    integer :: k, a

    f = 0
    do k = 1, 4
       xi = gauss * xi_node(k)
       eta = gauss * eta_node(k)
       n = 0.25_dp * (1 + xi_node * xi) * (1 + eta_node * eta)
       tx = 0
       te = 0
       do a = 1, 4
          tx = tx + 0.25_dp * xi_node(a) * (1 + eta_node(a) * eta) * (x(:, a) - x(:, 1))
          te = te + 0.25_dp * eta_node(a) * (1 + xi_node(a) * xi) * (x(:, a) - x(:, 1))
       end do
       area_vector = [tx(2) * te(3) - tx(3) * te(2), tx(3) * te(1) - tx(1) * te(3), tx(1) * te(2) - tx(2) * te(1)]
       do a = 1, 4
          f(:, a) = f(:, a) + p * n(a) * area_vector
       end do
    end do
  end subroutine face_forces_3d
end module driver_pressure
