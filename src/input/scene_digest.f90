!> Builds the scene's digest (model_digest) from the keyword deck: a hash per keyword line
!> (name and parameters as parsed) and per data line (its fields), with file and line.
!> *RESTART is left out: how often checkpoints are written changes nothing a restart repeats,
!> so it may be changed for the continued run.
module scene_digest
  use, intrinsic :: iso_fortran_env, only: int64
  use keyword_reader, only: keyword_deck_t
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
    integer :: ib, k, j, n
    character(len=:), allocatable :: text

    n = 0
    do ib = 1, deck%n_blocks
       if (counted(deck%blocks(ib)%name)) n = n + 1 + deck%blocks(ib)%n_lines
    end do
    allocate (d%hash(n), d%line(n), d%file(n), d%files(0))
    n = 0
    do ib = 1, deck%n_blocks
       if (.not. counted(deck%blocks(ib)%name)) cycle
       associate (b => deck%blocks(ib))
         text = '*' // b%name
         if (allocated(b%params)) then
            do k = 1, size(b%params)
               text = text // field_mark // b%params(k)%name
               if (b%params(k)%has_value) text = text // '=' // merge('"', ' ', b%params(k)%quoted) // &
                    b%params(k)%value
            end do
         end if
         n = n + 1
         call record(n, text, b%file, b%line)
         do j = 1, b%n_lines
            text = ''
            if (allocated(b%lines(j)%fields)) then
               do k = 1, size(b%lines(j)%fields)
                  text = text // field_mark // b%lines(j)%fields(k)%s
               end do
            end if
            n = n + 1
            call record(n, text, b%lines(j)%file, b%lines(j)%line)
         end do
       end associate
    end do

  contains

    subroutine record(i, text, file, line)
      integer, intent(in) :: i, line
      character(len=*), intent(in) :: text, file
      integer :: f

      d%hash(i) = line_hash(text)
      d%line(i) = line
      f = file_index(file)
      if (f == 0) then
         d%files = [character(len=1024) :: d%files, file]
         f = size(d%files)
      end if
      d%file(i) = f
    end subroutine record

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

  pure integer(int64) function line_hash(text) result(h)
    character(len=*), intent(in) :: text
    integer(int64) :: a, b
    integer :: i

    a = 1
    b = 7
    do i = 1, len(text)
       a = mod(a * mult_a + ichar(text(i:i)), prime_a)
       b = mod(b * mult_b + ichar(text(i:i)), prime_b)
    end do
    a = mod(a * mult_a + len(text), prime_a)
    h = a * 2147483648_int64 + b
  end function line_hash
end module scene_digest
