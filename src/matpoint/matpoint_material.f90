!> The material of a material-point run, as Abaqus describes it: name (passed to the
!> VUMAT as `cmname`), `*USER MATERIAL` constants, `*DENSITY`, `*DEPVAR` and whether a
!> `*USER DEFINED FIELD` (VUSDFLD) is active. Also the names of the state variables for
!> output: those given on `*DEPVAR` lines, else the umat/README.md names for our own
!> models (MC, DP), else SDV<i>.
module matpoint_material
  use material_kinds, only: dp
  implicit none
  private

  public :: matpoint_material_t, material_cmname, sdv_label, is_bulkflow_plastic_model

  !> Names of our MC/DP state variables (umat/README.md, "State variables").
  character(len=5), parameter :: builtin_sdv_names(8) = &
       [character(len=5) :: 'PEEQ', 'EVP', 'EV', 'SIG1C', 'YIELD', 'COH', 'PHI', 'PSI']

  type :: name_t
     character(len=:), allocatable :: s
  end type name_t

  type :: matpoint_material_t
     character(len=:), allocatable :: name        !< upper case, as given on *MATERIAL
     real(dp), allocatable :: props(:)            !< *USER MATERIAL constants
     real(dp) :: density = 1.0_dp                 !< reference (initial) density
     integer :: nstatev = 0                       !< *DEPVAR
     logical :: user_field = .false.              !< *USER DEFINED FIELD present: call vusdfld
     integer :: nfieldv = 0                       !< field variables passed to vusdfld/vumat
     type(name_t), allocatable :: sdv_names(:)    !< optional names from *DEPVAR lines
  contains
     procedure :: set_sdv_name
  end type matpoint_material_t

contains

  !> The name as Abaqus passes it: upper case, left-justified, 80 characters.
  pure function material_cmname(mat) result(cmname)
    type(matpoint_material_t), intent(in) :: mat
    character(len=80) :: cmname

    cmname = ''
    if (allocated(mat%name)) cmname = adjustl(mat%name)
  end function material_cmname

  !> True when the leading token of the name selects our MC or DP model (umat/README.md).
  pure logical function is_bulkflow_plastic_model(name)
    character(len=*), intent(in) :: name
    integer :: i, n

    n = len_trim(name)
    i = 1
    do while (i <= n)
       if (index('-_. ', name(i:i)) > 0) exit
       i = i + 1
    end do
    select case (name(1:i - 1))
    case ('MC', 'MOHRCOULOMB', 'DP', 'DRUCKERPRAGER')
       is_bulkflow_plastic_model = .true.
    case default
       is_bulkflow_plastic_model = .false.
    end select
  end function is_bulkflow_plastic_model

  !> Record the output name of state variable `i` (from a *DEPVAR data line).
  subroutine set_sdv_name(self, i, name)
    class(matpoint_material_t), intent(inout) :: self
    integer, intent(in) :: i
    character(len=*), intent(in) :: name
    integer :: k

    if (i < 1 .or. i > self%nstatev) return
    if (.not. allocated(self%sdv_names)) then
       allocate (self%sdv_names(self%nstatev))
       do k = 1, self%nstatev
          self%sdv_names(k)%s = ''
       end do
    end if
    self%sdv_names(i)%s = trim(name)
  end subroutine set_sdv_name

  !> Column label of state variable `i`.
  pure function sdv_label(mat, i) result(label)
    type(matpoint_material_t), intent(in) :: mat
    integer, intent(in) :: i
    character(len=:), allocatable :: label
    character(len=16) :: buf

    if (allocated(mat%sdv_names)) then
       if (i <= size(mat%sdv_names)) then
          if (len(mat%sdv_names(i)%s) > 0) then
             label = mat%sdv_names(i)%s
             return
          end if
       end if
    end if
    if (allocated(mat%name) .and. i <= size(builtin_sdv_names)) then
       if (is_bulkflow_plastic_model(mat%name)) then
          label = trim(builtin_sdv_names(i))
          return
       end if
    end if
    write (buf, '(a,i0)') 'SDV', i
    label = trim(buf)
  end function sdv_label

end module matpoint_material
