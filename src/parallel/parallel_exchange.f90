!> Exchanges of real(dp) buffers between ranks for a spatial decomposition (the MPM's halo sums
!> and particle migration):
!>
!> * `exchange_neighbours`: every rank sends one buffer to each of its neighbours and receives
!>   one from each (non-blocking, sizes known on both sides: a plan both derive alike);
!> * `exchange_all`: every rank sends a buffer of any length to every rank (lengths first, then
!>   the data; MPI_Alltoall + MPI_Alltoallv), the received pieces in rank order.
!>
!> Both are collective over the ranks that take part (exchange_all: all ranks of `comm`).
module parallel_exchange
  use mpi_f08, only: MPI_Comm, MPI_Request, MPI_Isend, MPI_Irecv, MPI_Waitall, MPI_STATUSES_IGNORE, &
       MPI_DOUBLE_PRECISION, MPI_INTEGER, MPI_Alltoall, MPI_Alltoallv
  use base_kinds, only: dp
  implicit none
  private

  public :: exchange_neighbours, exchange_all

  !> Message tag of the neighbour exchange (the element assembly uses 7301).
  integer, parameter :: tag_halo = 7302

contains

  !> Send send_buf(send_first(k) : send_first(k + 1) − 1) to rank nbr(k) and receive
  !> recv_buf(recv_first(k) : recv_first(k + 1) − 1) from it, for every neighbour k. Collective
  !> over the neighbours (each pair must list the other).
  subroutine exchange_neighbours(comm, nbr, send_first, send_buf, recv_first, recv_buf)
    type(MPI_Comm), intent(in) :: comm
    integer, intent(in) :: nbr(:)
    integer, intent(in) :: send_first(:), recv_first(:)       !< size(nbr) + 1 each
    real(dp), contiguous, intent(in) :: send_buf(:)
    real(dp), contiguous, intent(inout) :: recv_buf(:)
    type(MPI_Request), allocatable :: req(:)
    integer :: k, n, nr

    nr = 0
    allocate (req(2 * size(nbr)))
    do k = 1, size(nbr)
       n = recv_first(k + 1) - recv_first(k)
       if (n > 0) then
          nr = nr + 1
          call MPI_Irecv(recv_buf(recv_first(k):), n, MPI_DOUBLE_PRECISION, nbr(k), tag_halo, comm, req(nr))
       end if
    end do
    do k = 1, size(nbr)
       n = send_first(k + 1) - send_first(k)
       if (n > 0) then
          nr = nr + 1
          call MPI_Isend(send_buf(send_first(k):), n, MPI_DOUBLE_PRECISION, nbr(k), tag_halo, comm, req(nr))
       end if
    end do
    call MPI_Waitall(nr, req(1:nr), MPI_STATUSES_IGNORE)
  end subroutine exchange_neighbours

  !> Every rank r sends send_buf(send_first(r) : send_first(r + 1) − 1) to rank r (r = 0 ..
  !> nranks − 1: send_first has nranks + 1 entries); recv_buf is what all ranks sent to this one,
  !> in rank order, recv_first(r) its pieces' starts. Collective over comm.
  subroutine exchange_all(comm, nranks, send_first, send_buf, recv_first, recv_buf)
    type(MPI_Comm), intent(in) :: comm
    integer, intent(in) :: nranks
    integer, intent(in) :: send_first(0:nranks)
    real(dp), contiguous, intent(in) :: send_buf(:)
    integer, intent(out) :: recv_first(0:nranks)
    real(dp), allocatable, intent(out) :: recv_buf(:)
    integer :: scount(0:nranks - 1), rcount(0:nranks - 1), sdispl(0:nranks - 1), rdispl(0:nranks - 1), r
    real(dp), allocatable :: sb(:), rb(:)

    do r = 0, nranks - 1
       scount(r) = send_first(r + 1) - send_first(r)
       sdispl(r) = send_first(r) - 1
    end do
    call MPI_Alltoall(scount, 1, MPI_INTEGER, rcount, 1, MPI_INTEGER, comm)
    recv_first(0) = 1
    do r = 0, nranks - 1
       rdispl(r) = recv_first(r) - 1
       recv_first(r + 1) = recv_first(r) + rcount(r)
    end do
    ! buffers of at least one value: an empty one still needs an address on both sides
    allocate (sb(max(1, size(send_buf))), rb(max(1, recv_first(nranks) - 1)))
    sb(1:size(send_buf)) = send_buf
    call MPI_Alltoallv(sb, scount, sdispl, MPI_DOUBLE_PRECISION, rb, rcount, rdispl, MPI_DOUBLE_PRECISION, comm)
    allocate (recv_buf(recv_first(nranks) - 1), source=rb(1:recv_first(nranks) - 1))
  end subroutine exchange_all
end module parallel_exchange
