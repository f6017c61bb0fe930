!> Fused forward and back substitution for the kd = 3 band Cholesky factor of
!> LAPACK (dpbtrf, 'U'), the solve of the time loop; S and M by diagonals for its
!> vectorized products.
!>
!> LAPACK stays the factorization: A = U^T U comes from dpbtrf. The factor is
!> rewritten once as A = (I + N)^T D^2 (I + N), D = diag(U), N = D^{-1} U - I
!> (strictly upper, three diagonals). Each row of each substitution is then three
!> multiply-adds and no division, and the dependency from one row to the next is a
!> single multiply-add (the nearest value is subtracted last): the chain of the two
!> solves is 2n multiply-adds, the shortest a row-by-row substitution can have.
!> dpbtrs (two dtbsv calls) divides by the diagonal on the chain and goes through the
!> generic band loops. Agrees with dpbtrs to round-off (tests/python/test_speed_fused.py).
!>
!> The loops take three rows a turn: the last three values stay in three registers
!> and each new row overwrites the farthest, so the roles rotate and no value is
!> copied between rows (a register copy lengthens the chain by a cycle a row).
module beamstops_band_solve
   use, intrinsic :: iso_c_binding, only: c_int32_t, c_double
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   implicit none
   private
   public :: band_solver, prepare_solver, fused_solve, forward_substitution, back_substitution
   public :: back_substitution_edge, back_substitution_update, load_work_product
   public :: energy_dots, forward_substitution_energy
   public :: band_diagonals, prepare_diagonals, diagonal_matvec, diagonal_matvec_rhs, diagonal_row, dot

   !> The factor of A = M + dt^2 beta S in the form the fused substitutions read.
   type :: band_solver
      !> Number of unknowns n.
      integer :: n = 0
      !> N = D^{-1} U - I in band storage (kd, n): off(kd + 1 + i - j, j) = U(i,j)/U(i,i), j - kd <= i < j.
      real(wp), allocatable :: off(:, :)
      !> 1/U(j,j)^2 (n).
      real(wp), allocatable :: inv_d2(:)
   end type band_solver

   interface
      !> The sums of energy_dots (src/beamstops/energy_rows.c): u.su, d.su and d.M d.
      pure subroutine energy_rows(n, m, u, d, su, sums) bind(C, name='beamstops_energy_rows')
         import :: c_int32_t, c_double
         integer(c_int32_t), value, intent(in) :: n
         real(c_double), intent(in) :: m(n, 0:3), u(n), d(n), su(n)
         real(c_double), intent(out) :: sums(3)
      end subroutine energy_rows
   end interface

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

   !> Solve A x = b in place.
   pure subroutine fused_solve(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> Right-hand side (n), replaced by the solution.
      real(wp), intent(inout), contiguous :: b(:)
      call forward_substitution(solver, b)
      call back_substitution(solver, b)
   end subroutine fused_solve

   !> Forward substitution (I + N)^T w = b, w_j = b_j - N(j-3,j) w_{j-3} - N(j-2,j) w_{j-2}
   !> - N(j-1,j) w_{j-1}; b is replaced by D^{-2} w, the right-hand side of back_substitution
   !> (the scaling is off the chain here; in the back substitution it would be on it).
   pure subroutine forward_substitution(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> Right-hand side b (n), replaced by D^{-2} w.
      real(wp), intent(inout), contiguous :: b(:)
      integer :: j, n
      n = solver%n
      associate (off => solver%off, inv_d2 => solver%inv_d2)
         if (n < kd) then
            do j = 2, n
               b(j) = b(j) - sum(off(kd + 1 - min(j - 1, kd):kd, j)*b(max(1, j - kd):j - 1))
            end do
            b = b*inv_d2
            return
         end if
         call forward_rows(n, off, inv_d2, b)
      end associate
   end subroutine forward_substitution

   !> forward_substitution, then energy_dots' sums of u, d and su (usu, dsu, dmd): the same
   !> operations and bits. The sums are taken halfway down the substitution's chain (n >= kd),
   !> where their instructions run beside it; after the chain they stood between the two
   !> substitutions and delayed the second (docs/performance_notes.md, "The energy sums halfway
   !> down the forward substitution").
   pure subroutine forward_substitution_energy(solver, mass, u, d, su, b, usu, dsu, dmd)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> M by diagonals.
      type(band_diagonals), intent(in) :: mass
      !> u, d and su (n).
      real(wp), intent(in), contiguous :: u(:), d(:), su(:)
      !> Right-hand side b (n), replaced by D^{-2} w.
      real(wp), intent(inout), contiguous :: b(:)
      !> u.su, d.su and d.M d.
      real(wp), intent(out) :: usu, dsu, dmd
      real(wp) :: sums(3)
      if (solver%n < kd) then
         call forward_substitution(solver, b)
         call energy_dots(mass, u, d, su, usu, dsu, dmd)
         return
      end if
      call forward_rows(solver%n, solver%off, solver%inv_d2, b, mass%a, u, d, su, sums)
      usu = sums(1)
      dsu = sums(2)
      dmd = sums(3)
   end subroutine forward_substitution_energy

   !> The rows of forward_substitution for n >= kd, all in one routine of explicit-shape arrays:
   !> the compiler keeps the three running values in registers and every array at a fixed
   !> stride, and the first and last rows are written out (no call, no loop of their own on the
   !> chain). With `sums`, energy_rows' sums of m, u, d and su halfway down the chain (one
   !> routine for both, so that the compiler keeps the edge rows inlined).
   pure subroutine forward_rows(n, off, inv_d2, b, m, u, d, su, sums)
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
      real(wp), intent(inout) :: b(n)
      real(wp), intent(in), optional :: m(n, 0:kd), u(n), d(n), su(n)
      real(wp), intent(out), optional :: sums(3)
      real(wp) :: xa, xb, xc
      integer :: j, half
      ! the first row of the turns after the sums: about the middle, else past the last turn
      if (present(sums)) then
         half = kd + 1 + 3*max(0, (n/2 - kd - 1)/3)
      else
         half = kd + 1 + 3*max(0, (n - kd)/3)
      end if
      call first_rows(n, off, inv_d2, b, xa, xb, xc)
      do j = kd + 1, half - 1, 3
         call forward_turn(n, off, inv_d2, j, b, xa, xb, xc)
      end do
      if (present(sums)) call energy_rows(n, m, u, d, su, sums)
      do j = half, n - 2, 3
         call forward_turn(n, off, inv_d2, j, b, xa, xb, xc)
      end do
      call last_rows(n, off, inv_d2, j, b, xa, xb, xc)
   end subroutine forward_rows

   !> Rows j, j+1 and j+2 of the forward substitution; xa, xb, xc hold w_{j-3}, w_{j-2},
   !> w_{j-1} and are left holding w_j, w_{j+1}, w_{j+2}.
   pure subroutine forward_turn(n, off, inv_d2, j, b, xa, xb, xc)
      integer, intent(in) :: n, j
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
      real(wp), intent(inout) :: b(n), xa, xb, xc
      xa = row(b(j), off(1, j), off(2, j), off(3, j), xa, xb, xc)
      b(j) = xa*inv_d2(j)
      xb = row(b(j + 1), off(1, j + 1), off(2, j + 1), off(3, j + 1), xb, xc, xa)
      b(j + 1) = xb*inv_d2(j + 1)
      xc = row(b(j + 2), off(1, j + 2), off(2, j + 2), off(3, j + 2), xc, xa, xb)
      b(j + 2) = xc*inv_d2(j + 2)
   end subroutine forward_turn

   !> The dot products of the discrete energy: usu = u.su, dsu = d.su and dmd = d.M d =
   !> sum_j d_j (M_jj d_j + 2 sum_k M_j-k,j d_j-k) (M by diagonals), each in eight partial sums
   !> (row j in sum mod(j - 1, 8) + 1, so that eight rows are one vector operation) added as
   !> ((s1 + s2) + (s3 + s4)) + ((s5 + s6) + (s7 + s8)) at the end: a fixed order, with no running
   !> sum of products for the compiler to round apart (beamstops_band_solve_lockstep's
   !> lockstep_energy_dots does the same for each member). A lane with no row (n < 8) stays 0.
   !> The rows are those of src/beamstops/energy_rows.c (eight rows a vector operation with
   !> AVX-512).
   pure subroutine energy_dots(mass, u, d, su, usu, dsu, dmd)
      !> M by diagonals.
      type(band_diagonals), intent(in) :: mass
      !> u, d and su (n).
      real(wp), intent(in), contiguous :: u(:), d(:), su(:)
      !> u.su, d.su and d.M d.
      real(wp), intent(out) :: usu, dsu, dmd
      real(wp) :: sums(3)
      call energy_rows(mass%n, mass%a, u, d, su, sums)
      usu = sums(1)
      dsu = sums(2)
      dmd = sums(3)
   end subroutine energy_dots

   !> The first three rows of the forward substitution (n >= 3): b(1:3) replaced by
   !> D^{-2} w(1:3), and w(1:3) returned in xa, xb, xc for the rows that follow.
   pure subroutine first_rows(n, off, inv_d2, b, xa, xb, xc)
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
      real(wp), intent(inout) :: b(n)
      real(wp), intent(out) :: xa, xb, xc
      xa = b(1)
      xb = b(2) - off(3, 2)*xa
      xc = b(3) - off(2, 3)*xa - off(3, 3)*xb
      b(1) = xa*inv_d2(1)
      b(2) = xb*inv_d2(2)
      b(3) = xc*inv_d2(3)
   end subroutine first_rows

   !> The rows j and j+1 (those of them <= n) left after the forward substitution's loop by
   !> three; xa, xb, xc hold w_{j-3}, w_{j-2}, w_{j-1}.
   pure subroutine last_rows(n, off, inv_d2, j, b, xa, xb, xc)
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
      integer, intent(in) :: j
      real(wp), intent(inout) :: b(n)
      real(wp), intent(inout) :: xa, xb, xc
      if (j <= n) then
         xa = row(b(j), off(1, j), off(2, j), off(3, j), xa, xb, xc)
         b(j) = xa*inv_d2(j)
      end if
      if (j + 1 <= n) b(j + 1) = row(b(j + 1), off(1, j + 1), off(2, j + 1), off(3, j + 1), xb, xc, xa) &
         & *inv_d2(j + 1)
   end subroutine last_rows

   !> Back substitution (I + N) x = b in place (b from forward_substitution):
   !> x_i = b_i - N(i,i+3) x_{i+3} - N(i,i+2) x_{i+2} - N(i,i+1) x_{i+1}.
   pure subroutine back_substitution(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> D^{-2} w (n), replaced by x.
      real(wp), intent(inout), contiguous :: b(:)
      integer :: i, j, n
      n = solver%n
      if (n <= kd) then
         do i = n - 1, 1, -1
            do j = n, i + 1, -1
               b(i) = b(i) - solver%off(kd + 1 + i - j, j)*b(j)
            end do
         end do
         return
      end if
      call back_rows(n, solver%off, b)
   end subroutine back_substitution

   !> The rows of back_substitution for n > kd in one routine of explicit-shape arrays (as
   !> forward_rows): x_n, x_{n-1}, x_{n-2} written out (each row farthest value first, as every
   !> other row), then three rows a turn.
   pure subroutine back_rows(n, off, b)
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n)
      real(wp), intent(inout) :: b(n)
      real(wp) :: xa, xb, xc
      integer :: i
      xa = b(n)
      xb = b(n - 1) - off(3, n)*xa
      xc = b(n - 2) - off(2, n)*xa - off(3, n - 1)*xb
      b(n - 1) = xb
      b(n - 2) = xc
      do i = n - kd, 3, -3
         xa = row(b(i), off(1, i + 3), off(2, i + 2), off(3, i + 1), xa, xb, xc)
         b(i) = xa
         xb = row(b(i - 1), off(1, i + 2), off(2, i + 1), off(3, i), xb, xc, xa)
         b(i - 1) = xb
         xc = row(b(i - 2), off(1, i + 1), off(2, i), off(3, i - 1), xc, xa, xb)
         b(i - 2) = xc
      end do
      ! The first rows (fewer than three): xa, xb, xc hold x_{i+3}, x_{i+2}, x_{i+1}.
      if (i >= 1) then
         xa = row(b(i), off(1, i + 3), off(2, i + 2), off(3, i + 1), xa, xb, xc)
         b(i) = xa
      end if
      if (i - 1 >= 1) b(i - 1) = row(b(i - 1), off(1, i + 2), off(2, i + 1), off(3, i), xb, xc, xa)
   end subroutine back_rows

   !> The first rows of back_substitution, x_n, x_{n-1} and x_{n-2} (all of it when n <= kd):
   !> the tip value x_{n-1} that the contact law needs before the rest of the substitution,
   !> back_substitution_update.
   pure subroutine back_substitution_edge(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> D^{-2} w (n); its last kd rows replaced by those of x.
      real(wp), intent(inout), contiguous :: b(:)
      integer :: n
      n = solver%n
      if (n <= kd) then
         call back_substitution(solver, b)
         return
      end if
      ! farthest value first (as back_rows)
      b(n - 1) = b(n - 1) - solver%off(3, n)*b(n)
      b(n - 2) = b(n - 2) - solver%off(2, n)*b(n) - solver%off(3, n - 1)*b(n - 1)
   end subroutine back_substitution_edge

   !> The rest of back_substitution after back_substitution_edge, each row of x followed at
   !> once by its row of the update d^n = d^{n-1} + x + c z, u^{n+1} = u^n + d^n and its term of
   !> g.d^n: the update and the product ride in the shadow of the substitution's chain instead
   !> of passes of their own, and the next forward pass, which starts from the first rows, finds
   !> them updated last. Per row the same operations as back_substitution then
   !> beamstops_contact_tip_contact's update; gd is load_work_product(g, d^n), its sums taken
   !> in the same order; x itself is not stored (b keeps D^{-2} w below the edge rows).
   pure subroutine back_substitution_update(solver, b, c, z, g, d, u, gd)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> D^{-2} w (n) with its last kd rows from back_substitution_edge (all of x when n <= kd).
      real(wp), intent(in), contiguous :: b(:)
      !> Multiple of z.
      real(wp), intent(in) :: c
      !> z = A^{-1} e_tip and the load vector g (n).
      real(wp), intent(in), contiguous :: z(:), g(:)
      !> d^{n-1} and u^n on entry, d^n and u^{n+1} on return (n).
      real(wp), intent(inout), contiguous :: d(:), u(:)
      !> g.d^n (load_work_product).
      real(wp), intent(out) :: gd
      integer :: n
      n = solver%n
      if (n <= kd) then
         d = d + b + c*z
         u = u + d
         gd = load_work_product(g, d)
         return
      end if
      call back_update_rows(n, solver%off, b, c, z, g, d, u, gd)
   end subroutine back_substitution_update

   !> The rows of back_substitution_update in one routine of explicit-shape arrays (as back_rows).
   pure subroutine back_update_rows(n, off, b, c, z, g, d, u, gd)
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), b(n), c, z(n), g(n)
      real(wp), intent(inout) :: d(n), u(n)
      real(wp), intent(out) :: gd
      real(wp) :: xa, xb, xc, ga, gb, gc
      integer :: i
      xa = b(n)
      xb = b(n - 1)
      xc = b(n - 2)
      d(n) = d(n) + xa + c*z(n)
      u(n) = u(n) + d(n)
      ga = g(n)*d(n)
      d(n - 1) = d(n - 1) + xb + c*z(n - 1)
      u(n - 1) = u(n - 1) + d(n - 1)
      gb = g(n - 1)*d(n - 1)
      d(n - 2) = d(n - 2) + xc + c*z(n - 2)
      u(n - 2) = u(n - 2) + d(n - 2)
      gc = g(n - 2)*d(n - 2)
      do i = n - kd, 3, -3
         xa = row(b(i), off(1, i + 3), off(2, i + 2), off(3, i + 1), xa, xb, xc)
         d(i) = d(i) + xa + c*z(i)
         u(i) = u(i) + d(i)
         ga = ga + g(i)*d(i)
         xb = row(b(i - 1), off(1, i + 2), off(2, i + 1), off(3, i), xb, xc, xa)
         d(i - 1) = d(i - 1) + xb + c*z(i - 1)
         u(i - 1) = u(i - 1) + d(i - 1)
         gb = gb + g(i - 1)*d(i - 1)
         xc = row(b(i - 2), off(1, i + 1), off(2, i), off(3, i - 1), xc, xa, xb)
         d(i - 2) = d(i - 2) + xc + c*z(i - 2)
         u(i - 2) = u(i - 2) + d(i - 2)
         gc = gc + g(i - 2)*d(i - 2)
      end do
      ! The first rows (fewer than three): xa, xb, xc hold x_{i+3}, x_{i+2}, x_{i+1}.
      if (i >= 1) then
         xa = row(b(i), off(1, i + 3), off(2, i + 2), off(3, i + 1), xa, xb, xc)
         d(i) = d(i) + xa + c*z(i)
         u(i) = u(i) + d(i)
         ga = ga + g(i)*d(i)
      end if
      if (i - 1 >= 1) then
         xb = row(b(i - 1), off(1, i + 2), off(2, i + 1), off(3, i), xb, xc, xa)
         d(i - 1) = d(i - 1) + xb + c*z(i - 1)
         u(i - 1) = u(i - 1) + d(i - 1)
         gb = gb + g(i - 1)*d(i - 1)
      end if
      gd = (ga + gb) + gc
   end subroutine back_update_rows

   !> g.d, the product of the load's work (SPEC 3's G^n.(u^{n+1} - u^n)), summed in the order of
   !> the back substitution, from the last row down, so that back_substitution_update can take it
   !> in the substitution's shadow: row j in sum mod(n - j, 3) + 1, each sum starting with the
   !> product of its top row, then (s1 + s2) + s3. Every path of the engine takes g.d with this
   !> order (the lockstep lanes too), so that their work is the same to the bit.
   pure function load_work_product(g, d) result(gd)
      !> The load vector and d (n >= 1).
      real(wp), intent(in), contiguous :: g(:), d(:)
      real(wp) :: gd
      gd = work_rows(size(g), g, d)
   end function load_work_product

   !> load_work_product in explicit-shape arrays.
   pure function work_rows(n, g, d) result(gd)
      integer, intent(in) :: n
      real(wp), intent(in) :: g(n), d(n)
      real(wp) :: gd
      real(wp) :: s(3)
      integer :: j, p
      s = 0
      do j = n, max(1, n - 2), -1
         s(n - j + 1) = g(j)*d(j)
      end do
      do j = n - 3, 1, -1
         p = mod(n - j, 3) + 1
         s(p) = s(p) + g(j)*d(j)
      end do
      gd = (s(1) + s(2)) + s(3)
   end function work_rows

   !> One row of a substitution, b - o3 x3 - o2 x2 - o1 x1, with x1 the nearest value:
   !> subtracted last, it is the only input the row waits for.
   pure function row(b, o3, o2, o1, x3, x2, x1) result(x)
      real(wp), intent(in) :: b, o3, o2, o1, x3, x2, x1
      real(wp) :: x
      x = b - o3*x3 - o2*x2 - o1*x1
   end function row

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
      integer :: n
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
      end associate
      call matvec_rows(n, diagonals%a, x, y)
   end subroutine diagonal_matvec

   !> The rows of diagonal_matvec for n >= 2 kd + 1, in explicit-shape arrays (as energy_rows):
   !> the edge rows written out, the interior rows vectorized.
   pure subroutine matvec_rows(n, a, x, y)
      integer, intent(in) :: n
      real(wp), intent(in) :: a(n, 0:kd), x(n)
      real(wp), intent(out) :: y(n)
      integer :: j
      call edge_rows(n, a, x, y)
      do j = kd + 1, n - kd
         y(j) = a(j, 3)*x(j - 3) + a(j, 2)*x(j - 2) + a(j, 1)*x(j - 1) + a(j, 0)*x(j) &
            & + a(j + 1, 1)*x(j + 1) + a(j + 2, 2)*x(j + 2) + a(j + 3, 3)*x(j + 3)
      end do
   end subroutine matvec_rows

   !> The 2 kd edge rows of A x, 1..3 and n-2..n (n >= 2 kd + 1), written out.
   pure subroutine edge_rows(n, a, x, y)
      integer, intent(in) :: n
      real(wp), intent(in) :: a(n, 0:kd), x(n)
      real(wp), intent(inout) :: y(n)
      y(1) = a(1, 0)*x(1) + a(2, 1)*x(2) + a(3, 2)*x(3) + a(4, 3)*x(4)
      y(2) = a(2, 1)*x(1) + a(2, 0)*x(2) + a(3, 1)*x(3) + a(4, 2)*x(4) + a(5, 3)*x(5)
      y(3) = a(3, 2)*x(1) + a(3, 1)*x(2) + a(3, 0)*x(3) + a(4, 1)*x(4) + a(5, 2)*x(5) + a(6, 3)*x(6)
      y(n - 2) = a(n - 2, 3)*x(n - 5) + a(n - 2, 2)*x(n - 4) + a(n - 2, 1)*x(n - 3) + a(n - 2, 0)*x(n - 2) &
         & + a(n - 1, 1)*x(n - 1) + a(n, 2)*x(n)
      y(n - 1) = a(n - 1, 3)*x(n - 4) + a(n - 1, 2)*x(n - 3) + a(n - 1, 1)*x(n - 2) + a(n - 1, 0)*x(n - 1) &
         & + a(n, 1)*x(n)
      y(n) = a(n, 3)*x(n - 3) + a(n, 2)*x(n - 2) + a(n, 1)*x(n - 1) + a(n, 0)*x(n)
   end subroutine edge_rows

   !> y = A x (diagonal_matvec) and rhs = a g - b y in one pass over the rows (the forward pass's
   !> right-hand side without its tip term).
   pure subroutine diagonal_matvec_rhs(diagonals, x, a, g, b, y, rhs)
      !> Matrix by diagonals.
      type(band_diagonals), intent(in) :: diagonals
      !> Vector (n).
      real(wp), intent(in), contiguous :: x(:)
      !> Coefficients of rhs = a g - b y.
      real(wp), intent(in) :: a, b
      !> Load vector (n).
      real(wp), intent(in), contiguous :: g(:)
      !> Product (n).
      real(wp), intent(out), contiguous :: y(:)
      !> Right-hand side (n).
      real(wp), intent(out), contiguous :: rhs(:)
      integer :: n
      n = diagonals%n
      if (n < 2*kd + 1) then
         call diagonal_matvec(diagonals, x, y)
         rhs = a*g - b*y
         return
      end if
      call matvec_rhs_rows(n, diagonals%a, x, a, g, b, y, rhs)
   end subroutine diagonal_matvec_rhs

   !> The rows of diagonal_matvec_rhs for n >= 2 kd + 1 (as matvec_rows, rhs row by row). The
   !> interior row is written out here and in matvec_rows: as a shared pure function gfortran 12
   !> no longer vectorized the loops (1,741 -> 1,829 instructions a step, callgrind).
   pure subroutine matvec_rhs_rows(n, s, x, a, g, b, y, rhs)
      integer, intent(in) :: n
      real(wp), intent(in) :: s(n, 0:kd), x(n), a, g(n), b
      real(wp), intent(out) :: y(n), rhs(n)
      integer :: j
      call edge_rows(n, s, x, y)
      rhs(1:3) = a*g(1:3) - b*y(1:3)
      do j = kd + 1, n - kd
         y(j) = s(j, 3)*x(j - 3) + s(j, 2)*x(j - 2) + s(j, 1)*x(j - 1) + s(j, 0)*x(j) &
            & + s(j + 1, 1)*x(j + 1) + s(j + 2, 2)*x(j + 2) + s(j + 3, 3)*x(j + 3)
         rhs(j) = a*g(j) - b*y(j)
      end do
      rhs(n - 2:n) = a*g(n - 2:n) - b*y(n - 2:n)
   end subroutine matvec_rhs_rows

   !> Row k of A x for a symmetric band matrix stored by diagonals (any row, the edges included).
   pure function diagonal_row(diagonals, x, k) result(y)
      !> Matrix by diagonals.
      type(band_diagonals), intent(in) :: diagonals
      !> Vector (n).
      real(wp), intent(in) :: x(:)
      !> Row.
      integer, intent(in) :: k
      real(wp) :: y
      integer :: j
      y = diagonals%a(k, 0)*x(k)
      do j = 1, kd
         if (k - j >= 1) y = y + diagonals%a(k, j)*x(k - j)
         if (k + j <= diagonals%n) y = y + diagonals%a(k + j, j)*x(k + j)
      end do
   end function diagonal_row

   !> x . y with eight partial sums: the products vectorize and the dependency chain is
   !> n/8 additions long instead of n (a fixed order, so the result is reproducible). Row j goes
   !> into sum mod(j - 1, 8) + 1, the rows after the last eight too, each as sum + x y (one
   !> multiply-add where the machine has them), then ((s1 + s5) + (s2 + s6)) + ((s3 + s7) + (s4 +
   !> s8)). No running sum over the rows is left for the compiler to vectorize: it would add
   !> them in order from a vector of products rounded first, or not, as its tuning decides
   !> (gfortran 12 did for -march=x86-64-v3 and not for -march=znver3), and the lockstep lanes
   !> (lockstep_dot) could not follow.
   pure function dot(x, y) result(s)
      !> Vectors of the same length.
      real(wp), intent(in), contiguous :: x(:), y(:)
      real(wp) :: s
      real(wp) :: partial(8)
      integer :: j, n
      n = size(x)
      partial = 0
      do j = 1, n - 7, 8
         partial = partial + x(j:j + 7)*y(j:j + 7)
      end do
      partial(:n - j + 1) = partial(:n - j + 1) + x(j:n)*y(j:n)
      s = ((partial(1) + partial(5)) + (partial(2) + partial(6))) + ((partial(3) + partial(7)) + (partial(4) + partial(8)))
   end function dot
end module beamstops_band_solve
