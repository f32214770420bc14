!> The structure of a scene deck before anything is built: which keywords exist, where
!> each may stand (model data, inside *STEP ... *END STEP, or right after the keyword it
!> belongs to) and which block owns each option block.
!>
!> Doing this first means every later pass can assume a well-formed deck: an unknown
!> keyword, a material option without *MATERIAL, a *DLOAD outside a step or a missing
!> *END STEP is reported once, here, with the line of the offending keyword.
module scene_layout
  use error_report, only: error_t
  use keyword_reader, only: keyword_deck_t
  use scene_util, only: itoa, where_text
  use scene_unsupported, only: unsupported_hint
  implicit none
  private

  public :: scene_layout_t, scan_layout, keyword_kind
  public :: is_material_option

  integer, parameter, public :: kw_unknown = 0
  integer, parameter, public :: kw_model = 1            !< model data only
  integer, parameter, public :: kw_step_only = 2        !< history data only (inside a step)
  integer, parameter, public :: kw_anywhere = 3         !< model or history data
  integer, parameter, public :: kw_material_option = 4  !< follows *MATERIAL
  integer, parameter, public :: kw_interaction_option = 5  !< follows *SURFACE INTERACTION
  integer, parameter, public :: kw_output_option = 6    !< follows *OUTPUT
  integer, parameter, public :: kw_step = 7             !< *STEP
  integer, parameter, public :: kw_end_step = 8         !< *END STEP

  type :: scene_layout_t
     integer :: n_steps = 0
     integer, allocatable :: step_of(:)     !< per block: 0 model data, k inside step k
     integer, allocatable :: owner(:)       !< per option block: its *MATERIAL/... block; else 0
     integer, allocatable :: step_block(:)  !< per step: block index of *STEP
     integer, allocatable :: end_block(:)   !< per step: block index of *END STEP
  end type scene_layout_t

contains

  !> Where a keyword (normalized name without '*') may stand.
  pure integer function keyword_kind(name)
    character(len=*), intent(in) :: name

    select case (name)
    case ('HEADING', 'NODE', 'ELEMENT', 'NSET', 'ELSET', 'SOLID SECTION', 'MATERIAL', &
         'SURFACE', 'RIGID BODY', 'SURFACE INTERACTION', 'INITIAL CONDITIONS', 'SECTION CONTROLS', &
         'MPM GRID', 'PARTICLES', 'OUTFLOW', 'NONLOCAL')
       keyword_kind = kw_model
    case ('DYNAMIC', 'DLOAD', 'DSLOAD', 'BULK VISCOSITY', 'OUTPUT', 'RESTART', 'FIXED MASS SCALING', &
          'STOP CONDITION', 'INFLOW', 'TEMPERATURE')
       keyword_kind = kw_step_only
    case ('AMPLITUDE', 'BOUNDARY', 'CONTACT PAIR', 'MPM CONTROLS', 'MPM WALL', 'TIME POINTS', 'MPM SIDE FRICTION')
       keyword_kind = kw_anywhere
    case ('FRICTION')
       keyword_kind = kw_interaction_option
    case ('NODE OUTPUT', 'ELEMENT OUTPUT', 'ENERGY OUTPUT')
       keyword_kind = kw_output_option
    case ('STEP')
       keyword_kind = kw_step
    case ('END STEP')
       keyword_kind = kw_end_step
    case default
       if (is_material_option(name)) then
          keyword_kind = kw_material_option
       else
          keyword_kind = kw_unknown
       end if
    end select
  end function keyword_kind

  pure logical function is_material_option(name)
    character(len=*), intent(in) :: name

    select case (name)
    case ('DENSITY', 'ELASTIC', 'MOHR COULOMB', 'MOHR COULOMB HARDENING', 'TENSION CUTOFF', &
         'DRUCKER PRAGER', 'DRUCKER PRAGER HARDENING', 'USER MATERIAL', 'DEPVAR', &
         'USER DEFINED FIELD', 'FLOW FUNCTION', 'INERTIAL FRICTION')
       is_material_option = .true.
    case default
       is_material_option = .false.
    end select
  end function is_material_option

  !> Classify every block, find the steps and the owner of every option block.
  subroutine scan_layout(deck, layout, err)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_layout_t), intent(out) :: layout
    type(error_t), intent(inout) :: err
    integer :: i, kind, step, chain_material, chain_interaction, chain_output, nb

    nb = deck%n_blocks
    allocate (layout%step_of(nb), layout%owner(nb), layout%step_block(nb), layout%end_block(nb))
    layout%step_of = 0
    layout%owner = 0
    step = 0
    ! The block an option may attach to; 0 when the previous keyword breaks the chain.
    chain_material = 0
    chain_interaction = 0
    chain_output = 0
    do i = 1, nb
       associate (blk => deck%blocks(i))
         kind = keyword_kind(blk%name)
         select case (kind)
         case (kw_unknown)
            if (len(unsupported_hint(blk%name)) > 0) then
               call blk%fail('*' // blk%name // ' is not simulated by bulkflow; ' // unsupported_hint(blk%name), err)
            else
               call blk%fail('unknown keyword *' // blk%name // &
                    '; expected a keyword listed in docs/keywords.md', err)
            end if
            return
         case (kw_step)
            if (step > 0) then
               call blk%fail('*STEP inside the step started at ' // &
                    where_text(deck%blocks(layout%step_block(layout%n_steps))%file, &
                    deck%blocks(layout%step_block(layout%n_steps))%line) // &
                    '; expected *END STEP before the next *STEP', err)
               return
            end if
            layout%n_steps = layout%n_steps + 1
            step = layout%n_steps
            layout%step_block(step) = i
         case (kw_end_step)
            if (step == 0) then
               call blk%fail('*END STEP without a *STEP; expected *STEP ... *END STEP', err)
               return
            end if
            layout%end_block(step) = i
         case (kw_model)
            if (step > 0) then
               call blk%fail('*' // blk%name // ' is model data and cannot stand inside a step ' // &
                    '(step ' // itoa(step) // '); expected it before the first *STEP', err)
               return
            end if
         case (kw_step_only)
            if (step == 0) then
               call blk%fail('*' // blk%name // ' outside a step; expected it between *STEP and ' // &
                    '*END STEP', err)
               return
            end if
         case (kw_material_option)
            if (chain_material == 0) then
               call blk%fail('*' // blk%name // ' does not follow a *MATERIAL; expected it ' // &
                    'right after *MATERIAL or another option of that material', err)
               return
            end if
            layout%owner(i) = chain_material
         case (kw_interaction_option)
            if (chain_interaction == 0) then
               call blk%fail('*' // blk%name // ' does not follow a *SURFACE INTERACTION; ' // &
                    'expected it right after *SURFACE INTERACTION', err)
               return
            end if
            layout%owner(i) = chain_interaction
         case (kw_output_option)
            if (chain_output == 0) then
               call blk%fail('*' // blk%name // ' does not follow an *OUTPUT; expected it ' // &
                    'after *OUTPUT, FIELD or *OUTPUT, HISTORY', err)
               return
            end if
            layout%owner(i) = chain_output
         end select
         layout%step_of(i) = step
         ! chains: an option continues the chain of its owner; anything else ends it
         if (kind /= kw_material_option) chain_material = 0
         if (kind /= kw_interaction_option) chain_interaction = 0
         if (kind /= kw_output_option) chain_output = 0
         if (blk%name == 'MATERIAL') chain_material = i
         if (blk%name == 'SURFACE INTERACTION') chain_interaction = i
         if (blk%name == 'OUTPUT') chain_output = i
         if (kind == kw_end_step) step = 0
       end associate
    end do
    if (step > 0) then
       associate (blk => deck%blocks(layout%step_block(step)))
         call blk%fail('*END STEP missing for the step that starts here; expected ' // &
              '*STEP ... *END STEP', err)
       end associate
       return
    end if
    layout%step_block = layout%step_block(1:layout%n_steps)
    layout%end_block = layout%end_block(1:layout%n_steps)
  end subroutine scan_layout
end module scene_layout
