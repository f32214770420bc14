!> The material door: the one call path from the solvers to a material. Elements (src/driver),
!> MPM particles (src/mpm) and the material-point driver (src/matpoint) call a material only
!> here, with the `material_t` the scene reader built (docs/user_subroutines.md, src/material/
!> README.md).
!>
!> It owns: one increment of a block ([VUSDFLD +] VUMAT with the full Abaqus argument contract:
!> jblock, coordMp, charLength, density, strainInc, relSpinInc, temperatures, stretch and defgrad
!> old/new, fields, stress, state, energies), and Abaqus's packaging call with its result checked
!> (a stiffness that is not positive and finite stops with the material's name).
!>
!> vumat and vusdfld are called through implicit interfaces, exactly as Abaqus calls user code;
!> material_entry says whose (ours, or the --user library's for a *USER MATERIAL). The first
!> argument of vumat is jblock = [nblock, npt, layer, kspt, noel(1:nblock)] so both the
!> scalar-nblock and the "jblock" styles of VUMAT work (docs/user_subroutines.md). Times passed
!> are those at the end of the increment; the packaging call has stepTime = totalTime = 0.
!> A user's VUMAT gets at most n_vec_length = 136 points per call, coordMp and the temperatures
!> from the work set (the caller fills them), and stressNew, stateNew and the energies holding
!> the old values on entry (call_user_material).
!> With a user field, vusdfld runs first on the same block with the start-of-increment stress
!> and logarithmic strain available to vgetvrm; its fields become the vumat's fieldNew and its
!> state the vumat's stateOld.
module material_door
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use abaqus_host, only: host_set_block, host_set_block_extra, host_set_block_moduli, host_set_block_material, &
       host_clear_block
  use material_props, only: model_from_name, model_mohr_coulomb, model_drucker_prager
  use model_materials, only: material_t
  use model_sets, only: name_length
  use material_entry, only: vumat_entry, vusdfld_entry
  use material_kinematics, only: stretch_from_log_strain, defgrad_from_stretch
  implicit none
  private

  !> The most points one call hands a user's VUMAT (Abaqus's n_vec_Length, vaba_param.inc).
  integer, parameter, public :: n_vec_length = 136

  !> Arguments of a vumat call that the solver does not keep between increments.
  !> A set is made once for up to `capacity` points (vumat_work_init) and then serves a call of
  !> `rows` points (vumat_work_rows): the 2D/3D arrays the VUMAT sees as (nblock, ...) are views
  !> of exactly `rows` rows into one store, so a set changes its row count without allocating
  !> (the MPM's partial blocks change counts every few increments as particles leave and
  !> arrive: re-making a set each time was 3 % of a rank's run, docs/scaling.md); the 1D
  !> arrays have capacity rows (their (1:rows) sections are contiguous anyway); the new stress,
  !> state and energies are allocatables of exactly `rows` rows, because the door swaps them
  !> with the block's arrays instead of copying.
  type, public :: vumat_work_t
     character(len=8) :: point_kind = 'element'       !< what elem_number counts (messages)
     integer :: capacity = 0                          !< most rows (vumat_work_init's nmax)
     integer :: rows = 0                              !< rows of the views now
     integer :: ncomp = 0, nshr = 0, nstatev = 0, nfieldv = 0
     integer, allocatable :: jblock(:)
     real(dp), allocatable :: temp(:), temp_new(:)
     real(dp), pointer, contiguous :: coord(:, :) => null(), stretch_old(:, :) => null(), &
          stretch_new(:, :) => null(), defgrad_old(:, :) => null(), defgrad_new(:, :) => null(), &
          field_new(:, :) => null(), state_mid(:, :) => null(), direct(:, :, :) => null()
     real(dp), pointer, contiguous :: store(:) => null()   !< the views' storage
     real(dp), allocatable :: stress_new(:, :), state_new(:, :), e_int_new(:), e_inel_new(:)
  end type vumat_work_t

  public :: vumat_work_init, vumat_work_rows, call_material, call_field, packaging_modulus, checked_packaging_modulus
  public :: packaging_moduli, checked_packaging_moduli

  !> The strain increment of the packaging call (direction 11).
  real(dp), parameter :: packaging_strain = 1.0e-6_dp
  !> elastic_moduli's answers, per material name and component count (found once).
  integer :: known_count = 0
  character(len=name_length), allocatable :: known_names(:)
  integer, allocatable :: known_ncomp(:)
  real(dp), allocatable :: known_moduli(:, :)

contains

  !> A set for up to nmax points, serving nmax rows (vumat_work_rows changes that).
  subroutine vumat_work_init(w, nmax, ncomp, nshr, nstatev, nfieldv)
    type(vumat_work_t), intent(inout) :: w
    integer, intent(in) :: nmax, ncomp, nshr, nstatev, nfieldv

    if (allocated(w%jblock)) deallocate(w%jblock, w%temp, w%temp_new)
    if (associated(w%store)) deallocate(w%store)
    w%capacity = nmax
    w%ncomp = ncomp
    w%nshr = nshr
    w%nstatev = max(1, nstatev)
    w%nfieldv = max(1, nfieldv)
    allocate(w%jblock(4 + nmax), w%temp(nmax), w%temp_new(nmax))
    allocate(w%store(nmax * view_columns(w)))
    w%jblock = 1
    w%temp = 0
    w%temp_new = 0
    w%rows = -1
    call vumat_work_rows(w, nmax)
  end subroutine vumat_work_init

  !> Columns of all views together (each view has its own `capacity`-row region of the store).
  pure integer function view_columns(w)
    type(vumat_work_t), intent(in) :: w
    view_columns = 3 + 2 * w%ncomp + 2 * (w%ncomp + w%nshr) + w%nfieldv + w%nstatev + 9
  end function view_columns

  !> The set serves `rows` points (1 <= rows <= capacity): its views become (rows, ...) arrays,
  !> coordMp zero and the direction cosines the identity in them (what a freshly made set holds;
  !> the stretch and defgrad views are the caller's to fill), and the swapped arrays get exactly
  !> `rows` rows. Nothing is done when the set has that count already.
  subroutine vumat_work_rows(w, rows)
    type(vumat_work_t), intent(inout) :: w
    integer, intent(in) :: rows
    integer :: off, k

    if (rows == w%rows) return
    if (rows < 1 .or. rows > w%capacity) call raise_error('vumat_work_rows', 0, &
         'a work set asked for more rows than it was made for (internal error)')
    off = 0
    call view(w%coord, 3)
    call view(w%stretch_old, w%ncomp)
    call view(w%stretch_new, w%ncomp)
    call view(w%defgrad_old, w%ncomp + w%nshr)
    call view(w%defgrad_new, w%ncomp + w%nshr)
    call view(w%field_new, w%nfieldv)
    call view(w%state_mid, w%nstatev)
    w%direct(1:rows, 1:3, 1:3) => w%store(off + 1:off + 9 * rows)
    w%coord = 0
    w%direct = 0
    do k = 1, 3
       w%direct(:, k, k) = 1
    end do
    if (allocated(w%stress_new)) deallocate(w%stress_new, w%state_new, w%e_int_new, w%e_inel_new)
    allocate(w%stress_new(rows, w%ncomp), w%state_new(rows, w%nstatev), w%e_int_new(rows), w%e_inel_new(rows))
    w%rows = rows
  contains
    subroutine view(a, ncol)
      real(dp), pointer, contiguous, intent(inout) :: a(:, :)
      integer, intent(in) :: ncol
      a(1:rows, 1:ncol) => w%store(off + 1:off + ncol * rows)
      off = off + ncol * w%capacity
    end subroutine view
  end subroutine vumat_work_rows

  !> One increment of the material of a block: [vusdfld] then vumat. Arrays are the block's
  !> (nb, ...) arrays; on return stress/state/field/energies hold the new values.
  !> With `field_given` (the MPM's *NONLOCAL, docs/nonlocal.md) the VUSDFLD has run already
  !> (call_field, its state written to `state`): field_given is the VUMAT's fieldNew, `field` its
  !> fieldOld, and field_given becomes the block's field.
  subroutine call_material(mat, nb, ncomp, nshr, elem_number, step_time, total_time, dt, &
       char_length, density, strain_inc, rel_spin, stretch_old, stretch_new, defgrad_old, &
       defgrad_new, log_strain, stress, state, field, e_int, e_inel, w, field_given)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: nb, ncomp, nshr
    integer, intent(in) :: elem_number(nb)
    real(dp), intent(in) :: step_time, total_time, dt
    real(dp), intent(in) :: char_length(nb), density(nb), strain_inc(nb, ncomp), rel_spin(nb, nshr)
    real(dp), intent(in) :: stretch_old(nb, ncomp), stretch_new(nb, ncomp)
    real(dp), intent(in) :: defgrad_old(nb, ncomp + nshr), defgrad_new(nb, ncomp + nshr)
    real(dp), intent(in) :: log_strain(:, :)
    ! stress and state are the block's own arrays: allocatable, so the new values can be
    ! swapped in from the work arrays instead of copied (the copies were most of the memmove
    ! of a run).
    real(dp), allocatable, intent(inout) :: stress(:, :), state(:, :)
    real(dp), intent(inout) :: field(:, :)
    ! Allocatable for the same reason as stress and state.
    real(dp), allocatable, intent(inout) :: e_int(:), e_inel(:)
    type(vumat_work_t), intent(inout) :: w
    real(dp), intent(in), optional :: field_given(:, :)
    integer :: nstatev, nfieldv, nprops, ns, nf, piece, i0
    procedure(), pointer :: umat

    if (mat%user_code) then
       call call_user_material(mat, nb, ncomp, nshr, elem_number, step_time, total_time, dt, char_length, &
            density, strain_inc, rel_spin, stretch_old, stretch_new, defgrad_old, defgrad_new, log_strain, &
            stress, state, field, e_int, e_inel, w, field_given)
       return
    end if
    umat => vumat_entry(.false.)
    nstatev = mat%nstatev
    nfieldv = mat%nfieldv
    nprops = size(mat%props)
    ! The block's state and field arrays have this material's columns (at least one); the work
    ! arrays have the largest count of all materials. Every copy and every argument uses the
    ! block's count: whole-column assignments between the two failed (debug) or overran the
    ! block's arrays (release) as soon as two materials had different *DEPVAR counts. The
    ! sections (1:nb, 1:ns) are contiguous (the work arrays have exactly nb rows).
    ns = size(state, 2)
    nf = size(field, 2)
    w%jblock(1:4) = [nb, 1, 1, 1]
    w%jblock(5:4 + nb) = elem_number
    if (present(field_given)) then
       ! the VUSDFLD's state is the block's already (call_field): stateOld is the block's state
       call umat(w%jblock, 3, nshr, nstatev, nfieldv, nprops, 0, step_time, total_time, dt, &
            mat%vumat_name, w%coord(1:nb, :), char_length, mat%props, density, strain_inc, rel_spin, &
            w%temp(1:nb), stretch_old, defgrad_old, field(1:nb, 1:nf), stress, state(1:nb, 1:ns), &
            e_int, e_inel, w%temp_new(1:nb), stretch_new, defgrad_new, field_given(1:nb, 1:nf), &
            w%stress_new(1:nb, :), w%state_new(1:nb, 1:ns), w%e_int_new(1:nb), w%e_inel_new(1:nb))
       field(1:nb, 1:nf) = field_given(1:nb, 1:nf)
    else if (mat%user_field) then
       ! A user's VUSDFLD gets at most n_vec_length points a call (Abaqus's nblock), ours the
       ! whole block; each point's answer depends on that point alone.
       w%field_new(1:nb, 1:nfieldv) = field(1:nb, 1:nfieldv)
       piece = nb
       if (mat%user_field_code) piece = n_vec_length
       do i0 = 1, nb, piece
          call call_field_piece(mat, i0, min(nb, i0 + piece - 1), i0, ncomp, nshr, elem_number, step_time, &
               total_time, dt, char_length, stress, log_strain, state(1:nb, 1:ns), w)
       end do
       call umat(w%jblock, 3, nshr, nstatev, nfieldv, nprops, 0, step_time, total_time, dt, &
            mat%vumat_name, w%coord(1:nb, :), char_length, mat%props, density, strain_inc, rel_spin, &
            w%temp(1:nb), stretch_old, defgrad_old, field(1:nb, 1:nf), stress, w%state_mid(1:nb, 1:ns), &
            e_int, e_inel, w%temp_new(1:nb), stretch_new, defgrad_new, w%field_new(1:nb, 1:nf), &
            w%stress_new(1:nb, :), w%state_new(1:nb, 1:ns), w%e_int_new(1:nb), w%e_inel_new(1:nb))
    else
       ! Without a user field stateOld is the block's state itself (a contiguous (nb, ns) array,
       ! read only by the VUMAT): no copy through state_mid. The fields do not change, so the
       ! block's array is fieldOld and fieldNew at once (both read-only for a VUMAT); before, it
       ! was copied to the work array and back every call.
       call umat(w%jblock, 3, nshr, nstatev, nfieldv, nprops, 0, step_time, total_time, dt, &
            mat%vumat_name, w%coord(1:nb, :), char_length, mat%props, density, strain_inc, rel_spin, &
            w%temp(1:nb), stretch_old, defgrad_old, field(1:nb, 1:nf), stress, state(1:nb, 1:ns), &
            e_int, e_inel, w%temp_new(1:nb), stretch_new, defgrad_new, field(1:nb, 1:nf), &
            w%stress_new(1:nb, :), w%state_new(1:nb, 1:ns), w%e_int_new(1:nb), w%e_inel_new(1:nb))
    end if
    ! The new stress and state become the block's by swapping allocations when the shapes agree
    ! (work sets have exactly nb rows; state columns agree unless materials differ in *DEPVAR
    ! counts); the old arrays become the work arrays the next VUMAT call overwrites.
    call swap_or_copy(stress, w%stress_new, nb, ncomp)
    call swap_or_copy(state, w%state_new, nb, ns)
    if (mat%user_field) field(1:nb, 1:nf) = w%field_new(1:nb, 1:nf)
    call swap_or_copy_1d(e_int, w%e_int_new, nb)
    call swap_or_copy_1d(e_inel, w%e_inel_new, nb)
  end subroutine call_material

  !> The material's VUSDFLD alone on a block (the MPM's *NONLOCAL runs it on every block, averages
  !> a field variable over the particles, then calls call_material with field_given): the same
  !> arguments and pieces as inside call_material; its stateNew is written to `state` (the
  !> VUMAT's stateOld, as inside call_material) and its fields to field_new (nb, nfieldv), with
  !> `field` (the block's, the last increment's values) as fieldNew on entry.
  subroutine call_field(mat, nb, ncomp, nshr, elem_number, step_time, total_time, dt, char_length, &
       stress, log_strain, state, field, field_new, w)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: nb, ncomp, nshr
    integer, intent(in) :: elem_number(nb)
    real(dp), intent(in) :: step_time, total_time, dt
    real(dp), intent(in) :: char_length(nb), stress(:, :), log_strain(:, :), field(:, :)
    real(dp), intent(inout) :: state(:, :)
    real(dp), intent(out) :: field_new(:, :)
    type(vumat_work_t), intent(inout) :: w
    integer :: ns, nf, piece, i0

    ns = size(state, 2)
    nf = mat%nfieldv
    w%field_new(1:nb, 1:nf) = field(1:nb, 1:nf)
    piece = nb
    if (mat%user_field_code) piece = n_vec_length
    do i0 = 1, nb, piece
       call call_field_piece(mat, i0, min(nb, i0 + piece - 1), i0, ncomp, nshr, elem_number, step_time, &
            total_time, dt, char_length, stress, log_strain, state(1:nb, 1:ns), w)
    end do
    state(1:nb, 1:ns) = w%state_mid(1:nb, 1:ns)
    field_new = 0
    field_new(1:nb, 1:nf) = w%field_new(1:nb, 1:nf)
  end subroutine call_field

  !> call_material for a *USER MATERIAL with a user's file loaded: the block in pieces of at most
  !> n_vec_length points (array sections: copied in and out by the compiler where they are not
  !> contiguous), stressNew, stateNew, fieldNew and the energies holding the old values on entry
  !> (a VUMAT that leaves an output alone keeps the old value, as in Abaqus).
  subroutine call_user_material(mat, nb, ncomp, nshr, elem_number, step_time, total_time, dt, &
       char_length, density, strain_inc, rel_spin, stretch_old, stretch_new, defgrad_old, &
       defgrad_new, log_strain, stress, state, field, e_int, e_inel, w, field_given)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: nb, ncomp, nshr
    integer, intent(in) :: elem_number(nb)
    real(dp), intent(in) :: step_time, total_time, dt
    real(dp), intent(in) :: char_length(nb), density(nb), strain_inc(nb, ncomp), rel_spin(nb, nshr)
    real(dp), intent(in) :: stretch_old(nb, ncomp), stretch_new(nb, ncomp)
    real(dp), intent(in) :: defgrad_old(nb, ncomp + nshr), defgrad_new(nb, ncomp + nshr)
    real(dp), intent(in) :: log_strain(:, :)
    real(dp), intent(inout) :: stress(:, :), state(:, :), field(:, :), e_int(:), e_inel(:)
    type(vumat_work_t), intent(inout) :: w
    real(dp), intent(in), optional :: field_given(:, :)
    procedure(), pointer :: umat
    integer :: nstatev, nfieldv, nprops, ns, nf, i0, i1, n

    umat => vumat_entry(.true.)
    nstatev = mat%nstatev
    nfieldv = mat%nfieldv
    nprops = size(mat%props)
    ns = size(state, 2)
    nf = size(field, 2)
    do i0 = 1, nb, n_vec_length
       i1 = min(nb, i0 + n_vec_length - 1)
       n = i1 - i0 + 1
       w%jblock(1:4) = [n, 1, 1, 1]
       w%jblock(5:4 + n) = elem_number(i0:i1)
       w%stress_new(1:n, :) = stress(i0:i1, :)
       w%state_mid(1:n, 1:ns) = state(i0:i1, 1:ns)
       w%field_new(1:n, 1:nf) = field(i0:i1, 1:nf)
       w%e_int_new(1:n) = e_int(i0:i1)
       w%e_inel_new(1:n) = e_inel(i0:i1)
       if (present(field_given)) then
          w%field_new(1:n, 1:nf) = field_given(i0:i1, 1:nf)
       else if (mat%user_field) then
          call call_field_piece(mat, i0, i1, 1, ncomp, nshr, elem_number, step_time, total_time, dt, &
               char_length, stress, log_strain, state(:, 1:ns), w)
       end if
       w%state_new(1:n, 1:ns) = w%state_mid(1:n, 1:ns)
       call umat(w%jblock, 3, nshr, nstatev, nfieldv, nprops, 0, step_time, total_time, dt, &
            mat%vumat_name, w%coord(i0:i1, :), char_length(i0:i1), mat%props, density(i0:i1), &
            strain_inc(i0:i1, :), rel_spin(i0:i1, :), w%temp(i0:i1), stretch_old(i0:i1, :), &
            defgrad_old(i0:i1, :), field(i0:i1, 1:nf), stress(i0:i1, :), w%state_mid(1:n, 1:ns), &
            e_int(i0:i1), e_inel(i0:i1), w%temp_new(i0:i1), stretch_new(i0:i1, :), defgrad_new(i0:i1, :), &
            w%field_new(1:n, 1:nf), w%stress_new(1:n, :), w%state_new(1:n, 1:ns), w%e_int_new(1:n), &
            w%e_inel_new(1:n))
       call check_finite(mat, n, ncomp, elem_number(i0:i1), total_time, w%stress_new, w%point_kind)
       stress(i0:i1, :) = w%stress_new(1:n, :)
       state(i0:i1, 1:ns) = w%state_new(1:n, 1:ns)
       field(i0:i1, 1:nf) = w%field_new(1:n, 1:nf)
       e_int(i0:i1) = w%e_int_new(1:n)
       e_inel(i0:i1) = w%e_inel_new(1:n)
    end do
  end subroutine call_user_material

  !> The material's VUSDFLD on the points i0..i1 of a block: the host's vgetvrm data for those
  !> points (start-of-increment S, LE, SDV, TEMP, PE from the packaging moduli and, for our
  !> plastic models, PEEQ = SDV1), then the call, whose stateNew and field land in rows
  !> first.. of w%state_mid and w%field_new (fieldNew holding its old values on entry). A user's
  !> VUSDFLD on our plastic models gets the *DEPVAR state variables only (user_state_first).
  subroutine call_field_piece(mat, i0, i1, first, ncomp, nshr, elem_number, step_time, total_time, dt, &
       char_length, stress, log_strain, state, w)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: i0, i1, first, ncomp, nshr
    integer, intent(in) :: elem_number(:)
    real(dp), intent(in) :: step_time, total_time, dt
    real(dp), intent(in) :: char_length(:)
    ! TARGET: the host points at them while the VUSDFLD runs (vgetvrm; abaqus_host)
    real(dp), intent(in), target :: stress(:, :), log_strain(:, :), state(:, :)
    type(vumat_work_t), intent(inout), target :: w
    procedure(), pointer :: usdfld
    integer :: n, last, ns, nf, model, j0, nsu
    real(dp) :: lambda, shear

    usdfld => vusdfld_entry(mat%user_field_code)
    n = i1 - i0 + 1
    last = first + n - 1
    ns = size(state, 2)
    nf = mat%nfieldv
    ! A user's VUSDFLD sees SDV j0..nstatev (on our plastic models the *DEPVAR ones after our
    ! model's own) and may leave stateNew alone: it holds stateOld on entry.
    j0 = mat%user_state_first
    nsu = mat%nstatev - j0 + 1
    if (mat%user_field_code) w%state_mid(first:last, 1:ns) = state(i0:i1, :)
    call elastic_moduli(mat, ncomp, nshr, lambda, shear)
    call host_set_block(n, ncomp, stress(i0:i1, :), log_strain(i0:i1, :))
    model = model_from_name(mat%vumat_name)
    if (.not. mat%user_code .and. (model == model_mohr_coulomb .or. model == model_drucker_prager)) then
       call host_set_block_extra(state(i0:i1, j0:j0 + nsu - 1), w%temp(i0:i1), peeq=state(i0:i1, 1))
    else
       call host_set_block_extra(state(i0:i1, j0:j0 + nsu - 1), w%temp(i0:i1))
    end if
    call host_set_block_moduli(lambda, shear)
    call host_set_block_material(mat%name, mat%user_code)
    if (allocated(mat%field_props)) then
       call usdfld(n, nsu, nf, size(mat%field_props), 3, nshr, elem_number(i0:i1), 1, 1, 1, &
            step_time, total_time, dt, mat%vumat_name, w%coord(i0:i1, :), w%direct(1:n, :, :), &
            w%direct(1:n, :, :), char_length(i0:i1), mat%field_props, state(i0:i1, j0:ns), &
            w%state_mid(first:last, j0:ns), w%field_new(first:last, 1:nf))
    else
       call usdfld(n, nsu, nf, size(mat%props), 3, nshr, elem_number(i0:i1), 1, 1, 1, step_time, &
            total_time, dt, mat%vumat_name, w%coord(i0:i1, :), w%direct(1:n, :, :), w%direct(1:n, :, :), &
            char_length(i0:i1), mat%props, state(i0:i1, j0:ns), w%state_mid(first:last, j0:ns), &
            w%field_new(first:last, 1:nf))
    end if
    call host_clear_block()
  end subroutine call_field_piece

  !> Stop with the material, the element or particle and the time when a user's VUMAT returned
  !> a stress that is not a finite number (it would spread through the mesh as NaN).
  subroutine check_finite(mat, n, ncomp, numbers, total_time, stress_new, point_kind)
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    type(material_t), intent(in) :: mat
    integer, intent(in) :: n, ncomp, numbers(n)
    real(dp), intent(in) :: total_time, stress_new(:, :)
    character(len=*), intent(in) :: point_kind
    character(len=160) :: text
    integer :: k, j

    do j = 1, ncomp
       do k = 1, n
          if (ieee_is_finite(stress_new(k, j))) cycle
          write (text, '(a,i0,a,i0,a,es13.6)') trim(point_kind) // ' ', numbers(k), ': stress component ', j, &
               ' is not a finite number at total time ', total_time
          call raise_error(trim(mat%source), 0, 'the user VUMAT of material ' // trim(mat%name) // &
               ' returned a stress that is not a number: ' // trim(text) // '; expected finite stressNew')
       end do
    end do
  end subroutine check_finite

  !> swap_or_copy for the (nb) energy arrays.
  subroutine swap_or_copy_1d(block, work, nb)
    real(dp), allocatable, intent(inout) :: block(:), work(:)
    integer, intent(in) :: nb
    real(dp), allocatable :: held(:)

    if (size(block) == nb .and. size(work) == nb) then
       call move_alloc(block, held)
       call move_alloc(work, block)
       call move_alloc(held, work)
    else
       block(1:nb) = work(1:nb)
    end if
  end subroutine swap_or_copy_1d

  !> block(1:nb, 1:nc) ← work(1:nb, 1:nc): by exchanging the allocations when both have exactly
  !> that shape, else by copying.
  subroutine swap_or_copy(block, work, nb, nc)
    real(dp), allocatable, intent(inout) :: block(:, :), work(:, :)
    integer, intent(in) :: nb, nc
    real(dp), allocatable :: held(:, :)

    if (size(block, 1) == nb .and. size(block, 2) == nc .and. size(work, 1) == nb &
         .and. size(work, 2) == nc) then
       call move_alloc(block, held)
       call move_alloc(work, block)
       call move_alloc(held, work)
    else
       block(1:nb, 1:nc) = work(1:nb, 1:nc)
    end if
  end subroutine swap_or_copy

  !> packaging_modulus, stopping with the material's name (where it is defined) when the VUMAT's
  !> answer is no stiffness: zero, negative, NaN or infinite (a stable increment from it would be
  !> meaningless; Abaqus makes this check on its own packaging call). With `err` the error is
  !> recorded there instead (tests).
  function checked_packaging_modulus(mat, ncomp, nshr, file, err) result(modulus)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: ncomp, nshr
    character(len=*), intent(in) :: file
    type(error_t), intent(inout), optional :: err
    real(dp) :: modulus
    character(len=16) :: value

    modulus = packaging_modulus(mat, ncomp, nshr)
    if (stiffness_ok(modulus)) return
    write (value, '(es12.4)') modulus
    call refuse_stiffness(mat, file, 'a strain increment 1e-6 in direction 11', &
         'the stiffness ' // trim(adjustl(value)), 'a positive, finite elastic modulus', err)
  end function checked_packaging_modulus

  !> packaging_moduli, stopping (or recording in `err`) as checked_packaging_modulus does when
  !> 2G or K is not a positive, finite number.
  subroutine checked_packaging_moduli(mat, ncomp, field, dt, file, two_g, bulk, err)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: field(:), dt
    character(len=*), intent(in) :: file
    real(dp), intent(out) :: two_g, bulk
    type(error_t), intent(inout), optional :: err
    character(len=16) :: shear, bulk_value

    call packaging_moduli(mat, ncomp, field, dt, two_g, bulk)
    if (stiffness_ok(two_g) .and. stiffness_ok(bulk)) return
    write (shear, '(es12.4)') two_g
    write (bulk_value, '(es12.4)') bulk
    call refuse_stiffness(mat, file, 'a volumetric strain increment -3e-6 and the same with a shear ' // &
         '1e-7', '2G = ' // trim(adjustl(shear)) // ', K = ' // trim(adjustl(bulk_value)), &
         'a positive, finite shear and bulk modulus', err)
  end subroutine checked_packaging_moduli

  !> A positive, finite modulus. NaN is tested first: an ordered comparison with NaN raises
  !> the invalid flag, which the debug build traps.
  pure logical function stiffness_ok(modulus)
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    real(dp), intent(in) :: modulus

    stiffness_ok = .false.
    if (ieee_is_finite(modulus)) stiffness_ok = modulus > 0
  end function stiffness_ok

  !> The packaging call's error: the material, where it is defined, the probe and the answer.
  subroutine refuse_stiffness(mat, file, probe, answer, expected, err)
    type(material_t), intent(in) :: mat
    character(len=*), intent(in) :: file, probe, answer, expected
    type(error_t), intent(inout), optional :: err

    call raise_error(file, 0, 'material ' // trim(mat%name) // ' (defined at ' // trim(mat%source) // &
         '): its VUMAT answered the packaging call (' // probe // ' at stepTime = totalTime = 0) ' // &
         'with ' // answer // '; expected ' // expected // ' (stress from strainInc or defgradNew; ' // &
         'see docs/user_subroutines.md)', err)
  end subroutine refuse_stiffness

  !> The two-point packaging call of the material-point driver: from a stress-free state at
  !> stepTime = totalTime = 0, point 1 a volumetric compression Δε_ii = −δ gives K, point 2 the
  !> same plus a tensor shear 0.1δ in component 12 gives 2G (δ = 1e-6). The kinematic arrays are
  !> those of the strain increment from rest (material_kinematics), the density the current one
  !> at mid-increment (ρ0 exp(−tr ε_mid)); the VUMAT's answers are then thrown away.
  subroutine packaging_moduli(mat, ncomp, field, dt, two_g, bulk)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: field(:), dt
    real(dp), intent(out) :: two_g, bulk
    real(dp), parameter :: delta = 1.0e-6_dp
    integer, parameter :: np = 2
    real(dp) :: strain(np, ncomp), spin(np, ncomp - 3), stretch_old(np, ncomp), stretch_new(np, ncomp)
    real(dp) :: defgrad_old(np, 2 * ncomp - 3), defgrad_new(np, 2 * ncomp - 3)
    real(dp) :: stress_old(np, ncomp), stress_new(np, ncomp), state_old(np, max(1, mat%nstatev))
    real(dp) :: state_new(np, max(1, mat%nstatev)), fields(np, max(1, mat%nfieldv))
    real(dp) :: coord(np, 3), zero(np), e_new(np), ei_new(np), density(np), char_length(np)
    real(dp) :: zero_c(ncomp), u(ncomp), f(2 * ncomp - 3), dsig(ncomp)
    integer :: k
    procedure(), pointer :: umat

    umat => vumat_entry(mat%user_code)
    zero_c = 0
    do k = 1, np
       strain(k, :) = 0
       strain(k, 1:3) = -delta
       if (k == 2) strain(k, 4) = 0.1_dp * delta
       call stretch_from_log_strain(ncomp, zero_c, u)
       call defgrad_from_stretch(ncomp, u, f)
       stretch_old(k, :) = u
       defgrad_old(k, :) = f
       call stretch_from_log_strain(ncomp, strain(k, :), u)
       call defgrad_from_stretch(ncomp, u, f)
       stretch_new(k, :) = u
       defgrad_new(k, :) = f
       density(k) = mat%density * exp(-(0.5_dp * strain(k, 1) + 0.5_dp * strain(k, 2) + 0.5_dp * strain(k, 3)))
       fields(k, :) = 0
       fields(k, 1:min(size(field), mat%nfieldv)) = field(1:min(size(field), mat%nfieldv))
    end do
    spin = 0
    stress_old = 0
    stress_new = 0
    state_old = 0
    state_new = 0
    coord = 0
    zero = 0
    e_new = 0
    ei_new = 0
    char_length = 1
    call umat([np, 1, 1, 1, 1, 1], 3, ncomp - 3, mat%nstatev, mat%nfieldv, size(mat%props), 0, 0.0_dp, &
         0.0_dp, dt, mat%vumat_name, coord, char_length, mat%props, density, strain, spin, zero, &
         stretch_old, defgrad_old, fields, stress_old, state_old, zero, zero, zero, stretch_new, &
         defgrad_new, fields, stress_new, state_new, e_new, ei_new)
    dsig = stress_new(1, :)
    bulk = (dsig(1) + dsig(2) + dsig(3)) / 3.0_dp / (-3.0_dp * delta)
    two_g = stress_new(2, 4) / (0.1_dp * delta)
  end subroutine packaging_moduli

  !> Abaqus's packaging call: a tiny uniaxial strain increment from a stress-free state at
  !> stepTime = totalTime = 0; Δσ11/Δε11 is the P-wave modulus λ + 2G that sets the wave
  !> speed for the stable increment, hourglass and bulk viscosity.
  function packaging_modulus(mat, ncomp, nshr) result(modulus)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: ncomp, nshr
    real(dp) :: modulus
    real(dp) :: s11, s22

    call packaging_probe(mat, ncomp, nshr, s11, s22)
    modulus = s11 / packaging_strain
  end function packaging_modulus

  !> The packaging call itself: the stresses σ11 and σ22 answered to the strain increment
  !> packaging_strain in direction 11 from a stress-free state at stepTime = totalTime = 0.
  subroutine packaging_probe(mat, ncomp, nshr, s11, s22)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: ncomp, nshr
    real(dp), intent(out) :: s11, s22
    real(dp), parameter :: probe = packaging_strain
    real(dp) :: strain(1, ncomp), spin(1, nshr), stretch(1, ncomp), defgrad(1, ncomp + nshr)
    real(dp) :: stretch_new(1, ncomp), defgrad_new(1, ncomp + nshr)
    real(dp) :: stress_old(1, ncomp), stress_new(1, ncomp), state_old(1, max(1, mat%nstatev))
    real(dp) :: state_new(1, max(1, mat%nstatev)), field(1, max(1, mat%nfieldv))
    real(dp) :: coord(1, 3), scalar1(1), e_old(1), e_new(1), ei_new(1), density(1)
    integer :: jblock(5)
    procedure(), pointer :: umat

    umat => vumat_entry(mat%user_code)
    strain = 0
    strain(1, 1) = probe
    spin = 0
    stretch = 0
    stretch(1, 1:3) = 1
    defgrad = 0
    defgrad(1, 1:3) = 1
    ! The end state agrees with the strain increment: a VUMAT that forms its stress from
    ! defgradNew or stretchNew (hyperelastic) sees the same probe as one that integrates strainInc.
    stretch_new = stretch
    stretch_new(1, 1) = 1 + probe
    defgrad_new = defgrad
    defgrad_new(1, 1) = 1 + probe
    stress_old = 0
    stress_new = 0
    state_old = 0
    field = 0
    coord = 0
    scalar1 = 0
    e_old = 0
    density = mat%density
    jblock = [1, 1, 1, 1, 1]
    state_new = 0
    e_new = 0
    ei_new = 0
    call umat(jblock, 3, nshr, mat%nstatev, mat%nfieldv, size(mat%props), 0, 0.0_dp, 0.0_dp, 1.0_dp, &
         mat%vumat_name, coord, [1.0_dp], mat%props, density, strain, spin, scalar1, stretch, defgrad, &
         field, stress_old, state_old, e_old, e_old, scalar1, stretch_new, defgrad_new, field, stress_new, &
         state_new, e_new, ei_new)
    s11 = stress_new(1, 1)
    s22 = stress_new(1, 2)
  end subroutine packaging_probe

  !> The isotropic moduli λ = Δσ22/Δε11 and G = (Δσ11 − Δσ22)/(2 Δε11) of a material's packaging
  !> call, found once per material and kept (vgetvrm('PE') for a VUSDFLD: PE = LE − C⁻¹:σ).
  subroutine elastic_moduli(mat, ncomp, nshr, lambda, shear)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: ncomp, nshr
    real(dp), intent(out) :: lambda, shear
    real(dp) :: s11, s22
    integer :: k

    do k = 1, known_count
       if (known_names(k) == mat%name .and. known_ncomp(k) == ncomp) then
          lambda = known_moduli(1, k)
          shear = known_moduli(2, k)
          return
       end if
    end do
    call packaging_probe(mat, ncomp, nshr, s11, s22)
    lambda = s22 / packaging_strain
    shear = (s11 - s22) / (2 * packaging_strain)
    if (.not. allocated(known_names)) allocate(known_names(8), known_ncomp(8), known_moduli(2, 8))
    if (known_count == size(known_names)) then
       known_names = [known_names, known_names]
       known_ncomp = [known_ncomp, known_ncomp]
       known_moduli = reshape([known_moduli, known_moduli], [2, 2 * known_count])
    end if
    known_count = known_count + 1
    known_names(known_count) = mat%name
    known_ncomp(known_count) = ncomp
    known_moduli(:, known_count) = [lambda, shear]
  end subroutine elastic_moduli
end module material_door
