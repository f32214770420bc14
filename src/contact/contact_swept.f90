!> Geometry of Abaqus's 3D analytic rigid surfaces made from a 2D profile (*SURFACE,
!> TYPE=CYLINDER and TYPE=REVOLUTION): the START/LINE/CIRCL chain of contact_geometry, swept along
!> a generator or revolved about an axis. The closest point of a 3D point is the closest point of
!> its profile coordinates to the chain, lifted back into 3D, so gap, side and corners are exactly
!> those of the 2D chain (material on the left of travel in the profile plane) and
!> x = cp + gap * normal holds as in 2D.
!>
!>   * CYLINDER: profile coordinates (x, y) = components of x - a along the local axes e1, e2; the
!>     generator e3 = e1 x e2. The surface is unbounded along the generator.
!>   * REVOLUTION: profile coordinates (r, z): z = (x - a) . e3 along the symmetry axis, r = the
!>     distance from the axis; the meridian direction e_r = the radial unit vector of x (e1 for a
!>     point on the axis). The surface is the full revolution (360 degrees).
!> The local frame (rigid_surface_t%axes, columns e1, e2, e3) and the origin a
!> (rigid_surface_t%point) are built by the scene reader from the data lines (docs/keywords.md).
module contact_swept
  use base_kinds, only: dp
  use model_surfaces, only: rigid_surface_t, shape_cylinder, shape_revolution
  use contact_geometry, only: chain_closest_point
  implicit none
  private

  public :: swept_closest_point

contains

  !> The wall in its reference position: gap, unit normal into the material and closest point of
  !> x (3D). A wall without segments, or of another shape, returns gap = huge.
  pure subroutine swept_closest_point(wall, x, gap, normal, cp)
    type(rigid_surface_t), intent(in) :: wall
    real(dp), intent(in) :: x(3)
    real(dp), intent(out) :: gap
    real(dp), intent(out) :: normal(3)
    real(dp), intent(out) :: cp(3)

    real(dp) :: d(3), q(2), n2(2), t2(2), c2(2), e_in(3), e_out(3), radial(3), r
    integer :: feature, iseg

    gap = huge(1.0_dp)
    normal = 0.0_dp
    cp = x
    if (.not. allocated(wall%segments) .or. wall%n_segments < 1) return
    d = x - wall%point
    select case (wall%shape)
    case (shape_cylinder)
       e_in = wall%axes(:, 1)
       e_out = wall%axes(:, 2)
       q = [dot_product(d, e_in), dot_product(d, e_out)]
    case (shape_revolution)
       e_out = wall%axes(:, 3)
       q(2) = dot_product(d, e_out)
       radial = d - q(2) * e_out
       r = norm2(radial)
       if (r > 0.0_dp) then
          e_in = radial / r
       else
          e_in = wall%axes(:, 1)
       end if
       q(1) = r
    case default
       return
    end select
    call chain_closest_point(wall%segments(1:wall%n_segments), q, gap, n2, t2, c2, feature, iseg)
    normal = n2(1) * e_in + n2(2) * e_out
    ! the component of x off the profile plane (along the generator, or none for a revolution)
    cp = x + (c2(1) - q(1)) * e_in + (c2(2) - q(2)) * e_out
  end subroutine swept_closest_point
end module contact_swept
