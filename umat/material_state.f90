!> Layout of the state variables (SDVs) our Mohr-Coulomb and Drucker-Prager VUMATs keep.
!> One table, used by the kernels, the drivers' output headers and the README.
module material_state
  implicit none
  private

  integer, parameter, public :: sdv_peeq = 1       !< equivalent plastic shear strain
  integer, parameter, public :: sdv_evp = 2        !< volumetric plastic strain, dilation positive
  integer, parameter, public :: sdv_ev = 3         !< total volumetric strain (ln J), dilation positive
  integer, parameter, public :: sdv_sigma1_consolidation = 4  !< recorded σ1, compression positive
  integer, parameter, public :: sdv_yield = 5      !< return region of the last increment
  integer, parameter, public :: sdv_cohesion = 6   !< cohesion used in the last increment
  integer, parameter, public :: sdv_phi = 7        !< friction angle used, degrees
  integer, parameter, public :: sdv_psi = 8        !< dilation angle used, degrees
  integer, parameter, public :: n_state_plastic = 8

  character(len=5), parameter, public :: state_names(n_state_plastic) = &
       [character(len=5) :: 'PEEQ', 'EVP', 'EV', 'SIG1C', 'YIELD', 'COH', 'PHI', 'PSI']
end module material_state
