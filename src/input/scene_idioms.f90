!> The keywords Abaqus/CAE and hand-written decks carry that bulkflow either need not act on
!> or reads as another keyword it has, resolved before the layout pass:
!> * print and file requests (*PREPRINT, *NODE PRINT, *CONTACT OUTPUT, *DIAGNOSTICS, ...)
!>   cannot change results: dropped, with one note per keyword naming the first line;
!> * *PHYSICAL CONSTANTS (temperatures, radiation, gases: nothing a mechanical explicit run
!>   uses): dropped with a note;
!> * *SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD: our contact is hard (kinematic) contact
!>   that lets surfaces separate, so it is checked and dropped; NO SEPARATION and the softened
!>   laws are refused;
!> * a model-level *RESTART, WRITE is moved into the first step (it carries over, as ours does);
!> * general contact (*CONTACT with *CONTACT INCLUSIONS and *CONTACT PROPERTY ASSIGNMENT)
!>   becomes the *CONTACT PAIR blocks it means for pairs of an element surface and an analytic
!>   rigid surface (scene_general_contact).
module scene_idioms
  use error_report, only: error_t
  use keyword_reader, only: keyword_deck_t, keyword_block_t
  use scene_util, only: itoa, where_text
  use scene_general_contact, only: convert_general_contact
  implicit none
  private

  public :: rewrite_idioms

contains

  !> Why a dropped keyword cannot change results (empty: not a dropped keyword).
  pure function dropped_reason(name) result(reason)
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: reason

    select case (name)
    case ('PREPRINT', 'NODE PRINT', 'EL PRINT', 'ENERGY PRINT', 'CONTACT PRINT', 'PRINT', 'MONITOR', &
         'NODE FILE', 'EL FILE', 'ENERGY FILE', 'CONTACT FILE', 'FILE FORMAT', 'FILE OUTPUT', 'DIAGNOSTICS')
       reason = 'a print/file request of Abaqus; bulkflow writes BASE_history.csv and BASE.h5 (*OUTPUT)'
    case ('CONTACT OUTPUT', 'INCREMENTATION OUTPUT')
       reason = 'an output request bulkflow does not write (contact and increment data); ' // &
            'wall forces and the increment are in BASE_history.csv'
    case ('PHYSICAL CONSTANTS')
       reason = 'constants for temperature, radiation and gases, which a mechanical explicit run does not use'
    case default
       reason = ''
    end select
  end function dropped_reason

  !> Resolve the idioms of `deck` in place; `notes` gets one line per dropped keyword.
  subroutine rewrite_idioms(deck, notes, err)
    type(keyword_deck_t), intent(inout) :: deck
    character(len=512), allocatable, intent(inout) :: notes(:)
    type(error_t), intent(inout) :: err
    logical, allocatable :: keep(:)

    allocate (keep(deck%n_blocks))
    keep = .true.
    call drop_requests(deck, keep, notes)
    call check_surface_behavior(deck, keep, notes, err)
    if (err%raised) return
    call compact(deck, keep)
    call move_model_restart(deck, notes)
    call convert_general_contact(deck, err)
    if (.not. allocated(notes)) allocate (notes(0))
  end subroutine rewrite_idioms

  subroutine add_note(notes, text)
    character(len=512), allocatable, intent(inout) :: notes(:)
    character(len=*), intent(in) :: text

    if (.not. allocated(notes)) allocate (notes(0))
    notes = [character(len=512) :: notes, text]
  end subroutine add_note

  !> Drop print/file requests; an *OUTPUT left with no option and no VARIABLE= goes too.
  subroutine drop_requests(deck, keep, notes)
    type(keyword_deck_t), intent(in) :: deck
    logical, intent(inout) :: keep(:)
    character(len=512), allocatable, intent(inout) :: notes(:)
    character(len=:), allocatable :: reason, times
    integer :: i, j, count_same, last_output
    logical :: options_left

    do i = 1, deck%n_blocks
       reason = dropped_reason(deck%blocks(i)%name)
       if (len(reason) == 0) cycle
       keep(i) = .false.
       count_same = 0
       do j = 1, i - 1
          if (deck%blocks(j)%name == deck%blocks(i)%name) count_same = count_same + 1
       end do
       if (count_same > 0) cycle
       count_same = 0
       do j = i, deck%n_blocks
          if (deck%blocks(j)%name == deck%blocks(i)%name) count_same = count_same + 1
       end do
       times = ''
       if (count_same > 1) times = ' (x' // itoa(count_same) // ')'
       call add_note(notes, where_text(deck%blocks(i)%file, deck%blocks(i)%line) // ': note: *' // &
            deck%blocks(i)%name // times // ' accepted and not acted on: ' // reason)
    end do
    ! An *OUTPUT whose only options were dropped requests nothing any more.
    last_output = 0
    options_left = .false.
    do i = 1, deck%n_blocks + 1
       if (i <= deck%n_blocks) then
          if (is_output_option(deck%blocks(i)%name)) then
             if (keep(i)) options_left = .true.
             cycle
          end if
          if (.not. keep(i) .and. last_output /= 0) cycle
       end if
       if (last_output /= 0 .and. .not. options_left) then
          if (.not. deck%blocks(last_output)%has_param('VARIABLE') .and. i > last_output + 1) then
             keep(last_output) = .false.
             call add_note(notes, where_text(deck%blocks(last_output)%file, deck%blocks(last_output)%line) // &
                  ': note: *OUTPUT with only requests bulkflow does not write; dropped with them')
          end if
       end if
       last_output = 0
       if (i > deck%n_blocks) exit
       if (deck%blocks(i)%name == 'OUTPUT') then
          last_output = i
          options_left = .false.
       end if
    end do
  end subroutine drop_requests

  pure logical function is_output_option(name)
    character(len=*), intent(in) :: name

    is_output_option = any(name == [character(len=21) :: 'NODE OUTPUT', 'ELEMENT OUTPUT', 'ENERGY OUTPUT', &
         'CONTACT OUTPUT', 'INCREMENTATION OUTPUT'])
  end function is_output_option

  !> *SURFACE BEHAVIOR: only the hard law with separation, which is what our contact does.
  subroutine check_surface_behavior(deck, keep, notes, err)
    type(keyword_deck_t), intent(in) :: deck
    logical, intent(inout) :: keep(:)
    character(len=512), allocatable, intent(inout) :: notes(:)
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: law
    integer :: i
    logical :: noted

    noted = .false.
    do i = 1, deck%n_blocks
       associate (blk => deck%blocks(i))
         if (blk%name /= 'SURFACE BEHAVIOR') cycle
         call blk%check_params([character(len=22) :: 'PRESSURE-OVERCLOSURE', 'NO SEPARATION'], err)
         if (err%raised) return
         if (blk%has_param('NO SEPARATION')) then
            call blk%fail('*SURFACE BEHAVIOR, NO SEPARATION is not simulated; bulkflow offers hard contact ' // &
                 'that lets the surfaces separate (PRESSURE-OVERCLOSURE=HARD, or omit *SURFACE BEHAVIOR)', err)
            return
         end if
         call blk%get_string('PRESSURE-OVERCLOSURE', law, err, default='HARD')
         if (err%raised) return
         if (law /= 'HARD') then
            call blk%fail('*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=' // law // ' is not simulated; bulkflow ' // &
                 'offers hard (kinematic) contact: PRESSURE-OVERCLOSURE=HARD, or omit *SURFACE BEHAVIOR', err)
            return
         end if
         if (blk%n_lines > 0) then
            call blk%fail('data lines on *SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD; expected none', err)
            return
         end if
         keep(i) = .false.
         if (.not. noted) call add_note(notes, where_text(blk%file, blk%line) // ': note: *SURFACE BEHAVIOR, ' // &
              'PRESSURE-OVERCLOSURE=HARD is what bulkflow contact does (kinematic, separation allowed)')
         noted = .true.
       end associate
    end do
  end subroutine check_surface_behavior

  subroutine compact(deck, keep)
    type(keyword_deck_t), intent(inout) :: deck
    logical, intent(in) :: keep(:)
    type(keyword_block_t), allocatable :: kept(:)
    integer :: i, n

    if (all(keep)) return
    allocate (kept(count(keep)))
    n = 0
    do i = 1, deck%n_blocks
       if (.not. keep(i)) cycle
       n = n + 1
       kept(n) = deck%blocks(i)
    end do
    call move_alloc(kept, deck%blocks)
    deck%n_blocks = n
  end subroutine compact

  !> A *RESTART before the first *STEP: Abaqus/Explicit takes it as the request of the steps
  !> that follow; ours carries over from the step that has it, so it moves into step 1
  !> (unless step 1 has its own, which then wins).
  subroutine move_model_restart(deck, notes)
    type(keyword_deck_t), intent(inout) :: deck
    character(len=512), allocatable, intent(inout) :: notes(:)
    type(keyword_block_t) :: moved
    integer :: i, first_step, at, j

    first_step = 0
    at = 0
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name == 'STEP') then
          first_step = i
          exit
       end if
       if (deck%blocks(i)%name == 'RESTART') at = i
    end do
    if (at == 0 .or. first_step == 0) return
    do j = first_step + 1, deck%n_blocks
       if (deck%blocks(j)%name == 'END STEP') exit
       if (deck%blocks(j)%name == 'RESTART') then
          call add_note(notes, where_text(deck%blocks(at)%file, deck%blocks(at)%line) // ': note: model-level ' // &
               '*RESTART not used: step 1 has its own')
          deck%blocks(at:deck%n_blocks - 1) = deck%blocks(at + 1:deck%n_blocks)
          deck%n_blocks = deck%n_blocks - 1
          return
       end if
    end do
    moved = deck%blocks(at)
    ! shift the blocks between it and *STEP one place up; it goes right after *STEP
    deck%blocks(at:first_step - 1) = deck%blocks(at + 1:first_step)
    deck%blocks(first_step) = moved
  end subroutine move_model_restart
end module scene_idioms
