!> Builds the scene's digest (model_digest) from the keyword deck: a hash per keyword line
!> (name and parameters as parsed) and per data line (its fields), with file and line.
!> *RESTART is left out: how often checkpoints are written changes nothing a restart repeats,
!> so it may be changed for the continued run.
module scene_digest
  use, intrinsic :: iso_fortran_env, only: int64
  use keyword_reader, only: keyword_deck_t, keyword_block_t, data_line_t
  use model_digest, only: scene_digest_t
  implicit none
  private

  public :: digest_deck

  ! Two polynomial hashes modulo primes below 2^31, joined into one 62-bit value: every
  ! product stays below 2^62, so no integer overflows (a 64-bit FNV would need wrap-around,
  ! which Fortran does not define). Two lines that differ collide with a chance of ~2^-62.
  integer(int64), parameter :: prime_a = 2147483647_int64, prime_b = 2147483629_int64
  integer(int64), parameter :: mult_a = 1000003_int64, mult_b = 911382323_int64
  character(len=*), parameter :: field_mark = achar(31)   ! between fields: "a,b" is not "a" "b"

contains

  subroutine digest_deck(deck, d)
    type(keyword_deck_t), intent(in) :: deck
    type(scene_digest_t), intent(out) :: d
    integer :: ib, j, n, last_f
    character(len=:), allocatable :: last_file

    n = 0
    do ib = 1, deck%n_blocks
       if (counted(deck%blocks(ib)%name)) n = n + 1 + deck%blocks(ib)%n_lines
    end do
    allocate (d%hash(n), d%line(n), d%file(n), d%files(0))
    last_f = 0
    last_file = ''
    n = 0
    do ib = 1, deck%n_blocks
       if (.not. counted(deck%blocks(ib)%name)) cycle
       associate (b => deck%blocks(ib))
         n = n + 1
         call record_hash(n, keyword_hash(b), b%file, b%line)
         do j = 1, b%n_lines
            n = n + 1
            call record_hash(n, data_line_hash(b%lines(j)), b%lines(j)%file, b%lines(j)%line)
         end do
       end associate
    end do

  contains

    subroutine record_hash(i, hash, file, line)
      integer, intent(in) :: i, line
      integer(int64), intent(in) :: hash
      character(len=*), intent(in) :: file
      integer :: f

      d%hash(i) = hash
      d%line(i) = line
      ! consecutive lines nearly always share their file: compare with the last one first
      ! (a search of the 1024-character table for every line was a fifth of reading a big deck)
      if (last_f > 0) then
         if (len(file) == len(last_file)) then
            if (file == last_file) then
               d%file(i) = last_f
               return
            end if
         end if
      end if
      f = file_index(file)
      if (f == 0) then
         d%files = [character(len=1024) :: d%files, file]
         f = size(d%files)
      end if
      d%file(i) = f
      last_f = f
      last_file = file
    end subroutine record_hash

    integer function file_index(file) result(f)
      character(len=*), intent(in) :: file

      do f = size(d%files), 1, -1
         if (d%files(f) == file) return
      end do
      f = 0
    end function file_index

  end subroutine digest_deck

  pure logical function counted(keyword)
    character(len=*), intent(in) :: keyword

    counted = keyword /= 'RESTART'
  end function counted

  !> The hash of a keyword line: hash of '*NAME' followed, for each parameter, by
  !> field_mark, its name and '=' with the quote mark (or a blank) and the value, formed piece
  !> by piece (a keyword line of 10 k parameters is not assembled).
  integer(int64) function keyword_hash(blk) result(h)
    type(keyword_block_t), intent(in) :: blk
    integer(int64) :: a, b, total
    integer :: k

    a = 1
    b = 7
    call hash_add('*' // blk%name, a, b)
    total = 1 + len(blk%name)
    if (allocated(blk%params)) then
       do k = 1, size(blk%params)
          associate (p => blk%params(k))
            call hash_add(field_mark // p%name, a, b)
            total = total + len(field_mark) + len(p%name)
            if (p%has_value) then
               call hash_add('=' // merge('"', ' ', p%quoted) // p%value, a, b)
               total = total + 2 + len(p%value)
            end if
          end associate
       end do
    end if
    a = mod(a * mult_a + int(total), prime_a)
    h = a * 2147483648_int64 + b
  end function keyword_hash

  !> The hash of a data line's fields, each after field_mark: the hash of their
  !> concatenation, formed field by field (a line of 100 k fields is not assembled).
  integer(int64) function data_line_hash(dl) result(h)
    type(data_line_t), intent(in) :: dl
    integer(int64) :: a, b, total
    integer :: k
    character(len=:), allocatable :: field

    a = 1
    b = 7
    total = 0
    do k = 1, dl%n_fields()
       field = dl%field(k)
       call hash_add(field_mark, a, b)
       call hash_add(field, a, b)
       total = total + len(field_mark) + len(field)
    end do
    ! the length at the end (as a default integer: the hashes stay those of earlier checkpoints)
    a = mod(a * mult_a + int(total), prime_a)
    h = a * 2147483648_int64 + b
  end function data_line_hash

  pure subroutine hash_add(text, a, b)
    character(len=*), intent(in) :: text
    integer(int64), intent(inout) :: a, b
    integer :: i

    do i = 1, len(text)
       a = mod(a * mult_a + ichar(text(i:i)), prime_a)
       b = mod(b * mult_b + ichar(text(i:i)), prime_b)
    end do
  end subroutine hash_add
end module scene_digest
