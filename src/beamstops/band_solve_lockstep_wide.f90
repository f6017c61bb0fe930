!> The inner rows of the lockstep kernels shaped for 32 vector registers (AVX-512's zmm0..zmm31):
!> a row of the eight lanes is one register, so that a loop over the lanes may keep three rows'
!> coefficients and running values live at once. Three rows a turn in one loop over the lanes in
!> the substitutions, the periodic product's two rows in one loop (fourteen coefficients in
!> registers), the forward substitution interleaved with the product (its chain in the product's
!> shadow), and g.d riding on the back substitution. With 16 registers these shapes spill every
!> row (beamstops_band_solve_lockstep_narrow has the shapes for them); with 32, bench_lockstep
!> K = 8 reads about 20 % fewer ns per member-step at J = 100 and 10 % at J = 19 than with the
!> narrow shapes (docs/lockstep.md). Per lane both shapes do the operations of the one-member rows
!> of beamstops_band_solve in the same order (tests/fortran/test_lockstep.f90 compares the two
!> bit for bit).
module beamstops_band_solve_lockstep_wide
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   use beamstops_band_solve_lockstep_edges, only: lockstep_lanes, forward_first_rows, forward_last_rows, &
      & back_first_rows, back_last_rows, back_update_first_rows, back_update_last_rows, matvec_rhs_first_rows, matvec_rhs_last_rows, &
      & load_work_first_rows, load_work_last_rows
   implicit none
   private
   public :: wide_forward_rows, wide_back_rows, wide_back_update_rows, wide_periodic_rows
   public :: wide_matvec_rhs_forward_rows

contains

   !> Forward substitution (I + N)^T w = b of every lane, b replaced by D^{-2} w, in
   !> explicit-shape arrays: three rows a turn in one loop over the lanes (as
   !> beamstops_band_solve's forward_rows), their twelve coefficients and the six running values
   !> live at once.
   pure subroutine wide_forward_rows(n, off, inv_d2, b)
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
            xb(k) = b(k, j + 1) - off(1, j + 1)*xb(k) - off(2, j + 1)*xc(k) - off(3, j + 1)*xa(k)
            b(k, j + 1) = xb(k)*inv_d2(j + 1)
            xc(k) = b(k, j + 2) - off(1, j + 2)*xc(k) - off(2, j + 2)*xa(k) - off(3, j + 2)*xb(k)
            b(k, j + 2) = xc(k)*inv_d2(j + 2)
         end do
      end do
      call forward_last_rows(off, inv_d2, j, n, b, xa, xb, xc)
   end subroutine wide_forward_rows

   !> Back substitution (I + N) x = b of every lane in explicit-shape arrays, three rows a turn in
   !> one loop over the lanes (as wide_forward_rows).
   pure subroutine wide_back_rows(n, off, b)
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
            xb(k) = b(k, i - 1) - off(1, i + 2)*xb(k) - off(2, i + 1)*xc(k) - off(3, i)*xa(k)
            b(k, i - 1) = xb(k)
            xc(k) = b(k, i - 2) - off(1, i + 1)*xc(k) - off(2, i)*xa(k) - off(3, i - 1)*xb(k)
            b(k, i - 2) = xc(k)
         end do
      end do
      call back_last_rows(off, i, n, b, xa, xb, xc)
   end subroutine wide_back_rows

   !> The back substitution after its edge rows with the update riding on it (d = d + x + c z,
   !> u = u + d; beamstops_band_solve_lockstep's lockstep_back_update), three rows a turn in one
   !> loop over the lanes, and g.d^n taken on the way in three partial sums (row j in sum
   !> mod(n - j, 3) + 1, then (s1 + s2) + s3: lockstep_load_work's order).
   pure subroutine wide_back_update_rows(n, off, b, c, z, g, d, u, gd)
      !> Unknowns, the factor's off-diagonals, D^{-2} w with its last kd rows those of x (lanes,
      !> n), the multiples of z (lanes), z (n) and the load vectors (lanes, n).
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), b(lockstep_lanes, n), c(lockstep_lanes), z(n), g(lockstep_lanes, n)
      !> d^{n-1} and u^n on entry, d^n and u^{n+1} on return (lanes, n).
      real(wp), intent(inout) :: d(lockstep_lanes, n), u(lockstep_lanes, n)
      !> g.d^n of every lane.
      real(wp), intent(out) :: gd(lockstep_lanes)
      real(wp) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      real(wp) :: ga(lockstep_lanes), gb(lockstep_lanes), gc(lockstep_lanes)
      integer :: i, k
      call back_update_first_rows(n, b, c, z, d, u, xa, xb, xc)
      call load_work_first_rows(n, g, d, ga, gb, gc)
      do i = n - kd, 3, -3
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, i) - off(1, i + 3)*xa(k) - off(2, i + 2)*xb(k) - off(3, i + 1)*xc(k)
            d(k, i) = d(k, i) + xa(k) + c(k)*z(i)
            u(k, i) = u(k, i) + d(k, i)
            ga(k) = ga(k) + g(k, i)*d(k, i)
            xb(k) = b(k, i - 1) - off(1, i + 2)*xb(k) - off(2, i + 1)*xc(k) - off(3, i)*xa(k)
            d(k, i - 1) = d(k, i - 1) + xb(k) + c(k)*z(i - 1)
            u(k, i - 1) = u(k, i - 1) + d(k, i - 1)
            gb(k) = gb(k) + g(k, i - 1)*d(k, i - 1)
            xc(k) = b(k, i - 2) - off(1, i + 1)*xc(k) - off(2, i)*xa(k) - off(3, i - 1)*xb(k)
            d(k, i - 2) = d(k, i - 2) + xc(k) + c(k)*z(i - 2)
            u(k, i - 2) = u(k, i - 2) + d(k, i - 2)
            gc(k) = gc(k) + g(k, i - 2)*d(k, i - 2)
         end do
      end do
      ! the rows left (fewer than three), then their terms of g.d (each row's term needs only
      ! its own d)
      call back_update_last_rows(off, i, n, b, c, z, d, u, xa, xb, xc)
      call load_work_last_rows(i, n, g, d, ga, gb, gc, gd)
   end subroutine wide_back_update_rows

   !> The interior rows kd+1 .. n-kd of the product by a periodic S and the right-hand side
   !> (beamstops_band_solve_lockstep's lockstep_matvec_rhs with `rows`): y = S x and rhs = a g - b y
   !> there, a pair of rows a turn, the fourteen coefficients in registers for the whole pass.
   pure subroutine wide_periodic_rows(n, rows, x, a, g, b, y, rhs)
      !> Unknowns.
      integer, intent(in) :: n
      !> The coefficients of interior rows kd+1 and kd+2 (lockstep_periodic_rows).
      real(wp), intent(in) :: rows(2*kd + 1, 2)
      !> x (lanes, n), dt^2 times the load weights (lanes), the load vectors (lanes, n), dt^2.
      real(wp), intent(in) :: x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b
      !> S x and the right-hand sides (lanes, n), their interior rows set.
      real(wp), intent(inout) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      real(wp) :: p1, p2, p3, p4, p5, p6, p7, q1, q2, q3, q4, q5, q6, q7
      integer :: j, k
      p1 = rows(1, 1); p2 = rows(2, 1); p3 = rows(3, 1); p4 = rows(4, 1); p5 = rows(5, 1); p6 = rows(6, 1)
      p7 = rows(7, 1)
      q1 = rows(1, 2); q2 = rows(2, 2); q3 = rows(3, 2); q4 = rows(4, 2); q5 = rows(5, 2); q6 = rows(6, 2)
      q7 = rows(7, 2)
      ! n - 2 kd interior rows: n = 2J and 2 kd are even, so whole pairs
      do j = kd + 1, n - kd - 1, 2
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            y(k, j) = p1*x(k, j - 3) + p2*x(k, j - 2) + p3*x(k, j - 1) + p4*x(k, j) + p5*x(k, j + 1) &
               & + p6*x(k, j + 2) + p7*x(k, j + 3)
            rhs(k, j) = a(k)*g(k, j) - b*y(k, j)
            y(k, j + 1) = q1*x(k, j - 2) + q2*x(k, j - 1) + q3*x(k, j) + q4*x(k, j + 1) + q5*x(k, j + 2) &
               & + q6*x(k, j + 3) + q7*x(k, j + 4)
            rhs(k, j + 1) = a(k)*g(k, j + 1) - b*y(k, j + 1)
         end do
      end do
   end subroutine wide_periodic_rows

   !> The product by a periodic S, the right-hand side and the forward substitution
   !> (beamstops_band_solve_lockstep's lockstep_matvec_rhs_forward) in one pass of explicit-shape
   !> arrays: the forward substitution follows the product six rows at a time, so that its chain
   !> (one multiply-add a row) runs while the product of the next six rows is computed instead of
   !> after the whole product. Every array at a fixed stride, so that the rows of a block address
   !> the factor from one register (through the descriptors of solver%off and stiffness%a,
   !> gfortran 12 kept an address per row and coefficient, 24 a block, and spilled them: about
   !> 20 % slower, bench_lockstep). The forward rows are written out here: taken from a helper
   !> shared with wide_forward_rows (three rows a turn while j <= last), the pass was 12 % slower
   !> at J = 19 and 15 % at J = 100 (bench_lockstep, A/B).
   pure subroutine wide_matvec_rhs_forward_rows(n, s, off, inv_d2, rows, x, a, g, b, spring, y, rhs)
      !> Unknowns, S by diagonals, the factor's off-diagonals and 1/U(j,j)^2, the coefficients of
      !> interior rows kd+1 and kd+2 of S.
      integer, intent(in) :: n
      real(wp), intent(in) :: s(n, 0:kd), off(kd, n), inv_d2(n), rows(2*kd + 1, 2)
      !> u (lanes, n), dt^2 times the load weights (lanes), the load vectors (lanes, n), dt^2, the
      !> force term of the tip row (lanes).
      real(wp), intent(in) :: x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b, spring(lockstep_lanes)
      !> S u and D^{-2} w (lanes, n).
      real(wp), intent(out) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      real(wp) :: p1, p2, p3, p4, p5, p6, p7, q1, q2, q3, q4, q5, q6, q7
      real(wp) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: i, j, k
      p1 = rows(1, 1); p2 = rows(2, 1); p3 = rows(3, 1); p4 = rows(4, 1); p5 = rows(5, 1); p6 = rows(6, 1)
      p7 = rows(7, 1)
      q1 = rows(1, 2); q2 = rows(2, 2); q3 = rows(3, 2); q4 = rows(4, 2); q5 = rows(5, 2); q6 = rows(6, 2)
      q7 = rows(7, 2)
      call matvec_rhs_first_rows(n, s, x, a, g, b, y, rhs)
      call forward_first_rows(off, inv_d2, n, rhs, xa, xb, xc)
      j = kd + 1
      do while (j + 5 <= n - kd)
         do i = j, j + 4, 2
!GCC$ ivdep
!GCC$ vector
            do k = 1, lockstep_lanes
               y(k, i) = p1*x(k, i - 3) + p2*x(k, i - 2) + p3*x(k, i - 1) + p4*x(k, i) + p5*x(k, i + 1) &
                  & + p6*x(k, i + 2) + p7*x(k, i + 3)
               rhs(k, i) = a(k)*g(k, i) - b*y(k, i)
               y(k, i + 1) = q1*x(k, i - 2) + q2*x(k, i - 1) + q3*x(k, i) + q4*x(k, i + 1) + q5*x(k, i + 2) &
                  & + q6*x(k, i + 3) + q7*x(k, i + 4)
               rhs(k, i + 1) = a(k)*g(k, i + 1) - b*y(k, i + 1)
            end do
         end do
         do i = j, j + 3, 3
!GCC$ ivdep
!GCC$ vector
            do k = 1, lockstep_lanes
               xa(k) = rhs(k, i) - off(1, i)*xa(k) - off(2, i)*xb(k) - off(3, i)*xc(k)
               rhs(k, i) = xa(k)*inv_d2(i)
               xb(k) = rhs(k, i + 1) - off(1, i + 1)*xb(k) - off(2, i + 1)*xc(k) - off(3, i + 1)*xa(k)
               rhs(k, i + 1) = xb(k)*inv_d2(i + 1)
               xc(k) = rhs(k, i + 2) - off(1, i + 2)*xc(k) - off(2, i + 2)*xa(k) - off(3, i + 2)*xb(k)
               rhs(k, i + 2) = xc(k)*inv_d2(i + 2)
            end do
         end do
         j = j + 6
      end do
      do i = j, n - kd - 1, 2
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            y(k, i) = p1*x(k, i - 3) + p2*x(k, i - 2) + p3*x(k, i - 1) + p4*x(k, i) + p5*x(k, i + 1) &
               & + p6*x(k, i + 2) + p7*x(k, i + 3)
            rhs(k, i) = a(k)*g(k, i) - b*y(k, i)
            y(k, i + 1) = q1*x(k, i - 2) + q2*x(k, i - 1) + q3*x(k, i) + q4*x(k, i + 1) + q5*x(k, i + 2) &
               & + q6*x(k, i + 3) + q7*x(k, i + 4)
            rhs(k, i + 1) = a(k)*g(k, i + 1) - b*y(k, i + 1)
         end do
      end do
      call matvec_rhs_last_rows(n, s, x, a, g, b, spring, y, rhs)
      do j = j, n - 2, 3
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = rhs(k, j) - off(1, j)*xa(k) - off(2, j)*xb(k) - off(3, j)*xc(k)
            rhs(k, j) = xa(k)*inv_d2(j)
            xb(k) = rhs(k, j + 1) - off(1, j + 1)*xb(k) - off(2, j + 1)*xc(k) - off(3, j + 1)*xa(k)
            rhs(k, j + 1) = xb(k)*inv_d2(j + 1)
            xc(k) = rhs(k, j + 2) - off(1, j + 2)*xc(k) - off(2, j + 2)*xa(k) - off(3, j + 2)*xb(k)
            rhs(k, j + 2) = xc(k)*inv_d2(j + 2)
         end do
      end do
      call forward_last_rows(off, inv_d2, j, n, rhs, xa, xb, xc)
   end subroutine wide_matvec_rhs_forward_rows

end module beamstops_band_solve_lockstep_wide
