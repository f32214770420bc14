!> TEMPORARY: the old name of src/material/material_vumat_call.f90, kept only for
!> src/mpm/mpm_run.f90, which branch i18-mpm is splitting into phase modules that use
!> material_vumat_call directly; delete this file with the last `use driver_vumat_call`
!> (scripts/check_layers.py lists it among its temporary exceptions).
module driver_vumat_call
  use material_vumat_call, only: n_vec_length, vumat_work_t, vumat_work_init, call_material, &
       packaging_modulus, checked_packaging_modulus
  implicit none
  private

  public :: n_vec_length, vumat_work_t, vumat_work_init, call_material, packaging_modulus, &
       checked_packaging_modulus
end module driver_vumat_call
