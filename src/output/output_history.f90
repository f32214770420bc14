!> History output: one CSV file per run, written by rank 0 only.
!>
!> First line: the column names, comma-separated (Abaqus history identifiers: time, ALLKE,
!> ALLIE, ..., RF2_<set> ... as the driver chooses them). Then one row per history output:
!> numbers as ES23.15E3 (16 significant digits, so a double reads back to within one unit
!> in the last place), comma-separated without blanks. Each row is flushed at once, so a
!> run that stops leaves every row it computed, and post-processing can follow a live run.
!>
!> Restart: history_open(..., restart_rows=n) or (..., restart_time=t) keeps the header and
!> the first n rows, or the rows whose first column (the time) is not after t, drops the
!> rest (rows of the interrupted run after its last checkpoint) and appends from there. The
!> kept rows are copied to a temporary file renamed over the old one, so a crash during the
!> truncation keeps the old file. The header must not have changed.
!>
!> All procedures may be called on every rank: with `comm` given, only its rank 0 touches
!> the file; errors found on open are shared with all ranks.
module output_history
  use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Bcast, MPI_INTEGER
  use base_kinds, only: dp
  use error_report, only: error_t, raise_error
  use output_files, only: rename_file, file_exists, int_to_str
  use output_collective, only: agree_on_error
  implicit none
  private

  public :: history_t, history_open, history_row, history_close, history_row_count

  !> Edit descriptor of one number.
  character(len=*), parameter :: number_format = '(es23.15e3)'

  !> An open history file (components private).
  type :: history_t
     private
     logical :: writer = .false.        !< this process writes the file
     integer :: unit = -1
     integer :: n_columns = 0
     integer :: rows = 0                !< data rows in the file
     character(len=:), allocatable :: path
  end type history_t

contains

  !> Create the file (or, with restart_rows / restart_time, truncate and reopen it) and write
  !> the header. With `comm`, collective: rank 0 writes.
  subroutine history_open(h, path, columns, comm, restart_rows, restart_time, err)
    type(history_t), intent(out) :: h
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: columns(:)
    type(MPI_Comm), intent(in), optional :: comm
    integer, intent(in), optional :: restart_rows
    real(dp), intent(in), optional :: restart_time
    type(error_t), intent(inout), optional :: err
    character(len=:), allocatable :: header, msg
    logical :: any_failed
    integer :: rank, i, ios

    rank = 0
    if (present(comm)) call MPI_Comm_rank(comm, rank)
    h%writer = rank == 0
    h%path = path
    h%n_columns = size(columns)

    if (h%writer) then
       header = ''
       do i = 1, size(columns)
          if (len_trim(columns(i)) == 0 .or. scan(trim(columns(i)), ', "') > 0) then
             msg = 'column ' // int_to_str(i) // ' has an empty name or one with a comma, ' // &
                  'blank or quote: "' // trim(columns(i)) // '"'
             exit
          end if
          if (i > 1) header = header // ','
          header = header // trim(columns(i))
       end do
       if (size(columns) == 0) msg = 'no columns'
       if (.not. allocated(msg)) then
          if (present(restart_rows) .or. present(restart_time)) then
             call truncate_for_restart(h, header, msg, restart_rows, restart_time)
             if (.not. allocated(msg)) then
                open (newunit=h%unit, file=path, status='old', position='append', &
                     action='write', form='formatted', iostat=ios)
                if (ios /= 0) msg = 'cannot reopen the file for appending'
             end if
          else
             open (newunit=h%unit, file=path, status='replace', action='write', &
                  form='formatted', iostat=ios)
             if (ios /= 0) then
                msg = 'cannot create the file'
             else
                write (h%unit, '(a)', iostat=ios) header
                flush (h%unit)
                if (ios /= 0) msg = 'cannot write the header'
             end if
          end if
       end if
    end if

    if (present(comm)) then
       call agree_on_error(comm, allocated(msg), msg, any_failed)
       ! The rows kept by a restart are known on rank 0 only.
       if (.not. any_failed) call MPI_Bcast(h%rows, 1, MPI_INTEGER, 0, comm)
    else
       any_failed = allocated(msg)
    end if
    if (any_failed) then
       if (h%writer .and. h%unit /= -1) close (h%unit, iostat=ios)
       h%unit = -1
       h%writer = .false.
       call raise_error(path, 0, msg, err)
    end if
  end subroutine history_open

  !> One row; values(:) in the order of the columns. A no-op on ranks other than 0.
  subroutine history_row(h, values)
    type(history_t), intent(inout) :: h
    real(dp), intent(in) :: values(:)
    character(len=:), allocatable :: line
    character(len=32) :: buf
    integer :: i, ios

    ! Counted on every rank, so history_row_count can go into any rank's checkpoint.
    h%rows = h%rows + 1
    if (.not. h%writer) return
    if (size(values) /= h%n_columns) call raise_error(h%path, 0, &
         'a row of ' // int_to_str(size(values)) // ' values for ' // &
         int_to_str(h%n_columns) // ' columns')
    line = ''
    do i = 1, size(values)
       write (buf, number_format) values(i)
       if (i > 1) line = line // ','
       line = line // trim(adjustl(buf))
    end do
    write (h%unit, '(a)', iostat=ios) line
    if (ios /= 0) call raise_error(h%path, 0, 'write failed')
    flush (h%unit)
  end subroutine history_row

  subroutine history_close(h)
    type(history_t), intent(inout) :: h
    integer :: ios

    if (h%writer .and. h%unit /= -1) close (h%unit, iostat=ios)
    h%unit = -1
    h%writer = .false.
  end subroutine history_close

  !> Data rows in the file (header excluded), the same on every rank. A checkpoint records
  !> it so that a restart can truncate exactly (history_open restart_rows).
  pure integer function history_row_count(h)
    type(history_t), intent(in) :: h

    history_row_count = h%rows
  end function history_row_count

  !> Keep the header and the rows up to the restart point; `msg` set on a problem.
  subroutine truncate_for_restart(h, header, msg, restart_rows, restart_time)
    type(history_t), intent(inout) :: h
    character(len=*), intent(in) :: header
    character(len=:), allocatable, intent(inout) :: msg
    integer, intent(in), optional :: restart_rows
    real(dp), intent(in), optional :: restart_time
    character(len=:), allocatable :: line, tmp
    character(len=32) :: buf
    real(dp) :: t_row, t_limit
    integer :: in, out, ios, comma
    logical :: ok

    if (.not. file_exists(h%path)) then
       msg = 'cannot restart: the file does not exist'
       return
    end if
    if (present(restart_time)) then
       ! Compare times as they were printed: a row written at exactly the restart time
       ! reads back as the printed (rounded) value, which must count as "not after".
       write (buf, number_format) restart_time
       read (buf, *) t_limit
    end if
    open (newunit=in, file=h%path, status='old', action='read', form='formatted', iostat=ios)
    if (ios /= 0) then
       msg = 'cannot open the file to restart'
       return
    end if
    call read_line(in, line, ios)
    if (ios /= 0 .or. line /= header) then
       msg = 'cannot restart: the header in the file differs from the columns of this run'
       close (in)
       return
    end if
    tmp = h%path // '.tmp'
    open (newunit=out, file=tmp, status='replace', action='write', form='formatted', iostat=ios)
    if (ios /= 0) then
       msg = 'cannot write ' // tmp
       close (in)
       return
    end if
    write (out, '(a)') header
    h%rows = 0
    do
       if (present(restart_rows)) then
          if (h%rows >= restart_rows) exit
       end if
       call read_line(in, line, ios)
       if (ios /= 0) exit
       if (present(restart_time)) then
          comma = index(line, ',')
          if (comma == 0) comma = len(line) + 1
          read (line(:comma - 1), *, iostat=ios) t_row
          if (ios /= 0) then
             msg = 'cannot restart: unreadable time in row ' // int_to_str(h%rows + 1)
             exit
          end if
          if (t_row > t_limit) exit
       end if
       write (out, '(a)') line
       h%rows = h%rows + 1
    end do
    close (in)
    close (out)
    if (.not. allocated(msg) .and. present(restart_rows)) then
       if (h%rows < restart_rows) msg = 'cannot restart after row ' // &
            int_to_str(restart_rows) // ': the file holds only ' // int_to_str(h%rows) // ' rows'
    end if
    if (allocated(msg)) then
       open (newunit=out, file=tmp, status='old', iostat=ios)
       if (ios == 0) close (out, status='delete')
       return
    end if
    call rename_file(tmp, h%path, ok)
    if (.not. ok) msg = 'cannot replace the file by its truncated copy ' // tmp
  end subroutine truncate_for_restart

  !> One line of any length (non-advancing reads in chunks).
  subroutine read_line(unit, line, ios)
    integer, intent(in) :: unit
    character(len=:), allocatable, intent(out) :: line
    integer, intent(out) :: ios
    character(len=512) :: chunk
    integer :: n

    line = ''
    do
       read (unit, '(a)', advance='no', size=n, iostat=ios) chunk
       line = line // chunk(:n)
       if (ios /= 0) exit
    end do
    ! End of record ends the line; end of file with text read is still a (last) line.
    if (is_iostat_eor(ios)) ios = 0
    if (is_iostat_end(ios) .and. len(line) > 0) ios = 0
  end subroutine read_line

end module output_history
