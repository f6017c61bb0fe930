!> Exact contact at m points along the span (SPEC 7): the box-constrained quadratic
!> program on the Schur complement C = P^T A^{-1} P (m x m, symmetric positive definite).
!>
!> Given the trial values y' = P^T u' of the unconstrained solution u', find lambda (m) with
!> y = y' + C lambda and, for every stop i,
!>
!>     lo_i <= y_i <= hi_i,
!>     lambda_i >= 0 where y_i = lo_i,  lambda_i <= 0 where y_i = hi_i,
!>     lambda_i = 0 where lo_i < y_i < hi_i:
!>
!> the KKT system of min 1/2 (u - u')^T A (u - u') subject to lo <= P^T u <= hi, whose solution
!> is u = u' + A^{-1} P lambda. In y = P^T u alone it is the strictly convex program
!>
!>     min f(y) = 1/2 (y - y')^T C^{-1} (y - y'),  lo <= y <= hi,
!>
!> whose gradient at y is lambda = C^{-1} (y - y'), and f(y) = 1/2 lambda^T C lambda. Its
!> solution exists (the box is not empty: lo <= hi) and is unique.
!>
!> Method: the dual active-set method of Goldfarb and Idnani (Math. Programming 27, 1-33,
!> 1983) written for bounds. It starts from the unconstrained minimum lambda = 0, y = y'
!> (the trial solution: when every trial value is inside its box it returns at once, O(m)),
!> and keeps an active set A of stops held on one of their bounds, y_A = b_A, whose
!> multipliers have the right signs, with the Cholesky factor R of C_AA = R^T R in the order
!> of A. R is updated, not recomputed: O(k^2) for k active stops (a triangular solve to add
!> a stop, Givens rotations to drop one). An iteration takes the most violated stop p
!> outside A and moves lambda_p towards its bound b_p while y_A stays on its bounds:
!> lambda_A moves by delta g, g = -C_AA^{-1} C_Ap, and y_p by delta s, where
!> s = C_pp - C_pA C_AA^{-1} C_Ap > 0 is a Schur complement of a principal submatrix of C.
!>  - full step, delta = (b_p - y_p)/s: y_p reaches its bound and p joins A;
!>  - partial step: a multiplier of A reaches zero first; its stop leaves A (lambda = 0)
!>    and the iteration goes on with the same p.
!>
!> Finite termination (exact arithmetic). Call (y, A) an S-pair when y_A = b_A and the
!> multipliers, zero outside A, have the right signs on A. These are the KKT conditions of
!> min f over the polyhedron Q(A) = {y : the bounds of A hold}, so y is that minimum and,
!> f being strictly convex, y and f(y) depend on A alone. The start (A empty) is an S-pair
!> and so is the state after every full step. Along a step of length t = |delta| on p,
!> d f/dt = lambda^T C dlambda/dt = s |lambda_p| (C dlambda/dt vanishes on A, is sign(delta) s
!> on p, and lambda is zero elsewhere), and |lambda_p| >= t grows with t, so f increases
!> by at least s t^2/2. A full step is never of zero length: y_p is still strictly outside
!> its box (a partial step moves it towards b_p without reaching it). Hence f strictly
!> increases from one S-pair to the next, no active set is an S-pair twice, and there are
!> at most 3^m full steps (each stop free, on its lower or on its upper bound). Between two
!> full steps each partial step removes a stop from A and adds none, and with A empty no
!> multiplier can block: at most m partial steps. The method stops after at most
!> (m + 1) 3^m iterations, at an S-pair with no stop violated, which satisfies all the KKT
!> conditions above: it is the solution. (Two bounds of one stop are never both in A, so
!> the active constraints are always independent and s > 0.) In practice it takes about
!> one iteration per active stop.
!>
!> Finite precision. y_A, y_p after a full step and the multiplier of a dropped stop are
!> set exactly (to b_A, b_p, 0); other values accumulate a few roundings per iteration.
!> The first time, a stop is taken at any violation, however small (m = 1 then gives
!> exactly lambda = (P(y') - y')/C_11, the tip projection of contact/tip_projection.f90);
!> a stop that already left A in this call re-enters only beyond 16 eps times the scale of
!> the data (largest |lo|, |hi|, |y'|), so round-off cannot make it cycle, and values left
!> outside within that tolerance are set onto their bound with a zero multiplier (a weakly
!> active stop). Two guards report instead of looping: an iteration limit far beyond what
!> the method needs (qp_iteration_limit) and s <= eps C_pp, the stops of A and p
!> numerically dependent (qp_singular).
!>
!> Workspace lives in box_qp_type, built once (new_box_qp): solve allocates nothing.
module beamstops_contact_box_qp
   use beamstops_kinds, only: wp
   use beamstops_error, only: error_type, fatal_error
   implicit none
   private
   public :: box_qp_type, new_box_qp, qp_message
   public :: qp_solved, qp_iteration_limit, qp_singular

   !> solve's info: the KKT conditions hold.
   integer, parameter :: qp_solved = 0
   !> solve's info: the iteration limit was reached (round-off; not expected).
   integer, parameter :: qp_iteration_limit = 1
   !> solve's info: a Schur complement s was not positive (C numerically singular).
   integer, parameter :: qp_singular = 2

   !> The box-constrained program of m stops on a fixed C, with its workspace.
   type :: box_qp_type
      !> Number of stops m.
      integer :: m = 0
      !> C = P^T A^{-1} P (m, m), symmetric positive definite (stored symmetrized).
      real(wp), allocatable :: c(:, :)
      !> Number k of stops on a bound with their multiplier after the last solve.
      integer :: n_active = 0
      !> Those stops, active(1:n_active) (m); the multipliers of all others are zero.
      integer, allocatable :: active(:)
      !> Per stop after the last solve: +1 held on its lower bound, -1 on its upper bound, 0 free (m).
      integer, allocatable :: side(:)
      !> Iterations (full and partial steps) of the last solve.
      integer :: iterations = 0
      !> Largest number of iterations of one solve before it reports qp_iteration_limit.
      integer :: max_iterations = 0
      ! Workspace: the factor R of C_AA (m, m), C_AA^{-1/2}-type vectors w and g (m), and
      ! whether a stop left A during this call (m).
      real(wp), allocatable, private :: r(:, :), w(:), g(:)
      logical, allocatable, private :: dropped(:)
   contains
      !> Solve the program for trial values and bounds.
      procedure :: solve
   end type box_qp_type

   interface
      subroutine dpotrf(uplo, n, a, lda, info)
         import :: wp
         character, intent(in) :: uplo
         integer, intent(in) :: n, lda
         real(wp), intent(inout) :: a(lda, *)
         integer, intent(out) :: info
      end subroutine dpotrf
   end interface

contains

   !> Build the program of a Schur complement C: checks that C is square, symmetric (to
   !> 1e-10 relative) and positive definite (LAPACK dpotrf), stores it symmetrized and
   !> allocates the workspace.
   subroutine new_box_qp(self, c, error)
      !> The program, ready for solve.
      type(box_qp_type), intent(out) :: self
      !> C = P^T A^{-1} P (m, m).
      real(wp), intent(in) :: c(:, :)
      !> Set when C is not square, not symmetric or not positive definite.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: copy(:, :)
      real(wp) :: big, asym
      integer :: m, info, i, j
      character(len=16) :: buf
      m = size(c, 1)
      if (size(c, 2) /= m) then
         call fatal_error(error, 'box QP: the Schur complement C is not square')
         return
      end if
      big = 0
      asym = 0
      do j = 1, m
         do i = 1, m
            big = max(big, abs(c(i, j)))
            asym = max(asym, abs(c(i, j) - c(j, i)))
         end do
      end do
      if (asym > 1.0e-10_wp*big) then
         call fatal_error(error, 'box QP: the Schur complement C is not symmetric')
         return
      end if
      self%m = m
      allocate (self%c(m, m))
      self%c = 0.5_wp*(c + transpose(c))
      if (m > 0) then
         copy = self%c
         call dpotrf('U', m, copy, m, info)
         if (info /= 0) then
            write (buf, '(i0)') abs(info)
            if (info > 0) then
               call fatal_error(error, 'box QP: dpotrf: the leading minor of order '//trim(buf)// &
                  & ' of the Schur complement C is not positive definite')
            else
               call fatal_error(error, 'box QP: dpotrf: argument '//trim(buf)//' had an illegal value')
            end if
            return
         end if
      end if
      allocate (self%active(m), self%side(m), self%r(m, m), self%w(m), self%g(m), self%dropped(m))
      self%active = 0
      self%side = 0
      self%r = 0
      self%dropped = .false.
      ! About one iteration per active stop is the rule, a few drops the exception; the limit
      ! only turns a round-off pathology into a reported failure.
      self%max_iterations = 100*(m + 1)
   end subroutine new_box_qp

   !> What a solve's info means.
   pure function qp_message(info) result(message)
      !> info returned by solve.
      integer, intent(in) :: info
      character(len=:), allocatable :: message
      select case (info)
      case (qp_solved)
         message = 'solved'
      case (qp_iteration_limit)
         message = 'the contact problem of the stops did not converge within its iteration limit'
      case (qp_singular)
         message = 'the contact problem of the stops is numerically singular (stops too close together)'
      case default
         message = 'unknown status of the contact problem'
      end select
   end function qp_message

   !> Solve: lambda and y = y' + C lambda satisfying the KKT conditions of the module's
   !> header; the active stops and their sides are left in self%active, self%side.
   !> Requires lower <= upper. Allocates nothing.
   subroutine solve(self, trial, lower, upper, lambda, y, info)
      !> The program (its workspace and the active set are overwritten).
      class(box_qp_type), intent(inout) :: self
      !> Trial values y' = P^T u' (m).
      real(wp), intent(in) :: trial(:)
      !> Lower bounds lo (m).
      real(wp), intent(in) :: lower(:)
      !> Upper bounds hi (m), hi >= lo.
      real(wp), intent(in) :: upper(:)
      !> Multipliers lambda (m): u = u' + A^{-1} P lambda.
      real(wp), intent(out) :: lambda(:)
      !> Constrained values y = y' + C lambda (m), within [lo, hi].
      real(wp), intent(out) :: y(:)
      !> qp_solved, qp_iteration_limit or qp_singular.
      integer, intent(out) :: info
      real(wp) :: tol, target, s, delta, t, t_block, acc
      integer :: m, i, j, k, p, q, a, sp

      m = self%m
      info = qp_solved
      self%n_active = 0
      self%iterations = 0
      do i = 1, m
         lambda(i) = 0
         y(i) = trial(i)
         self%side(i) = 0
      end do
      do i = 1, m
         if (trial(i) < lower(i) .or. trial(i) > upper(i)) exit
      end do
      if (i > m) return

      tol = 0
      do i = 1, m
         tol = max(tol, abs(lower(i)), abs(upper(i)), abs(trial(i)))
         self%dropped(i) = .false.
      end do
      tol = 16*epsilon(1.0_wp)*tol

      outer: do
         call most_violated(self, y, lower, upper, tol, p, sp, target)
         if (p == 0) exit outer
         do
            self%iterations = self%iterations + 1
            if (self%iterations > self%max_iterations) then
               info = qp_iteration_limit
               exit outer
            end if
            k = self%n_active
            associate (r => self%r, w => self%w, g => self%g, c => self%c, act => self%active)
               ! w = R^{-T} C_Ap, s = C_pp - w.w, g = -R^{-1} w = -C_AA^{-1} C_Ap
               do j = 1, k
                  acc = c(act(j), p)
                  do i = 1, j - 1
                     acc = acc - r(i, j)*w(i)
                  end do
                  w(j) = acc/r(j, j)
               end do
               s = c(p, p)
               do j = 1, k
                  s = s - w(j)**2
               end do
               if (.not. s > epsilon(1.0_wp)*c(p, p)) then
                  info = qp_singular
                  exit outer
               end if
               do j = k, 1, -1
                  acc = w(j)
                  do i = j + 1, k
                     acc = acc - r(j, i)*g(i)
                  end do
                  g(j) = acc/r(j, j)
               end do
               do j = 1, k
                  g(j) = -g(j)
               end do

               ! The full step, unless a multiplier of A reaches zero first.
               delta = (target - y(p))/s
               t = abs(delta)
               q = 0
               do j = 1, k
                  a = act(j)
                  if (self%side(a)*sp*g(j) < 0) then
                     t_block = max(self%side(a)*lambda(a), 0.0_wp)/abs(g(j))
                     if (t_block < t) then
                        t = t_block
                        q = j
                     end if
                  end if
               end do
               if (q /= 0) delta = sp*t

               lambda(p) = lambda(p) + delta
               do j = 1, k
                  lambda(act(j)) = lambda(act(j)) + delta*g(j)
               end do
               do i = 1, m
                  if (self%side(i) /= 0 .or. i == p) cycle
                  acc = c(i, p)
                  do j = 1, k
                     acc = acc + c(i, act(j))*g(j)
                  end do
                  y(i) = y(i) + delta*acc
               end do

               if (q == 0) then
                  ! p joins A: R gains the column (w, sqrt(s)).
                  y(p) = target
                  do i = 1, k
                     r(i, k + 1) = w(i)
                  end do
                  r(k + 1, k + 1) = sqrt(s)
                  act(k + 1) = p
                  self%side(p) = sp
                  self%n_active = k + 1
               else
                  ! The stop act(q) leaves A, exactly on its bound, with a zero multiplier.
                  y(p) = y(p) + delta*s
                  a = act(q)
                  lambda(a) = 0
                  self%side(a) = 0
                  self%dropped(a) = .true.
                  call drop_column(r, k, q)
                  do j = q, k - 1
                     act(j) = act(j + 1)
                  end do
                  self%n_active = k - 1
               end if
            end associate
            if (q == 0) exit
         end do
      end do outer

      ! Free values within the tolerance outside their box lie on it (weakly active stops).
      if (info /= qp_solved) return
      do i = 1, m
         y(i) = min(max(y(i), lower(i)), upper(i))
      end do
   end subroutine solve

   !> The free stop farthest outside its box: a stop that left A in this call counts only
   !> beyond tol. p = 0 when there is none; sp = +1 below its box (target lo), -1 above.
   pure subroutine most_violated(self, y, lower, upper, tol, p, sp, target)
      type(box_qp_type), intent(in) :: self
      real(wp), intent(in) :: y(:), lower(:), upper(:), tol
      integer, intent(out) :: p, sp
      real(wp), intent(out) :: target
      real(wp) :: worst, v, floor
      integer :: i
      p = 0
      sp = 0
      target = 0
      worst = 0
      do i = 1, self%m
         if (self%side(i) /= 0) cycle
         floor = 0
         if (self%dropped(i)) floor = tol
         v = lower(i) - y(i)
         if (v > floor .and. v > worst) then
            worst = v
            p = i
            sp = 1
            target = lower(i)
         end if
         v = y(i) - upper(i)
         if (v > floor .and. v > worst) then
            worst = v
            p = i
            sp = -1
            target = upper(i)
         end if
      end do
   end subroutine most_violated

   !> Remove column q of the k x k upper triangular R (C_AA = R^T R) and restore the
   !> triangular form by Givens rotations on rows q..k: R becomes the factor of C_AA
   !> without stop q, (k-1) x (k-1); row and column k are zeroed.
   pure subroutine drop_column(r, k, q)
      real(wp), intent(inout) :: r(:, :)
      integer, intent(in) :: k, q
      real(wp) :: a, b, h, cs, sn, t1, t2
      integer :: j, l
      do l = q, k - 1
         r(1:l + 1, l) = r(1:l + 1, l + 1)
      end do
      r(1:k, k) = 0
      do j = q, k - 1
         a = r(j, j)
         b = r(j + 1, j)
         h = hypot(a, b)
         cs = a/h
         sn = b/h
         r(j, j) = h
         r(j + 1, j) = 0
         do l = j + 1, k - 1
            t1 = r(j, l)
            t2 = r(j + 1, l)
            r(j, l) = cs*t1 + sn*t2
            r(j + 1, l) = cs*t2 - sn*t1
         end do
      end do
      r(k, 1:k) = 0
   end subroutine drop_column
end module beamstops_contact_box_qp
