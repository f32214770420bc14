!> Materials of a scene: each *MATERIAL with its options becomes a `material_t` that the
!> solver hands to a VUMAT. Built-in keywords are translated into our VUMATs
!> (umat/README.md): *ELASTIC alone -> ELASTIC-<name>, with *MOHR COULOMB -> MC-<name>,
!> with *DRUCKER PRAGER -> DP-<name>; *USER MATERIAL keeps the material name and constants.
!>
!> After translation the props go through the same decoder the VUMAT uses (material_props),
!> so a scene that passes here cannot be rejected by the material on its first call.
module scene_materials
  use base_kinds, only: dp, deg_to_rad
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t
  use model, only: model_t
  use model_materials, only: material_t
  use material_props, only: model_from_name, model_names_help, model_unknown, model_elastic, &
       model_mohr_coulomb, model_drucker_prager, decode_elastic, decode_mohr_coulomb, &
       decode_drucker_prager, mohr_coulomb_props_t, drucker_prager_props_t, message_length, &
       mc_n_scalar_props
  use material_state, only: n_state_plastic
  use scene_layout, only: scene_layout_t, is_material_option
  use scene_material_options, only: material_input_t, read_material_option, opt_density, &
       opt_elastic, opt_mohr_coulomb, opt_mc_hardening, opt_tension_cutoff, opt_drucker_prager, &
       opt_inertial_friction, &
       opt_dp_hardening, opt_user_material, opt_depvar, opt_user_field, opt_flow_function, &
       dp_hardening_shear, dp_hardening_tension
  use scene_util, only: rtoa, itoa, where_text, expect_lines, check_name
  use user_library, only: user_vumat, user_vusdfld, user_library_name
  implicit none
  private

  public :: build_materials, build_deck_materials, find_material

contains

  pure integer function find_material(model, name)
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: name
    integer :: k

    find_material = 0
    do k = 1, model%n_materials
       if (model%materials(k)%name == name) then
          find_material = k
          return
       end if
    end do
  end function find_material

  !> All *MATERIAL blocks -> model%materials. `user_subroutine`: a user's VUMAT is linked
  !> in, so *USER MATERIAL names need not be ours.
  subroutine build_materials(deck, layout, model, user_subroutine, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(in) :: layout
    type(model_t), intent(inout) :: model
    logical, intent(in) :: user_subroutine
    type(error_t), intent(inout) :: err
    type(material_input_t) :: mat
    type(material_t), allocatable :: tmp(:)
    character(len=:), allocatable :: name
    integer :: i, j, k

    allocate (model%materials(0))
    model%n_materials = 0
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'MATERIAL') cycle
       associate (blk => deck%blocks(i))
         call blk%check_params([character(len=4) :: 'NAME'], err)
         if (err%raised) return
         call blk%get_string('NAME', name, err)
         if (.not. err%raised) call check_name(blk, 'material', name, 72, err)
         if (.not. err%raised) call expect_lines(blk, 0, 0, 'no data lines (options follow *MATERIAL)', err)
         if (err%raised) return
         k = find_material(model, name)
         if (k /= 0) then
            call blk%fail('material ' // name // ' defined twice (first at ' // &
                 trim(model%materials(k)%source) // '); expected unique material names', err)
            return
         end if
         mat = material_input_t()
         mat%name = name
         mat%block = i
         do j = i + 1, deck%n_blocks
            if (layout%owner(j) /= i) exit
            call read_material_option(deck, j, mat, err)
            if (err%raised) return
         end do
         allocate (tmp(model%n_materials + 1))
         tmp(1:model%n_materials) = model%materials
         call move_alloc(tmp, model%materials)
         model%n_materials = model%n_materials + 1
         call translate(deck, mat, user_subroutine, model%materials(model%n_materials), err)
         if (err%raised) return
       end associate
    end do
  end subroutine build_materials

  !> The materials of a deck that is not a scene (the material-point driver's input, whose
  !> other keywords scan_layout does not know): the options of a *MATERIAL are the material
  !> options that follow it directly, as in a scene. An option that follows no *MATERIAL is
  !> left to the caller (its keyword loop sees it first).
  subroutine build_deck_materials(deck, model, user_subroutine, err)
    type(keyword_deck_t), intent(in) :: deck
    type(model_t), intent(inout) :: model
    logical, intent(in) :: user_subroutine
    type(error_t), intent(inout) :: err
    type(scene_layout_t) :: layout
    integer :: i, chain

    allocate (layout%owner(deck%n_blocks))
    layout%owner = 0
    chain = 0
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name == 'MATERIAL') then
          chain = i
       else if (is_material_option(deck%blocks(i)%name)) then
          layout%owner(i) = chain
       else
          chain = 0
       end if
    end do
    call build_materials(deck, layout, model, user_subroutine, err)
  end subroutine build_deck_materials

  subroutine translate(deck, mat, user_subroutine, m, err)
    type(keyword_deck_t), intent(in) :: deck
    type(material_input_t), intent(in) :: mat
    logical, intent(in) :: user_subroutine
    type(material_t), intent(inout) :: m
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: nm

    nm = trim(mat%name)
    associate (mblk => deck%blocks(mat%block))
      m%name = mat%name
      m%source = where_text(mblk%file, mblk%line)
      call check_combinations(deck, mat, err)
      if (err%raised) return
      if (mat%option_block(opt_density) == 0) then
         call mblk%fail('material ' // nm // ' has no *DENSITY; expected *DENSITY with a ' // &
              'positive value', err)
         return
      end if
      m%density = mat%density
      m%nstatev = mat%depvar
      if (allocated(mat%sdv_names)) m%sdv_names = mat%sdv_names
      if (mat%option_block(opt_user_field) /= 0) then
         m%nfieldv = mat%user_fields
         m%user_field = .true.
         if (allocated(mat%field_props)) m%field_props = mat%field_props
         ! As in Abaqus: with a user file, *USER DEFINED FIELD calls the user's VUSDFLD.
         if (user_subroutine) then
            if (.not. associated(user_vusdfld)) then
               call deck%blocks(mat%option_block(opt_user_field))%fail('*USER DEFINED FIELD in ' // &
                    'material ' // nm // ' but the user file ' // user_library_name() // ' defines no ' // &
                    'VUSDFLD; expected SUBROUTINE VUSDFLD in it', err)
               return
            end if
            m%user_field_code = .true.
         end if
      end if
      if (mat%option_block(opt_user_material) /= 0) then
         call translate_user(deck, mat, user_subroutine, m, err)
      else if (mat%option_block(opt_mohr_coulomb) /= 0) then
         call translate_mohr_coulomb(deck, mat, m, err)
      else if (mat%option_block(opt_drucker_prager) /= 0) then
         call translate_drucker_prager(deck, mat, m, err)
      else
         m%vumat_name = 'ELASTIC-' // nm
         m%props = [mat%young, mat%poisson]
         call final_check(mblk, m, err)
      end if
      if (.not. err%raised .and. allocated(m%field_props) .and. .not. m%user_field_code) &
           call check_our_field_props(deck%blocks(mat%option_block(opt_user_field)), m, err)
    end associate
  end subroutine translate

  !> *USER DEFINED FIELD, PROPERTIES= for our VUSDFLD (umat/README.md): three constants, mode 0
  !> (volumetric strain) or 1 (flow function), t_freeze, record 0 or 1; the flow-function mode
  !> keeps sigma1 in the last state variable, which must not be one of our VUMAT's own.
  subroutine check_our_field_props(blk, m, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_t), intent(in) :: m
    type(error_t), intent(inout) :: err
    integer :: own

    associate (fp => m%field_props)
      if (size(fp) /= 3) then
         call blk%fail('our VUSDFLD takes PROPERTIES=3 (mode, freeze time, record); got PROPERTIES=' // &
              itoa(size(fp)) // '; expected 3 constants or none', err)
      else if (.not. (is_flag(fp(1)) .and. is_flag(fp(3)))) then
         call blk%fail('our VUSDFLD''s properties ' // rtoa(fp(1)) // ', ' // rtoa(fp(2)) // ', ' // &
              rtoa(fp(3)) // '; expected mode 0 (volumetric strain) or 1 (flow function), a freeze ' // &
              'time, record 0 (current) or 1 (maximum)', err)
      else if (fp(1) > 0) then
         own = 0
         if (model_from_name(m%vumat_name) /= model_elastic) own = n_state_plastic
         if (m%nstatev <= own) call blk%fail('the flow-function VUSDFLD keeps sigma1 in the last state ' // &
              'variable, but material ' // trim(m%name) // ' has ' // itoa(m%nstatev) // ', all its ' // &
              'VUMAT''s; expected *DEPVAR >= ' // itoa(own + 1), err)
      end if
    end associate
  end subroutine check_our_field_props

  !> The state variables of a built-in plastic model: our VUMAT's n_state_plastic first. Our own
  !> VUSDFLD shares them (*DEPVAR forced to at least n_state_plastic, its flow-function record in
  !> the last); a user's VUSDFLD gets the *DEPVAR ones only, as in Abaqus, after ours.
  subroutine model_state_first(m)
    type(material_t), intent(inout) :: m

    character(len=len(m%name)), allocatable :: names(:)

    if (m%user_field_code) then
       m%user_state_first = n_state_plastic + 1
       m%nstatev = n_state_plastic + m%nstatev
       if (allocated(m%sdv_names)) then
          ! names from *DEPVAR lines belong to the user's state variables, after ours
          allocate (names(m%nstatev))
          names = ''
          names(m%user_state_first:) = m%sdv_names
          call move_alloc(names, m%sdv_names)
       end if
    else
       m%nstatev = max(m%nstatev, n_state_plastic)
    end if
  end subroutine model_state_first

  !> 0 or 1 exactly.
  pure logical function is_flag(x)
    real(dp), intent(in) :: x
    is_flag = abs(x) <= 0 .or. abs(x - 1) <= 0
  end function is_flag

  !> Which options may stand together.
  subroutine check_combinations(deck, mat, err)
    type(keyword_deck_t), intent(in) :: deck
    type(material_input_t), intent(in) :: mat
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: nm
    integer :: opt

    nm = trim(mat%name)
    associate (mblk => deck%blocks(mat%block), ob => mat%option_block)
      if (ob(opt_user_material) /= 0) then
         do opt = opt_elastic, opt_dp_hardening
            if (ob(opt) /= 0) then
               call deck%blocks(ob(opt))%fail('*' // deck%blocks(ob(opt))%name // ' together with ' // &
                    '*USER MATERIAL in material ' // nm // '; expected either *USER MATERIAL or ' // &
                    'built-in behaviour', err)
               return
            end if
         end do
         if (ob(opt_flow_function) /= 0) then
            call deck%blocks(ob(opt_flow_function))%fail('*FLOW FUNCTION together with *USER ' // &
                 'MATERIAL in material ' // nm // '; expected it with *MOHR COULOMB only', err)
         end if
         return
      end if
      if (ob(opt_elastic) == 0) then
         if (ob(opt_mohr_coulomb) /= 0 .or. ob(opt_drucker_prager) /= 0) then
            associate (pblk => deck%blocks(max(ob(opt_mohr_coulomb), ob(opt_drucker_prager))))
              call pblk%fail('material ' // nm // ' has *' // pblk%name // ' but no *ELASTIC; ' // &
                   'expected *ELASTIC (E, nu) in the same material', err)
            end associate
         else
            call mblk%fail('material ' // nm // ' has no mechanical behaviour; expected *ELASTIC ' // &
                 '(alone, with *MOHR COULOMB or *DRUCKER PRAGER) or *USER MATERIAL', err)
         end if
         return
      end if
      if (ob(opt_mohr_coulomb) /= 0 .and. ob(opt_drucker_prager) /= 0) then
         call deck%blocks(ob(opt_drucker_prager))%fail('*DRUCKER PRAGER and *MOHR COULOMB in ' // &
              'material ' // nm // '; expected one plasticity model', err)
         return
      end if
      if (ob(opt_mohr_coulomb) == 0) then
         do opt = opt_mc_hardening, opt_tension_cutoff
            if (ob(opt) /= 0) call deck%blocks(ob(opt))%fail('*' // deck%blocks(ob(opt))%name // &
                 ' without *MOHR COULOMB in material ' // nm // '; expected it with *MOHR COULOMB', err)
            if (err%raised) return
         end do
         if (ob(opt_flow_function) /= 0) then
            call deck%blocks(ob(opt_flow_function))%fail('*FLOW FUNCTION without *MOHR COULOMB in ' // &
                 'material ' // nm // '; expected it with *MOHR COULOMB', err)
            return
         end if
         if (ob(opt_inertial_friction) /= 0) then
            call deck%blocks(ob(opt_inertial_friction))%fail('*INERTIAL FRICTION without *MOHR ' // &
                 'COULOMB in material ' // nm // '; expected it with *MOHR COULOMB', err)
            return
         end if
      else if (ob(opt_mc_hardening) == 0 .and. ob(opt_flow_function) == 0) then
         call deck%blocks(ob(opt_mohr_coulomb))%fail('material ' // nm // ' has *MOHR COULOMB ' // &
              'but no cohesion; expected *MOHR COULOMB HARDENING or *FLOW FUNCTION', err)
         return
      end if
      if (ob(opt_drucker_prager) == 0 .and. ob(opt_dp_hardening) /= 0) then
         call deck%blocks(ob(opt_dp_hardening))%fail('*DRUCKER PRAGER HARDENING without *DRUCKER ' // &
              'PRAGER in material ' // nm // '; expected it with *DRUCKER PRAGER', err)
         return
      end if
      if (ob(opt_drucker_prager) /= 0 .and. ob(opt_dp_hardening) == 0) then
         call deck%blocks(ob(opt_drucker_prager))%fail('material ' // nm // ' has *DRUCKER PRAGER ' // &
              'but no *DRUCKER PRAGER HARDENING; expected the yield stress that gives d', err)
         return
      end if
    end associate
  end subroutine check_combinations

  subroutine translate_user(deck, mat, user_subroutine, m, err)
    type(keyword_deck_t), intent(in) :: deck
    type(material_input_t), intent(in) :: mat
    logical, intent(in) :: user_subroutine
    type(material_t), intent(inout) :: m
    type(error_t), intent(inout) :: err

    m%user_material = .true.
    ! cmname as Abaqus passes it: the material name in upper case, padded with blanks to 80.
    m%vumat_name = mat%name
    m%props = mat%user_props
    ! With a user file every *USER MATERIAL is the user's, whatever its name (Abaqus's rule);
    ! our models stay reachable from it through bulkflow_vumat.
    ! A user file with only a VUSDFLD (its vusdfld loaded, no vumat) leaves *USER MATERIAL to
    ! our VUMATs.
    m%user_code = user_subroutine .and. (associated(user_vumat) .or. .not. associated(user_vusdfld))
    if (m%user_code) return
    ! Without a user's subroutine our VUMAT will receive the name: check it now.
    if (model_from_name(m%vumat_name) == model_unknown) then
       if (user_subroutine) then
          call deck%blocks(mat%block)%fail('user material ' // trim(mat%name) // ' is not one of ' // &
               'our VUMATs and the user file ' // user_library_name() // ' defines no VUMAT (only a ' // &
               'VUSDFLD); expected SUBROUTINE VUMAT in it or ' // model_names_help(), err)
       else
          call deck%blocks(mat%block)%fail('user material ' // trim(mat%name) // ' is not one of ' // &
               'our VUMATs and no user subroutine is in use; expected ' // model_names_help(), err)
       end if
       return
    end if
    call final_check(deck%blocks(mat%option_block(opt_user_material)), m, err)
  end subroutine translate_user

  !> MC props (umat/README.md): 16 scalars, then the angle, cohesion and flow-function tables.
  subroutine translate_mohr_coulomb(deck, mat, m, err)
    type(keyword_deck_t), intent(in) :: deck
    type(material_input_t), intent(in) :: mat
    type(material_t), intent(inout) :: m
    type(error_t), intent(inout) :: err
    real(dp), allocatable :: p(:)
    integer :: n_ang, n_coh, n_ff, k, coh_columns
    real(dp) :: apex
    logical :: on_field

    n_ang = 0
    if (allocated(mat%angle_table)) n_ang = size(mat%angle_table, 2)
    n_coh = 0
    coh_columns = 2
    if (allocated(mat%cohesion)) then
       n_coh = size(mat%cohesion, 2)
       coh_columns = size(mat%cohesion, 1)
    end if
    if (n_coh == 1) n_coh = 0          ! one row: a constant cohesion (prop 5)
    ! rows (c, PEEQ, field 1): *MOHR COULOMB HARDENING, DEPENDENCIES=1 (prop 15 negative)
    on_field = n_coh > 0 .and. coh_columns == 3
    n_ff = 0
    if (allocated(mat%flow_table)) n_ff = size(mat%flow_table, 2)
    ! + the mu(I) block (kind 1, phi2, I0, d, rho_s) with our *INERTIAL FRICTION
    allocate (p(mc_n_scalar_props + 3 * n_ang + coh_columns * n_coh + 2 * n_ff &
         + merge(5, 0, mat%option_block(opt_inertial_friction) /= 0)))
    p = 0
    p(1) = mat%young
    p(2) = mat%poisson
    p(3) = mat%phi
    p(4) = mat%psi
    if (allocated(mat%cohesion)) p(5) = mat%cohesion(1, 1)
    if (mat%option_block(opt_tension_cutoff) /= 0) then
       p(6) = 1
       p(7) = mat%sigma_t
    end if
    p(8) = mat%flow_kind
    p(9) = mat%fc0
    p(10) = mat%slope
    p(11) = mat%t_freeze
    p(12) = merge(1, 0, mat%record_maximum)
    p(13) = n_ang
    p(14) = merge(1, 0, n_ang > 0 .or. on_field)
    p(15) = merge(-n_coh, n_coh, on_field)
    p(16) = n_ff
    k = mc_n_scalar_props
    if (n_ang > 0) p(k + 1:k + 3 * n_ang) = reshape(mat%angle_table, [3 * n_ang])
    k = k + 3 * n_ang
    if (n_coh > 0) p(k + 1:k + coh_columns * n_coh) = reshape(mat%cohesion, [coh_columns * n_coh])
    k = k + coh_columns * n_coh
    if (n_ff > 0) p(k + 1:k + 2 * n_ff) = reshape(mat%flow_table, [2 * n_ff])
    k = k + 2 * n_ff
    if (mat%option_block(opt_inertial_friction) /= 0) p(k + 1:k + 5) = [1.0_dp, mat%inertial]
    m%vumat_name = 'MC-' // trim(mat%name)
    call move_alloc(p, m%props)
    call model_state_first(m)
    if (n_ang > 0 .or. on_field) then
       ! the tables run on field 1, which our VUSDFLD sets: the volumetric strain, or with
       ! *USER DEFINED FIELD, PROPERTIES=3 (1, t_freeze, record) the consolidation stress
       m%nfieldv = max(m%nfieldv, 1)
       m%user_field = .true.
    end if
    ! A cut-off above the apex of the cone c*cot(phi) would never be reached; only the
    ! constant case can be checked before the run.
    if (mat%option_block(opt_tension_cutoff) /= 0 .and. n_ang == 0 .and. n_coh == 0 .and. &
         mat%flow_kind == 0) then
       apex = mat%cohesion(1, 1) / tan(mat%phi * deg_to_rad)
       if (.not. (mat%sigma_t < apex)) then
          associate (blk => deck%blocks(mat%option_block(opt_tension_cutoff)))
            call raise_error(blk%lines(1)%file, blk%lines(1)%line, 'tension cut-off ' // &
                 rtoa(mat%sigma_t) // ' is not below the apex c*cot(phi) = ' // rtoa(apex) // &
                 '; expected 0 <= sigma_t < c*cot(phi)', err)
          end associate
          return
       end if
    end if
    call final_check(deck%blocks(mat%option_block(opt_mohr_coulomb)), m, err)
  end subroutine translate_mohr_coulomb

  !> DP props: E, nu, beta, psi, d, mode 0. d from the hardening's first row with K = 1
  !> (docs/theory/abaqus_contract.md §5.2): compression d = (1 - tan(beta)/3) sigma_c,
  !> shear d = sqrt(3) tau, tension d = (1 + tan(beta)/3) sigma_t.
  subroutine translate_drucker_prager(deck, mat, m, err)
    type(keyword_deck_t), intent(in) :: deck
    type(material_input_t), intent(in) :: mat
    type(material_t), intent(inout) :: m
    type(error_t), intent(inout) :: err
    real(dp) :: tan_beta, d

    tan_beta = tan(mat%beta * deg_to_rad)
    select case (mat%dp_hardening_type)
    case (dp_hardening_shear)
       d = sqrt(3.0_dp) * mat%dp_yield
    case (dp_hardening_tension)
       d = (1 + tan_beta / 3) * mat%dp_yield
    case default
       d = (1 - tan_beta / 3) * mat%dp_yield
    end select
    if (d < 0) then
       associate (blk => deck%blocks(mat%option_block(opt_dp_hardening)))
         call blk%fail('compression yield stress with tan(beta) > 3 gives d = ' // rtoa(d) // &
              '; expected beta < 71.57 degrees with TYPE=COMPRESSION', err)
       end associate
       return
    end if
    m%vumat_name = 'DP-' // trim(mat%name)
    m%props = [mat%young, mat%poisson, mat%beta, mat%psi_dp, d, 0.0_dp]
    call model_state_first(m)
    call final_check(deck%blocks(mat%option_block(opt_drucker_prager)), m, err)
  end subroutine translate_drucker_prager

  !> The VUMAT's own props decoder on the translated material (reported at `blk`).
  subroutine final_check(blk, m, err)
    type(keyword_block_t), intent(in) :: blk
    type(material_t), intent(in) :: m
    type(error_t), intent(inout) :: err
    type(mohr_coulomb_props_t) :: mc
    type(drucker_prager_props_t) :: dpp
    character(len=message_length) :: message
    real(dp) :: lam, shear
    logical :: ok
    integer :: n

    n = size(m%props)
    select case (model_from_name(m%vumat_name))
    case (model_elastic)
       call decode_elastic(m%props, n, lam, shear, ok, message)
    case (model_mohr_coulomb)
       call decode_mohr_coulomb(m%props, n, m%nstatev, m%nfieldv, mc, ok, message)
    case (model_drucker_prager)
       call decode_drucker_prager(m%props, n, m%nstatev, dpp, ok, message)
    case default
       ok = .true.
    end select
    if (.not. ok) call blk%fail('material ' // trim(m%name) // ' (' // trim(m%vumat_name) // &
         '): ' // trim(message) // '; expected props as in umat/README.md', err)
  end subroutine final_check
end module scene_materials
