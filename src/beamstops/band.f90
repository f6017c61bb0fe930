!> Symmetric band storage (LAPACK 'U', kd = 3) of the assembled Hermite matrices,
!> and the LAPACK calls on it (interfaces and info messages: beamstops_lapack).
module beamstops_band
   use beamstops_kinds, only: wp
   use beamstops_error, only: error_type, fatal_error
   use beamstops_lapack, only: dpbtrf, dpbtrs, dsbgv, dgbtrf, dgbtrs, dpbtrf_message, dpbtrs_message, &
      & dsbgv_message, dgbtrf_message, dgbtrs_message
   implicit none
   private
   public :: kd, assemble_band, band_matvec, band_to_dense, cholesky_factor, cholesky_solve
   public :: largest_eigenvalue_exact, largest_eigenvalue_iterative, generalized_eigenvalues

   !> Half-bandwidth of Hermite cubic matrices with (u, u') interleaved.
   integer, parameter :: kd = 3


contains

   !> Assemble J identical element matrices into band storage; node 0 (clamped) is removed,
   !> unknowns are (u_1, u'_1, ..., u_J, u'_J).
   pure subroutine assemble_band(elements, me, ab)
      !> Number of elements J.
      integer, intent(in) :: elements
      !> Element matrix (4 x 4, symmetric).
      real(wp), intent(in) :: me(4, 4)
      !> Band storage (kd+1, 2J), overwritten.
      real(wp), intent(out) :: ab(:, :)
      integer :: e, a, b, i, j
      ab = 0
      do e = 1, elements
         do b = 1, 4
            j = 2*(e - 1) - 2 + b
            if (j < 1) cycle
            do a = 1, b
               i = 2*(e - 1) - 2 + a
               if (i < 1) cycle
               ab(kd + 1 + i - j, j) = ab(kd + 1 + i - j, j) + me(a, b)
            end do
         end do
      end do
   end subroutine assemble_band

   !> y = A x for a symmetric matrix in upper band storage with kd = 3.
   !> Interior rows are written out (seven terms, no zero fill, no inner loop): the
   !> time loop calls this every step.
   pure subroutine band_matvec(ab, x, y)
      !> Band storage (kd+1, n).
      real(wp), intent(in) :: ab(:, :)
      !> Vector (n).
      real(wp), intent(in) :: x(:)
      !> Product (n).
      real(wp), intent(out) :: y(:)
      integer :: j, n
      n = size(x)
      do j = 1, min(kd, n)
         y(j) = band_row(ab, x, j)
      end do
      do j = kd + 1, n - kd
         y(j) = ab(1, j)*x(j - 3) + ab(2, j)*x(j - 2) + ab(3, j)*x(j - 1) + ab(4, j)*x(j) &
            & + ab(3, j + 1)*x(j + 1) + ab(2, j + 2)*x(j + 2) + ab(1, j + 3)*x(j + 3)
      end do
      do j = max(n - kd + 1, kd + 1), n
         y(j) = band_row(ab, x, j)
      end do
   end subroutine band_matvec

   !> Row j of A x for a symmetric band matrix (any row, the edges included).
   pure function band_row(ab, x, j) result(y)
      real(wp), intent(in) :: ab(:, :), x(:)
      integer, intent(in) :: j
      real(wp) :: y
      integer :: i
      y = 0
      do i = max(1, j - kd), j
         y = y + ab(kd + 1 + i - j, j)*x(i)
      end do
      do i = j + 1, min(size(x), j + kd)
         y = y + ab(kd + 1 + j - i, i)*x(i)
      end do
   end function band_row

   !> Dense copy of a symmetric band matrix (for tests and small checks).
   pure function band_to_dense(ab) result(a)
      !> Band storage (kd+1, n).
      real(wp), intent(in) :: ab(:, :)
      real(wp) :: a(size(ab, 2), size(ab, 2))
      integer :: i, j
      a = 0
      do j = 1, size(ab, 2)
         do i = max(1, j - kd), j
            a(i, j) = ab(kd + 1 + i - j, j)
            a(j, i) = a(i, j)
         end do
      end do
   end function band_to_dense

   !> Cholesky factorization A = U^T U in place (LAPACK dpbtrf).
   subroutine cholesky_factor(ab, what, error)
      !> Band storage, replaced by the factor U.
      real(wp), intent(inout) :: ab(:, :)
      !> Name of the matrix for messages.
      character(len=*), intent(in) :: what
      !> Set when the matrix is not positive definite.
      type(error_type), allocatable, intent(out) :: error
      integer :: info
      call dpbtrf('U', size(ab, 2), kd, ab, size(ab, 1), info)
      if (info /= 0) call fatal_error(error, dpbtrf_message(info, what))
   end subroutine cholesky_factor

   !> Solve A x = b with the factor from cholesky_factor (LAPACK dpbtrs).
   subroutine cholesky_solve(factor, b, error)
      !> Factor U in band storage.
      real(wp), intent(in) :: factor(:, :)
      !> Right-hand side, replaced by the solution.
      real(wp), intent(inout) :: b(:)
      !> Set when dpbtrs refuses its arguments (sizes that do not match); absent: not checked.
      type(error_type), allocatable, intent(out), optional :: error
      integer :: info
      call dpbtrs('U', size(factor, 2), kd, 1, factor, size(factor, 1), b, size(b), info)
      if (info /= 0 .and. present(error)) call fatal_error(error, dpbtrs_message(info))
   end subroutine cholesky_solve

   !> Largest eigenvalue of S v = kappa M v, exactly (LAPACK dsbgv). Cost O(n^2): small n only.
   subroutine largest_eigenvalue_exact(s, m, kappa, error)
      !> Stiffness, band storage.
      real(wp), intent(in) :: s(:, :)
      !> Mass, band storage (positive definite).
      real(wp), intent(in) :: m(:, :)
      !> Largest generalized eigenvalue.
      real(wp), intent(out) :: kappa
      !> Set when LAPACK fails.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: w(:)
      kappa = 0
      call pencil_eigenvalues(s, m, w, error)
      if (.not. allocated(error)) kappa = w(size(w))
   end subroutine largest_eigenvalue_exact

   !> All finite eigenvalues kappa of S v = kappa M v, ascending (LAPACK dsbgv; O(n^2): small n
   !> only), each accurate relative to itself. dsbgv's eigenvalues are accurate to about eps times
   !> the largest, so the low end of S v = kappa M v alone is not (the lowest mode's kappa off by
   !> 1e-10 at J = 19, 6 % at J = 1000): the pencil is also taken the other way round,
   !> M v = mu S v (S is positive definite), whose largest mu = 1/kappa are the accurate ones, and
   !> each kappa comes from the pencil in which it is the larger end (kappa^2 below or above
   !> kappa_min kappa_max). M may be singular with `massless` zero rows (mass redistribution):
   !> then only the pencil taken the other way round, whose `massless` smallest eigenvalues are
   !> the zeros of M (infinite kappa), the others giving kappa = 1/mu.
   subroutine generalized_eigenvalues(s, m, massless, kappa, error)
      !> Stiffness, band storage (positive definite).
      real(wp), intent(in) :: s(:, :)
      !> Mass, band storage (positive definite, or semi-definite with `massless` zero rows).
      real(wp), intent(in) :: m(:, :)
      !> Number of zero rows of M.
      integer, intent(in) :: massless
      !> The n - massless finite eigenvalues, ascending.
      real(wp), allocatable, intent(out) :: kappa(:)
      !> Set when LAPACK fails.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: w(:), low(:)
      integer :: n, j
      n = size(s, 2)
      ! M v = mu S v: mu ascending, kappa = 1/mu descending
      call pencil_eigenvalues(m, s, w, error)
      if (allocated(error)) then
         allocate (kappa(0))
         return
      end if
      low = 1/w(n:massless + 1:-1)
      if (massless > 0) then
         kappa = low
         return
      end if
      ! S v = kappa M v: the high end
      call pencil_eigenvalues(s, m, w, error)
      if (allocated(error)) then
         allocate (kappa(0))
         return
      end if
      kappa = w
      do j = 1, n
         if (w(j)**2 < w(1)*w(n)) kappa(j) = low(j)
      end do
   end subroutine generalized_eigenvalues

   !> The eigenvalues w of a v = w b v, ascending (dsbgv; a symmetric, b positive definite).
   subroutine pencil_eigenvalues(a, b, w, error)
      real(wp), intent(in) :: a(:, :), b(:, :)
      real(wp), allocatable, intent(out) :: w(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: aa(:, :), bb(:, :), work(:)
      real(wp) :: zdum(1, 1)
      integer :: n, info
      n = size(a, 2)
      allocate (aa, source=a)
      allocate (bb, source=b)
      allocate (w(n), work(3*n))
      call dsbgv('N', 'U', n, kd, kd, aa, kd + 1, bb, kd + 1, w, zdum, 1, work, info)
      if (info /= 0) call fatal_error(error, dsbgv_message(info, n))
   end subroutine pencil_eigenvalues

   !> Largest eigenvalue of S v = kappa M v by inverse iteration shifted at an upper bound
   !> `shift` (O(n) per iteration; for meshes too large for dsbgv). Converges to the top of
   !> the spectrum; its Rayleigh quotient is a lower bound, `shift` an upper bound.
   subroutine largest_eigenvalue_iterative(s, m, shift, kappa, error)
      !> Stiffness, band storage.
      real(wp), intent(in) :: s(:, :)
      !> Mass, band storage.
      real(wp), intent(in) :: m(:, :)
      !> An upper bound of the spectrum.
      real(wp), intent(in) :: shift
      !> Largest generalized eigenvalue (Rayleigh quotient at convergence).
      real(wp), intent(out) :: kappa
      !> Set when LAPACK fails.
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: kl = kd, ku = kd, ldab = 2*kl + ku + 1, max_iterations = 300
      real(wp), allocatable :: ab(:, :), x(:), y(:), sx(:), mx(:)
      integer, allocatable :: ipiv(:)
      real(wp) :: previous
      integer :: n, i, j, it, info
      n = size(s, 2)
      allocate (ab(ldab, n), x(n), y(n), sx(n), mx(n), ipiv(n))
      ab = 0
      do j = 1, n
         do i = max(1, j - kd), j
            ab(kl + ku + 1 + i - j, j) = s(kd + 1 + i - j, j) - shift*m(kd + 1 + i - j, j)
            ab(kl + ku + 1 + j - i, i) = ab(kl + ku + 1 + i - j, j)
         end do
      end do
      call dgbtrf(n, n, kl, ku, ab, ldab, ipiv, info)
      if (info /= 0) then
         call fatal_error(error, dgbtrf_message(info)//' (the shifted matrix S - shift M)')
         kappa = shift
         return
      end if
      x = [(merge(1.0_wp, -1.0_wp, mod(i, 4) < 2), i=1, n)]
      kappa = 0
      do it = 1, max_iterations
         call band_matvec(m, x, y)
         call dgbtrs('N', n, kl, ku, 1, ab, ldab, ipiv, y, n, info)
         if (info /= 0) then
            call fatal_error(error, dgbtrs_message(info))
            return
         end if
         x = y/norm2(y)
         call band_matvec(s, x, sx)
         call band_matvec(m, x, mx)
         previous = kappa
         kappa = dot_product(x, sx)/dot_product(x, mx)
         if (abs(kappa - previous) <= 1.0e-14_wp*abs(kappa)) exit
      end do
   end subroutine largest_eigenvalue_iterative
end module beamstops_band
