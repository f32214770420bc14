!> The progress line of a run, the same for every technique: at most every 2 s of wall time,
!>   "  step 2/3 SLIDE  t 4.000E-01/1.000E+00  total 1.400E+00  inc 12345  dt 1.23E-05  ETA 0:00:42"
!> (plus the technique's note), and a line when a step ends,
!>   "  step 1/2 FILL done  t = 1.0000E+00  inc 1234  wall       12.3 s"
!> (benchmarks split a fill from a discharge with its wall time). Rank 0's own clock decides
!> when: no collective call (the ranks' clocks differ). The ETA is this run's wall time per
!> simulated second so far (since the restart, if any) times the simulated time left.
module run_progress
  use, intrinsic :: iso_fortran_env, only: output_unit, int64
  use base_kinds, only: dp
  use model, only: model_t
  use output_timer, only: clock_text
  use run_technique, only: run_clock_t, technique_t
  implicit none
  private

  type, public :: progress_t
     logical :: on = .false.                  !< print (rank 0 of a run without --quiet)
     integer(int64) :: start = 0, last = 0, rate = 1
     real(dp) :: sim_start = 0                !< total time when the loop began
  end type progress_t

  public :: progress_begin, progress_line, progress_step_done, progress_seconds

contains

  subroutine progress_begin(p, on, c)
    type(progress_t), intent(out) :: p
    logical, intent(in) :: on
    type(run_clock_t), intent(in) :: c

    p%on = on
    call system_clock(p%start, p%rate)
    p%last = p%start
    p%sim_start = c%total_time
  end subroutine progress_begin

  !> Wall seconds since progress_begin.
  real(dp) function progress_seconds(p)
    type(progress_t), intent(in) :: p
    integer(int64) :: now

    call system_clock(now)
    progress_seconds = real(now - p%start, dp) / real(p%rate, dp)
  end function progress_seconds

  !> The technique's note is asked for only when the line is written (it may format numbers).
  subroutine progress_line(p, m, c, tech)
    type(progress_t), intent(inout) :: p
    type(model_t), intent(in) :: m
    type(run_clock_t), intent(in) :: c
    class(technique_t), intent(in) :: tech
    integer(int64) :: now
    real(dp) :: elapsed, remaining, eta
    integer :: s

    if (.not. p%on) return
    call system_clock(now)
    if (real(now - p%last, dp) / real(p%rate, dp) <= 2.0_dp) return
    p%last = now
    elapsed = real(now - p%start, dp) / real(p%rate, dp)
    s = c%step
    remaining = m%steps(s)%period - c%step_time
    if (s < m%n_steps) remaining = remaining + sum(m%steps(s + 1:m%n_steps)%period)
    eta = 0
    if (c%total_time > p%sim_start) eta = elapsed / (c%total_time - p%sim_start) * remaining
    write (output_unit, '(a,i0,a,i0,1x,a,a,es10.3,a,es10.3,a,es10.3,a,i0,a,es9.2,a,a,a)') '  step ', s, '/', &
         m%n_steps, trim(m%steps(s)%name), '  t ', c%step_time, '/', m%steps(s)%period, '  total ', &
         c%total_time, '  inc ', c%increment, '  dt ', c%dt, '  ETA ', clock_text(eta), tech%progress_note()
    flush (output_unit)
  end subroutine progress_line

  subroutine progress_step_done(p, m, c)
    type(progress_t), intent(in) :: p
    type(model_t), intent(in) :: m
    type(run_clock_t), intent(in) :: c

    if (.not. p%on) return
    write (output_unit, '(a,i0,a,i0,1x,a,a,es11.4,a,i0,a,f10.1,a)') '  step ', c%step, '/', m%n_steps, &
         trim(m%steps(c%step)%name), ' done  t = ', c%total_time, '  inc ', c%increment, '  wall ', &
         progress_seconds(p), ' s'
    flush (output_unit)
  end subroutine progress_step_done
end module run_progress
