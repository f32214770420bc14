!> NaN or Inf in a run: noticed at the increment it appears, said with what, where and when,
!> and the run stopped on every rank (exit 2; the message says "infinite or not a number": the
!> test suites reject any output with NaN in it) - before, a model gone bad ran on to NaN energies
!> and exited 0.
!>
!> Noticed for nothing: the energy sums the increment forms anyway (the external work sums
!> f·v·Δt over every owned node, so a non-finite velocity or load shows in it at once and a
!> non-finite internal force one increment later, through the velocities it makes; the bulk
!> viscosity and hourglass work sum every element). One test of their sum per increment, folded
!> into the collective minimum of the stable increment the increment takes anyway (a rank that
!> finds a non-finite sum gives -huge), so every rank learns of it in the same increment. Only
!> then is the state searched for the first non-finite value.
module driver_finite
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
  use base_kinds, only: dp
  use model, only: model_t
  use driver_solver, only: solver_t
  use error_report, only: error_t
  use output_collective, only: agree_on_error, stop_agreed_error
  implicit none
  private

  public :: energies_finite, stop_non_finite

  !> The value a rank gives the collective minimum of the stable increment to say "non-finite".
  real(dp), parameter, public :: non_finite_flag = -huge(1.0_dp)

contains

  !> .true. when this rank's running energy sums are finite.
  logical function energies_finite(solver)
    type(solver_t), intent(in) :: solver

    energies_finite = ieee_is_finite(solver%e_external + solver%e_viscous + solver%e_artificial + &
         solver%e_friction)
  end function energies_finite

  !> Collective: every rank searches its part, the lowest failing rank's finding is said once,
  !> every rank stops (exit 2).
  subroutine stop_non_finite(m, solver)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    character(len=:), allocatable :: where, message
    character(len=64) :: when
    logical :: mine, any_failed
    type(error_t) :: err

    where = first_non_finite(m, solver)
    mine = len(where) > 0 .or. .not. energies_finite(solver)
    if (len(where) == 0) where = non_finite_energy(solver)
    write (when, '(a,i0,a,i0,a,es12.5)') 'increment ', solver%increment, ' (step ', solver%step, &
         ') at total time ', solver%total_time
    message = trim(m%input_file) // ': ' // trim(when) // ': ' // where // ' became infinite or not a number; ' // &
         'the run stops (expected finite forces and energies: look for loads, masses or material ' // &
         'constants far out of scale, or a user material that returns values that are not numbers)'
    call agree_on_error(solver%part%comm, mine, message, any_failed)
    err%raised = .true.
    err%message = message
    call stop_agreed_error(solver%part%comm, err)
  end subroutine stop_non_finite

  !> Which running energy sum is not finite (none of the state is).
  function non_finite_energy(solver) result(text)
    type(solver_t), intent(in) :: solver
    character(len=:), allocatable :: text

    if (.not. ieee_is_finite(solver%e_external)) then
       text = 'the external work ALLWK'
    else if (.not. ieee_is_finite(solver%e_viscous)) then
       text = 'the bulk-viscosity dissipation ALLVD'
    else if (.not. ieee_is_finite(solver%e_artificial)) then
       text = 'the hourglass energy ALLAE'
    else
       text = 'the friction dissipation ALLFD'
    end if
    text = text // ' (a sum of finite forces and motions beyond the range of reals)'
  end function non_finite_energy

  !> '' or the first non-finite value of this rank: a nodal velocity, acceleration, internal or
  !> external force, or an element's stress (user node and element numbers).
  function first_non_finite(m, solver) result(text)
    type(model_t), intent(in) :: m
    type(solver_t), intent(in) :: solver
    character(len=:), allocatable :: text
    integer :: i, j, ib, e

    text = ''
    do i = 1, size(solver%part%node_global)
       do j = 1, solver%ndim
          if (.not. ieee_is_finite(solver%v(j, i))) then
             text = described('velocity V', j, solver%v(j, i), 'node', m%mesh%node_id(solver%part%node_global(i)))
          else if (.not. ieee_is_finite(solver%f_int(j, i))) then
             text = described('internal force component ', j, solver%f_int(j, i), 'node', &
                  m%mesh%node_id(solver%part%node_global(i)))
          else if (.not. ieee_is_finite(solver%f_ext(j, i))) then
             text = described('external force component ', j, solver%f_ext(j, i), 'node', &
                  m%mesh%node_id(solver%part%node_global(i)))
          else if (.not. ieee_is_finite(solver%a(j, i))) then
             text = described('acceleration A', j, solver%a(j, i), 'node', m%mesh%node_id(solver%part%node_global(i)))
          end if
          if (len(text) > 0) return
       end do
    end do
    do ib = 1, solver%n_blocks
       associate (blk => solver%blocks(ib))
         do e = 1, blk%count
            do j = 1, size(blk%stress, 2)
               if (.not. ieee_is_finite(blk%stress(e, j))) then
                  text = described('stress S', j, blk%stress(e, j), 'element', blk%elem_number(e))
                  return
               end if
            end do
         end do
       end associate
    end do
  end function first_non_finite

  function described(what, component, value, kind, number) result(text)
    character(len=*), intent(in) :: what, kind
    integer, intent(in) :: component, number
    real(dp), intent(in) :: value
    character(len=:), allocatable :: text
    character(len=32) :: buf

    write (buf, '(i0,a,i0)') component, ' of ' // kind // ' ', number
    text = what // trim(buf)
    if (ieee_is_nan(value)) then
       text = text // ' (not a number)'
    else
       text = text // ' (infinite)'
    end if
  end function described
end module driver_finite
