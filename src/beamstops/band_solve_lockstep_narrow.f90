!> The inner rows of the lockstep kernels shaped for 16 vector registers (AVX2's ymm0..ymm15, or
!> fewer bits per register): a row of the eight lanes is two AVX2 registers, so that a loop whose
!> body keeps more than a handful of row values and coefficients live spills them to the stack and
!> reloads them every row. The loops are cut to fit: one row per loop over the lanes in the
!> substitutions (the vectorizer broadcasts a loop's coefficients at its start: three rows in one
!> loop held twelve broadcasts and the six running values at once), the periodic product's two
!> rows in loops of their own (seven coefficients each, not fourteen), the forward substitution
!> after the product rather than interleaved with it, and g.d after the back substitution rather
!> than riding on it. gfortran 12, -march=znver3: no spill in those loops; docs/lockstep.md has
!> the measurements. beamstops_band_solve_lockstep_wide has the shapes for 32 registers; per lane
!> both do the operations of the one-member rows of beamstops_band_solve in the same order
!> (tests/fortran/test_lockstep.f90 compares the two shapes bit for bit).
module beamstops_band_solve_lockstep_narrow
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   use beamstops_band_solve_lockstep_edges, only: lockstep_lanes, forward_first_rows, forward_last_rows, &
      & back_first_rows, back_last_rows, back_update_first_rows, back_update_last_rows, matvec_rhs_first_rows, matvec_rhs_last_rows, &
      & lockstep_load_work
   implicit none
   private
   public :: narrow_forward_rows, narrow_back_rows, narrow_back_update_rows, narrow_periodic_rows
   public :: narrow_matvec_rhs_forward_rows

contains

   !> Forward substitution (I + N)^T w = b of every lane, b replaced by D^{-2} w, in
   !> explicit-shape arrays (every array at a fixed stride: the rows of a turn address the factor
   !> from one register). Three rows a turn, as
   !> beamstops_band_solve's forward_rows, each row a loop over the lanes of its own: its four
   !> coefficients are broadcast at its start, so that a turn keeps the six running values (xa,
   !> xb, xc of eight lanes) and one row's coefficients live, not the twelve of three rows.
   pure subroutine narrow_forward_rows(n, off, inv_d2, b)
      !> Unknowns, the factor's off-diagonals and 1/U(j,j)^2 (beamstops_band_solve's band_solver).
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
      !> Right-hand sides (lanes, n), replaced by D^{-2} w.
      real(wp), intent(inout) :: b(lockstep_lanes, n)
      real(wp) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: j, k
      call forward_first_rows(off, inv_d2, n, b, xa, xb, xc)
      do j = kd + 1, n - 2, 3
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, j) - off(1, j)*xa(k) - off(2, j)*xb(k) - off(3, j)*xc(k)
            b(k, j) = xa(k)*inv_d2(j)
         end do
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xb(k) = b(k, j + 1) - off(1, j + 1)*xb(k) - off(2, j + 1)*xc(k) - off(3, j + 1)*xa(k)
            b(k, j + 1) = xb(k)*inv_d2(j + 1)
         end do
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xc(k) = b(k, j + 2) - off(1, j + 2)*xc(k) - off(2, j + 2)*xa(k) - off(3, j + 2)*xb(k)
            b(k, j + 2) = xc(k)*inv_d2(j + 2)
         end do
      end do
      call forward_last_rows(off, inv_d2, j, n, b, xa, xb, xc)
   end subroutine narrow_forward_rows

   !> Back substitution (I + N) x = b of every lane in explicit-shape arrays, one loop over the
   !> lanes a row (as narrow_forward_rows).
   pure subroutine narrow_back_rows(n, off, b)
      !> Unknowns and the factor's off-diagonals.
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n)
      !> D^{-2} w (lanes, n), replaced by x.
      real(wp), intent(inout) :: b(lockstep_lanes, n)
      real(wp) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: i, k
      call back_first_rows(off, n, b, xa, xb, xc)
      do i = n - kd, 3, -3
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, i) - off(1, i + 3)*xa(k) - off(2, i + 2)*xb(k) - off(3, i + 1)*xc(k)
            b(k, i) = xa(k)
         end do
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xb(k) = b(k, i - 1) - off(1, i + 2)*xb(k) - off(2, i + 1)*xc(k) - off(3, i)*xa(k)
            b(k, i - 1) = xb(k)
         end do
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xc(k) = b(k, i - 2) - off(1, i + 1)*xc(k) - off(2, i)*xa(k) - off(3, i - 1)*xb(k)
            b(k, i - 2) = xc(k)
         end do
      end do
      call back_last_rows(off, i, n, b, xa, xb, xc)
   end subroutine narrow_back_rows

   !> The back substitution after its edge rows with the update riding on it (d = d + x + c z,
   !> u = u + d; beamstops_band_solve_lockstep's lockstep_back_update), one loop over the lanes a
   !> row (as narrow_forward_rows), then g.d^n. g.d is not taken on the way: its three partial
   !> sums of eight lanes beside the six running values and c did not fit in the sixteen
   !> registers of AVX2 and were spilled and reloaded every row; lockstep_load_work takes it
   !> after, in the same order.
   pure subroutine narrow_back_update_rows(n, off, b, c, z, g, d, u, gd)
      !> Unknowns, the factor's off-diagonals, D^{-2} w with its last kd rows those of x (lanes,
      !> n), the multiples of z (lanes), z (n) and the load vectors (lanes, n).
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), b(lockstep_lanes, n), c(lockstep_lanes), z(n), g(lockstep_lanes, n)
      !> d^{n-1} and u^n on entry, d^n and u^{n+1} on return (lanes, n).
      real(wp), intent(inout) :: d(lockstep_lanes, n), u(lockstep_lanes, n)
      !> g.d^n of every lane.
      real(wp), intent(out) :: gd(lockstep_lanes)
      real(wp) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: i, k
      call back_update_first_rows(n, b, c, z, d, u, xa, xb, xc)
      do i = n - kd, 3, -3
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, i) - off(1, i + 3)*xa(k) - off(2, i + 2)*xb(k) - off(3, i + 1)*xc(k)
            d(k, i) = d(k, i) + xa(k) + c(k)*z(i)
            u(k, i) = u(k, i) + d(k, i)
         end do
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xb(k) = b(k, i - 1) - off(1, i + 2)*xb(k) - off(2, i + 1)*xc(k) - off(3, i)*xa(k)
            d(k, i - 1) = d(k, i - 1) + xb(k) + c(k)*z(i - 1)
            u(k, i - 1) = u(k, i - 1) + d(k, i - 1)
         end do
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xc(k) = b(k, i - 2) - off(1, i + 1)*xc(k) - off(2, i)*xa(k) - off(3, i - 1)*xb(k)
            d(k, i - 2) = d(k, i - 2) + xc(k) + c(k)*z(i - 2)
            u(k, i - 2) = u(k, i - 2) + d(k, i - 2)
         end do
      end do
      call back_update_last_rows(off, i, n, b, c, z, d, u, xa, xb, xc)
      call lockstep_load_work(n, g, d, gd)
   end subroutine narrow_back_update_rows

   !> The interior rows kd+1 .. n-kd of the product by a periodic S and the right-hand side
   !> (beamstops_band_solve_lockstep's lockstep_matvec_rhs with `rows`):
   !> y = S x and rhs = a g - b y there, the rows of each coefficient set in a loop of their own
   !> (periodic_half).
   pure subroutine narrow_periodic_rows(n, rows, x, a, g, b, y, rhs)
      !> Unknowns.
      integer, intent(in) :: n
      !> The coefficients of interior rows kd+1 and kd+2 (lockstep_periodic_rows).
      real(wp), intent(in) :: rows(2*kd + 1, 2)
      !> x (lanes, n), dt^2 times the load weights (lanes), the load vectors (lanes, n), dt^2.
      real(wp), intent(in) :: x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b
      !> S x and the right-hand sides (lanes, n), their interior rows set.
      real(wp), intent(inout) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      ! n - 2 kd interior rows: n = 2J and 2 kd are even, so as many of each
      call periodic_half(n, kd + 1, rows(:, 1), x, a, g, b, y, rhs)
      call periodic_half(n, kd + 2, rows(:, 2), x, a, g, b, y, rhs)
   end subroutine narrow_periodic_rows

   !> The interior rows first, first + 2, .. <= n - kd of narrow_periodic_rows, all with the
   !> coefficients p: seven coefficients, dt^2 and the eight load weights stay in registers for
   !> the loop (ten of the sixteen of AVX2; both rows' fourteen coefficients in one loop did not
   !> fit and were reloaded from the stack every row).
   pure subroutine periodic_half(n, first, p, x, a, g, b, y, rhs)
      integer, intent(in) :: n, first
      real(wp), intent(in) :: p(2*kd + 1)
      real(wp), intent(in) :: x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b
      real(wp), intent(inout) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      real(wp) :: p1, p2, p3, p4, p5, p6, p7
      integer :: j, k
      p1 = p(1); p2 = p(2); p3 = p(3); p4 = p(4); p5 = p(5); p6 = p(6); p7 = p(7)
      do j = first, n - kd, 2
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            y(k, j) = p1*x(k, j - 3) + p2*x(k, j - 2) + p3*x(k, j - 1) + p4*x(k, j) + p5*x(k, j + 1) &
               & + p6*x(k, j + 2) + p7*x(k, j + 3)
            rhs(k, j) = a(k)*g(k, j) - b*y(k, j)
         end do
      end do
   end subroutine periodic_half

   !> The product by a periodic S, the right-hand side and the forward substitution
   !> (beamstops_band_solve_lockstep's lockstep_matvec_rhs_forward) in explicit-shape arrays:
   !> every array at a fixed stride (through the descriptors of solver%off and stiffness%a,
   !> gfortran 12 kept an address per row and coefficient and spilled them). The forward
   !> substitution follows the whole product: interleaved with it (the wide kernels' way), its
   !> six running values stayed live across the product's rows and pushed the coefficients out of
   !> AVX2's registers.
   pure subroutine narrow_matvec_rhs_forward_rows(n, s, off, inv_d2, rows, x, a, g, b, spring, y, rhs)
      !> Unknowns, S by diagonals, the factor's off-diagonals and 1/U(j,j)^2, the coefficients of
      !> interior rows kd+1 and kd+2 of S.
      integer, intent(in) :: n
      real(wp), intent(in) :: s(n, 0:kd), off(kd, n), inv_d2(n), rows(2*kd + 1, 2)
      !> u (lanes, n), dt^2 times the load weights (lanes), the load vectors (lanes, n), dt^2, the
      !> force term of the tip row (lanes).
      real(wp), intent(in) :: x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b, spring(lockstep_lanes)
      !> S u and D^{-2} w (lanes, n).
      real(wp), intent(out) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      call matvec_rhs_first_rows(n, s, x, a, g, b, y, rhs)
      call narrow_periodic_rows(n, rows, x, a, g, b, y, rhs)
      call matvec_rhs_last_rows(n, s, x, a, g, b, spring, y, rhs)
      call narrow_forward_rows(n, off, inv_d2, rhs)
   end subroutine narrow_matvec_rhs_forward_rows

end module beamstops_band_solve_lockstep_narrow
