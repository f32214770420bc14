!> Explicit interfaces of the LAPACK routines bulkflow calls (reference LAPACK 3.x argument
!> lists, double precision), so every call is checked at compile time. Where LAPACK is used
!> and where it is not (the vectorised kernels and the VUMATs): src/material/README.md.
module lapack_interfaces
  implicit none
  private

  public :: dgesv, dsyev

  interface
     !> Solve A X = B by LU factorisation with partial pivoting (A overwritten by L and U).
     subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
       integer, intent(in) :: n, nrhs, lda, ldb
       double precision, intent(inout) :: a(lda, *), b(ldb, *)
       integer, intent(out) :: ipiv(*), info
     end subroutine dgesv

     !> Eigenvalues (ascending) and, with jobz = 'V', orthonormal eigenvectors of a symmetric A.
     subroutine dsyev(jobz, uplo, n, a, lda, w, work, lwork, info)
       character(len=1), intent(in) :: jobz, uplo
       integer, intent(in) :: n, lda, lwork
       double precision, intent(inout) :: a(lda, *)
       double precision, intent(out) :: w(*), work(*)
       integer, intent(out) :: info
     end subroutine dsyev
  end interface
end module lapack_interfaces
