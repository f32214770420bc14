!> Lumped (diagonal) mass of one-point elements: equal shares m_I = ρ V / nen.
!> For one-point elements the equal share is standard; it differs from the row sum of the
!> consistent matrix only for distorted elements. Computed once from the reference density
!> and volume (mass is conserved in a Lagrangian mesh). In plane strain V = A·t, so the
!> element mass is ρ A t.
module fem_mass
  use base_kinds, only: dp
  implicit none
  private

  public :: lumped_mass

contains

  !> mass(nb, nen): nodal masses of each element of the block (assembled by the driver).
  pure subroutine lumped_mass(nb, nen, density, volume, mass)
    integer, intent(in) :: nb, nen
    real(dp), intent(in) :: density(nb), volume(nb)
    real(dp), intent(out) :: mass(nb, nen)
    integer :: n

    do n = 1, nen
       mass(:, n) = density * volume / real(nen, dp)
    end do
  end subroutine lumped_mass
end module fem_mass
