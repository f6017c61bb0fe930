!> The kd = 3 substitutions, products and dot products of beamstops_band_solve for
!> lockstep_lanes right-hand sides at once, the member index innermost: arrays (lanes, n),
!> column j holding row j of every member, so that each multiply-add of a row acts on all the
!> lanes (SIMD across members) and the chain of a step is shared by them.
!>
!> Each row is one loop over the lanes (a compile-time width, marked for vectorization), so that
!> a row is a few whole-register operations with no loop of its own to pay.
!>
!> Registers: with AVX2 (16 ymm registers of four doubles, no AVX-512) a row of the eight lanes
!> is two registers, so that a loop whose body keeps more than a handful of row values and
!> coefficients live spills them to the stack and reloads them every row. The loops are cut to
!> fit: one row per loop over the lanes in the substitutions (the vectorizer broadcasts a loop's
!> coefficients at its start: three rows in one loop held twelve broadcasts and the six running
!> values at once), the periodic product's two rows in loops of their own (seven coefficients
!> each, not fourteen), the forward substitution after the product rather than interleaved with
!> it (its six running values stayed live across the product's rows), and g.d after the back
!> substitution rather than riding on it (its six partial sums were spilled). gfortran 12,
!> -march=znver3: no spill in those loops; bench_lockstep K = 8, J = 19 and 100: see
!> docs/lockstep.md.
!>
!> Bit for bit: every routine performs, for each lane, the floating-point operations of its
!> one-member counterpart in beamstops_band_solve, in the same order, with the same expressions
!> and the same multiply-adds. The one-member routines are written so that the compiler has no
!> choice of rounding to make: no running sum over rows that it could vectorize in order (the
!> dot and energy sums keep partial sums per row lane), so that every product met by an addition
!> is a multiply-add in both, whatever the vector width and tuning. tests/fortran/test_lockstep.f90
!> checks every kernel lane by lane against its one-member counterpart (J = 4..13, 19, 20, 100,
!> 101), and whole runs against the one-scene path:
!> a change of compiler, flags or of beamstops_band_solve shows there first.
!>
!> n >= 2 kd + 2 (J >= 4) is assumed; beamstops_lockstep refuses smaller meshes.
module beamstops_band_solve_lockstep
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   use beamstops_band_solve, only: band_solver, band_diagonals
   implicit none
   private
   public :: lockstep_forward, lockstep_energy_dots, lockstep_back, lockstep_matvec, lockstep_dot
   public :: lockstep_rhs, lockstep_update, lockstep_matvec_rhs, lockstep_periodic_rows
   public :: lockstep_back_edge, lockstep_back_update, lockstep_matvec_rhs_forward, lockstep_load_work
   public :: lockstep_min_unknowns, lockstep_work_columns, lockstep_lanes

   !> Fewest unknowns these routines handle (J >= 4).
   integer, parameter :: lockstep_min_unknowns = 2*kd + 2
   !> Columns of the work arrays of these routines.
   integer, parameter :: lockstep_work_columns = 8
   !> Members the routines advance at once (the first extent of their arrays): two AVX2
   !> registers of doubles.
   integer, parameter :: lockstep_lanes = 8

contains

   !> Forward substitution (I + N)^T w = b of every lane (beamstops_band_solve's
   !> forward_substitution): b replaced by D^{-2} w. Row j scales row j - 3, the last it needs.
   pure subroutine lockstep_forward(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> Right-hand sides (lanes, n), replaced by D^{-2} w.
      real(wp), intent(inout) :: b(lockstep_lanes, solver%n)
      call forward_rows(solver%n, solver%off, solver%inv_d2, b)
   end subroutine lockstep_forward

   !> The rows of lockstep_forward in explicit-shape arrays (every array at a fixed stride: the
   !> rows of a turn address the factor from one register). Three rows a turn, as
   !> beamstops_band_solve's forward_rows, each row a loop over the lanes of its own: its four
   !> coefficients are broadcast at its start, so that a turn keeps the six running values (xa,
   !> xb, xc of eight lanes) and one row's coefficients live, not the twelve of three rows.
   pure subroutine forward_rows(n, off, inv_d2, b)
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
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
   end subroutine forward_rows

   !> The first three rows of the forward substitution of every lane: b(:, 1:3) replaced by
   !> D^{-2} w(:, 1:3), w(:, 1:3) returned in xa, xb, xc (beamstops_band_solve's first_rows).
   pure subroutine forward_first_rows(off, inv_d2, n, b, xa, xb, xc)
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
      real(wp), intent(inout) :: b(lockstep_lanes, n)
      real(wp), intent(out) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         xa(k) = b(k, 1)
         xb(k) = b(k, 2) - off(3, 2)*xa(k)
         xc(k) = b(k, 3) - off(2, 3)*xa(k) - off(3, 3)*xb(k)
         b(k, 1) = xa(k)*inv_d2(1)
         b(k, 2) = xb(k)*inv_d2(2)
         b(k, 3) = xc(k)*inv_d2(3)
      end do
   end subroutine forward_first_rows

   !> The rows j and j+1 (those of them <= n) left after the loop by three (last_rows).
   pure subroutine forward_last_rows(off, inv_d2, j, n, b, xa, xb, xc)
      integer, intent(in) :: j, n
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
      real(wp), intent(inout) :: b(lockstep_lanes, n)
      real(wp), intent(inout) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: k
      if (j <= n) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, j) - off(1, j)*xa(k) - off(2, j)*xb(k) - off(3, j)*xc(k)
            b(k, j) = xa(k)*inv_d2(j)
         end do
      end if
      if (j + 1 <= n) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            b(k, j + 1) = (b(k, j + 1) - off(1, j + 1)*xb(k) - off(2, j + 1)*xc(k) - off(3, j + 1)*xa(k))*inv_d2(j + 1)
         end do
      end if
   end subroutine forward_last_rows

   !> The dot products of the discrete energy of every lane (beamstops_band_solve's
   !> energy_dots): usu = u.su, dsu = d.su, dmd = d.M d, each in eight partial sums per lane (row
   !> j in sum mod(j - 1, 8) + 1; a sum with no row stays 0) added as
   !> ((s1 + s2) + (s3 + s4)) + ((s5 + s6) + (s7 + s8)).
   pure subroutine lockstep_energy_dots(mass, u, d, su, usu, dsu, dmd)
      !> M by diagonals.
      type(band_diagonals), intent(in) :: mass
      !> u, d and su of every lane (lanes, n).
      real(wp), intent(in) :: u(lockstep_lanes, mass%n), d(lockstep_lanes, mass%n), su(lockstep_lanes, mass%n)
      !> u.su, d.su and d.M d of every lane (lanes).
      real(wp), intent(out) :: usu(lockstep_lanes), dsu(lockstep_lanes), dmd(lockstep_lanes)
      integer, parameter :: sums = 8
      real(wp) :: a(lockstep_lanes, sums), b(lockstep_lanes, sums), c(lockstep_lanes, sums)
      integer :: i, k, l, n
      n = mass%n
      a = 0
      b = 0
      c = 0
      associate (m => mass%a)
         do i = 1, min(n, sums)
!GCC$ ivdep
!GCC$ vector
            do k = 1, lockstep_lanes
               a(k, i) = u(k, i)*su(k, i)
               b(k, i) = d(k, i)*su(k, i)
            end do
         end do
         ! the first three rows, with fewer neighbours (n >= 1)
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            c(k, 1) = d(k, 1)*(m(1, 0)*d(k, 1))
            if (n >= 2) c(k, 2) = d(k, 2)*(m(2, 0)*d(k, 2) + 2*(m(2, 1)*d(k, 1)))
            if (n >= 3) c(k, 3) = d(k, 3)*(m(3, 0)*d(k, 3) + 2*(m(3, 1)*d(k, 2) + m(3, 2)*d(k, 1)))
         end do
         do i = 4, min(n, sums)
!GCC$ ivdep
!GCC$ vector
            do k = 1, lockstep_lanes
               c(k, i) = d(k, i)*(m(i, 0)*d(k, i) + 2*(m(i, 1)*d(k, i - 1) + m(i, 2)*d(k, i - 2) &
                  & + m(i, 3)*d(k, i - 3)))
            end do
         end do
         do i = sums + 1, n
            l = mod(i - 1, sums) + 1
!GCC$ ivdep
!GCC$ vector
            do k = 1, lockstep_lanes
               a(k, l) = a(k, l) + u(k, i)*su(k, i)
               b(k, l) = b(k, l) + d(k, i)*su(k, i)
               c(k, l) = c(k, l) + d(k, i)*(m(i, 0)*d(k, i) + 2*(m(i, 1)*d(k, i - 1) + m(i, 2)*d(k, i - 2) &
                  & + m(i, 3)*d(k, i - 3)))
            end do
         end do
      end associate
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         usu(k) = ((a(k, 1) + a(k, 2)) + (a(k, 3) + a(k, 4))) + ((a(k, 5) + a(k, 6)) + (a(k, 7) + a(k, 8)))
         dsu(k) = ((b(k, 1) + b(k, 2)) + (b(k, 3) + b(k, 4))) + ((b(k, 5) + b(k, 6)) + (b(k, 7) + b(k, 8)))
         dmd(k) = ((c(k, 1) + c(k, 2)) + (c(k, 3) + c(k, 4))) + ((c(k, 5) + c(k, 6)) + (c(k, 7) + c(k, 8)))
      end do
   end subroutine lockstep_energy_dots

   !> Back substitution (I + N) x = b of every lane (beamstops_band_solve's back_substitution,
   !> its edge rows included).
   pure subroutine lockstep_back(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> D^{-2} w (lanes, n), replaced by x.
      real(wp), intent(inout) :: b(lockstep_lanes, solver%n)
      call back_rows(solver%n, solver%off, b)
   end subroutine lockstep_back

   !> The rows of lockstep_back in explicit-shape arrays, one loop over the lanes a row (as
   !> forward_rows).
   pure subroutine back_rows(n, off, b)
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n)
      real(wp), intent(inout) :: b(lockstep_lanes, n)
      real(wp) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: i, k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         ! the edge rows, farthest value first (as back_rows)
         b(k, n - 1) = b(k, n - 1) - off(3, n)*b(k, n)
         b(k, n - 2) = b(k, n - 2) - off(2, n)*b(k, n) - off(3, n - 1)*b(k, n - 1)
         xa(k) = b(k, n)
         xb(k) = b(k, n - 1)
         xc(k) = b(k, n - 2)
      end do
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
      if (i >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, i) - off(1, i + 3)*xa(k) - off(2, i + 2)*xb(k) - off(3, i + 1)*xc(k)
            b(k, i) = xa(k)
         end do
      end if
      if (i - 1 >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            b(k, i - 1) = b(k, i - 1) - off(1, i + 2)*xb(k) - off(2, i + 1)*xc(k) - off(3, i)*xa(k)
         end do
      end if
   end subroutine back_rows

   !> The first rows of lockstep_back, x_n, x_{n-1} and x_{n-2} of every lane (beamstops_band_solve's
   !> back_substitution_edge): the tip value x_{n-1} that the contact law needs before the rest
   !> of the substitution, lockstep_back_update.
   pure subroutine lockstep_back_edge(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> D^{-2} w (lanes, n); its last kd rows replaced by those of x.
      real(wp), intent(inout) :: b(lockstep_lanes, solver%n)
      integer :: k, n
      n = solver%n
      associate (off => solver%off)
         ! farthest value first (as back_rows); a loop over the lanes (the sections b(:, n - 1)
         ! were scalar code, a loop of their own each)
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            b(k, n - 1) = b(k, n - 1) - off(3, n)*b(k, n)
            b(k, n - 2) = b(k, n - 2) - off(2, n)*b(k, n) - off(3, n - 1)*b(k, n - 1)
         end do
      end associate
   end subroutine lockstep_back_edge

   !> The rest of lockstep_back after lockstep_back_edge, each row of x followed at once by its
   !> row of the update (lockstep_update: d = d + x + c z, u = u + d), so that the update rides in
   !> the shadow of the substitution's chain instead of a pass of its own, and x itself is not
   !> stored (the update is its only use); then g.d^n (lockstep_load_work). Per lane the same
   !> operations as lockstep_back, lockstep_update then lockstep_load_work (the update of a row
   !> needs only that row).
   pure subroutine lockstep_back_update(solver, b, c, z, g, d, u, gd)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> D^{-2} w (lanes, n) with its last kd rows from lockstep_back_edge (left as it is).
      real(wp), intent(in) :: b(lockstep_lanes, solver%n)
      !> Multiples of z (lanes).
      real(wp), intent(in) :: c(lockstep_lanes)
      !> z = A^{-1} e_tip (n).
      real(wp), intent(in) :: z(solver%n)
      !> Load vectors (lanes, n).
      real(wp), intent(in) :: g(lockstep_lanes, solver%n)
      !> d^{n-1} and u^n on entry, d^n and u^{n+1} on return (lanes, n).
      real(wp), intent(inout) :: d(lockstep_lanes, solver%n), u(lockstep_lanes, solver%n)
      !> g.d^n of every lane (lanes; beamstops_band_solve's load_work_product).
      real(wp), intent(out) :: gd(lockstep_lanes)
      call back_update_rows(solver%n, solver%off, b, c, z, d, u)
      call lockstep_load_work(solver%n, g, d, gd)
   end subroutine lockstep_back_update

   !> The rows of lockstep_back_update in explicit-shape arrays, one loop over the lanes a row (as
   !> forward_rows). g.d is not taken here: its three partial sums of eight lanes beside the six
   !> running values and c did not fit in the sixteen registers of AVX2 and were spilled and
   !> reloaded every row; lockstep_load_work takes it after, in the same order.
   pure subroutine back_update_rows(n, off, b, c, z, d, u)
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), b(lockstep_lanes, n), c(lockstep_lanes), z(n)
      real(wp), intent(inout) :: d(lockstep_lanes, n), u(lockstep_lanes, n)
      real(wp) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: i, k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         xa(k) = b(k, n)
         xb(k) = b(k, n - 1)
         xc(k) = b(k, n - 2)
         d(k, n) = d(k, n) + xa(k) + c(k)*z(n)
         u(k, n) = u(k, n) + d(k, n)
         d(k, n - 1) = d(k, n - 1) + xb(k) + c(k)*z(n - 1)
         u(k, n - 1) = u(k, n - 1) + d(k, n - 1)
         d(k, n - 2) = d(k, n - 2) + xc(k) + c(k)*z(n - 2)
         u(k, n - 2) = u(k, n - 2) + d(k, n - 2)
      end do
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
      if (i >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, i) - off(1, i + 3)*xa(k) - off(2, i + 2)*xb(k) - off(3, i + 1)*xc(k)
            d(k, i) = d(k, i) + xa(k) + c(k)*z(i)
            u(k, i) = u(k, i) + d(k, i)
         end do
      end if
      if (i - 1 >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xb(k) = b(k, i - 1) - off(1, i + 2)*xb(k) - off(2, i + 1)*xc(k) - off(3, i)*xa(k)
            d(k, i - 1) = d(k, i - 1) + xb(k) + c(k)*z(i - 1)
            u(k, i - 1) = u(k, i - 1) + d(k, i - 1)
         end do
      end if
   end subroutine back_update_rows

   !> g.d of every lane in the order of beamstops_band_solve's load_work_product (row j in sum
   !> mod(n - j, 3) + 1 from the last row down, then (s1 + s2) + s3), n >= kd: for the loops whose
   !> update does not ride on the back substitution (lockstep_back_update takes it there).
   pure subroutine lockstep_load_work(n, g, d, gd)
      !> Unknowns.
      integer, intent(in) :: n
      !> Load vectors and d (lanes, n).
      real(wp), intent(in) :: g(lockstep_lanes, n), d(lockstep_lanes, n)
      !> The products (lanes).
      real(wp), intent(out) :: gd(lockstep_lanes)
      real(wp) :: ga(lockstep_lanes), gb(lockstep_lanes), gc(lockstep_lanes)
      integer :: i, k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         ga(k) = g(k, n)*d(k, n)
         gb(k) = g(k, n - 1)*d(k, n - 1)
         gc(k) = g(k, n - 2)*d(k, n - 2)
      end do
      do i = n - kd, 3, -3
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            ga(k) = ga(k) + g(k, i)*d(k, i)
            gb(k) = gb(k) + g(k, i - 1)*d(k, i - 1)
            gc(k) = gc(k) + g(k, i - 2)*d(k, i - 2)
         end do
      end do
      if (i >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            ga(k) = ga(k) + g(k, i)*d(k, i)
         end do
      end if
      if (i - 1 >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            gb(k) = gb(k) + g(k, i - 1)*d(k, i - 1)
         end do
      end if
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         gd(k) = (ga(k) + gb(k)) + gc(k)
      end do
   end subroutine lockstep_load_work

   !> y = A x of every lane for a symmetric band matrix by diagonals (beamstops_band_solve's
   !> diagonal_matvec, n >= 2 kd + 1).
   pure subroutine lockstep_matvec(diagonals, x, y)
      !> Matrix by diagonals.
      type(band_diagonals), intent(in) :: diagonals
      !> Vectors (lanes, n).
      real(wp), intent(in) :: x(lockstep_lanes, diagonals%n)
      !> Products (lanes, n).
      real(wp), intent(out) :: y(lockstep_lanes, diagonals%n)
      integer :: j, k, n
      n = diagonals%n
      associate (a => diagonals%a)
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            y(k, 1) = a(1, 0)*x(k, 1) + a(2, 1)*x(k, 2) + a(3, 2)*x(k, 3) + a(4, 3)*x(k, 4)
            y(k, 2) = a(2, 1)*x(k, 1) + a(2, 0)*x(k, 2) + a(3, 1)*x(k, 3) + a(4, 2)*x(k, 4) + a(5, 3)*x(k, 5)
            y(k, 3) = a(3, 2)*x(k, 1) + a(3, 1)*x(k, 2) + a(3, 0)*x(k, 3) + a(4, 1)*x(k, 4) + a(5, 2)*x(k, 5) &
               & + a(6, 3)*x(k, 6)
         end do
         do j = kd + 1, n - kd
!GCC$ ivdep
!GCC$ vector
            do k = 1, lockstep_lanes
               y(k, j) = a(j, 3)*x(k, j - 3) + a(j, 2)*x(k, j - 2) + a(j, 1)*x(k, j - 1) + a(j, 0)*x(k, j) &
                  & + a(j + 1, 1)*x(k, j + 1) + a(j + 2, 2)*x(k, j + 2) + a(j + 3, 3)*x(k, j + 3)
            end do
         end do
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            y(k, n - 2) = a(n - 2, 3)*x(k, n - 5) + a(n - 2, 2)*x(k, n - 4) + a(n - 2, 1)*x(k, n - 3) &
               & + a(n - 2, 0)*x(k, n - 2) + a(n - 1, 1)*x(k, n - 1) + a(n, 2)*x(k, n)
            y(k, n - 1) = a(n - 1, 3)*x(k, n - 4) + a(n - 1, 2)*x(k, n - 3) + a(n - 1, 1)*x(k, n - 2) &
               & + a(n - 1, 0)*x(k, n - 1) + a(n, 1)*x(k, n)
            y(k, n) = a(n, 3)*x(k, n - 3) + a(n, 2)*x(k, n - 2) + a(n, 1)*x(k, n - 1) + a(n, 0)*x(k, n)
         end do
      end associate
   end subroutine lockstep_matvec

   !> s_k = x_k . y_k of every lane with the eight partial sums of beamstops_band_solve's dot
   !> (row j in sum mod(j - 1, 8) + 1, the rows after the last eight too).
   pure subroutine lockstep_dot(n, x, y, partial, s)
      !> Length of the vectors.
      integer, intent(in) :: n
      !> Vectors (lanes, n).
      real(wp), intent(in) :: x(lockstep_lanes, n), y(lockstep_lanes, n)
      !> Work array (lanes, lockstep_work_columns).
      real(wp), intent(out) :: partial(lockstep_lanes, lockstep_work_columns)
      !> The dot products (lanes).
      real(wp), intent(out) :: s(lockstep_lanes)
      integer :: j, k, l
      partial(:, 1:8) = 0
      do j = 1, n - 7, 8
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            partial(k, 1) = partial(k, 1) + x(k, j)*y(k, j)
            partial(k, 2) = partial(k, 2) + x(k, j + 1)*y(k, j + 1)
            partial(k, 3) = partial(k, 3) + x(k, j + 2)*y(k, j + 2)
            partial(k, 4) = partial(k, 4) + x(k, j + 3)*y(k, j + 3)
            partial(k, 5) = partial(k, 5) + x(k, j + 4)*y(k, j + 4)
            partial(k, 6) = partial(k, 6) + x(k, j + 5)*y(k, j + 5)
            partial(k, 7) = partial(k, 7) + x(k, j + 6)*y(k, j + 6)
            partial(k, 8) = partial(k, 8) + x(k, j + 7)*y(k, j + 7)
         end do
      end do
      do l = 1, n - j + 1
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            partial(k, l) = partial(k, l) + x(k, j + l - 1)*y(k, j + l - 1)
         end do
      end do
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         s(k) = ((partial(k, 1) + partial(k, 5)) + (partial(k, 2) + partial(k, 6))) &
            & + ((partial(k, 3) + partial(k, 7)) + (partial(k, 4) + partial(k, 8)))
      end do
   end subroutine lockstep_dot

   !> lockstep_matvec (S u) and lockstep_rhs (rhs = a g - b S u + spring e_{n-1}) in one pass. With
   !> `rows`, for an S whose interior rows kd+1 .. n-kd repeat with period 2 (a uniform mesh:
   !> lockstep_periodic_rows says whether they do), the two rows' coefficients, given once, stay in
   !> registers for the whole pass instead of being broadcast row by row: the same products of the
   !> same values in the same order, the same bits.
   pure subroutine lockstep_matvec_rhs(stiffness, u, a, g, b, spring, su, rhs, rows)
      !> S by diagonals.
      type(band_diagonals), intent(in) :: stiffness
      !> u of every lane (lanes, n).
      real(wp), intent(in) :: u(lockstep_lanes, stiffness%n)
      !> dt^2 times the load weight of every lane (lanes).
      real(wp), intent(in) :: a(lockstep_lanes)
      !> Load vectors (lanes, n).
      real(wp), intent(in) :: g(lockstep_lanes, stiffness%n)
      !> dt^2.
      real(wp), intent(in) :: b
      !> Force term of the tip row (lanes).
      real(wp), intent(in) :: spring(lockstep_lanes)
      !> S u (lanes, n).
      real(wp), intent(out) :: su(lockstep_lanes, stiffness%n)
      !> Right-hand sides (lanes, n).
      real(wp), intent(out) :: rhs(lockstep_lanes, stiffness%n)
      !> The coefficients of interior rows kd+1 and kd+2 of a periodic S in the order of a row's
      !> products (lockstep_periodic_rows).
      real(wp), intent(in), optional :: rows(2*kd + 1, 2)
      integer :: j, k, n
      n = stiffness%n
      call matvec_rhs_first_rows(n, stiffness%a, u, a, g, b, su, rhs)
      if (present(rows)) then
         call matvec_rhs_periodic_rows(n, rows, u, a, g, b, su, rhs)
      else
         associate (s => stiffness%a, x => u, y => su)
            do j = kd + 1, n - kd
!GCC$ ivdep
!GCC$ vector
               do k = 1, lockstep_lanes
                  y(k, j) = s(j, 3)*x(k, j - 3) + s(j, 2)*x(k, j - 2) + s(j, 1)*x(k, j - 1) + s(j, 0)*x(k, j) &
                     & + s(j + 1, 1)*x(k, j + 1) + s(j + 2, 2)*x(k, j + 2) + s(j + 3, 3)*x(k, j + 3)
                  rhs(k, j) = a(k)*g(k, j) - b*y(k, j)
               end do
            end do
         end associate
      end if
      call matvec_rhs_last_rows(n, stiffness%a, u, a, g, b, spring, su, rhs)
   end subroutine lockstep_matvec_rhs

   !> The interior rows kd+1 .. n-kd of lockstep_matvec_rhs with period-2 coefficients `rows`:
   !> y = S x and rhs = a g - b y there, the rows of each coefficient set in a loop of their own
   !> (periodic_half).
   pure subroutine matvec_rhs_periodic_rows(n, rows, x, a, g, b, y, rhs)
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
   end subroutine matvec_rhs_periodic_rows

   !> The interior rows first, first + 2, .. <= n - kd of matvec_rhs_periodic_rows, all with the
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

   !> lockstep_matvec_rhs with `rows` (a periodic S) then lockstep_forward: rhs is returned as
   !> lockstep_forward leaves it (D^{-2} w). The forward substitution follows the whole product
   !> (it was interleaved with it, six rows at a time, so that its chain would run in the
   !> product's shadow; with AVX2 its six running values then stayed live across the product's
   !> rows and pushed the coefficients out of the registers: the product and the substitution
   !> are both bound by the multiply-adds they issue, so the interleaving won nothing back).
   pure subroutine lockstep_matvec_rhs_forward(stiffness, solver, rows, u, a, g, b, spring, su, rhs)
      !> S by diagonals and the factor of A.
      type(band_diagonals), intent(in) :: stiffness
      type(band_solver), intent(in) :: solver
      !> The coefficients of interior rows kd+1 and kd+2 of S (lockstep_periodic_rows).
      real(wp), intent(in) :: rows(2*kd + 1, 2)
      !> u of every lane (lanes, n), dt^2 times the load weights (lanes), the load vectors
      !> (lanes, n), dt^2 and the force term of the tip row (lanes).
      real(wp), intent(in) :: u(lockstep_lanes, stiffness%n), a(lockstep_lanes), g(lockstep_lanes, stiffness%n), &
         & b, spring(lockstep_lanes)
      !> S u (lanes, n).
      real(wp), intent(out) :: su(lockstep_lanes, stiffness%n)
      !> D^{-2} w, w the forward substitution of rhs = a g - b S u + spring e_{n-1} (lanes, n).
      real(wp), intent(out) :: rhs(lockstep_lanes, stiffness%n)
      call matvec_rhs_forward_rows(stiffness%n, stiffness%a, solver%off, solver%inv_d2, rows, u, a, g, b, spring, su, rhs)
   end subroutine lockstep_matvec_rhs_forward

   !> The rows of lockstep_matvec_rhs_forward in explicit-shape arrays (as forward_rows): every
   !> array at a fixed stride (through the descriptors of solver%off and stiffness%a, gfortran 12
   !> kept an address per row and coefficient and spilled them).
   pure subroutine matvec_rhs_forward_rows(n, s, off, inv_d2, rows, x, a, g, b, spring, y, rhs)
      integer, intent(in) :: n
      real(wp), intent(in) :: s(n, 0:kd), off(kd, n), inv_d2(n), rows(2*kd + 1, 2)
      real(wp), intent(in) :: x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b, spring(lockstep_lanes)
      real(wp), intent(out) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      call matvec_rhs_first_rows(n, s, x, a, g, b, y, rhs)
      call matvec_rhs_periodic_rows(n, rows, x, a, g, b, y, rhs)
      call matvec_rhs_last_rows(n, s, x, a, g, b, spring, y, rhs)
      call forward_rows(n, off, inv_d2, rhs)
   end subroutine matvec_rhs_forward_rows

   !> Whether the interior rows kd+1 .. n-kd of a band matrix repeat with period 2, and the
   !> coefficients of the first two in the order of a row's products (A(j, j-3), A(j, j-2),
   !> A(j, j-1), A(j, j), A(j, j+1), A(j, j+2), A(j, j+3)): exactly, value for value, so that
   !> lockstep_matvec_rhs computes the same with them as without.
   pure subroutine lockstep_periodic_rows(diagonals, periodic, rows)
      !> Matrix by diagonals (n >= 2 kd + 2).
      type(band_diagonals), intent(in) :: diagonals
      !> Whether they repeat.
      logical, intent(out) :: periodic
      !> The coefficients of rows kd+1 and kd+2.
      real(wp), intent(out) :: rows(2*kd + 1, 2)
      integer :: j
      rows(:, 1) = row_coefficients(diagonals, kd + 1)
      rows(:, 2) = row_coefficients(diagonals, kd + 2)
      periodic = .true.
      do j = kd + 1, diagonals%n - kd
         periodic = periodic .and. all(row_coefficients(diagonals, j) == rows(:, 1 + mod(j - kd - 1, 2)))
      end do
   end subroutine lockstep_periodic_rows

   !> The coefficients of interior row j in the order of its products.
   pure function row_coefficients(diagonals, j) result(c)
      type(band_diagonals), intent(in) :: diagonals
      integer, intent(in) :: j
      real(wp) :: c(2*kd + 1)
      associate (s => diagonals%a)
         c = [s(j, 3), s(j, 2), s(j, 1), s(j, 0), s(j + 1, 1), s(j + 2, 2), s(j + 3, 3)]
      end associate
   end function row_coefficients

   !> The first kd rows of lockstep_matvec_rhs.
   pure subroutine matvec_rhs_first_rows(n, s, x, a, g, b, y, rhs)
      integer, intent(in) :: n
      real(wp), intent(in) :: s(n, 0:kd), x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b
      real(wp), intent(inout) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      integer :: k
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            y(k, 1) = s(1, 0)*x(k, 1) + s(2, 1)*x(k, 2) + s(3, 2)*x(k, 3) + s(4, 3)*x(k, 4)
            y(k, 2) = s(2, 1)*x(k, 1) + s(2, 0)*x(k, 2) + s(3, 1)*x(k, 3) + s(4, 2)*x(k, 4) + s(5, 3)*x(k, 5)
            y(k, 3) = s(3, 2)*x(k, 1) + s(3, 1)*x(k, 2) + s(3, 0)*x(k, 3) + s(4, 1)*x(k, 4) + s(5, 2)*x(k, 5) &
               & + s(6, 3)*x(k, 6)
            rhs(k, 1) = a(k)*g(k, 1) - b*y(k, 1)
            rhs(k, 2) = a(k)*g(k, 2) - b*y(k, 2)
            rhs(k, 3) = a(k)*g(k, 3) - b*y(k, 3)
         end do
   end subroutine matvec_rhs_first_rows

   !> The last kd rows of lockstep_matvec_rhs, and the spring term of the tip row n-1.
   pure subroutine matvec_rhs_last_rows(n, s, x, a, g, b, spring, y, rhs)
      integer, intent(in) :: n
      real(wp), intent(in) :: s(n, 0:kd), x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b, &
         & spring(lockstep_lanes)
      real(wp), intent(inout) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      integer :: k
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            y(k, n - 2) = s(n - 2, 3)*x(k, n - 5) + s(n - 2, 2)*x(k, n - 4) + s(n - 2, 1)*x(k, n - 3) &
               & + s(n - 2, 0)*x(k, n - 2) + s(n - 1, 1)*x(k, n - 1) + s(n, 2)*x(k, n)
            y(k, n - 1) = s(n - 1, 3)*x(k, n - 4) + s(n - 1, 2)*x(k, n - 3) + s(n - 1, 1)*x(k, n - 2) &
               & + s(n - 1, 0)*x(k, n - 1) + s(n, 1)*x(k, n)
            y(k, n) = s(n, 3)*x(k, n - 3) + s(n, 2)*x(k, n - 2) + s(n, 1)*x(k, n - 1) + s(n, 0)*x(k, n)
            rhs(k, n - 2) = a(k)*g(k, n - 2) - b*y(k, n - 2)
            rhs(k, n - 1) = a(k)*g(k, n - 1) - b*y(k, n - 1)
            rhs(k, n) = a(k)*g(k, n) - b*y(k, n)
            rhs(k, n - 1) = rhs(k, n - 1) + spring(k)
         end do
   end subroutine matvec_rhs_last_rows

   !> The right-hand sides of a step, rhs = a g - b S u plus `spring` in the tip row n-1 (the
   !> forward pass of beamstops_scheme), of every lane.
   pure subroutine lockstep_rhs(n, a, g, b, su, spring, rhs)
      !> Unknowns.
      integer, intent(in) :: n
      !> dt^2 times the load weight of every lane (lanes).
      real(wp), intent(in) :: a(lockstep_lanes)
      !> Load vectors (lanes, n).
      real(wp), intent(in) :: g(lockstep_lanes, n)
      !> dt^2.
      real(wp), intent(in) :: b
      !> S u (lanes, n).
      real(wp), intent(in) :: su(lockstep_lanes, n)
      !> Force term of the tip row (lanes).
      real(wp), intent(in) :: spring(lockstep_lanes)
      !> Right-hand sides (lanes, n).
      real(wp), intent(out) :: rhs(lockstep_lanes, n)
      integer :: j, k
      do j = 1, n
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            rhs(k, j) = a(k)*g(k, j) - b*su(k, j)
         end do
      end do
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         rhs(k, n - 1) = rhs(k, n - 1) + spring(k)
      end do
   end subroutine lockstep_rhs

   !> The update of a step, d^n = d^{n-1} + x + c z, u^{n+1} = u^n + d^n, of every lane.
   pure subroutine lockstep_update(n, x, c, z, d, u)
      !> Unknowns.
      integer, intent(in) :: n
      !> A^{-1} rhs (lanes, n).
      real(wp), intent(in) :: x(lockstep_lanes, n)
      !> Multiples of z (lanes).
      real(wp), intent(in) :: c(lockstep_lanes)
      !> z = A^{-1} e_tip (n).
      real(wp), intent(in) :: z(n)
      !> d^{n-1} and u^n on entry, d^n and u^{n+1} on return (lanes, n).
      real(wp), intent(inout) :: d(lockstep_lanes, n), u(lockstep_lanes, n)
      integer :: j, k
      do j = 1, n
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            d(k, j) = d(k, j) + x(k, j) + c(k)*z(j)
            u(k, j) = u(k, j) + d(k, j)
         end do
      end do
   end subroutine lockstep_update
end module beamstops_band_solve_lockstep
