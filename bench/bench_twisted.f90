!> The band solve of the time loop, twisted: a prototype measured against today's solve.
!>
!>   bench_twisted [J [repeats]]
!>
!> Today's solve (beamstops_band_solve: forward then back substitution of A = U^T U) is a chain
!> of 2n dependent multiply-adds, the floor scripts/bench.py computes. A twisted solve splits the
!> unknowns into a top block T (rows 1..p), three interface rows I and a bottom block B (the
!> rest, n - p - 3 >= p rows; kd = 3, so T and B do not touch): the forward substitutions of T
!> (from the top) and of B (from the bottom, on the factor of the flipped matrix) run at once,
!> the interface's 3 x 3 Schur complement is solved, then the two back substitutions run at once,
!> from the interface outwards. Two chains of about n/2 rows each way: about n + 6 latencies.
!> Both factors still come from LAPACK's dpbtrf (the top one is the leading block of A's factor).
!> Prints the two solves' ns (least of the repeats, each solve feeding the next as in the time
!> loop) and the largest difference of their solutions relative to the solution's largest entry.
program bench_twisted
   use, intrinsic :: iso_fortran_env, only: output_unit
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd, cholesky_factor
   use beamstops_band_solve, only: band_solver, prepare_solver, fused_solve
   use beamstops_clock, only: thread_cpu_seconds
   use beamstops_error, only: error_type
   use beamstops_model, only: model_type, build_model
   use beamstops_scene, only: scene_type, law_signorini
   use bench_support, only: runtime_one, put, int_argument, fail
   implicit none

   !> The twisted factor: top and flipped bottom in the fused form, the interface's terms.
   type :: twisted_type
      integer :: n = 0, p = 0, q = 0
      !> Top (p rows) and flipped bottom (q rows, row i of it is row n + 1 - i of A).
      type(band_solver) :: top, bottom
      !> The last three rows of (I + N)^{-T} A_TI and (I + N)^{-T} A_BI (flipped), (3, 3) each.
      real(wp) :: qt(3, 3) = 0, qb(3, 3) = 0
      !> D^{-2} of those rows times them, for the back substitutions' corrections.
      real(wp) :: st(3, 3) = 0, sb(3, 3) = 0
      !> The inverse of the interface's Schur complement (3, 3).
      real(wp) :: si(3, 3) = 0
      !> The back substitutions' multipliers N(i, i + k) of each block, 0 beyond its last row (3, rows).
      real(wp), allocatable :: bt(:, :), bb(:, :)
   end type twisted_type

   type(scene_type) :: scene
   type(model_type) :: model
   type(twisted_type) :: tw
   type(error_type), allocatable :: error
   real(wp), allocatable :: r(:), b(:), x(:)
   real(wp) :: zero, t0, diff
   real(wp), allocatable :: ns(:, :)
   integer :: rep, k, count, repeats, which

   scene%elements = int_argument(1, 19)
   repeats = int_argument(2, 7)
   scene%dt = 1.0e-6_wp
   scene%beta = 0.5_wp
   scene%law = law_signorini
   scene%output_file = 'unused.h5'
   call build_model(scene, model, error)
   if (allocated(error)) call fail(error%message)
   call prepare_twisted(model%stiffness, model%mass, model%dt2*model%beta, tw)
   allocate (r(model%n), b(model%n), x(model%n), ns(2, repeats))
   call random_number(r)
   r = r - 0.5_wp
   b = r
   call fused_solve(model%solver, b)
   x = r
   call twisted_solve(tw, x)
   diff = maxval(abs(x - b))/maxval(abs(b))
   zero = runtime_one() - 1
   count = max(10, int(4.0e7_wp/model%n))
   ! each solve's right-hand side waits for the solve before (b = r + 0 b), as in the time loop
   do rep = 1, repeats
      do which = 1, 2
         b = r
         t0 = thread_cpu_seconds()
         do k = 1, count
            if (which == 1) then
               call fused_solve(model%solver, b)
            else
               call twisted_solve(tw, b)
            end if
            b = r + zero*b
         end do
         ns(which, rep) = 1.0e9_wp*(thread_cpu_seconds() - t0)/count
      end do
   end do
   call put('n', real(model%n, wp))
   call put('top_rows', real(tw%p, wp))
   call put('bottom_rows', real(tw%q, wp))
   call put('solve_sweep_min_ns', minval(ns(1, :)))
   call put('solve_twisted_min_ns', minval(ns(2, :)))
   call put('twisted_over_sweep', minval(ns(2, :))/minval(ns(1, :)))
   call put('relative_difference', diff)
   flush (output_unit)

contains

   !> A(i, j) of A = M + c S from their upper band storage (0 outside the band).
   pure function entry(s, m, c, i, j) result(a)
      real(wp), intent(in) :: s(:, :), m(:, :), c
      integer, intent(in) :: i, j
      real(wp) :: a
      integer :: lo, hi
      lo = min(i, j)
      hi = max(i, j)
      a = 0
      if (hi - lo <= kd) a = m(kd + 1 + lo - hi, hi) + c*s(kd + 1 + lo - hi, hi)
   end function entry

   !> The twisted factor of A = M + c S: T = 1..p, I = p+1..p+3, B = p+4..n with q = n - p - 3.
   subroutine prepare_twisted(s, m, c, tw)
      real(wp), intent(in) :: s(:, :), m(:, :), c
      type(twisted_type), intent(out) :: tw
      real(wp), allocatable :: ab(:, :), w(:)
      type(error_type), allocatable :: error
      real(wp) :: sc(3, 3), a(3, 3)
      integer :: n, p, q, i, j, e
      n = size(s, 2)
      p = (n - 3)/2
      q = n - p - 3
      tw%n = n
      tw%p = p
      tw%q = q
      ! the top block's factor, and the flipped bottom block's
      allocate (ab(kd + 1, p))
      do j = 1, p
         do i = max(1, j - kd), j
            ab(kd + 1 + i - j, j) = entry(s, m, c, i, j)
         end do
      end do
      call cholesky_factor(ab, 'A_TT', error)
      if (allocated(error)) call fail(error%message)
      call prepare_solver(ab, tw%top)
      deallocate (ab)
      allocate (ab(kd + 1, q))
      do j = 1, q
         do i = max(1, j - kd), j
            ab(kd + 1 + i - j, j) = entry(s, m, c, n + 1 - i, n + 1 - j)
         end do
      end do
      call cholesky_factor(ab, 'A_BB flipped', error)
      if (allocated(error)) call fail(error%message)
      call prepare_solver(ab, tw%bottom)
      ! (I + N)^{-T} A_TI: the forward substitution of each interface column, unscaled
      sc = 0
      do e = 1, 3
         allocate (w(p))
         w = 0
         do i = p - 2, p
            w(i) = entry(s, m, c, i, p + e)
         end do
         call unscaled_forward(tw%top, w)
         tw%qt(:, e) = w(p - 2:p)
         deallocate (w)
         allocate (w(q))
         w = 0
         do i = q - 2, q
            w(i) = entry(s, m, c, n + 1 - i, p + e)
         end do
         call unscaled_forward(tw%bottom, w)
         tw%qb(:, e) = w(q - 2:q)
         deallocate (w)
      end do
      do e = 1, 3
         tw%st(:, e) = tw%top%inv_d2(p - 2:p)*tw%qt(:, e)
         tw%sb(:, e) = tw%bottom%inv_d2(q - 2:q)*tw%qb(:, e)
      end do
      ! the interface's Schur complement A_II - Q_T^T D^-2 Q_T - Q_B^T D^-2 Q_B and its inverse
      do j = 1, 3
         do i = 1, 3
            a(i, j) = entry(s, m, c, p + i, p + j) - dot_product(tw%qt(:, i), tw%st(:, j)) &
               & - dot_product(tw%qb(:, i), tw%sb(:, j))
         end do
      end do
      tw%si = inverse3(a)
      allocate (tw%bt(3, p), tw%bb(3, q))
      do i = 1, p
         do e = 1, 3
            tw%bt(e, i) = back_coefficient(tw%top%off, p, i, e)
         end do
      end do
      do i = 1, q
         do e = 1, 3
            tw%bb(e, i) = back_coefficient(tw%bottom%off, q, i, e)
         end do
      end do
   end subroutine prepare_twisted

   !> (I + N)^T w = b in place, without the D^{-2} scaling.
   pure subroutine unscaled_forward(solver, w)
      type(band_solver), intent(in) :: solver
      real(wp), intent(inout) :: w(:)
      integer :: i, j
      do j = 2, size(w)
         do i = max(1, j - kd), j - 1
            w(j) = w(j) - solver%off(kd + 1 + i - j, j)*w(i)
         end do
      end do
   end subroutine unscaled_forward

   !> The inverse of a 3 x 3 matrix (cofactors).
   pure function inverse3(a) result(v)
      real(wp), intent(in) :: a(3, 3)
      real(wp) :: v(3, 3), det
      v(1, 1) = a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)
      v(1, 2) = a(1, 3)*a(3, 2) - a(1, 2)*a(3, 3)
      v(1, 3) = a(1, 2)*a(2, 3) - a(1, 3)*a(2, 2)
      v(2, 1) = a(2, 3)*a(3, 1) - a(2, 1)*a(3, 3)
      v(2, 2) = a(1, 1)*a(3, 3) - a(1, 3)*a(3, 1)
      v(2, 3) = a(1, 3)*a(2, 1) - a(1, 1)*a(2, 3)
      v(3, 1) = a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1)
      v(3, 2) = a(1, 2)*a(3, 1) - a(1, 1)*a(3, 2)
      v(3, 3) = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
      det = a(1, 1)*v(1, 1) + a(1, 2)*v(2, 1) + a(1, 3)*v(3, 1)
      v = v/det
   end function inverse3

   !> Solve A x = b in place with the twisted factor.
   subroutine twisted_solve(tw, b)
      type(twisted_type), intent(in) :: tw
      real(wp), intent(inout) :: b(:)
      call twisted_rows(tw%n, tw%p, tw%q, tw%top%off, tw%top%inv_d2, tw%bottom%off, tw%bottom%inv_d2, &
         & tw%bt, tw%bb, tw%qt, tw%qb, tw%st, tw%sb, tw%si, b)
   end subroutine twisted_solve

   !> The rows of twisted_solve (explicit shapes; q = p or p + 1): the top rows 1..p and the
   !> bottom rows n, n-1, .., n+1-q at once, each three multiply-adds with the farthest value
   !> first (as beamstops_band_solve's rows), the interface, then both back substitutions.
   subroutine twisted_rows(n, p, q, ot, dt, ob, db, bt, bb, qt, qb, st, sb, si, b)
      integer, intent(in) :: n, p, q
      real(wp), intent(in) :: ot(kd, p), dt(p), ob(kd, q), db(q), bt(3, p), bb(3, q), qt(3, 3), qb(3, 3), st(3, 3), sb(3, 3), si(3, 3)
      real(wp), intent(inout) :: b(n)
      real(wp) :: t1, t2, t3, u1, u2, u3, r(3), x(3)
      integer :: i, j, jb, k
      ! forward, three rows of each block a turn (the roles of the running values rotate, as in
      ! beamstops_band_solve's rows): t1, t2, t3 the top's last three values (t3 the nearest),
      ! u1, u2, u3 the bottom's
      call zero_values(t1, t2, t3)
      call zero_values(u1, u2, u3)
      k = n + 1
      do j = 1, p - 2, 3
         t1 = b(j) - ot(1, j)*t1 - ot(2, j)*t2 - ot(3, j)*t3
         u1 = b(k - j) - ob(1, j)*u1 - ob(2, j)*u2 - ob(3, j)*u3
         b(j) = t1*dt(j)
         b(k - j) = u1*db(j)
         t2 = b(j + 1) - ot(1, j + 1)*t2 - ot(2, j + 1)*t3 - ot(3, j + 1)*t1
         u2 = b(k - j - 1) - ob(1, j + 1)*u2 - ob(2, j + 1)*u3 - ob(3, j + 1)*u1
         b(j + 1) = t2*dt(j + 1)
         b(k - j - 1) = u2*db(j + 1)
         t3 = b(j + 2) - ot(1, j + 2)*t3 - ot(2, j + 2)*t1 - ot(3, j + 2)*t2
         u3 = b(k - j - 2) - ob(1, j + 2)*u3 - ob(2, j + 2)*u1 - ob(3, j + 2)*u2
         b(j + 2) = t3*dt(j + 2)
         b(k - j - 2) = u3*db(j + 2)
      end do
      do i = j, p
         call rotate(b(i) - ot(1, i)*t1 - ot(2, i)*t2 - ot(3, i)*t3, t1, t2, t3)
         b(i) = t3*dt(i)
      end do
      do i = j, q
         call rotate(b(k - i) - ob(1, i)*u1 - ob(2, i)*u2 - ob(3, i)*u3, u1, u2, u3)
         b(k - i) = u3*db(i)
      end do
      ! the interface: b_I - Q_T^T D^-2 w_T - Q_B^T D^-2 w_B, then x_I
      do j = 1, 3
         r(j) = b(p + j) - (qt(1, j)*b(p - 2) + qt(2, j)*b(p - 1) + qt(3, j)*b(p)) &
            & - (qb(1, j)*b(n + 3 - q) + qb(2, j)*b(n + 2 - q) + qb(3, j)*b(n + 1 - q))
      end do
      x = matmul(si, r)
      b(p + 1:p + 3) = x
      b(p - 2:p) = b(p - 2:p) - matmul(st, x)
      b(n + 3 - q:n + 1 - q:-1) = b(n + 3 - q:n + 1 - q:-1) - matmul(sb, x)
      ! back, from the interface outwards, three rows of each block a turn: t3, u3 the nearest
      call zero_values(t1, t2, t3)
      call zero_values(u1, u2, u3)
      jb = q
      do j = p, 3, -3
         t1 = b(j) - bt(3, j)*t1 - bt(2, j)*t2 - bt(1, j)*t3
         u1 = b(k - jb) - bb(3, jb)*u1 - bb(2, jb)*u2 - bb(1, jb)*u3
         b(j) = t1
         b(k - jb) = u1
         t2 = b(j - 1) - bt(3, j - 1)*t2 - bt(2, j - 1)*t3 - bt(1, j - 1)*t1
         u2 = b(k - jb + 1) - bb(3, jb - 1)*u2 - bb(2, jb - 1)*u3 - bb(1, jb - 1)*u1
         b(j - 1) = t2
         b(k - jb + 1) = u2
         t3 = b(j - 2) - bt(3, j - 2)*t3 - bt(2, j - 2)*t1 - bt(1, j - 2)*t2
         u3 = b(k - jb + 2) - bb(3, jb - 2)*u3 - bb(2, jb - 2)*u1 - bb(1, jb - 2)*u2
         b(j - 2) = t3
         b(k - jb + 2) = u3
         jb = jb - 3
      end do
      do i = j, 1, -1
         call rotate(b(i) - bt(3, i)*t1 - bt(2, i)*t2 - bt(1, i)*t3, t1, t2, t3)
         b(i) = t3
      end do
      do i = jb, 1, -1
         call rotate(b(k - i) - bb(3, i)*u1 - bb(2, i)*u2 - bb(1, i)*u3, u1, u2, u3)
         b(k - i) = u3
      end do
   end subroutine twisted_rows

   !> N(i, i + k) of a block's factor (0 beyond its last row): the back substitution's multiplier.
   pure function back_coefficient(off, m, i, k) result(c)
      real(wp), intent(in) :: off(:, :)
      integer, intent(in) :: m, i, k
      real(wp) :: c
      c = 0
      if (i + k <= m) c = off(kd + 1 - k, i + k)
   end function back_coefficient

   !> Three running values set to zero.
   pure subroutine zero_values(x1, x2, x3)
      real(wp), intent(out) :: x1, x2, x3
      x1 = 0
      x2 = 0
      x3 = 0
   end subroutine zero_values

   !> Shift the three running values by one: x1 <- x2 <- x3 <- v (x3 the nearest).
   pure subroutine rotate(v, x1, x2, x3)
      real(wp), intent(in) :: v
      real(wp), intent(inout) :: x1, x2, x3
      x1 = x2
      x2 = x3
      x3 = v
   end subroutine rotate
end program bench_twisted
