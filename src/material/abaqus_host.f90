!> Host-side state behind the Abaqus utility routines a user subroutine may call.
!>
!> Abaqus's `vgetvrm` takes no argument naming the block, so the host must say beforehand
!> which block is current: `host_set_block` points at its start-of-increment stress and
!> logarithmic strain (VUMAT layout, `(nblock, ncomp)`), and `host_set_block_extra` at its state
!> variables, temperature and, for our plastic models, PEEQ (a plastic strain given is copied),
!> until `host_clear_block` after the VUSDFLD call. Why pointers, not copies: the copies (and the
!> state's reallocation), made for every block whether or not the VUSDFLD asks for a key, go;
!> `vgetvrm` copies only what is asked (perf, ch. 4 discharge on 1 rank: memcpy samples per
!> increment −8 %, about 1 % of the run; results the same bytes). The caller's arrays must stay
!> in place until the clear (TARGET dummies of the caller, no temporary), and
!> `host_set_block_moduli` the material's isotropic moduli (PE = LE − C⁻¹:σ for any material),
!> `host_set_block_material` whose block it is (messages); the external `vgetvrm` reads them back
!> in Abaqus's flat layout (docs/user_subroutines.md lists the keys).
!> A key whose values the current block does not have is an error that names the key, the
!> material and the keys the block has (`host_available_keys`): user code that ignores jStatus
!> would otherwise read whatever its buffer held.
!> `host_set_job` records what vgetjobname, vgetoutdir, vgetrank and vgetnumcpus answer.
!> `host_set_exit_handler` lets the application decide how `xplb_exit` ends the run (plain
!> exit, or MPI_Abort in the parallel solver).
module abaqus_host
  use base_kinds, only: dp
  implicit none
  private

  abstract interface
     subroutine exit_handler(status)
       integer, intent(in) :: status
     end subroutine exit_handler
  end interface

  real(dp), pointer :: block_stress(:, :) => null(), block_log_strain(:, :) => null()
  real(dp), pointer :: block_state(:, :) => null(), block_temp(:) => null(), block_peeq(:) => null()
  real(dp), allocatable :: block_plastic(:, :)
  integer :: block_size = 0, block_components = 0
  !> Isotropic moduli λ, G of the current block's material (packaging call); < 0: not known.
  real(dp) :: block_lambda = -1, block_shear = -1
  !> The current block's material (its scene name) and whether the user's VUMAT computes it.
  character(len=:), allocatable :: block_material
  logical :: block_user_vumat = .false.
  procedure(exit_handler), pointer :: on_exit => null()
  character(len=:), allocatable :: job_name, output_dir
  integer :: job_rank = 0, job_ranks = 1

  public :: exit_handler
  public :: host_set_block, host_set_block_extra, host_set_block_moduli, host_get_variable, host_clear_block
  public :: host_set_exit_handler, host_exit
  public :: host_available_keys, host_set_block_material, host_block_material, host_missing_key_note
  public :: host_set_job, host_job_name, host_output_dir, host_rank, host_ranks

contains

  !> The current block's stress and LE; the extras of the previous block are forgotten.
  subroutine host_set_block(nblock, ncomp, stress, log_strain)
    integer, intent(in) :: nblock, ncomp
    real(dp), intent(in), target :: stress(:, :), log_strain(:, :)

    block_size = nblock
    block_components = ncomp
    block_stress => stress(1:nblock, 1:ncomp)
    block_log_strain => log_strain(1:nblock, 1:ncomp)
    nullify (block_state, block_temp, block_peeq)
    if (allocated(block_plastic)) deallocate(block_plastic)
    block_lambda = -1
    block_shear = -1
  end subroutine host_set_block

  !> No current block (after the VUSDFLD call: the arrays pointed at may go).
  subroutine host_clear_block()
    block_size = 0
    block_components = 0
    nullify (block_stress, block_log_strain, block_state, block_temp, block_peeq)
    if (allocated(block_plastic)) deallocate(block_plastic)
  end subroutine host_clear_block

  !> The current block's material (its name in the scene) and whether a user's VUMAT computes it
  !> (then the host keeps no equivalent plastic strain for it).
  subroutine host_set_block_material(name, user_vumat)
    character(len=*), intent(in) :: name
    logical, intent(in) :: user_vumat
    block_material = trim(name)
    block_user_vumat = user_vumat
  end subroutine host_set_block_material

  function host_block_material() result(name)
    character(len=:), allocatable :: name
    name = set_or(block_material, '(unknown)')
  end function host_block_material

  !> `text` once it has been set, else `default`.
  pure function set_or(text, default) result(answer)
    character(len=:), allocatable, intent(in) :: text
    character(len=*), intent(in) :: default
    character(len=:), allocatable :: answer

    answer = default
    if (allocated(text)) answer = text
  end function set_or

  !> Why the current block has no `key` (for vgetvrm's error), '' when there is nothing to add.
  !> PEEQ: Abaqus keeps an equivalent plastic strain only for its own plasticity models (a user
  !> material's inelastic history lives in its state variables, *Abaqus Analysis User's Guide*,
  !> "User-defined mechanical material behavior"); so does bulkflow.
  function host_missing_key_note(key) result(note)
    character(len=*), intent(in) :: key
    character(len=:), allocatable :: note

    note = ''
    if (trim(adjustl(key)) /= 'PEEQ') return
    if (block_user_vumat) then
       note = '; PEEQ exists only for built-in plasticity: a user VUMAT keeps its equivalent plastic ' // &
            'strain in a state variable (read it with vgetvrm(''SDV''))'
    else
       note = '; PEEQ exists only for plastic materials (our Mohr-Coulomb and Drucker-Prager)'
    end if
  end function host_missing_key_note

  !> The isotropic elastic moduli of the current block's material (its packaging call): with them
  !> vgetvrm('PE') answers LE − C⁻¹:σ when the block keeps no plastic strain of its own.
  subroutine host_set_block_moduli(lambda, shear)
    real(dp), intent(in) :: lambda, shear
    block_lambda = lambda
    block_shear = shear
  end subroutine host_set_block_moduli

  !> Further start-of-increment values of the current block (after host_set_block): state
  !> variables (SDV), temperature (TEMP), and when the material has them plastic strain (PE)
  !> and equivalent plastic strain (PEEQ).
  subroutine host_set_block_extra(state, temp, plastic, peeq)
    real(dp), intent(in), target :: state(:, :), temp(:)
    real(dp), intent(in), optional :: plastic(:, :)
    real(dp), intent(in), optional, target :: peeq(:)

    block_state => state(1:block_size, :)
    block_temp => temp(1:block_size)
    if (present(plastic)) then
       if (size(plastic, 1) >= block_size) block_plastic = plastic(1:block_size, :)
    end if
    if (present(peeq)) block_peeq => peeq(1:block_size)
  end subroutine host_set_block_extra

  !> Fill `values` in Abaqus's layout (component-major: all points of component 1 first).
  !> `status` is 0 on success, 1 for a key this host does not provide for the current block.
  subroutine host_get_variable(key, values, status)
    character(len=*), intent(in) :: key
    real(dp), intent(out) :: values(*)
    integer, intent(out) :: status

    status = 1
    if (block_size == 0) return
    select case (trim(adjustl(key)))
    case ('S')
       call put(block_stress)
    case ('LE')
       call put(block_log_strain)
    case ('SDV')
       if (.not. associated(block_state)) return
       call put(block_state)
    case ('TEMP')
       if (.not. associated(block_temp)) return
       values(1:block_size) = block_temp
    case ('PE')
       if (allocated(block_plastic)) then
          call put(block_plastic)
       else
          if (block_shear <= 0 .or. 3 * block_lambda + 2 * block_shear <= 0) return
          call put(plastic_from_moduli())
       end if
    case ('PEEQ')
       if (.not. associated(block_peeq)) return
       values(1:block_size) = block_peeq
    case default
       return
    end select
    status = 0
  contains
    !> LE − C⁻¹:σ for isotropic C (λ, G): ε_e = σ/(2G) − λ tr σ/(2G (3λ + 2G)) I, tensor shears.
    function plastic_from_moduli() result(pe)
      real(dp) :: pe(block_size, block_components), trace(block_size)
      integer :: j
      trace = block_stress(1:block_size, 1) + block_stress(1:block_size, 2) + block_stress(1:block_size, 3)
      do j = 1, block_components
         pe(:, j) = block_log_strain(1:block_size, j) - block_stress(1:block_size, j) / (2 * block_shear)
         if (j <= 3) pe(:, j) = pe(:, j) + block_lambda * trace / (2 * block_shear * (3 * block_lambda + &
              2 * block_shear))
      end do
    end function plastic_from_moduli
    subroutine put(a)
      real(dp), intent(in) :: a(:, :)
      integer :: j
      do j = 1, size(a, 2)
         values((j - 1) * block_size + 1:j * block_size) = a(1:block_size, j)
      end do
    end subroutine put
  end subroutine host_get_variable

  !> The vgetvrm keys the current block provides, for the error message of an unsupported one.
  function host_available_keys() result(keys)
    character(len=:), allocatable :: keys

    keys = ''
    if (block_size == 0) then
       keys = 'none (no material block is being computed)'
       return
    end if
    keys = 'S, LE'
    if (associated(block_state)) keys = keys // ', SDV'
    if (associated(block_temp)) keys = keys // ', TEMP'
    if (allocated(block_plastic) .or. block_shear > 0) keys = keys // ', PE'
    if (associated(block_peeq)) keys = keys // ', PEEQ'
  end function host_available_keys

  !> The run's name (output base), output folder, this process's rank and the number of ranks.
  subroutine host_set_job(name, folder, rank, ranks)
    character(len=*), intent(in) :: name, folder
    integer, intent(in) :: rank, ranks
    job_name = name
    output_dir = folder
    job_rank = rank
    job_ranks = ranks
  end subroutine host_set_job

  function host_job_name() result(name)
    character(len=:), allocatable :: name
    name = set_or(job_name, 'bulkflow')
  end function host_job_name

  function host_output_dir() result(folder)
    character(len=:), allocatable :: folder
    folder = set_or(output_dir, '.')
  end function host_output_dir

  integer function host_rank()
    host_rank = job_rank
  end function host_rank

  integer function host_ranks()
    host_ranks = job_ranks
  end function host_ranks

  subroutine host_set_exit_handler(handler)
    procedure(exit_handler) :: handler
    on_exit => handler
  end subroutine host_set_exit_handler

  !> End the run on behalf of user code; never returns.
  subroutine host_exit(status)
    integer, intent(in) :: status

    if (associated(on_exit)) call on_exit(status)
    ! A stop code must be a constant in Fortran 2008: 2 (bad input, as the host's own errors
    ! exit) or 3 (user code asked to stop).
    if (status == 2) error stop 2
    error stop 3
  end subroutine host_exit
end module abaqus_host
