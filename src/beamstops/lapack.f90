!> The LAPACK routines the engine calls, declared once, and what each `info` code of theirs
!> means, as a message (fortran-lang/stdlib's handle_<routine>_info, one per routine).
!> Every other module calls LAPACK through these interfaces; none repeats them.
module beamstops_lapack
   use, intrinsic :: iso_c_binding, only: c_int
   use beamstops_kinds, only: wp
   use beamstops_strings, only: itoa
   implicit none
   private
   public :: dpbtrf, dpbtrs, dsbgv, dsbgvx, dgbtrf, dgbtrs, dpotrf, dsygv
   public :: dpbtrf_message, dpbtrs_message, dsbgv_message, dsbgvx_message, dgbtrf_message, dgbtrs_message
   public :: dpotrf_message, dsygv_message
   public :: openblas_one_thread

   interface
      !> OpenBLAS on one thread, its pool of threads stopped (blas_threads.c): 1 when done, 0
      !> when the BLAS is not OpenBLAS.
      function openblas_one_thread() bind(C, name='beamstops_openblas_one_thread') result(done)
         import :: c_int
         integer(c_int) :: done
      end function openblas_one_thread
      !> Cholesky factorization of a symmetric positive definite band matrix.
      subroutine dpbtrf(uplo, n, kd, ab, ldab, info)
         import :: wp
         character, intent(in) :: uplo
         integer, intent(in) :: n, kd, ldab
         real(wp), intent(inout) :: ab(ldab, *)
         integer, intent(out) :: info
      end subroutine dpbtrf
      !> Solve with the band Cholesky factor of dpbtrf.
      subroutine dpbtrs(uplo, n, kd, nrhs, ab, ldab, b, ldb, info)
         import :: wp
         character, intent(in) :: uplo
         integer, intent(in) :: n, kd, nrhs, ldab, ldb
         real(wp), intent(in) :: ab(ldab, *)
         real(wp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dpbtrs
      !> Generalized symmetric-definite band eigenproblem A x = lambda B x.
      subroutine dsbgv(jobz, uplo, n, ka, kb, ab, ldab, bb, ldbb, w, z, ldz, work, info)
         import :: wp
         character, intent(in) :: jobz, uplo
         integer, intent(in) :: n, ka, kb, ldab, ldbb, ldz
         real(wp), intent(inout) :: ab(ldab, *), bb(ldbb, *)
         real(wp), intent(out) :: w(*), z(ldz, *), work(*)
         integer, intent(out) :: info
      end subroutine dsbgv
      !> Selected eigenvalues (and eigenvectors) of a generalized symmetric-definite band
      !> eigenproblem A x = lambda B x.
      subroutine dsbgvx(jobz, range, uplo, n, ka, kb, ab, ldab, bb, ldbb, q, ldq, vl, vu, il, iu, abstol, m, w, &
         & z, ldz, work, iwork, ifail, info)
         import :: wp
         character, intent(in) :: jobz, range, uplo
         integer, intent(in) :: n, ka, kb, ldab, ldbb, ldq, il, iu, ldz
         real(wp), intent(inout) :: ab(ldab, *), bb(ldbb, *)
         real(wp), intent(out) :: q(ldq, *), w(*), z(ldz, *), work(*)
         real(wp), intent(in) :: vl, vu, abstol
         integer, intent(out) :: m, iwork(*), ifail(*), info
      end subroutine dsbgvx
      !> LU factorization of a general band matrix.
      subroutine dgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
         import :: wp
         integer, intent(in) :: m, n, kl, ku, ldab
         real(wp), intent(inout) :: ab(ldab, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgbtrf
      !> Solve with the band LU factor of dgbtrf.
      subroutine dgbtrs(trans, n, kl, ku, nrhs, ab, ldab, ipiv, b, ldb, info)
         import :: wp
         character, intent(in) :: trans
         integer, intent(in) :: n, kl, ku, nrhs, ldab, ipiv(*), ldb
         real(wp), intent(in) :: ab(ldab, *)
         real(wp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dgbtrs
      !> Cholesky factorization of a dense symmetric positive definite matrix.
      subroutine dpotrf(uplo, n, a, lda, info)
         import :: wp
         character, intent(in) :: uplo
         integer, intent(in) :: n, lda
         real(wp), intent(inout) :: a(lda, *)
         integer, intent(out) :: info
      end subroutine dpotrf
      !> Generalized symmetric-definite dense eigenproblem.
      subroutine dsygv(itype, jobz, uplo, n, a, lda, b, ldb, w, work, lwork, info)
         import :: wp
         integer, intent(in) :: itype, n, lda, ldb, lwork
         character, intent(in) :: jobz, uplo
         real(wp), intent(inout) :: a(lda, *), b(ldb, *)
         real(wp), intent(out) :: w(*), work(*)
         integer, intent(out) :: info
      end subroutine dsygv
   end interface

contains

   !> Message of dpbtrf's info (empty for 0); `what` names the matrix.
   pure function dpbtrf_message(info, what) result(message)
      !> LAPACK's info.
      integer, intent(in) :: info
      !> Name of the matrix factored.
      character(len=*), intent(in) :: what
      character(len=:), allocatable :: message
      message = cholesky_message('dpbtrf', info, what)
   end function dpbtrf_message

   !> Message of dpbtrs's info (empty for 0).
   pure function dpbtrs_message(info) result(message)
      !> LAPACK's info.
      integer, intent(in) :: info
      character(len=:), allocatable :: message
      message = illegal('dpbtrs', info)
   end function dpbtrs_message

   !> Message of dsbgv's info (empty for 0); n is the order of the problem.
   pure function dsbgv_message(info, n) result(message)
      !> LAPACK's info.
      integer, intent(in) :: info
      !> Order of the matrices.
      integer, intent(in) :: n
      character(len=:), allocatable :: message
      if (info > n) then
         message = 'dsbgv: the mass matrix is not positive definite (its factorization failed at order '// &
            & itoa(info - n)//')'
      else if (info > 0) then
         message = 'dsbgv: the tridiagonal QR iteration did not converge ('//itoa(info)// &
            & ' off-diagonal elements did not reach zero)'
      else
         message = illegal('dsbgv', info)
      end if
   end function dsbgv_message

   !> Message of dsbgvx's info (empty for 0); n is the order of the problem.
   pure function dsbgvx_message(info, n) result(message)
      !> LAPACK's info.
      integer, intent(in) :: info
      !> Order of the matrices.
      integer, intent(in) :: n
      character(len=:), allocatable :: message
      if (info > n) then
         message = 'dsbgvx: the mass matrix is not positive definite (its factorization failed at order '// &
            & itoa(info - n)//')'
      else if (info > 0) then
         message = 'dsbgvx: '//itoa(info)//' eigenvectors did not converge'
      else
         message = illegal('dsbgvx', info)
      end if
   end function dsbgvx_message

   !> Message of dgbtrf's info (empty for 0).
   pure function dgbtrf_message(info) result(message)
      !> LAPACK's info.
      integer, intent(in) :: info
      character(len=:), allocatable :: message
      if (info > 0) then
         message = 'dgbtrf: the matrix is exactly singular (U('//itoa(info)//','//itoa(info)//') = 0)'
      else
         message = illegal('dgbtrf', info)
      end if
   end function dgbtrf_message

   !> Message of dgbtrs's info (empty for 0).
   pure function dgbtrs_message(info) result(message)
      !> LAPACK's info.
      integer, intent(in) :: info
      character(len=:), allocatable :: message
      message = illegal('dgbtrs', info)
   end function dgbtrs_message

   !> Message of dpotrf's info (empty for 0); `what` names the matrix.
   pure function dpotrf_message(info, what) result(message)
      !> LAPACK's info.
      integer, intent(in) :: info
      !> Name of the matrix factored.
      character(len=*), intent(in) :: what
      character(len=:), allocatable :: message
      message = cholesky_message('dpotrf', info, what)
   end function dpotrf_message

   !> Message of dsygv's info (empty for 0); n is the order of the problem.
   pure function dsygv_message(info, n) result(message)
      !> LAPACK's info.
      integer, intent(in) :: info
      !> Order of the matrices.
      integer, intent(in) :: n
      character(len=:), allocatable :: message
      if (info > n) then
         message = 'dsygv: the leading minor of order '//itoa(info - n)//' of B is not positive definite'
      else if (info > 0) then
         message = 'dsygv: dsyev did not converge ('//itoa(info)//' off-diagonal elements did not reach zero)'
      else
         message = illegal('dsygv', info)
      end if
   end function dsygv_message

   !> The message of a Cholesky factorization's info (dpbtrf, dpotrf), empty for 0.
   pure function cholesky_message(routine, info, what) result(message)
      character(len=*), intent(in) :: routine
      integer, intent(in) :: info
      character(len=*), intent(in) :: what
      character(len=:), allocatable :: message
      if (info > 0) then
         message = routine//': the leading minor of order '//itoa(info)//' of '//what//' is not positive definite'
      else
         message = illegal(routine, info)
      end if
   end function cholesky_message

   !> The message of a negative info (an illegal argument), empty for 0.
   pure function illegal(routine, info) result(message)
      character(len=*), intent(in) :: routine
      integer, intent(in) :: info
      character(len=:), allocatable :: message
      message = ''
      if (info < 0) message = routine//': argument '//itoa(-info)//' had an illegal value'
      if (info > 0) message = routine//': failed with info = '//itoa(info)
   end function illegal
end module beamstops_lapack
