!> *AMPLITUDE, NAME=..., DEFINITION=TABULAR|SMOOTH STEP, TIME=STEP TIME|TOTAL TIME with
!> data pairs t, a (any number of pairs per line, as Abaqus allows up to four) ->
!> model%amplitudes. An amplitude may be defined in model data or inside a step; its name
!> is global either way, so every amplitude is known before steps refer to them.
module scene_amplitudes
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_deck_t, keyword_block_t
  use model, only: model_t
  use model_amplitudes, only: amplitude_t, amplitude_tabular, amplitude_smooth_step
  use scene_util, only: itoa, rtoa, get_real, last_field, expect_lines, keyword_text, check_name
  use model_sets, only: name_length
  implicit none
  private

  public :: build_amplitudes, find_amplitude, amplitude_param

contains

  pure integer function find_amplitude(model, name)
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: name
    integer :: k

    find_amplitude = 0
    do k = 1, model%n_amplitudes
       if (model%amplitudes(k)%name == name) then
          find_amplitude = k
          return
       end if
    end do
  end function find_amplitude

  !> The AMPLITUDE= parameter of a load or boundary block: 0 when absent, else its index.
  subroutine amplitude_param(blk, model, amp, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    integer, intent(out) :: amp
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name

    amp = 0
    if (.not. blk%has_param('AMPLITUDE')) return
    call blk%get_string('AMPLITUDE', name, err)
    if (err%raised) return
    amp = find_amplitude(model, name)
    if (amp == 0) call blk%fail('amplitude ' // name // ' is not defined; expected the name of ' // &
         'an *AMPLITUDE', err)
  end subroutine amplitude_param

  subroutine build_amplitudes(deck, model, err)
    type(keyword_deck_t), intent(in) :: deck
    type(model_t), intent(inout) :: model
    type(error_t), intent(inout) :: err
    type(amplitude_t), allocatable :: tmp(:)
    integer :: i

    allocate (model%amplitudes(0))
    model%n_amplitudes = 0
    do i = 1, deck%n_blocks
       if (deck%blocks(i)%name /= 'AMPLITUDE') cycle
       allocate (tmp(model%n_amplitudes + 1))
       tmp(1:model%n_amplitudes) = model%amplitudes
       call move_alloc(tmp, model%amplitudes)
       model%n_amplitudes = model%n_amplitudes + 1
       call read_amplitude(deck%blocks(i), model, model%amplitudes(model%n_amplitudes), err)
       if (err%raised) return
    end do
  end subroutine build_amplitudes

  subroutine read_amplitude(blk, model, amp, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    type(amplitude_t), intent(inout) :: amp
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name, definition, time
    real(dp), allocatable :: t(:), a(:)
    integer :: il, k, n, nf

    call blk%check_params([character(len=10) :: 'NAME', 'DEFINITION', 'TIME'], err)
    if (err%raised) return
    call blk%get_string('NAME', name, err)
    if (.not. err%raised) call check_name(blk, 'amplitude', name, name_length, err)
    if (err%raised) return
    if (find_amplitude(model, name) /= 0) then
       call blk%fail('amplitude ' // name // ' defined twice; expected unique amplitude names', err)
       return
    end if
    call blk%get_string('DEFINITION', definition, err, default='TABULAR', &
         choices=[character(len=11) :: 'TABULAR', 'SMOOTH STEP'])
    if (err%raised) return
    call blk%get_string('TIME', time, err, default='STEP TIME', &
         choices=[character(len=10) :: 'STEP TIME', 'TOTAL TIME'])
    if (err%raised) return
    amp%name = name
    amp%kind = merge(amplitude_smooth_step, amplitude_tabular, definition == 'SMOOTH STEP')
    amp%total_time = time == 'TOTAL TIME'
    call expect_lines(blk, 1, huge(1), 'pairs time, amplitude', err)
    if (err%raised) return
    n = 0
    do il = 1, blk%n_lines
       n = n + last_field(blk%lines(il))
    end do
    allocate (t(n / 2 + 1), a(n / 2 + 1))
    n = 0
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         nf = last_field(dl)
         if (mod(nf, 2) /= 0 .or. nf == 0) then
            call raise_error(dl%file, dl%line, itoa(nf) // ' values on an ' // keyword_text(blk) // &
                 ' line; expected pairs time, amplitude', err)
            return
         end if
         do k = 1, nf, 2
            n = n + 1
            call get_real(dl, k, t(n), err)
            if (.not. err%raised) call get_real(dl, k + 1, a(n), err)
            if (err%raised) return
            if (n > 1) then
               if (.not. (t(n) > t(n - 1))) then
                  call raise_error(dl%file, dl%line, 'time ' // rtoa(t(n)) // ' does not increase ' // &
                       '(previous ' // rtoa(t(n - 1)) // '); expected times strictly ascending', err)
                  return
               end if
            end if
         end do
       end associate
    end do
    amp%t = t(1:n)
    amp%a = a(1:n)
  end subroutine read_amplitude
end module scene_amplitudes
