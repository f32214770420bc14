!> The material point as a block of the material door (src/material/material_door.f90): point 1
!> carries the current guess of the increment, points 2.. the same old state with perturbed
!> strain increments (matpoint_solver), all in the door's `(nblock, ...)` layout, so one
!> call_material answers them all with the same Abaqus argument contract as elements and
!> particles: element number 1, coordMp 0, charLength 1, no rotation (relSpinInc = 0), stretch
!> and F from the logarithmic strain (material_kinematics), the current density ρ0 exp(−tr ε)
!> at mid-increment, the path's temperature at the increment's start and end as tempOld and
!> tempNew (set_temperature).
module matpoint_block
  use base_kinds, only: dp
  use model_materials, only: material_t
  use material_door, only: vumat_work_t, vumat_work_init, call_material
  use material_kinematics, only: stretch_from_log_strain, defgrad_from_stretch
  implicit none
  private

  public :: point_block_t

  type :: point_block_t
     integer :: nblock = 0, ncomp = 4, nshr = 1, nstatev = 0, nfieldv = 0
     integer, allocatable :: numbers(:)
     real(dp), allocatable :: char_length(:), density(:), strain_inc(:, :), rel_spin_inc(:, :)
     real(dp), allocatable :: stretch_old(:, :), stretch_new(:, :), defgrad_old(:, :), defgrad_new(:, :)
     !> start-of-increment logarithmic strain, for vgetvrm('LE') (not a VUMAT argument)
     real(dp), allocatable :: log_strain_old(:, :)
     !> old values before call_material, new values after it (the door swaps them in)
     real(dp), allocatable :: stress(:, :), state(:, :), field(:, :), ener_intern(:), ener_inelas(:)
     type(vumat_work_t) :: work
   contains
     procedure :: init => block_init
     procedure :: set_point => block_set_point
     procedure :: set_temperature => block_set_temperature
     procedure :: call_material => block_call_material
  end type point_block_t

contains

  !> Allocate a block of `nblock` points of `mat` at the temperature `temperature`.
  subroutine block_init(self, nblock, ncomp, mat, temperature)
    class(point_block_t), intent(inout) :: self
    integer, intent(in) :: nblock, ncomp
    type(material_t), intent(in) :: mat
    real(dp), intent(in) :: temperature
    integer :: nshr

    nshr = ncomp - 3
    self%nblock = nblock
    self%ncomp = ncomp
    self%nshr = nshr
    self%nstatev = mat%nstatev
    self%nfieldv = mat%nfieldv
    ! One element, one integration point: all points of the block are copies of it.
    allocate (self%numbers(nblock))
    self%numbers = 1
    allocate (self%char_length(nblock), self%density(nblock), self%strain_inc(nblock, ncomp))
    allocate (self%rel_spin_inc(nblock, ncomp - 3), self%log_strain_old(nblock, ncomp))
    allocate (self%stretch_old(nblock, ncomp), self%stretch_new(nblock, ncomp))
    allocate (self%defgrad_old(nblock, 2 * ncomp - 3), self%defgrad_new(nblock, 2 * ncomp - 3))
    allocate (self%stress(nblock, ncomp), self%state(nblock, max(1, mat%nstatev)))
    allocate (self%field(nblock, max(1, mat%nfieldv)), self%ener_intern(nblock), self%ener_inelas(nblock))
    self%char_length = 1.0_dp
    self%rel_spin_inc = 0.0_dp
    self%state = 0.0_dp
    self%field = 0.0_dp
    call vumat_work_init(self%work, nblock, ncomp, ncomp - 3, mat%nstatev, mat%nfieldv)
    self%work%point_kind = 'point'
    self%work%temp = temperature
    self%work%temp_new = temperature
  end subroutine block_init

  !> tempOld and tempNew of every point of the block (the temperature at the increment's start
  !> and end).
  subroutine block_set_temperature(self, temp_old, temp_new)
    class(point_block_t), intent(inout) :: self
    real(dp), intent(in) :: temp_old, temp_new

    self%work%temp(1:self%nblock) = temp_old
    self%work%temp_new(1:self%nblock) = temp_new
  end subroutine block_set_temperature

  !> Load point `k` with an old state and a strain increment.
  subroutine block_set_point(self, k, density0, log_strain, strain_inc, stress, state, field, &
       ener_intern, ener_inelas)
    class(point_block_t), intent(inout) :: self
    integer, intent(in) :: k
    real(dp), intent(in) :: density0
    real(dp), intent(in) :: log_strain(:), strain_inc(:), stress(:), state(:), field(:)
    real(dp), intent(in) :: ener_intern, ener_inelas
    integer :: nc
    real(dp) :: u(self%ncomp), f(self%ncomp + self%nshr), e_mid(self%ncomp)

    nc = self%ncomp
    self%log_strain_old(k, :) = log_strain(1:nc)
    self%strain_inc(k, :) = strain_inc(1:nc)
    call stretch_from_log_strain(nc, log_strain(1:nc), u)
    call defgrad_from_stretch(nc, u, f)
    self%stretch_old(k, :) = u
    self%defgrad_old(k, :) = f
    call stretch_from_log_strain(nc, log_strain(1:nc) + strain_inc(1:nc), u)
    call defgrad_from_stretch(nc, u, f)
    self%stretch_new(k, :) = u
    self%defgrad_new(k, :) = f
    ! current density at mid-increment: rho0 / J with ln J = tr E
    e_mid = log_strain(1:nc) + 0.5_dp * strain_inc(1:nc)
    self%density(k) = density0 * exp(-(e_mid(1) + e_mid(2) + e_mid(3)))
    self%stress(k, :) = stress(1:nc)
    self%state(k, 1:self%nstatev) = state(1:self%nstatev)
    self%field(k, 1:self%nfieldv) = field(1:self%nfieldv)
    self%ener_intern(k) = ener_intern
    self%ener_inelas(k) = ener_inelas
  end subroutine block_set_point

  !> [VUSDFLD +] VUMAT on the block through the door at stepTime = totalTime = `time`.
  subroutine block_call_material(self, mat, time, dt)
    class(point_block_t), intent(inout) :: self
    type(material_t), intent(in) :: mat
    real(dp), intent(in) :: time, dt

    call call_material(mat, self%nblock, self%ncomp, self%nshr, self%numbers, time, time, dt, &
         self%char_length, self%density, self%strain_inc, self%rel_spin_inc, self%stretch_old, &
         self%stretch_new, self%defgrad_old, self%defgrad_new, self%log_strain_old, self%stress, &
         self%state, self%field, self%ener_intern, self%ener_inelas, self%work)
  end subroutine block_call_material
end module matpoint_block
