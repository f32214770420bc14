!> The real kind and the numeric constants of bulkflow: the lowest layer, used by everything
!> (docs/architecture.md). umat/material_kinds re-exports these names, so the material kernels
!> shipped alone to Abaqus and CalculiX carry this file at the head of their single source.
module base_kinds
  use, intrinsic :: iso_fortran_env, only: real64
  implicit none
  private

  integer, parameter, public :: dp = real64
  real(dp), parameter, public :: pi = 3.14159265358979323846264338327950288_dp
  real(dp), parameter, public :: deg_to_rad = pi / 180.0_dp
  real(dp), parameter, public :: rad_to_deg = 180.0_dp / pi
end module base_kinds
