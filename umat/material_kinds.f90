!> The kinds of the material kernels: the names of src/base/base_kinds.f90, re-exported. The
!> kernels keep this one name so that they read the same in our tree, in the single Abaqus file
!> and in CalculiX; the solver takes its kinds from base_kinds directly.
module material_kinds
  use base_kinds, only: dp, pi, deg_to_rad, rad_to_deg
  implicit none
  private

  public :: dp, pi, deg_to_rad, rad_to_deg
end module material_kinds
