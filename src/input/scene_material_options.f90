!> The options of one *MATERIAL (*DENSITY, *ELASTIC, *MOHR COULOMB, ..., our *FLOW FUNCTION)
!> read into a `material_input_t` with every value checked at its own data line.
!> scene_materials then translates the whole record into our VUMAT names and props.
!>
!> Abaqus data layouts are kept (so a material block can be copied from an Abaqus input);
!> what our VUMATs cannot represent (temperature dependence, hardening of Drucker-Prager,
!> K /= 1, ...) is an error naming what was expected instead of being silently dropped.
module scene_material_options
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t
  use model_sets, only: name_length
  use scene_util, only: itoa, rtoa, get_real, get_int, get_real_param, expect_fields, &
       expect_lines, field_blank, where_text, keyword_text
  implicit none
  private

  public :: material_input_t, read_material_option

  integer, parameter, public :: opt_density = 1, opt_elastic = 2, opt_mohr_coulomb = 3, &
       opt_mc_hardening = 4, opt_tension_cutoff = 5, opt_drucker_prager = 6, &
       opt_dp_hardening = 7, opt_user_material = 8, opt_depvar = 9, opt_user_field = 10, &
       opt_flow_function = 11, opt_inertial_friction = 12
  integer, parameter, public :: n_material_options = 12

  integer, parameter, public :: dp_hardening_compression = 1, dp_hardening_shear = 2, &
       dp_hardening_tension = 3

  !> Everything the options of one material said, before translation.
  type :: material_input_t
     character(len=name_length) :: name = ''
     integer :: block = 0                         !< the *MATERIAL block
     integer :: option_block(n_material_options) = 0   !< block of each option, 0: absent
     real(dp) :: density = 0
     real(dp) :: young = 0, poisson = 0
     real(dp) :: phi = 0, psi = 0                 !< *MOHR COULOMB without DEPENDENCIES
     real(dp), allocatable :: angle_table(:, :)   !< (3, n): phi, psi, field 1 (DEPENDENCIES=1)
     !> (2, n): c, plastic strain; (3, n) with DEPENDENCIES=1: c, plastic strain, field 1
     real(dp), allocatable :: cohesion(:, :)
     real(dp) :: sigma_t = 0
     real(dp) :: beta = 0, k_ratio = 1, psi_dp = 0
     integer :: dp_hardening_type = dp_hardening_compression
     real(dp) :: dp_yield = 0
     real(dp), allocatable :: user_props(:)
     integer :: depvar = 0
     !> Output names from *DEPVAR lines "SDV number, name[, description]" ('' where none given)
     character(len=name_length), allocatable :: sdv_names(:)
     integer :: user_fields = 1                   !< *USER DEFINED FIELD, FIELDS=n (VUSDFLD's nfieldv)
     real(dp), allocatable :: field_props(:)      !< *USER DEFINED FIELD, PROPERTIES=n constants
     integer :: flow_kind = 0                     !< umat flow_function kinds: 1 linear, 2 bilinear, 3 table
     real(dp) :: fc0 = 0, slope = 0, t_freeze = 0
     logical :: record_maximum = .false.
     real(dp), allocatable :: flow_table(:, :)    !< (2, n): sigma1, fc
     !> our *INERTIAL FRICTION: phi2 (deg), I0, d, rho_s of the mu(I) block (docs/mu_of_i.md)
     real(dp) :: inertial(4) = 0
  end type material_input_t

contains

  !> Read the option block `ib` of the deck into `mat`.
  subroutine read_material_option(deck, ib, mat, err)
    type(keyword_deck_t), intent(in) :: deck
    integer, intent(in) :: ib
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    integer :: opt

    associate (blk => deck%blocks(ib))

    select case (blk%name)
    case ('DENSITY'); opt = opt_density
    case ('ELASTIC'); opt = opt_elastic
    case ('MOHR COULOMB'); opt = opt_mohr_coulomb
    case ('MOHR COULOMB HARDENING'); opt = opt_mc_hardening
    case ('TENSION CUTOFF'); opt = opt_tension_cutoff
    case ('DRUCKER PRAGER'); opt = opt_drucker_prager
    case ('DRUCKER PRAGER HARDENING'); opt = opt_dp_hardening
    case ('USER MATERIAL'); opt = opt_user_material
    case ('DEPVAR'); opt = opt_depvar
    case ('USER DEFINED FIELD'); opt = opt_user_field
    case ('INERTIAL FRICTION'); opt = opt_inertial_friction
    case default; opt = opt_flow_function
    end select
    if (mat%option_block(opt) /= 0) then
       call blk%fail('second ' // keyword_text(blk) // ' in material ' // trim(mat%name) // &
            ' (first at ' // where_text(deck%blocks(mat%option_block(opt))%file, &
            deck%blocks(mat%option_block(opt))%line) // &
            '); expected each option once per material', err)
       return
    end if
    mat%option_block(opt) = ib
    select case (opt)
    case (opt_density)
       call read_density(blk, mat, err)
    case (opt_elastic)
       call read_elastic(blk, mat, err)
    case (opt_mohr_coulomb)
       call read_mohr_coulomb(blk, mat, err)
    case (opt_mc_hardening)
       call read_mc_hardening(blk, mat, err)
    case (opt_tension_cutoff)
       call read_tension_cutoff(blk, mat, err)
    case (opt_drucker_prager)
       call read_drucker_prager(blk, mat, err)
    case (opt_dp_hardening)
       call read_dp_hardening(blk, mat, err)
    case (opt_user_material)
       call read_user_material(blk, mat, err)
    case (opt_depvar)
       call read_depvar(blk, mat, err)
    case (opt_inertial_friction)
       call read_inertial_friction(blk, mat, err)
    case (opt_user_field)
       ! FIELDS=n as bulkflow-matpoint takes it: the nfieldv a VUSDFLD writes (a user's VUSDFLD
       ! may write more than field 1; the host's arrays must have that many columns).
       call read_user_field(blk, mat, err)
    case default
       call read_flow_function(blk, mat, err)
    end select
    end associate
  end subroutine read_material_option

  !> The single data line of a one-line option, with its field count checked.
  subroutine one_line(blk, nmin, nmax, expected, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: nmin, nmax
    character(len=*), intent(in) :: expected
    type(error_t), intent(inout) :: err

    call expect_lines(blk, 1, 1, 'one data line: ' // expected, err)
    if (err%raised) return
    call expect_fields(blk, blk%lines(1), nmin, nmax, expected, err)
  end subroutine one_line

  subroutine read_density(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err

    call blk%check_params([character(len=8) ::], err)
    if (err%raised) return
    call one_line(blk, 1, 1, 'the mass density', err)
    if (err%raised) return
    call get_real(blk%lines(1), 1, mat%density, err)
    if (err%raised) return
    if (.not. (mat%density > 0)) call raise_error(blk%lines(1)%file, blk%lines(1)%line, &
         'density must be positive; got ' // rtoa(mat%density), err)
  end subroutine read_density

  subroutine read_elastic(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: etype

    call blk%check_params([character(len=8) :: 'TYPE'], err)
    if (err%raised) return
    call blk%get_string('TYPE', etype, err, default='ISOTROPIC', choices=[character(len=9) :: 'ISOTROPIC'])
    if (err%raised) return
    call one_line(blk, 2, 2, 'E, nu', err)
    if (err%raised) return
    associate (dl => blk%lines(1))
      call get_real(dl, 1, mat%young, err)
      if (.not. err%raised) call get_real(dl, 2, mat%poisson, err)
      if (err%raised) return
      if (.not. (mat%young > 0)) then
         call raise_error(dl%file, dl%line, 'Young''s modulus must be positive; got ' // &
              rtoa(mat%young), err)
      else if (.not. (mat%poisson > -1 .and. mat%poisson < 0.5_dp)) then
         call raise_error(dl%file, dl%line, 'Poisson''s ratio ' // rtoa(mat%poisson) // &
              ' is out of range; expected -1 < nu < 0.5', err)
      end if
    end associate
  end subroutine read_elastic

  !> phi, psi of one row: 0.5 <= phi <= 89 degrees (our Mohr-Coulomb kernel's range),
  !> 0 <= psi <= phi.
  subroutine check_angles(dl, phi, psi, err)
    type(data_line_t), intent(in) :: dl
    real(dp), intent(in) :: phi, psi
    type(error_t), intent(inout) :: err

    if (.not. (phi >= 0.5_dp .and. phi <= 89)) then
       call raise_error(dl%file, dl%line, 'friction angle ' // rtoa(phi) // &
            ' is out of range; expected 0.5 <= phi <= 89 degrees', err)
    else if (psi > phi) then
       call raise_error(dl%file, dl%line, 'dilation angle ' // rtoa(psi) // &
            ' exceeds the friction angle ' // rtoa(phi) // '; expected 0 <= psi <= phi', err)
    else if (psi < 0) then
       call raise_error(dl%file, dl%line, 'dilation angle ' // rtoa(psi) // &
            ' is negative; expected 0 <= psi <= phi', err)
    end if
  end subroutine check_angles

  subroutine read_mohr_coulomb(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    integer :: ndep, il
    real(dp) :: temperature

    call blk%check_params([character(len=12) :: 'DEPENDENCIES'], err)
    if (err%raised) return
    call blk%get_integer('DEPENDENCIES', ndep, err, default=0, minimum=0)
    if (err%raised) return
    if (ndep == 0) then
       call one_line(blk, 2, 2, 'phi, psi (degrees); use DEPENDENCIES=1 for a table', err)
       if (err%raised) return
       call get_real(blk%lines(1), 1, mat%phi, err)
       if (.not. err%raised) call get_real(blk%lines(1), 2, mat%psi, err)
       if (.not. err%raised) call check_angles(blk%lines(1), mat%phi, mat%psi, err)
       return
    end if
    if (ndep /= 1) then
       call blk%fail('*MOHR COULOMB: DEPENDENCIES=' // itoa(ndep) // ' is not supported; ' // &
            'expected DEPENDENCIES=1 (field 1 = volumetric strain from our VUSDFLD)', err)
       return
    end if
    call expect_lines(blk, 1, huge(1), 'rows phi, psi, temperature (ignored), field 1', err)
    if (err%raised) return
    allocate (mat%angle_table(3, blk%n_lines))
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         call expect_fields(blk, dl, 4, 4, 'phi, psi, temperature (ignored, may be blank), field 1', err)
         if (err%raised) return
         call get_real(dl, 1, mat%angle_table(1, il), err)
         if (.not. err%raised) call get_real(dl, 2, mat%angle_table(2, il), err)
         if (.not. err%raised) call get_real(dl, 3, temperature, err, default=0.0_dp)
         if (.not. err%raised) call get_real(dl, 4, mat%angle_table(3, il), err)
         if (.not. err%raised) call check_angles(dl, mat%angle_table(1, il), mat%angle_table(2, il), err)
         if (err%raised) return
         if (il > 1) then
            if (mat%angle_table(3, il) < mat%angle_table(3, il - 1)) then
               call raise_error(dl%file, dl%line, 'field value ' // rtoa(mat%angle_table(3, il)) // &
                    ' is below the previous row''s; expected field 1 ascending', err)
               return
            end if
         end if
       end associate
    end do
    mat%phi = mat%angle_table(1, 1)
    mat%psi = mat%angle_table(2, 1)
  end subroutine read_mohr_coulomb

  !> *MOHR COULOMB HARDENING [, DEPENDENCIES=1]: rows c, plastic strain [, temperature (ignored,
  !> may be blank), field 1]. With the field, rows come in blocks of equal field value (ascending),
  !> the plastic strain ascending from 0 inside each block (Abaqus's data order).
  subroutine read_mc_hardening(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: expected
    integer :: il, ndep, ncol
    real(dp) :: temperature
    logical :: new_block

    call blk%check_params([character(len=12) :: 'DEPENDENCIES'], err)
    if (err%raised) return
    call blk%get_integer('DEPENDENCIES', ndep, err, default=0, minimum=0)
    if (err%raised) return
    if (ndep > 1) then
       call blk%fail('*MOHR COULOMB HARDENING: DEPENDENCIES=' // itoa(ndep) // ' is not supported; ' // &
            'expected DEPENDENCIES=1 (cohesion against plastic strain and field 1)', err)
       return
    end if
    ncol = 2 + ndep
    expected = 'cohesion, plastic strain (no temperature dependence)'
    if (ndep == 1) expected = 'cohesion, plastic strain, temperature (ignored, may be blank), field 1'
    call expect_lines(blk, 1, huge(1), 'rows ' // expected, err)
    if (err%raised) return
    allocate (mat%cohesion(ncol, blk%n_lines))
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         call expect_fields(blk, dl, 1 + 3 * ndep, 2 + 2 * ndep, expected, err)
         if (err%raised) return
         call get_real(dl, 1, mat%cohesion(1, il), err)
         if (.not. err%raised) call get_real(dl, 2, mat%cohesion(2, il), err, default=0.0_dp)
         if (ndep == 1) then
            if (.not. err%raised) call get_real(dl, 3, temperature, err, default=0.0_dp)
            if (.not. err%raised) call get_real(dl, 4, mat%cohesion(3, il), err)
         end if
         if (err%raised) return
         if (mat%cohesion(1, il) < 0) then
            call raise_error(dl%file, dl%line, 'cohesion ' // rtoa(mat%cohesion(1, il)) // &
                 ' is negative; expected c >= 0', err)
            return
         end if
         new_block = il == 1
         if (ndep == 1 .and. il > 1) then
            if (mat%cohesion(3, il) < mat%cohesion(3, il - 1)) then
               call raise_error(dl%file, dl%line, 'field value ' // rtoa(mat%cohesion(3, il)) // &
                    ' is below the previous row''s; expected field 1 ascending (rows of one field ' // &
                    'value together, plastic strain varying fastest)', err)
               return
            end if
            new_block = mat%cohesion(3, il) > mat%cohesion(3, il - 1)
         end if
         if (new_block .and. abs(mat%cohesion(2, il)) > 0) then
            call raise_error(dl%file, dl%line, 'first plastic strain' // &
                 trim(merge(' of this field value', '                    ', ndep == 1)) // ' is ' // &
                 rtoa(mat%cohesion(2, il)) // '; expected the first row at plastic strain 0', err)
            return
         end if
         if (.not. new_block) then
            if (.not. (mat%cohesion(2, il) > mat%cohesion(2, il - 1))) then
               call raise_error(dl%file, dl%line, 'plastic strain ' // rtoa(mat%cohesion(2, il)) // &
                    ' does not increase; expected plastic strain strictly ascending', err)
               return
            end if
         end if
       end associate
    end do
  end subroutine read_mc_hardening

  !> Our *INERTIAL FRICTION: one line phi2 (deg), I0, d, rho_s, the mu(I) block of the MC VUMAT
  !> (umat/README.md); the VUMAT's decoder checks the values against the static angles.
  subroutine read_inertial_friction(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    integer :: i

    call blk%check_params([character(len=8) ::], err)
    if (err%raised) return
    call one_line(blk, 4, 4, 'phi2 (deg), I0, d, rho_s', err)
    if (err%raised) return
    do i = 1, 4
       call get_real(blk%lines(1), i, mat%inertial(i), err)
       if (err%raised) return
    end do
  end subroutine read_inertial_friction

  subroutine read_tension_cutoff(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    real(dp) :: strain

    call blk%check_params([character(len=8) ::], err)
    if (err%raised) return
    call one_line(blk, 1, 2, 'tension cut-off stress[, 0] (constant: no softening table)', err)
    if (err%raised) return
    associate (dl => blk%lines(1))
      call get_real(dl, 1, mat%sigma_t, err)
      if (.not. err%raised) call get_real(dl, 2, strain, err, default=0.0_dp)
      if (err%raised) return
      if (mat%sigma_t < 0) then
         call raise_error(dl%file, dl%line, 'tension cut-off stress ' // rtoa(mat%sigma_t) // &
              ' is negative; expected sigma_t >= 0', err)
      else if (abs(strain) > 0) then
         call raise_error(dl%file, dl%line, 'plastic strain ' // rtoa(strain) // &
              ' given; expected 0 (bulkflow''s cut-off stress is constant)', err)
      end if
    end associate
  end subroutine read_tension_cutoff

  subroutine read_drucker_prager(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: crit

    call blk%check_params([character(len=16) :: 'SHEAR CRITERION'], err)
    if (err%raised) return
    call blk%get_string('SHEAR CRITERION', crit, err, default='LINEAR', &
         choices=[character(len=6) :: 'LINEAR'])
    if (err%raised) return
    call one_line(blk, 1, 3, 'beta, K, psi (degrees, K = 1)', err)
    if (err%raised) return
    associate (dl => blk%lines(1))
      call get_real(dl, 1, mat%beta, err)
      if (.not. err%raised) call get_real(dl, 2, mat%k_ratio, err, default=1.0_dp)
      if (.not. err%raised) call get_real(dl, 3, mat%psi_dp, err, default=0.0_dp)
      if (err%raised) return
      if (abs(mat%k_ratio - 1) > 1.0e-9_dp) then
         call raise_error(dl%file, dl%line, 'flow stress ratio K = ' // rtoa(mat%k_ratio) // &
              ' is not supported; expected K = 1', err)
      else if (.not. (mat%beta >= 0 .and. mat%beta < 89)) then
         call raise_error(dl%file, dl%line, 'friction angle beta = ' // rtoa(mat%beta) // &
              ' is out of range; expected 0 <= beta < 89 degrees', err)
      else if (.not. (mat%psi_dp >= 0 .and. mat%psi_dp <= mat%beta)) then
         call raise_error(dl%file, dl%line, 'dilation angle psi = ' // rtoa(mat%psi_dp) // &
              ' is out of range; expected 0 <= psi <= beta', err)
      end if
    end associate
  end subroutine read_drucker_prager

  subroutine read_dp_hardening(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: htype
    real(dp) :: strain

    call blk%check_params([character(len=8) :: 'TYPE'], err)
    if (err%raised) return
    call blk%get_string('TYPE', htype, err, default='COMPRESSION', &
         choices=[character(len=11) :: 'COMPRESSION', 'SHEAR', 'TENSION'])
    if (err%raised) return
    select case (htype)
    case ('SHEAR'); mat%dp_hardening_type = dp_hardening_shear
    case ('TENSION'); mat%dp_hardening_type = dp_hardening_tension
    case default; mat%dp_hardening_type = dp_hardening_compression
    end select
    call one_line(blk, 1, 2, 'yield stress[, 0] (bulkflow''s Drucker-Prager is perfectly plastic)', err)
    if (err%raised) return
    associate (dl => blk%lines(1))
      call get_real(dl, 1, mat%dp_yield, err)
      if (.not. err%raised) call get_real(dl, 2, strain, err, default=0.0_dp)
      if (err%raised) return
      if (mat%dp_yield < 0) then
         call raise_error(dl%file, dl%line, 'yield stress ' // rtoa(mat%dp_yield) // &
              ' is negative; expected >= 0', err)
      else if (abs(strain) > 0) then
         call raise_error(dl%file, dl%line, 'plastic strain ' // rtoa(strain) // &
              ' given; expected 0 (no hardening)', err)
      end if
    end associate
  end subroutine read_dp_hardening

  subroutine read_user_material(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: utype
    integer :: n

    call blk%check_params([character(len=9) :: 'CONSTANTS', 'TYPE'], err)
    if (err%raised) return
    call blk%get_string('TYPE', utype, err, default='MECHANICAL', choices=[character(len=10) :: 'MECHANICAL'])
    if (err%raised) return
    call blk%get_integer('CONSTANTS', n, err, minimum=0, maximum=100000)
    if (err%raised) return
    call read_constants(blk, n, 'CONSTANTS', mat%user_props, err)
  end subroutine read_user_material

  !> Exactly n real constants, any number per data line (*USER MATERIAL, *USER DEFINED FIELD).
  subroutine read_constants(blk, n, count_name, values, err)
    type(keyword_block_t), intent(in) :: blk
    integer, intent(in) :: n
    character(len=*), intent(in) :: count_name
    real(dp), allocatable, intent(out) :: values(:)
    type(error_t), intent(inout) :: err
    integer :: il, k, m

    allocate (values(n))
    m = 0
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         do k = 1, dl%n_fields()
            if (field_blank(dl, k) .and. k == dl%n_fields()) exit
            if (m >= n) then
               call raise_error(dl%file, dl%line, 'data beyond what ' // keyword_text(blk) // ' takes: more than ' // &
                    count_name // '=' // itoa(n) // ' values; expected ' // itoa(n) // ' constants', err)
               return
            end if
            m = m + 1
            call get_real(dl, k, values(m), err)
            if (err%raised) return
         end do
       end associate
    end do
    if (m < n) call blk%fail(keyword_text(blk) // ': ' // itoa(m) // ' constants given; expected ' // &
         count_name // '=' // itoa(n), err)
  end subroutine read_constants

  !> *USER DEFINED FIELD [, FIELDS=n] [, PROPERTIES=m]: FIELDS as bulkflow-matpoint takes it, the
  !> nfieldv a VUSDFLD writes (a user's VUSDFLD may write more than field 1); PROPERTIES, as in
  !> Abaqus/Explicit, the constants handed to VUSDFLD as props (m values on the data lines).
  subroutine read_user_field(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    integer :: n

    call blk%check_params([character(len=10) :: 'FIELDS', 'PROPERTIES'], err)
    if (err%raised) return
    call blk%get_integer('FIELDS', mat%user_fields, err, default=1, minimum=1, maximum=64)
    if (err%raised) return
    call blk%get_integer('PROPERTIES', n, err, default=0, minimum=0, maximum=100000)
    if (err%raised) return
    if (n == 0) then
       call expect_lines(blk, 0, 0, 'no data lines without PROPERTIES= (the fields are set by VUSDFLD)', err)
       return
    end if
    call read_constants(blk, n, 'PROPERTIES', mat%field_props, err)
  end subroutine read_user_field

  !> *DEPVAR: "n" on the first line; Abaqus's optional further lines "SDV number, output name[,
  !> description]" name the state variables in the material-point driver's CSV.
  subroutine read_depvar(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    integer :: il, k

    call blk%check_params([character(len=8) ::], err)
    if (err%raised) return
    call expect_lines(blk, 1, huge(1), 'the number of state variables, then optional lines ' // &
         '"SDV number, name[, description]"', err)
    if (err%raised) return
    call expect_fields(blk, blk%lines(1), 1, 1, 'the number of state variables (element deletion, ' // &
         'the second field, is not supported)', err)
    if (err%raised) return
    call get_int(blk%lines(1), 1, mat%depvar, err)
    if (err%raised) return
    if (mat%depvar < 0 .or. mat%depvar > 10000) then
       call raise_error(blk%lines(1)%file, blk%lines(1)%line, &
            'number of state variables ' // itoa(mat%depvar) // ' is out of range; expected 0..10000', err)
       return
    end if
    allocate (mat%sdv_names(mat%depvar))
    mat%sdv_names = ''
    do il = 2, blk%n_lines
       associate (dl => blk%lines(il))
         call get_int(dl, 1, k, err)
         if (err%raised) return
         if (k < 1 .or. k > mat%depvar .or. dl%n_fields() < 2) then
            call raise_error(dl%file, dl%line, 'state variable ' // itoa(k) // ' named; expected ' // &
                 '"SDV number (1..' // itoa(mat%depvar) // '), name[, description]"', err)
            return
         end if
         mat%sdv_names(k) = dl%field(2)
       end associate
    end do
  end subroutine read_depvar

  !> bulkflow's *FLOW FUNCTION, TYPE=LINEAR|BILINEAR|TABLE [, FREEZE TIME=t] [, RECORD=...]
  subroutine read_flow_function(blk, mat, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_input_t), intent(inout) :: mat
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: ftype, record
    integer :: il

    call blk%check_params([character(len=11) :: 'TYPE', 'FREEZE TIME', 'RECORD'], err)
    if (err%raised) return
    call blk%get_string('TYPE', ftype, err, choices=[character(len=8) :: 'LINEAR', 'BILINEAR', 'TABLE'])
    if (err%raised) return
    call blk%get_string('RECORD', record, err, default='CURRENT', &
         choices=[character(len=7) :: 'CURRENT', 'MAXIMUM'])
    if (err%raised) return
    mat%record_maximum = record == 'MAXIMUM'
    call get_real_param(blk, 'FREEZE TIME', mat%t_freeze, err, default=0.0_dp)
    if (err%raised) return
    if (ftype == 'TABLE') then
       mat%flow_kind = 3
       call expect_lines(blk, 1, huge(1), 'rows sigma1, fc', err)
       if (err%raised) return
       allocate (mat%flow_table(2, blk%n_lines))
       do il = 1, blk%n_lines
          associate (dl => blk%lines(il))
            call expect_fields(blk, dl, 2, 2, 'sigma1, fc', err)
            if (.not. err%raised) call get_real(dl, 1, mat%flow_table(1, il), err)
            if (.not. err%raised) call get_real(dl, 2, mat%flow_table(2, il), err)
            if (err%raised) return
            if (mat%flow_table(2, il) < 0) then
               call raise_error(dl%file, dl%line, 'unconfined yield strength ' // &
                    rtoa(mat%flow_table(2, il)) // ' is negative; expected fc >= 0', err)
               return
            end if
            if (il > 1) then
               if (mat%flow_table(1, il) < mat%flow_table(1, il - 1)) then
                  call raise_error(dl%file, dl%line, 'sigma1 = ' // rtoa(mat%flow_table(1, il)) // &
                       ' is below the previous row''s; expected sigma1 ascending', err)
                  return
               end if
            end if
          end associate
       end do
       return
    end if
    mat%flow_kind = merge(1, 2, ftype == 'LINEAR')
    call one_line(blk, 2, 2, 'fc0, k', err)
    if (err%raised) return
    associate (dl => blk%lines(1))
      call get_real(dl, 1, mat%fc0, err)
      if (.not. err%raised) call get_real(dl, 2, mat%slope, err)
      if (err%raised) return
      if (mat%fc0 < 0 .or. mat%slope < 0) then
         call raise_error(dl%file, dl%line, 'fc0 = ' // rtoa(mat%fc0) // ', k = ' // rtoa(mat%slope) // &
              '; expected fc0 >= 0 and k >= 0', err)
      else if (mat%flow_kind == 2 .and. mat%slope >= 1) then
         call raise_error(dl%file, dl%line, 'bilinear flow function with k = ' // rtoa(mat%slope) // &
              '; expected k < 1', err)
      end if
    end associate
  end subroutine read_flow_function
end module scene_material_options
