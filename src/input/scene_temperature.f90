!> *TEMPERATURE in a step (Abaqus's predefined temperature field) and the targets of predefined
!> fields in material-point scenes.
!>
!> *TEMPERATURE[, AMPLITUDE=name][, OP=MOD|NEW]: data lines `node or node set, value` (MPM
!> scenes: `material name, value`, the particles of that material). The temperature is value ×
!> a(t) with the referenced amplitude, the full value from the step's start without one (the
!> variation our loads follow, model_time_variation); nodes no *TEMPERATURE names keep their
!> *INITIAL CONDITIONS, TYPE=TEMPERATURE value. Entries carry into later steps like boundary
!> conditions (a step-time amplitude is held at its end value); OP=NEW drops the carried ones
!> (the nodes return to their initial temperatures). Abaqus Analysis User's Guide, "Predefined
!> fields" and "Amplitude curves".
module scene_temperature
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use keyword_reader, only: keyword_block_t, data_line_t
  use model, only: model_t
  use model_steps, only: temperature_t
  use scene_amplitudes, only: amplitude_param
  use scene_sets, only: node_targets
  use scene_util, only: itoa, get_real, field_name, expect_fields, expect_lines, where_text
  implicit none
  private

  public :: read_temperature, predefined_line

contains

  !> One *TEMPERATURE block of a step: its entries are appended to `active` (n of them in use),
  !> after dropping the carried ones with OP=NEW.
  subroutine read_temperature(blk, model, active, n, err)
    type(keyword_block_t), intent(in) :: blk
    type(model_t), intent(in) :: model
    type(temperature_t), allocatable, intent(inout) :: active(:)
    integer, intent(inout) :: n
    type(error_t), intent(inout) :: err
    type(temperature_t) :: entry
    character(len=:), allocatable :: op
    integer :: il, amp

    call blk%check_params([character(len=9) :: 'AMPLITUDE', 'OP'], err)
    if (.not. err%raised) call blk%get_string('OP', op, err, default='MOD', choices=[character(len=3) :: 'MOD', 'NEW'])
    if (.not. err%raised) call amplitude_param(blk, model, amp, err)
    if (.not. err%raised) call expect_lines(blk, 1, huge(1), 'temperatures', err)
    if (err%raised) return
    if (op == 'NEW') n = 0
    if (.not. allocated(active)) allocate (active(0))
    do il = 1, blk%n_lines
       associate (dl => blk%lines(il))
         call predefined_line(blk, dl, model, 'temperature', entry%nodes, entry%material, entry%value, err)
         if (err%raised) return
         entry%variation%amplitude = amp
         entry%source = where_text(dl%file, dl%line)
         if (n == size(active)) active = [active, entry]
         n = n + 1
         active(n) = entry
       end associate
    end do
  end subroutine read_temperature

  !> A data line `target, value` of a predefined field: target = node or node set (nodes), or in a
  !> material-point scene (no mesh) a material name (material, nodes empty).
  subroutine predefined_line(blk, dl, model, what, nodes, material, value, err)
    type(keyword_block_t), intent(in) :: blk
    type(data_line_t), intent(in) :: dl
    type(model_t), intent(in) :: model
    character(len=*), intent(in) :: what
    integer, allocatable, intent(out) :: nodes(:)
    integer, intent(out) :: material
    real(dp), intent(out) :: value
    type(error_t), intent(inout) :: err

    material = 0
    value = 0
    if (model%mesh%n_nodes == 0) then
       allocate (nodes(0))
       call expect_fields(blk, dl, 2, 2, 'material name (its particles), ' // what, err)
       if (.not. err%raised) call material_target(model, dl, 1, material, err)
    else
       call expect_fields(blk, dl, 2, 2, 'node or node set, ' // what, err)
       if (.not. err%raised) call node_targets(model, dl, 1, nodes, err)
    end if
    if (.not. err%raised) call get_real(dl, 2, value, err)
  end subroutine predefined_line

  !> Field `i` of `dl` names a material (MPM scenes: predefined fields are given per material's
  !> particles); `k` is its index.
  subroutine material_target(model, dl, i, k, err)
    type(model_t), intent(in) :: model
    type(data_line_t), intent(in) :: dl
    integer, intent(in) :: i
    integer, intent(out) :: k
    type(error_t), intent(inout) :: err
    character(len=:), allocatable :: name

    name = field_name(dl, i)
    do k = 1, model%n_materials
       if (model%materials(k)%name == name) return
    end do
    k = 0
    call raise_error(dl%file, dl%line, 'material ' // name // ' is not defined; expected in a ' // &
         'material-point scene the name of a *MATERIAL whose particles take the value (field ' // &
         itoa(i) // ')', err)
  end subroutine material_target
end module scene_temperature
