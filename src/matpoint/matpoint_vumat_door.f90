!> The material-point driver's side of the VUMAT/VUSDFLD door.
!>
!> A block holds every argument array of one call in Abaqus's layout, `(nblock, ncomp)`,
!> column-major, real(dp). `vumat` and `vusdfld` are called through IMPLICIT interfaces
!> (`external`), exactly as Abaqus calls user code, so any VUMAT built against the same
!> argument list links in its place (a user's file, fixed or free form). The first actual
!> argument of vumat is the integer array jblock = [nblock, npt, layer, kspt, noel(1:nblock)]
!> (docs/theory/abaqus_contract.md §0 item 2): a VUMAT declaring a scalar `nblock` reads
!> jblock(1), one written in the "jblock" style finds its element numbers in jblock(5:).
!>
!> Before each vumat call of a material with `*USER DEFINED FIELD`, vusdfld is called on
!> the same block with the start-of-increment stress and logarithmic strain made
!> available to `vgetvrm` (abaqus_host); the fields it returns become the vumat's fieldNew,
!> and the state it returns is the stateOld the vumat sees (Abaqus does not document this
!> sequencing; passing VUSDFLD's state on keeps any change it makes).
!>
!> The vusdfld receives the `*USER MATERIAL` constants as its props (our VUSDFLD uses none).
module matpoint_vumat_door
  use material_kinds, only: dp
  use abaqus_host, only: host_set_block, host_set_block_extra
  use material_entry, only: vumat_entry, vusdfld_entry
  use user_library, only: user_library_loaded
  use matpoint_material, only: matpoint_material_t, material_cmname
  use matpoint_kinematics, only: stretch_from_log_strain, defgrad_from_stretch
  implicit none
  private

  public :: vumat_block_t, call_vumat_block, call_vusdfld_block, packaging_moduli

  type :: vumat_block_t
     integer :: nblock = 0, ndir = 3, nshr = 1, ncomp = 4, nstatev = 0, nfieldv = 0
     integer, allocatable :: jblock(:)
     real(dp), allocatable :: coord(:, :), char_length(:), density(:)
     real(dp), allocatable :: strain_inc(:, :), rel_spin_inc(:, :)
     real(dp), allocatable :: temp_old(:), temp_new(:)
     real(dp), allocatable :: stretch_old(:, :), stretch_new(:, :)
     real(dp), allocatable :: defgrad_old(:, :), defgrad_new(:, :)
     real(dp), allocatable :: field_old(:, :), field_new(:, :)
     real(dp), allocatable :: stress_old(:, :), stress_new(:, :)
     real(dp), allocatable :: state_old(:, :), state_new(:, :)
     real(dp), allocatable :: ener_intern_old(:), ener_intern_new(:)
     real(dp), allocatable :: ener_inelas_old(:), ener_inelas_new(:)
     !> start-of-increment logarithmic strain, for vgetvrm('LE') (not a VUMAT argument)
     real(dp), allocatable :: log_strain_old(:, :)
   contains
     procedure :: init => block_init
     procedure :: set_point => block_set_point
  end type vumat_block_t

contains

  !> Allocate a block of `nblock` points; everything zero, element numbers 1.
  subroutine block_init(self, nblock, ncomp, nstatev, nfieldv)
    class(vumat_block_t), intent(inout) :: self
    integer, intent(in) :: nblock, ncomp, nstatev, nfieldv
    integer :: nf

    self%nblock = nblock
    self%ncomp = ncomp
    self%ndir = 3
    self%nshr = ncomp - 3
    self%nstatev = nstatev
    self%nfieldv = nfieldv
    nf = ncomp + self%nshr
    if (allocated(self%jblock)) then
       deallocate (self%jblock, self%coord, self%char_length, self%density, self%strain_inc, &
            self%rel_spin_inc, self%temp_old, self%temp_new, self%stretch_old, self%stretch_new, &
            self%defgrad_old, self%defgrad_new, self%field_old, self%field_new, self%stress_old, &
            self%stress_new, self%state_old, self%state_new, self%ener_intern_old, &
            self%ener_intern_new, self%ener_inelas_old, self%ener_inelas_new, self%log_strain_old)
    end if
    ! One element, one integration point: all points of the block are copies of it.
    allocate (self%jblock(4 + nblock))
    self%jblock(1:4) = [nblock, 1, 1, 1]
    self%jblock(5:) = 1
    allocate (self%coord(nblock, 3), self%char_length(nblock), self%density(nblock))
    allocate (self%strain_inc(nblock, ncomp), self%rel_spin_inc(nblock, self%nshr))
    allocate (self%temp_old(nblock), self%temp_new(nblock))
    allocate (self%stretch_old(nblock, ncomp), self%stretch_new(nblock, ncomp))
    allocate (self%defgrad_old(nblock, nf), self%defgrad_new(nblock, nf))
    allocate (self%field_old(nblock, nfieldv), self%field_new(nblock, nfieldv))
    allocate (self%stress_old(nblock, ncomp), self%stress_new(nblock, ncomp))
    allocate (self%state_old(nblock, nstatev), self%state_new(nblock, nstatev))
    allocate (self%ener_intern_old(nblock), self%ener_intern_new(nblock))
    allocate (self%ener_inelas_old(nblock), self%ener_inelas_new(nblock))
    allocate (self%log_strain_old(nblock, ncomp))
    self%coord = 0.0_dp
    self%char_length = 1.0_dp
    self%density = 1.0_dp
    self%strain_inc = 0.0_dp
    self%rel_spin_inc = 0.0_dp
    self%temp_old = 0.0_dp
    self%temp_new = 0.0_dp
    self%stretch_old = 0.0_dp
    self%stretch_new = 0.0_dp
    self%defgrad_old = 0.0_dp
    self%defgrad_new = 0.0_dp
    self%field_old = 0.0_dp
    self%field_new = 0.0_dp
    self%stress_old = 0.0_dp
    self%stress_new = 0.0_dp
    self%state_old = 0.0_dp
    self%state_new = 0.0_dp
    self%ener_intern_old = 0.0_dp
    self%ener_intern_new = 0.0_dp
    self%ener_inelas_old = 0.0_dp
    self%ener_inelas_new = 0.0_dp
    self%log_strain_old = 0.0_dp
  end subroutine block_init

  !> Load point `k` with an old state and a strain increment. The outputs start as copies
  !> of the old values, so a VUMAT that leaves the energies alone keeps them (Abaqus).
  subroutine block_set_point(self, k, density0, log_strain, strain_inc, stress, state, &
       field_old, field_new, ener_intern, ener_inelas)
    class(vumat_block_t), intent(inout) :: self
    integer, intent(in) :: k
    real(dp), intent(in) :: density0
    real(dp), intent(in) :: log_strain(:), strain_inc(:), stress(:), state(:)
    real(dp), intent(in) :: field_old(:), field_new(:)
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
    self%stress_old(k, :) = stress(1:nc)
    self%stress_new(k, :) = stress(1:nc)
    self%state_old(k, :) = state(1:self%nstatev)
    self%state_new(k, :) = state(1:self%nstatev)
    self%field_old(k, :) = field_old(1:self%nfieldv)
    self%field_new(k, :) = field_new(1:self%nfieldv)
    self%ener_intern_old(k) = ener_intern
    self%ener_intern_new(k) = ener_intern
    self%ener_inelas_old(k) = ener_inelas
    self%ener_inelas_new(k) = ener_inelas
  end subroutine block_set_point

  !> One VUMAT call on the block.
  subroutine call_vumat_block(blk, mat, step_time, total_time, dt)
    type(vumat_block_t), intent(inout) :: blk
    type(matpoint_material_t), intent(in) :: mat
    real(dp), intent(in) :: step_time, total_time, dt
    procedure(), pointer :: vumat
    character(len=80) :: cmname
    integer :: nprops, lanneal

    ! With --user the point's material is the user's (bulkflow-matpoint reads *USER MATERIAL only).
    vumat => vumat_entry(user_library_loaded())
    cmname = material_cmname(mat)
    nprops = size(mat%props)
    lanneal = 0
    call vumat(blk%jblock, blk%ndir, blk%nshr, blk%nstatev, blk%nfieldv, nprops, lanneal, &
         step_time, total_time, dt, cmname, blk%coord, blk%char_length, &
         mat%props, blk%density, blk%strain_inc, blk%rel_spin_inc, &
         blk%temp_old, blk%stretch_old, blk%defgrad_old, blk%field_old, &
         blk%stress_old, blk%state_old, blk%ener_intern_old, blk%ener_inelas_old, &
         blk%temp_new, blk%stretch_new, blk%defgrad_new, blk%field_new, &
         blk%stress_new, blk%state_new, blk%ener_intern_new, blk%ener_inelas_new)
  end subroutine call_vumat_block

  !> One VUSDFLD call on the block: fieldNew and stateOld of the block are replaced by
  !> what it returns (see the module header).
  subroutine call_vusdfld_block(blk, mat, step_time, total_time, dt)
    type(vumat_block_t), intent(inout) :: blk
    type(matpoint_material_t), intent(in) :: mat
    real(dp), intent(in) :: step_time, total_time, dt
    procedure(), pointer :: vusdfld
    character(len=80) :: cmname
    integer :: nprops, k, i
    integer, parameter :: k_int_pt = 1, k_layer = 1, k_sec_pt = 1
    real(dp) :: direct(blk%nblock, 3, 3), t_dir(blk%nblock, 3, 3)
    real(dp) :: field(blk%nblock, blk%nfieldv), state_out(blk%nblock, blk%nstatev)

    vusdfld => vusdfld_entry(user_library_loaded())
    cmname = material_cmname(mat)
    nprops = size(mat%props)
    direct = 0.0_dp
    do k = 1, blk%nblock
       do i = 1, 3
          direct(k, i, i) = 1.0_dp
       end do
    end do
    t_dir = direct
    field = blk%field_old
    state_out = blk%state_old
    call host_set_block(blk%nblock, blk%ncomp, blk%stress_old, blk%log_strain_old)
    call host_set_block_extra(blk%state_old, blk%temp_old)
    call vusdfld(blk%nblock, blk%nstatev, blk%nfieldv, nprops, blk%ndir, blk%nshr, &
         blk%jblock(5:), k_int_pt, k_layer, k_sec_pt, &
         step_time, total_time, dt, cmname, &
         blk%coord, direct, t_dir, blk%char_length, mat%props, &
         blk%state_old, &
         state_out, field)
    blk%field_new = field
    blk%state_old = state_out
    blk%state_new = state_out
  end subroutine call_vusdfld_block

  !> The Abaqus "packaging" call (stepTime = totalTime = 0, fictitious strain increments)
  !> on two points from zero stress: a volumetric compression gives K, the same plus a
  !> small shear gives 2G. The VUMAT's answers are then thrown away.
  !> `ok` is false when the response is not a positive, finite elastic stiffness.
  subroutine packaging_moduli(mat, ncomp, field, dt, two_g, bulk, ok)
    type(matpoint_material_t), intent(in) :: mat
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: field(:)
    real(dp), intent(in) :: dt
    real(dp), intent(out) :: two_g, bulk
    logical, intent(out) :: ok
    type(vumat_block_t) :: blk
    real(dp), parameter :: delta = 1.0e-6_dp
    real(dp) :: zero_c(ncomp), zero_s(mat%nstatev), de(ncomp), dsig(ncomp)
    integer :: k

    call blk%init(2, ncomp, mat%nstatev, mat%nfieldv)
    zero_c = 0.0_dp
    zero_s = 0.0_dp
    do k = 1, 2
       de = 0.0_dp
       de(1:3) = -delta
       if (k == 2) de(4) = 0.1_dp * delta
       call blk%set_point(k, mat%density, zero_c, de, zero_c, zero_s, field, field, &
            0.0_dp, 0.0_dp)
    end do
    call call_vumat_block(blk, mat, 0.0_dp, 0.0_dp, dt)
    dsig = blk%stress_new(1, :)
    bulk = (dsig(1) + dsig(2) + dsig(3)) / 3.0_dp / (-3.0_dp * delta)
    two_g = blk%stress_new(2, 4) / (0.1_dp * delta)
    ok = (bulk > 0.0_dp .and. bulk < huge(1.0_dp) .and. two_g > 0.0_dp .and. &
         two_g < huge(1.0_dp))
  end subroutine packaging_moduli

end module matpoint_vumat_door
