!> Fused forward and back substitution for the kd = 3 band Cholesky factor of
!> LAPACK (dpbtrf, 'U'), the solve of the time loop.
!>
!> LAPACK stays the factorization: A = U^T U comes from dpbtrf. The factor is
!> rewritten once as A = (I + N)^T D^2 (I + N), D = diag(U), N = D^{-1} U - I
!> (strictly upper, three diagonals). Each row of each substitution is then three
!> multiply-adds and no division, and the dependency from one row to the next is a
!> single multiply-add: the chain of the two solves is 2n fused multiply-adds, the
!> shortest a row-by-row substitution can have. dpbtrs (two dtbsv calls) divides
!> by the diagonal on the chain and goes through the generic band loops.
!> Agrees with dpbtrs to round-off (tests/python/test_speed_fused.py).
module beamstops_band_solve
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   implicit none
   private
   public :: band_solver, prepare_solver, fused_solve, forward_substitution, back_substitution, back_substitution_edge
   public :: band_diagonals, prepare_diagonals, diagonal_matvec

   !> The factor of A = M + dt^2 beta S in the form the fused substitutions read.
   type :: band_solver
      !> Number of unknowns n.
      integer :: n = 0
      !> N = D^{-1} U - I in band storage (kd, n): off(kd + 1 + i - j, j) = U(i,j)/U(i,i), j - kd <= i < j.
      real(wp), allocatable :: off(:, :)
      !> 1/U(j,j)^2 (n).
      real(wp), allocatable :: inv_d2(:)
   end type band_solver

   !> A symmetric kd = 3 band matrix stored by diagonals, the layout a vectorized product reads.
   type :: band_diagonals
      !> Number of rows n.
      integer :: n = 0
      !> a(j, k) = A(j-k, j) for k = 0..kd, zero where j <= k (n, 0:kd).
      real(wp), allocatable :: a(:, :)
   end type band_diagonals

contains

   !> Prepare the fused solver from LAPACK's band Cholesky factor U (from cholesky_factor).
   pure subroutine prepare_solver(factor, solver)
      !> Factor U in upper band storage (kd+1, n), kd = 3.
      real(wp), intent(in) :: factor(:, :)
      !> Solver, allocated and filled.
      type(band_solver), intent(out) :: solver
      integer :: n, i, j
      n = size(factor, 2)
      solver%n = n
      allocate (solver%off(kd, n), solver%inv_d2(n))
      solver%off = 0
      do j = 1, n
         solver%inv_d2(j) = 1/factor(kd + 1, j)**2
         do i = max(1, j - kd), j - 1
            solver%off(kd + 1 + i - j, j) = factor(kd + 1 + i - j, j)/factor(kd + 1, i)
         end do
      end do
   end subroutine prepare_solver

   !> Solve A x = b in place: (I + N)^T w = b, then (I + N) x = D^{-2} w.
   pure subroutine fused_solve(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> Right-hand side (n), replaced by the solution.
      real(wp), intent(inout) :: b(:)
      call forward_substitution(solver, b)
      call back_substitution(solver, b)
   end subroutine fused_solve

   !> Forward substitution (I + N)^T w = b in place:
   !> w_j = b_j - N(j-3,j) w_{j-3} - N(j-2,j) w_{j-2} - N(j-1,j) w_{j-1}.
   !> The last three values travel in registers (x1 the nearest, x3 the farthest), and
   !> the nearest is subtracted last, so that one multiply-add per row waits on the
   !> previous row.
   pure subroutine forward_substitution(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> Right-hand side b (n), replaced by w.
      real(wp), intent(inout), contiguous :: b(:)
      real(wp) :: x, x1, x2, x3
      integer :: j, n
      n = solver%n
      if (n <= kd) then
         call small_forward(solver, b)
         return
      end if
      associate (off => solver%off)
         x3 = b(1)
         x2 = b(2) - off(3, 2)*x3
         x1 = b(3) - off(2, 3)*x3 - off(3, 3)*x2
         b(2) = x2
         b(3) = x1
         do j = kd + 1, n
            x = b(j) - off(1, j)*x3 - off(2, j)*x2 - off(3, j)*x1
            b(j) = x
            x3 = x2
            x2 = x1
            x1 = x
         end do
      end associate
   end subroutine forward_substitution

   !> Back substitution (I + N) x = D^{-2} w in place:
   !> x_i = w_i/d_i^2 - N(i,i+3) x_{i+3} - N(i,i+2) x_{i+2} - N(i,i+1) x_{i+1}.
   pure subroutine back_substitution(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> w (n), replaced by x.
      real(wp), intent(inout), contiguous :: b(:)
      real(wp) :: x, x1, x2, x3
      integer :: i, n
      n = solver%n
      call back_substitution_edge(solver, b)
      if (n <= kd) return
      associate (off => solver%off, inv_d2 => solver%inv_d2)
         x3 = b(n)
         x2 = b(n - 1)
         x1 = b(n - 2)
         do i = n - kd, 1, -1
            x = b(i)*inv_d2(i) - off(1, i + 3)*x3 - off(2, i + 2)*x2 - off(3, i + 1)*x1
            b(i) = x
            x3 = x2
            x2 = x1
            x1 = x
         end do
      end associate
   end subroutine back_substitution

   !> The first kd rows of the back substitution (x_n, x_{n-1}, x_{n-2}); all of them when n <= kd.
   !> The time loop needs the tip value (row n-1) before it finishes the substitution.
   pure subroutine back_substitution_edge(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> w (n); its last kd rows replaced by those of x.
      real(wp), intent(inout) :: b(:)
      integer :: i, j, n
      n = solver%n
      do i = n, max(n - kd + 1, 1), -1
         b(i) = b(i)*solver%inv_d2(i)
         do j = n, i + 1, -1
            b(i) = b(i) - solver%off(kd + 1 + i - j, j)*b(j)
         end do
      end do
   end subroutine back_substitution_edge

   !> Forward substitution for n <= kd (every row is an edge row).
   pure subroutine small_forward(solver, b)
      type(band_solver), intent(in) :: solver
      real(wp), intent(inout) :: b(:)
      integer :: i, j
      do j = 2, solver%n
         do i = 1, j - 1
            b(j) = b(j) - solver%off(kd + 1 + i - j, j)*b(i)
         end do
      end do
   end subroutine small_forward
   !> Copy a symmetric band matrix from LAPACK upper band storage into diagonals.
   pure subroutine prepare_diagonals(ab, diagonals)
      !> Upper band storage (kd+1, n), kd = 3.
      real(wp), intent(in) :: ab(:, :)
      !> The same matrix by diagonals, allocated and filled.
      type(band_diagonals), intent(out) :: diagonals
      integer :: j, k, n
      n = size(ab, 2)
      diagonals%n = n
      allocate (diagonals%a(n, 0:kd))
      diagonals%a = 0
      do k = 0, kd
         do j = k + 1, n
            diagonals%a(j, k) = ab(kd + 1 - k, j)
         end do
      end do
   end subroutine prepare_diagonals

   !> y = A x for a symmetric band matrix stored by diagonals; the interior rows
   !> vectorize (unit-stride loads of every diagonal), the 2 kd edge rows are written out.
   pure subroutine diagonal_matvec(diagonals, x, y)
      !> Matrix by diagonals.
      type(band_diagonals), intent(in) :: diagonals
      !> Vector (n).
      real(wp), intent(in), contiguous :: x(:)
      !> Product (n).
      real(wp), intent(out), contiguous :: y(:)
      integer :: j, n
      n = diagonals%n
      associate (a => diagonals%a)
         if (n < 2*kd + 1) then
            y = a(:, 0)*x
            y(2:) = y(2:) + a(2:, 1)*x(:n - 1)
            y(:n - 1) = y(:n - 1) + a(2:, 1)*x(2:)
            y(3:) = y(3:) + a(3:, 2)*x(:n - 2)
            y(:n - 2) = y(:n - 2) + a(3:, 2)*x(3:)
            y(4:) = y(4:) + a(4:, 3)*x(:n - 3)
            y(:n - 3) = y(:n - 3) + a(4:, 3)*x(4:)
            return
         end if
         y(1) = a(1, 0)*x(1) + a(2, 1)*x(2) + a(3, 2)*x(3) + a(4, 3)*x(4)
         y(2) = a(2, 1)*x(1) + a(2, 0)*x(2) + a(3, 1)*x(3) + a(4, 2)*x(4) + a(5, 3)*x(5)
         y(3) = a(3, 2)*x(1) + a(3, 1)*x(2) + a(3, 0)*x(3) + a(4, 1)*x(4) + a(5, 2)*x(5) + a(6, 3)*x(6)
         do j = kd + 1, n - kd
            y(j) = a(j, 3)*x(j - 3) + a(j, 2)*x(j - 2) + a(j, 1)*x(j - 1) + a(j, 0)*x(j) &
               & + a(j + 1, 1)*x(j + 1) + a(j + 2, 2)*x(j + 2) + a(j + 3, 3)*x(j + 3)
         end do
         y(n - 2) = a(n - 2, 3)*x(n - 5) + a(n - 2, 2)*x(n - 4) + a(n - 2, 1)*x(n - 3) + a(n - 2, 0)*x(n - 2) &
            & + a(n - 1, 1)*x(n - 1) + a(n, 2)*x(n)
         y(n - 1) = a(n - 1, 3)*x(n - 4) + a(n - 1, 2)*x(n - 3) + a(n - 1, 1)*x(n - 2) + a(n - 1, 0)*x(n - 1) &
            & + a(n, 1)*x(n)
         y(n) = a(n, 3)*x(n - 3) + a(n, 2)*x(n - 2) + a(n, 1)*x(n - 1) + a(n, 0)*x(n)
      end associate
   end subroutine diagonal_matvec
end module beamstops_band_solve
