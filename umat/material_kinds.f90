!> Real kinds and small numeric constants shared by every material kernel.
!> The material layer depends on nothing else in bulkflow, so it owns the kind
!> definitions; the solver reuses them from here.
module material_kinds
  use, intrinsic :: iso_fortran_env, only: real64
  implicit none
  private

  integer, parameter, public :: dp = real64
  real(dp), parameter, public :: pi = 3.14159265358979323846264338327950288_dp
  real(dp), parameter, public :: deg_to_rad = pi / 180.0_dp
  real(dp), parameter, public :: rad_to_deg = 180.0_dp / pi
end module material_kinds
