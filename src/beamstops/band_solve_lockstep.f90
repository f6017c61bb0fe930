!> The kd = 3 substitutions, products and dot products of beamstops_band_solve for
!> lockstep_lanes right-hand sides at once, the member index innermost: arrays (lanes, n),
!> column j holding row j of every member, so that each multiply-add of a row acts on all the
!> lanes (SIMD across members) and the chain of a step is shared by them.
!>
!> Each row is one loop over the lanes (a compile-time width, marked for vectorization), so that
!> a row is a few whole-register operations with no loop of its own to pay.
!>
!> Shapes: the inner rows of the substitutions and of the product by a periodic S come in two
!> shapes, by the vector registers the build targets (beamstops_machine): with 32 (AVX-512) three
!> rows a turn in one loop over the lanes, the forward substitution interleaved with the product
!> and g.d riding on the back substitution (beamstops_band_solve_lockstep_wide); with 16 (AVX2)
!> one row a loop and the passes apart, so that nothing spills
!> (beamstops_band_solve_lockstep_narrow). The rows both share, and the lanes, are in
!> beamstops_band_solve_lockstep_edges.
!>
!> Bit for bit: every routine performs, for each lane, the floating-point operations of its
!> one-member counterpart in beamstops_band_solve, in the same order, with the same expressions
!> and the same multiply-adds. The one-member routines are written so that the compiler has no
!> choice of rounding to make: no running sum over rows that it could vectorize in order (the
!> dot and energy sums keep partial sums per row lane), so that every product met by an addition
!> is a multiply-add in both, whatever the vector width and tuning. tests/fortran/test_lockstep.f90
!> checks every kernel lane by lane against its one-member counterpart (J = 4..13, 19, 20, 100,
!> 101), the kernels' two shapes against each other, and whole runs against the one-scene path:
!> a change of compiler, flags or of beamstops_band_solve shows there first.
!>
!> n >= 2 kd + 2 (J >= 4) is assumed; beamstops_lockstep refuses smaller meshes.
module beamstops_band_solve_lockstep
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   use beamstops_band_solve, only: band_solver, band_diagonals
   use beamstops_machine, only: vector_registers
   use beamstops_band_solve_lockstep_edges, only: lockstep_lanes, lockstep_load_work, matvec_rhs_first_rows, &
      & matvec_rhs_last_rows
   use beamstops_band_solve_lockstep_narrow, only: narrow_forward_rows, narrow_back_rows, narrow_back_update_rows, &
      & narrow_periodic_rows, narrow_matvec_rhs_forward_rows
   use beamstops_band_solve_lockstep_wide, only: wide_forward_rows, wide_back_rows, wide_back_update_rows, &
      & wide_periodic_rows, wide_matvec_rhs_forward_rows
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
   !> Whether the kernels take the wide shapes (32 vector registers) or the narrow ones (16).
   logical, parameter :: wide = vector_registers >= 32

contains

   !> Forward substitution (I + N)^T w = b of every lane (beamstops_band_solve's
   !> forward_substitution): b replaced by D^{-2} w. Row j scales row j - 3, the last it needs.
   pure subroutine lockstep_forward(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> Right-hand sides (lanes, n), replaced by D^{-2} w.
      real(wp), intent(inout) :: b(lockstep_lanes, solver%n)
      if (wide) then
         call wide_forward_rows(solver%n, solver%off, solver%inv_d2, b)
      else
         call narrow_forward_rows(solver%n, solver%off, solver%inv_d2, b)
      end if
   end subroutine lockstep_forward

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
      if (wide) then
         call wide_back_rows(solver%n, solver%off, b)
      else
         call narrow_back_rows(solver%n, solver%off, b)
      end if
   end subroutine lockstep_back

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
   !> stored (the update is its only use); and g.d^n, in lockstep_load_work's order (the wide
   !> shape takes it on the way, the narrow one after). Per lane the same operations as
   !> lockstep_back, lockstep_update then lockstep_load_work (the update of a row needs only that
   !> row).
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
      if (wide) then
         call wide_back_update_rows(solver%n, solver%off, b, c, z, g, d, u, gd)
      else
         call narrow_back_update_rows(solver%n, solver%off, b, c, z, g, d, u, gd)
      end if
   end subroutine lockstep_back_update

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
         if (wide) then
            call wide_periodic_rows(n, rows, u, a, g, b, su, rhs)
         else
            call narrow_periodic_rows(n, rows, u, a, g, b, su, rhs)
         end if
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

   !> lockstep_matvec_rhs with `rows` (a periodic S) then lockstep_forward: rhs is returned as
   !> lockstep_forward leaves it (D^{-2} w). The wide shape interleaves the forward substitution
   !> with the product, six rows behind it, so that its chain runs in the product's shadow; the
   !> narrow one runs it after the whole product (interleaved, its six running values stayed live
   !> across the product's rows and pushed the coefficients out of AVX2's registers).
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
      if (wide) then
         call wide_matvec_rhs_forward_rows(stiffness%n, stiffness%a, solver%off, solver%inv_d2, rows, u, a, g, b, &
            & spring, su, rhs)
      else
         call narrow_matvec_rhs_forward_rows(stiffness%n, stiffness%a, solver%off, solver%inv_d2, rows, u, a, g, b, &
            & spring, su, rhs)
      end if
   end subroutine lockstep_matvec_rhs_forward

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
