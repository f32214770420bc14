!> Warnings on gravity that jumps at the start of a step. Abaqus's rules keep a load that is
!> carried over unchanged; it jumps only where the scene says so: defined again (OP=MOD or
!> OP=NEW) with an amplitude in step time that starts elsewhere (a ramp from 0 restarts the
!> load), with another magnitude and no amplitude, or dropped by OP=NEW. Such a jump is rarely
!> meant in a hopper (the fill springs up when gravity falls at the outlet's opening), so the
!> scene builder names the *DLOAD line and says what to write instead. The run goes on.
module scene_step_continuity
  use base_kinds, only: dp
  use model, only: model_t
  use model_steps, only: gravity_t
  use model_time_variation, only: variation_factor
  use scene_util, only: rtoa
  implicit none
  private

  public :: warn_gravity_jumps

contains

  !> Compare, per element set, the gravity at the end of step s-1 with that at the start of
  !> step s (which begins at total time `step_start`).
  subroutine warn_gravity_jumps(model, s, step_start)
    type(model_t), intent(inout) :: model
    integer, intent(in) :: s
    real(dp), intent(in) :: step_start
    real(dp) :: before(3), after(3), scale
    integer :: k, elset
    character(len=:), allocatable :: where, what, target

    associate (prev => model%steps(s - 1), now => model%steps(s))
      do k = 1, size(prev%gravity) + size(now%gravity)
         if (k <= size(prev%gravity)) then
            elset = prev%gravity(k)%elset
         else
            elset = now%gravity(k - size(prev%gravity))%elset
            if (any(prev%gravity%elset == elset)) cycle     ! compared already
         end if
         before = gravity_on(model, prev%gravity, elset, prev%period, step_start)
         after = gravity_on(model, now%gravity, elset, 0.0_dp, step_start)
         ! (a load carried over keeps its value, so a jump comes from a definition in step s)
         scale = max(norm2(before), norm2(after))
         if (.not. (norm2(after - before) > 1.0e-9_dp * scale)) cycle
         if (any(now%gravity%elset == elset)) then
            where = trim(now%gravity(findloc(now%gravity%elset, elset, dim=1))%source)
            what = 'is defined again there'
            if (now%gravity(findloc(now%gravity%elset, elset, dim=1))%variation%amplitude > 0) &
                 what = 'is defined again there and its step-time amplitude starts anew'
         else
            where = trim(prev%gravity(findloc(prev%gravity%elset, elset, dim=1))%source)
            what = 'is dropped there (OP=NEW)'
         end if
         target = 'the whole model'
         if (elset > 0) target = 'element set ' // trim(model%elsets(elset)%name)
         call add_warning(model, where // ': gravity on ' // target // ' jumps from ' // &
              rtoa(norm2(before)) // ' to ' // rtoa(norm2(after)) // ' at the start of step ' // &
              trim(now%name) // ': it ' // what // '; for gravity that stays on, define it once ' // &
              '(a load carried over keeps its value) or give its amplitude TIME=TOTAL TIME')
      end do
    end associate
  end subroutine warn_gravity_jumps

  !> The gravity vector of the loads on one element set at the given step and total time.
  function gravity_on(model, loads, elset, step_time, total_time) result(g)
    type(model_t), intent(in) :: model
    type(gravity_t), intent(in) :: loads(:)
    integer, intent(in) :: elset
    real(dp), intent(in) :: step_time, total_time
    real(dp) :: g(3)
    integer :: k

    g = 0
    do k = 1, size(loads)
       if (loads(k)%elset /= elset) cycle
       g = g + loads(k)%magnitude * loads(k)%direction * &
            variation_factor(loads(k)%variation, model%amplitudes, step_time, total_time)
    end do
  end function gravity_on

  subroutine add_warning(model, text)
    type(model_t), intent(inout) :: model
    character(len=*), intent(in) :: text
    character(len=len(model%warnings)), allocatable :: tmp(:)

    if (.not. allocated(model%warnings)) allocate (model%warnings(0))
    allocate (tmp(size(model%warnings) + 1))
    tmp(1:size(model%warnings)) = model%warnings
    tmp(size(tmp)) = text
    call move_alloc(tmp, model%warnings)
  end subroutine add_warning
end module scene_step_continuity
