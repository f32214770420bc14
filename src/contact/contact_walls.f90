!> One entry for the geometry of every kind of rigid wall the contact kernel meets: 2D chains and
!> 3D planes (contact_geometry), 3D faceted walls from R3D3/R3D4 elements (contact_facets) and the
!> swept and revolved analytic surfaces TYPE=CYLINDER / TYPE=REVOLUTION (contact_swept). Kept apart
!> from contact_geometry so that the 2D chain module does not depend on the 3D ones.
module contact_walls
  use base_kinds, only: dp
  use model_surfaces, only: rigid_surface_t, shape_plane, shape_facets, shape_cylinder, shape_revolution
  use contact_geometry, only: surface_closest_point, surface_coordinate_scale
  use contact_facets, only: facets_closest_point
  use contact_swept, only: swept_closest_point
  implicit none
  private

  public :: wall_closest_point
  public :: wall_coordinate_scale

contains

  !> The wall translated by `offset` (its reference node's displacement): gap, unit normal into
  !> the material and closest point of x; the contract of contact_geometry's
  !> surface_closest_point, for every wall shape.
  pure subroutine wall_closest_point(wall, offset, x, gap, normal, cp)
    type(rigid_surface_t), intent(in) :: wall
    real(dp), intent(in) :: offset(:)
    real(dp), intent(in) :: x(:)
    real(dp), intent(out) :: gap
    real(dp), intent(out) :: normal(:)
    real(dp), intent(out) :: cp(:)

    if (wall%ndim /= 3 .or. wall%shape == shape_plane) then
       call surface_closest_point(wall, offset, x, gap, normal, cp)
       return
    end if
    select case (wall%shape)
    case (shape_facets)
       call facets_closest_point(wall%facet_points, wall%facet_tris(:, 1:wall%n_facets), &
            x(1:3) - offset(1:3), gap, normal(1:3), cp(1:3))
    case (shape_cylinder, shape_revolution)
       call swept_closest_point(wall, x(1:3) - offset(1:3), gap, normal(1:3), cp(1:3))
    case default
       gap = huge(1.0_dp)
       normal = 0.0_dp
       cp = x
       return
    end select
    cp(1:3) = cp(1:3) + offset(1:3)
  end subroutine wall_closest_point

  !> Largest coordinate magnitude entering the wall's geometry (sets the contact's round-off
  !> tolerance, see contact_rigid_wall).
  pure function wall_coordinate_scale(wall) result(scale)
    type(rigid_surface_t), intent(in) :: wall
    real(dp) :: scale
    integer :: k

    if (wall%ndim /= 3 .or. wall%shape == shape_plane) then
       scale = surface_coordinate_scale(wall)
       return
    end if
    scale = 0.0_dp
    if (wall%shape == shape_facets) then
       if (allocated(wall%facet_points)) scale = maxval(abs(wall%facet_points))
       return
    end if
    ! profile coordinates are lengths from the origin a: add |a|
    if (allocated(wall%segments)) then
       do k = 1, wall%n_segments
          scale = max(scale, maxval(abs(wall%segments(k)%p0)), maxval(abs(wall%segments(k)%p1)), &
               maxval(abs(wall%segments(k)%centre)))
       end do
    end if
    scale = scale + maxval(abs(wall%point))
  end function wall_coordinate_scale
end module contact_walls
