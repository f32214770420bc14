!> Small file-system helpers shared by the output writers.
!>
!> Fortran has no rename: the C library's `rename` is called through iso_c_binding. It is
!> what makes our "write a temporary file, then rename it over the old one" pattern atomic
!> (POSIX rename replaces the target in one step), so a crash while a checkpoint, an XDMF
!> file or a truncated history file is being written leaves the previous complete version.
module output_files
  use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char
  implicit none
  private

  public :: rename_file, delete_file, file_exists, base_name, int_to_str

  interface
     integer(c_int) function c_rename(old, new) bind(C, name='rename')
       import :: c_char, c_int
       character(kind=c_char), dimension(*), intent(in) :: old
       character(kind=c_char), dimension(*), intent(in) :: new
     end function c_rename
  end interface

contains

  !> Rename `from` to `to`, replacing `to` if it exists. `ok` is false on failure.
  subroutine rename_file(from, to, ok)
    character(len=*), intent(in) :: from
    character(len=*), intent(in) :: to
    logical, intent(out) :: ok

    ok = c_rename(trim(from) // c_null_char, trim(to) // c_null_char) == 0
  end subroutine rename_file

  !> Delete a file if it exists (no error when it does not).
  subroutine delete_file(path)
    character(len=*), intent(in) :: path
    integer :: unit, ios

    if (.not. file_exists(path)) return
    open (newunit=unit, file=path, status='old', iostat=ios)
    if (ios == 0) close (unit, status='delete', iostat=ios)
  end subroutine delete_file

  logical function file_exists(path)
    character(len=*), intent(in) :: path

    inquire (file=path, exist=file_exists)
  end function file_exists

  !> The file name without its directory ("out/run.h5" -> "run.h5"): the XDMF file refers
  !> to the HDF5 file next to it by this relative name, so the pair can be moved together.
  pure function base_name(path) result(name)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: name
    integer :: slash

    slash = index(path, '/', back=.true.)
    name = path(slash + 1:)
  end function base_name

  pure function int_to_str(i) result(s)
    integer, intent(in) :: i
    character(len=:), allocatable :: s
    character(len=24) :: buf

    write (buf, '(i0)') i
    s = trim(buf)
  end function int_to_str

end module output_files
