!> How a prescribed condition (a load or a boundary condition) varies with time, by Abaqus's
!> rules for conditions across steps (Abaqus Analysis User's Guide, "Amplitude curves" and
!> "About prescribed conditions"; docs/keywords.md, "Prescribed conditions across steps"):
!>
!> * defined in the step (new, or named again with OP=MOD or OP=NEW): magnitude × a(t), with
!>   a(t) the referenced amplitude in its own time (step time of this step, or total time);
!>   without an amplitude the full magnitude from the step's start (Explicit's step variation);
!> * carried into a later step without being defined there: an amplitude in total time goes
!>   on being followed; an amplitude in step time is held at its value at the end of the step
!>   before (the condition keeps its last magnitude, it does not restart);
!> * an amplitude whose data end before the step does holds its last value.
!>
!> The scene builder applies the carry rule at each step start (carry_into_step); the element
!> driver and the MPM evaluate the factor with variation_factor and nothing else.
module model_time_variation
  use base_kinds, only: dp
  use model_amplitudes, only: amplitude_t
  implicit none
  private

  type, public :: time_variation_t
     integer :: amplitude = 0                 !< index into the model's amplitudes, 0: none
     logical :: held = .false.                !< carried over with a step-time amplitude
     real(dp) :: held_factor = 1              !< the factor it is held at
  end type time_variation_t

  public :: variation_factor, variation_is_constant, carry_into_step

contains

  !> The factor on the condition's magnitude at the given step and total time.
  pure real(dp) function variation_factor(v, amplitudes, step_time, total_time)
    type(time_variation_t), intent(in) :: v
    type(amplitude_t), intent(in) :: amplitudes(:)
    real(dp), intent(in) :: step_time, total_time

    if (v%held) then
       variation_factor = v%held_factor
    else if (v%amplitude == 0) then
       variation_factor = 1
    else
       variation_factor = amplitudes(v%amplitude)%value(step_time, total_time)
    end if
  end function variation_factor

  !> Is the factor the same at every time of the step?
  pure logical function variation_is_constant(v)
    type(time_variation_t), intent(in) :: v

    variation_is_constant = v%held .or. v%amplitude == 0
  end function variation_is_constant

  !> A condition carried into the next step without being defined there: a step-time amplitude
  !> is held at its value at the end of the step before (`previous_period` long, ending at total
  !> time `previous_end`); a total-time amplitude, a held factor or no amplitude stay as they are.
  pure subroutine carry_into_step(v, amplitudes, previous_period, previous_end)
    type(time_variation_t), intent(inout) :: v
    type(amplitude_t), intent(in) :: amplitudes(:)
    real(dp), intent(in) :: previous_period, previous_end

    if (v%held .or. v%amplitude == 0) return
    if (amplitudes(v%amplitude)%total_time) return
    v%held_factor = amplitudes(v%amplitude)%value(previous_period, previous_end)
    v%held = .true.
  end subroutine carry_into_step
end module model_time_variation
