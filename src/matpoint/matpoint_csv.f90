!> CSV output of a material-point run: one header line, then one row for the initial
!> state and one per increment. Numbers are written with 16 significant digits so that
!> post-processing and checks can use them at full precision.
!>
!> Columns (signs as in Abaqus: tension positive, dilation positive, unless said):
!>   time             total time at the end of the increment (0 for the initial row)
!>   stage            stage number (0 for the initial row)
!>   e11 e22 e33 e12 [e23 e31]   accumulated logarithmic strain, TENSOR shear (γ12 = 2 e12)
!>   s11 s22 s33 s12 [s23 s31]   Cauchy stress (corotational = global: no rotation)
!>   p                mean stress, COMPRESSION positive: −(s11+s22+s33)/3
!>   q                von Mises equivalent stress √(3 J2)
!>   ev               volumetric strain e11+e22+e33 (dilation positive)
!>   ea               axial strain e_aa (TRIAXIAL, BIAXIAL, OEDOMETER; a = AXIS)
!>   sv sh            OEDOMETER: vertical (axial) and horizontal stress, COMPRESSION positive
!>   gamma tau        SIMPLE SHEAR: engineering shear strain 2 e12 and shear stress s12
!>   <SDV names>      every state variable: names from *DEPVAR lines, else PEEQ, EVP, EV,
!>                    SIG1C, YIELD, COH, PHI, PSI for our MC/DP (umat/README.md), else SDV<i>
!>   FV1 ...          field variables used in the increment (with *USER DEFINED FIELD)
!>   ener_intern ener_inelas    specific internal / inelastic energy (per unit mass)
module matpoint_csv
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use model_materials, only: material_t
  use material_props, only: model_from_name, model_mohr_coulomb, model_drucker_prager
  use material_state, only: state_names
  use matpoint_path, only: matpoint_path_t, component_label, test_triaxial, test_biaxial, &
       test_oedometer, test_simple_shear, simple_shear_component
  use matpoint_solver, only: matpoint_history_t
  implicit none
  private

  public :: write_matpoint_csv, csv_header, mean_pressure, von_mises

contains

  !> Mean stress, compression positive.
  pure real(dp) function mean_pressure(ncomp, s)
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: s(ncomp)

    mean_pressure = -(s(1) + s(2) + s(3)) / 3.0_dp
  end function mean_pressure

  !> √(3 J2) with tensor shear components (each counted twice in s:s).
  pure real(dp) function von_mises(ncomp, s)
    integer, intent(in) :: ncomp
    real(dp), intent(in) :: s(ncomp)
    real(dp) :: m, j2

    m = (s(1) + s(2) + s(3)) / 3.0_dp
    j2 = 0.5_dp * ((s(1) - m)**2 + (s(2) - m)**2 + (s(3) - m)**2) + sum(s(4:ncomp)**2)
    von_mises = sqrt(3.0_dp * j2)
  end function von_mises

  !> The header line (comma-separated column names).
  function csv_header(mat, path, h) result(line)
    type(material_t), intent(in) :: mat
    type(matpoint_path_t), intent(in) :: path
    type(matpoint_history_t), intent(in) :: h
    character(len=:), allocatable :: line
    character(len=16) :: buf
    integer :: i

    line = 'time,stage'
    do i = 1, h%ncomp
       line = line // ',e' // component_label(i)
    end do
    do i = 1, h%ncomp
       line = line // ',s' // component_label(i)
    end do
    line = line // ',p,q,ev'
    select case (path%test)
    case (test_triaxial, test_biaxial)
       line = line // ',ea'
    case (test_oedometer)
       line = line // ',ea,sv,sh'
    case (test_simple_shear)
       line = line // ',gamma,tau'
    end select
    do i = 1, h%nstatev
       line = line // ',' // sdv_label(mat, i)
    end do
    do i = 1, h%nfieldv
       write (buf, '(a,i0)') 'FV', i
       line = line // ',' // trim(buf)
    end do
    line = line // ',ener_intern,ener_inelas'
  end function csv_header

  !> Write the history to `filename`.
  subroutine write_matpoint_csv(filename, mat, path, h, err)
    character(len=*), intent(in) :: filename
    type(material_t), intent(in) :: mat
    type(matpoint_path_t), intent(in) :: path
    type(matpoint_history_t), intent(in) :: h
    type(error_t), intent(inout), optional :: err
    integer :: unit, ios, row, nc
    real(dp), allocatable :: v(:)
    real(dp) :: s(h%ncomp), e(h%ncomp)

    open (newunit=unit, file=filename, status='replace', action='write', iostat=ios)
    if (ios /= 0) then
       call raise_error(filename, 0, 'cannot open the CSV file for writing', err)
       return
    end if
    write (unit, '(a)') csv_header(mat, path, h)
    nc = h%ncomp
    do row = 1, h%n_rows
       e = h%strain(:, row)
       s = h%stress(:, row)
       v = [h%time(row), real(h%stage(row), dp), e, s, mean_pressure(nc, s), von_mises(nc, s), &
            e(1) + e(2) + e(3)]
       select case (path%test)
       case (test_triaxial, test_biaxial)
          v = [v, e(path%axis)]
       case (test_oedometer)
          v = [v, e(path%axis), -s(path%axis), -s(path%lateral())]
       case (test_simple_shear)
          v = [v, 2.0_dp * e(simple_shear_component), s(simple_shear_component)]
       end select
       v = [v, h%state(:, row), h%field(:, row), h%ener_intern(row), h%ener_inelas(row)]
       call write_row(unit, v, h%stage(row))
    end do
    close (unit)
  end subroutine write_matpoint_csv

  !> One row; the stage (2nd value) as an integer, the rest as es23.15e3.
  subroutine write_row(unit, v, stage)
    integer, intent(in) :: unit
    real(dp), intent(in) :: v(:)
    integer, intent(in) :: stage
    character(len=32) :: buf
    character(len=:), allocatable :: line
    integer :: i

    write (buf, '(es23.15e3)') v(1)
    line = trim(adjustl(buf))
    write (buf, '(i0)') stage
    line = line // ',' // trim(buf)
    do i = 3, size(v)
       write (buf, '(es23.15e3)') v(i)
       line = line // ',' // trim(adjustl(buf))
    end do
    write (unit, '(a)') line
  end subroutine write_row

  !> Column label of state variable `i`: the name given on a *DEPVAR line, else for our MC and
  !> DP models their names (umat/README.md, "State variables"), else SDV<i>.
  function sdv_label(mat, i) result(label)
    type(material_t), intent(in) :: mat
    integer, intent(in) :: i
    character(len=:), allocatable :: label
    character(len=16) :: buf

    if (allocated(mat%sdv_names)) then
       if (i <= size(mat%sdv_names)) then
          if (len_trim(mat%sdv_names(i)) > 0) then
             label = trim(mat%sdv_names(i))
             return
          end if
       end if
    end if
    select case (model_from_name(mat%vumat_name))
    case (model_mohr_coulomb, model_drucker_prager)
       if (i <= size(state_names)) then
          label = trim(state_names(i))
          return
       end if
    end select
    write (buf, '(a,i0)') 'SDV', i
    label = trim(buf)
  end function sdv_label

end module matpoint_csv
