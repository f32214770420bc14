!> Material selection by name and decoding/validation of the VUMAT `props` array.
!>
!> Owns the one table that maps a material name to a model and the `props` layout of each
!> model (documented in umat/README.md). Decoding happens on every VUMAT call because a
!> VUMAT has no other hook and must keep no saved state (Abaqus runs it multi-threaded);
!> it is a few dozen operations per block of up to 512 points.
module material_props
  use material_kinds, only: dp, deg_to_rad
  use material_state, only: n_state_plastic
  use flow_function, only: flow_function_none, flow_function_linear, flow_function_bilinear, &
       flow_function_table
  use property_table, only: table_is_ascending, field_table_is_ordered
  use drucker_prager_match, only: match_plane_strain
  use elasticity, only: lame_constants
  implicit none
  private

  integer, parameter, public :: model_unknown = 0
  integer, parameter, public :: model_elastic = 1
  integer, parameter, public :: model_mohr_coulomb = 2
  integer, parameter, public :: model_drucker_prager = 3

  !> Number of leading scalar props of the Mohr-Coulomb layout (tables follow).
  integer, parameter, public :: mc_n_scalar_props = 16
  integer, parameter, public :: dp_n_props = 6
  !> Option block appended after the Mohr-Coulomb tables: its kind (1 = μ(I)) and constants.
  integer, parameter, public :: mc_option_mu_of_i = 1
  integer, parameter, public :: mc_mu_of_i_n_props = 5   !< kind, φ2 (deg), I0, d, ρs

  integer, parameter, public :: message_length = 200

  !> Decoded Mohr-Coulomb constants; tables stay in `props` and are addressed by offsets.
  type, public :: mohr_coulomb_props_t
     real(dp) :: lam = 0, shear = 0
     real(dp) :: phi = 0, psi = 0          !< radians, used when there is no angle table
     real(dp) :: cohesion = 0
     logical :: tension_cutoff = .false.
     real(dp) :: sigma_t = 0
     integer :: flow_kind = flow_function_none
     real(dp) :: fc0 = 0, slope = 0
     real(dp) :: t_freeze = 0
     logical :: record_maximum = .false.
     integer :: n_ang = 0, ang_field = 0, n_coh = 0, n_ff = 0
     !> Cohesion table rows (c, PEEQ, field) instead of (c, PEEQ): prop 15 < 0.
     logical :: coh_on_field = .false.
     integer :: ang_start = 0, coh_start = 0, ff_start = 0   !< index of the first table value
     !> Rate-dependent friction μ(I) (inertial_friction, docs/mu_of_i.md): sin φ2 = μ2, I0 and
     !> d·sqrt(ρs); off unless the option block is there.
     logical :: mu_of_i = .false.
     real(dp) :: sin_phi2 = 0, i0 = 0, d_sqrt_rho = 0
  end type mohr_coulomb_props_t

  !> Decoded Drucker-Prager constants in Abaqus q-form.
  type, public :: drucker_prager_props_t
     real(dp) :: lam = 0, shear = 0, bulk = 0
     real(dp) :: tan_beta = 0, tan_psi = 0, d = 0
  end type drucker_prager_props_t

  public :: model_from_name, model_names_help
  public :: decode_elastic, decode_mohr_coulomb, decode_drucker_prager

contains

  !> Model selected by the leading token of an (upper-case) material name.
  pure function model_from_name(name) result(model)
    character(len=*), intent(in) :: name
    integer :: model
    character(len=len(name)) :: token
    integer :: i, n

    n = len_trim(name)
    do i = 1, n
       if (index('-_. ', name(i:i)) > 0) exit
    end do
    token = upper(adjustl(name(1:i - 1)))
    select case (trim(token))
    case ('ELASTIC')
       model = model_elastic
    case ('MC', 'MOHRCOULOMB')
       model = model_mohr_coulomb
    case ('DP', 'DRUCKERPRAGER')
       model = model_drucker_prager
    case default
       model = model_unknown
    end select
  end function model_from_name

  pure function model_names_help() result(text)
    character(len=:), allocatable :: text
    text = 'known material name prefixes: ELASTIC, MC or MOHRCOULOMB, DP or DRUCKERPRAGER ' // &
         '(e.g. MC-SAND)'
  end function model_names_help

  pure subroutine decode_elastic(props, nprops, lam, shear, ok, message)
    integer, intent(in) :: nprops
    real(dp), intent(in) :: props(nprops)
    real(dp), intent(out) :: lam, shear
    logical, intent(out) :: ok
    character(len=message_length), intent(out) :: message

    lam = 0; shear = 0
    call check_elastic(props, nprops, ok, message)
    if (.not. ok) return
    ! A count that does not fit the layout is an error: extra constants would be ignored silently.
    if (nprops /= 2) then
       ok = .false.
       write (message, '(a,i0)') 'elasticity takes exactly 2 props (E, nu), got ', nprops
       return
    end if
    call lame_constants(props(1), props(2), lam, shear)
  end subroutine decode_elastic

  pure subroutine decode_mohr_coulomb(props, nprops, nstatev, nfieldv, mc, ok, message)
    integer, intent(in) :: nprops, nstatev, nfieldv
    real(dp), intent(in) :: props(nprops)
    type(mohr_coulomb_props_t), intent(out) :: mc
    logical, intent(out) :: ok
    character(len=message_length), intent(out) :: message
    integer :: needed, extra

    call check_elastic(props, nprops, ok, message)
    if (.not. ok) return
    ok = .false.
    if (nprops < mc_n_scalar_props) then
       write (message, '(a,i0,a,i0)') 'Mohr-Coulomb needs at least ', mc_n_scalar_props, &
            ' props (see umat/README.md), got ', nprops
       return
    end if
    if (nstatev < n_state_plastic) then
       write (message, '(a,i0,a,i0)') 'Mohr-Coulomb needs *DEPVAR >= ', n_state_plastic, ', got ', nstatev
       return
    end if
    call lame_constants(props(1), props(2), mc%lam, mc%shear)
    mc%phi = props(3) * deg_to_rad
    mc%psi = props(4) * deg_to_rad
    mc%cohesion = props(5)
    mc%tension_cutoff = nint(props(6)) == 1
    mc%sigma_t = props(7)
    mc%flow_kind = nint(props(8))
    mc%fc0 = props(9)
    mc%slope = props(10)
    mc%t_freeze = props(11)
    mc%record_maximum = nint(props(12)) == 1
    mc%n_ang = nint(props(13))
    mc%ang_field = nint(props(14))
    mc%n_coh = nint(props(15))
    mc%n_ff = nint(props(16))
    ! A negative cohesion row count selects rows (c, PEEQ, field) on the field of prop 14 (Abaqus
    ! *MOHR COULOMB HARDENING, DEPENDENCIES=1); a positive one rows (c, PEEQ).
    mc%coh_on_field = mc%n_coh < 0
    mc%n_coh = abs(mc%n_coh)

    if (mc%n_ang < 0 .or. mc%n_ff < 0) then
       message = 'Mohr-Coulomb table row counts (props 13, 16) must not be negative'
       return
    end if
    mc%ang_start = mc_n_scalar_props + 1
    mc%coh_start = mc%ang_start + 3 * mc%n_ang
    mc%ff_start = mc%coh_start + merge(3, 2, mc%coh_on_field) * mc%n_coh
    needed = mc%ff_start + 2 * mc%n_ff - 1
    ! Exactly the tables, or the tables and one option block: any other count is an error.
    extra = nprops - needed
    if (extra /= 0 .and. extra /= mc_mu_of_i_n_props) then
       write (message, '(a,i0,a,i0,a,i0)') 'Mohr-Coulomb with these table sizes (props 13, 15, 16) takes ' // &
            'exactly ', needed, ' props, or ', needed + mc_mu_of_i_n_props, ' with the mu(I) block, got ', nprops
       return
    end if

    if (mc%n_ang > 0 .or. mc%coh_on_field) then
       if (mc%ang_field < 1 .or. mc%ang_field > nfieldv) then
          write (message, '(a,i0,a,i0,a)') 'angle or cohesion table uses field variable ', mc%ang_field, &
               ' but the material has ', nfieldv, ' field variables (needs *USER DEFINED FIELD)'
          return
       end if
    end if
    if (mc%n_ang == 0) then
       call check_angles(props(3), props(4), ok, message)
       if (.not. ok) return
       ok = .false.
    else
       call check_angle_table(props(mc%ang_start:mc%coh_start - 1), mc%n_ang, ok, message)
       if (.not. ok) return
       ok = .false.
    end if

    if (props(5) < 0) then
       message = 'cohesion (prop 5) must not be negative'
       return
    end if
    if (mc%n_coh > 0 .and. mc%coh_on_field) then
       if (.not. field_table_is_ordered(props(mc%coh_start + 1:mc%ff_start - 1:3), &
            props(mc%coh_start + 2:mc%ff_start - 1:3))) then
          message = 'cohesion table on a field: field values must be ascending block by block and ' // &
               'PEEQ ascending within each block of equal field value'
          return
       end if
       if (minval(props(mc%coh_start:mc%ff_start - 1:3)) < 0) then
          message = 'cohesion table: cohesion must not be negative'
          return
       end if
    else if (mc%n_coh > 0) then
       if (.not. table_is_ascending(props(mc%coh_start + 1:mc%ff_start - 1:2))) then
          message = 'cohesion table: PEEQ values must be ascending'
          return
       end if
       if (minval(props(mc%coh_start:mc%ff_start - 2:2)) < 0) then
          message = 'cohesion table: cohesion must not be negative'
          return
       end if
    end if

    select case (mc%flow_kind)
    case (flow_function_none)
    case (flow_function_linear, flow_function_bilinear)
       if (mc%fc0 < 0 .or. mc%slope < 0) then
          message = 'flow function: fc0 (prop 9) and k (prop 10) must not be negative'
          return
       end if
       if (mc%flow_kind == flow_function_bilinear .and. mc%slope >= 1) then
          message = 'bilinear flow function needs k < 1 (it joins the linear one where fc = sigma1)'
          return
       end if
    case (flow_function_table)
       if (mc%n_ff < 1) then
          message = 'tabulated flow function (prop 8 = 3) needs n_ff >= 1 rows (prop 16)'
          return
       end if
       if (.not. table_is_ascending(props(mc%ff_start:needed:2))) then
          message = 'flow function table: sigma1 values must be ascending'
          return
       end if
       if (minval(props(mc%ff_start + 1:needed:2)) < 0) then
          message = 'flow function table: fc must not be negative'
          return
       end if
    case default
       write (message, '(a,i0,a)') 'flow function type (prop 8) must be 0, 1, 2 or 3, got ', mc%flow_kind, ''
       return
    end select

    if (mc%tension_cutoff) then
       if (mc%sigma_t < 0) then
          message = 'tension cut-off stress (prop 7) must not be negative'
          return
       end if
    end if
    if (extra > 0) then
       call decode_mu_of_i(props(needed + 1:nprops), props(3), props(mc%ang_start:mc%coh_start - 1), &
            needed + 1, mc, ok, message)
       if (.not. ok) return
    end if
    ok = .true.
    message = ''
  end subroutine decode_mohr_coulomb

  !> The μ(I) block (kind, φ2, I0, d, ρs) at props(first...). φ2 must not be below the static
  !> angle (prop 3, or every φ of the angle table): μ(I) may only raise the friction with rate.
  pure subroutine decode_mu_of_i(block, phi_deg, angle_rows, first, mc, ok, message)
    real(dp), intent(in) :: block(mc_mu_of_i_n_props), phi_deg, angle_rows(:)
    integer, intent(in) :: first
    type(mohr_coulomb_props_t), intent(inout) :: mc
    logical, intent(out) :: ok
    character(len=message_length), intent(out) :: message
    real(dp) :: phi_static_max

    ok = .false.
    message = ''
    ! Exactly the kind (NaN fails too).
    if (.not. (block(1) >= mc_option_mu_of_i .and. block(1) <= mc_option_mu_of_i)) then
       write (message, '(a,i0,a,g0.6)') 'option block after the tables: prop ', first, &
            ' must be 1 (mu(I)), got ', block(1)
       return
    end if
    phi_static_max = phi_deg
    if (mc%n_ang > 0) phi_static_max = maxval(angle_rows(1::3))
    if (.not. (block(2) >= phi_static_max .and. block(2) <= 89.0_dp)) then
       write (message, '(a,i0,a)') 'mu(I): phi2 (prop ', first + 1, &
            ') must lie between the static friction angle (largest of the table) and 89 degrees'
       return
    end if
    if (.not. (block(3) > 0 .and. block(4) > 0 .and. block(5) > 0)) then
       write (message, '(a,i0,a,i0,a)') 'mu(I): I0, d and rho_s (props ', first + 2, '-', first + 4, &
            ') must be positive'
       return
    end if
    mc%mu_of_i = .true.
    mc%sin_phi2 = sin(block(2) * deg_to_rad)
    mc%i0 = block(3)
    mc%d_sqrt_rho = block(4) * sqrt(block(5))
    ok = .true.
  end subroutine decode_mu_of_i

  pure subroutine decode_drucker_prager(props, nprops, nstatev, dpp, ok, message)
    integer, intent(in) :: nprops, nstatev
    real(dp), intent(in) :: props(nprops)
    type(drucker_prager_props_t), intent(out) :: dpp
    logical, intent(out) :: ok
    character(len=message_length), intent(out) :: message
    integer :: mode

    call check_elastic(props, nprops, ok, message)
    if (.not. ok) return
    ok = .false.
    if (nprops /= dp_n_props) then
       write (message, '(a,i0,a,i0)') 'Drucker-Prager takes exactly ', dp_n_props, ' props, got ', nprops
       return
    end if
    if (nstatev < n_state_plastic) then
       write (message, '(a,i0,a,i0)') 'Drucker-Prager needs *DEPVAR >= ', n_state_plastic, ', got ', nstatev
       return
    end if
    call lame_constants(props(1), props(2), dpp%lam, dpp%shear)
    dpp%bulk = dpp%lam + 2 * dpp%shear / 3
    mode = nint(props(6))
    select case (mode)
    case (0)
       if (props(3) < 0 .or. props(3) >= 89.0_dp .or. props(4) < 0 .or. props(4) > props(3)) then
          message = 'Drucker-Prager: need 0 <= psi <= beta < 89 degrees (props 3-4)'
          return
       end if
       dpp%tan_beta = tan(props(3) * deg_to_rad)
       dpp%tan_psi = tan(props(4) * deg_to_rad)
       dpp%d = props(5)
    case (1)
       call check_angles(props(3), props(4), ok, message)
       if (.not. ok) return
       ok = .false.
       call match_plane_strain(props(3) * deg_to_rad, props(4) * deg_to_rad, props(5), &
            dpp%tan_beta, dpp%tan_psi, dpp%d)
    case default
       write (message, '(a,i0)') 'Drucker-Prager mode (prop 6) must be 0 or 1, got ', mode
       return
    end select
    if (dpp%d < 0) then
       message = 'Drucker-Prager: cohesion d (or c) must not be negative'
       return
    end if
    ok = .true.
    message = ''
  end subroutine decode_drucker_prager

  pure subroutine check_elastic(props, nprops, ok, message)
    integer, intent(in) :: nprops
    real(dp), intent(in) :: props(nprops)
    logical, intent(out) :: ok
    character(len=message_length), intent(out) :: message

    ok = .false.
    message = ''
    if (nprops < 2) then
       write (message, '(a,i0)') 'need at least 2 props (E, nu), got ', nprops
    else if (.not. (props(1) > 0)) then
       message = 'Young''s modulus (prop 1) must be positive'
    else if (.not. (props(2) > -1 .and. props(2) < 0.5_dp)) then
       message = 'Poisson''s ratio (prop 2) must lie in (-1, 0.5)'
    else
       ok = .true.
    end if
  end subroutine check_elastic

  !> Friction angle range: below 0.5 degrees the apex c*cot(phi) runs away (Tresca limit),
  !> at 90 degrees the cone degenerates.
  pure subroutine check_angles(phi_deg, psi_deg, ok, message)
    real(dp), intent(in) :: phi_deg, psi_deg
    logical, intent(out) :: ok
    character(len=message_length), intent(inout) :: message

    ok = phi_deg >= 0.5_dp .and. phi_deg <= 89.0_dp .and. psi_deg >= 0 .and. psi_deg <= phi_deg
    if (.not. ok) message = 'need 0.5 <= phi <= 89 degrees and 0 <= psi <= phi'
  end subroutine check_angles

  pure subroutine check_angle_table(rows, n, ok, message)
    integer, intent(in) :: n
    real(dp), intent(in) :: rows(3 * n)
    logical, intent(out) :: ok
    character(len=message_length), intent(inout) :: message
    integer :: i

    do i = 1, n
       call check_angles(rows(3 * i - 2), rows(3 * i - 1), ok, message)
       if (.not. ok) then
          write (message, '(a,i0,a)') 'angle table row ', i, ': need 0.5 <= phi <= 89 and 0 <= psi <= phi'
          return
       end if
    end do
    ok = table_is_ascending(rows(3:3 * n:3))
    if (.not. ok) message = 'angle table: field values must be ascending'
  end subroutine check_angle_table

  pure function upper(text) result(up)
    character(len=*), intent(in) :: text
    character(len=len(text)) :: up
    integer :: i, code

    up = text
    do i = 1, len(text)
       code = iachar(text(i:i))
       if (code >= iachar('a') .and. code <= iachar('z')) up(i:i) = achar(code - 32)
    end do
  end function upper
end module material_props
