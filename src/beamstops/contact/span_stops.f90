!> Rigid stops at m nodes along the span (SPEC 7), solved exactly at every step.
!>
!> Stop i holds the physical displacement of node x_i between lower_i < 0 < upper_i. The
!> stops are fixed in space, like the tip stops of the paper: in the homogeneous unknown
!> u = u~ - h(x) phi(t) (SPEC 1) the bounds of step n+1 are lower_i - h_i phi(t_{n+1}) and
!> upper_i - h_i phi(t_{n+1}), h_i = h(x_i). At the tip h(L) = 0 (stored as an exact zero):
!> there the bounds are those of u itself, and a single stop at the tip is the paper's
!> Lemma 4.1 (contact/tip_projection.f90) to the last bit. With a support at rest (phi = 0)
!> the set is the paper's fixed convex K.
!>
!> Each step: the unconstrained solve gives u' (its values at the stops: the trial values
!> y'); if all are within their bounds, u = u' (O(m) more than a free step). Otherwise the
!> box-constrained program on C = P^T A^{-1} P (contact/box_qp.f90) gives the multipliers
!> lambda and u = u' + A^{-1} P lambda: with the precomputed columns Z = A^{-1} P for up to
!> max_columns active stops (one pass over the unknowns, as the tip's z), beyond that by one
!> more banded solve of P lambda (O(n) whatever m). The stops on a bound are then set to it
!> exactly. The reaction of stop i during the step is lambda_i/dt^2 per unit mass.
!>
!> Energy: with r_i = lambda_i/dt^2 the scheme's balance (SPEC 6) reads
!>   E^{n+1/2} - E^{n-1/2} = 1/2 G.(u^{n+1} - u^{n-1}) + 1/2 sum r_i (u^{n+1}_i - u^{n-1}_i),
!> and u_i = u~_i - h_i phi splits the stops' term into the energy the stops take,
!>   D^n = -1/2 sum r_i (u~^{n+1}_i - u~^{n-1}_i) >= 0
!> (u~^{n+1}_i is on the bound r_i pushes away from, u~^{n-1}_i within the stops), and the
!> work the moving support does through the stops, -1/2 sum r_i h_i (phi^{n+1} - phi^{n-1}),
!> counted with the work of the load. Both vanish at the tip's h = 0 but for D^n.
module beamstops_contact_span_stops
   use beamstops_kinds, only: wp, ik
   use beamstops_strings, only: fmt_real, fmt_int
   use beamstops_error, only: error_type, fatal_error
   use beamstops_band, only: cholesky_solve
   use beamstops_band_solve, only: band_solver, fused_solve
   use beamstops_contact_box_qp, only: box_qp_type, new_box_qp, qp_solved
   implicit none
   private
   public :: span_stops_type, span_work_type, new_span_stops, new_span_work, span_contact, span_correction
   public :: span_settle, span_energy, span_energy_massless, max_columns

   !> Active stops up to which the correction uses the columns Z (beyond: one banded solve).
   integer, parameter :: max_columns = 8

   !> What the stops imply before time runs (part of the model): positions, bounds, Z, C.
   type :: span_stops_type
      !> Number of stops m (0: no stops along the span).
      integer :: m = 0
      !> Which stop is at the tip (node J), 0 when none: its reaction is also the tip's.
      integer :: tip = 0
      !> Node index (1..J) of each stop (m).
      integer, allocatable :: node(:)
      !> Index of its value among the unknowns, 2 node - 1 (m).
      integer, allocatable :: unknown(:)
      !> Abscissa x_i of each stop (m).
      real(wp), allocatable :: x(:)
      !> Lifting shape h(x_i) at each stop, exactly 0 at the tip (m).
      real(wp), allocatable :: lift(:)
      !> Lower and upper stop of each (physical displacement, m) (m).
      real(wp), allocatable :: lower(:), upper(:)
      !> Columns Z = A^{-1} P (n, m): column i is A^{-1} e_{unknown(i)}.
      real(wp), allocatable :: z(:, :)
      !> Schur complement C = P^T A^{-1} P (m, m).
      real(wp), allocatable :: c(:, :)
   end type span_stops_type

   !> What the stops change from step to step (part of the time loop's state); rebuilt
   !> from the model by new_span_work, so a resumed run needs nothing of it.
   type :: span_work_type
      !> The program on C with its workspace (active set, factor).
      type(box_qp_type) :: qp
      !> Trial values, bounds of the step in u, multipliers and constrained values (m).
      real(wp), allocatable :: trial(:), lo(:), hi(:), lambda(:), y(:)
      !> Bounds of u^{n+1} itself at the stops (= lo, hi but with restitution, where lo, hi bound
      !> u^{n+1} + e u^{n-1} shifted; the violation is measured on these) (m).
      real(wp), allocatable :: vlo(:), vhi(:)
      !> Mass redistribution: (S u^n)_k and (S d^{n-1})_k at the stops before the step, and the
      !> reaction of each stop during the step, per unit mass (m).
      real(wp), allocatable :: s_u(:), s_d_prev(:), reaction(:)
      !> The energy each stop took during the step, per unit mass (span_energy) (m).
      real(wp), allocatable :: taken(:)
      !> u^n and d^{n-1} at the stops, before the step (m).
      real(wp), allocatable :: u_prev(:), d_prev(:)
      !> A record of the stops waiting for the recorder: u~ at each stop and reactions (N) (m).
      real(wp), allocatable :: record_u(:), record_reaction(:)
      !> qp_solved, or why the program of a step failed (contact/box_qp.f90).
      integer :: info = qp_solved
      !> Scratch for the correction by a solve (n).
      real(wp), allocatable :: scratch(:)
      !> Whether some stop acts during the step (a nonzero multiplier).
      logical :: contact = .false.
   end type span_work_type

contains

   !> Stops at the given nodes: Z by m banded solves with the factor of A, C = P^T Z.
   subroutine new_span_stops(self, nodes, lower, upper, x_nodes, lift_nodes, factor, error)
      !> The stops, built.
      type(span_stops_type), intent(out) :: self
      !> Node indices 1..J, distinct (m).
      integer, intent(in) :: nodes(:)
      !> Lower stops < 0 (m).
      real(wp), intent(in) :: lower(:)
      !> Upper stops > 0 (m).
      real(wp), intent(in) :: upper(:)
      !> Node abscissae x_0..x_J (J+1).
      real(wp), intent(in) :: x_nodes(0:)
      !> Lifting shape at the nodes h(x_0)..h(x_J) (J+1).
      real(wp), intent(in) :: lift_nodes(0:)
      !> Cholesky factor of A in band storage (kd+1, n), from cholesky_factor.
      real(wp), intent(in) :: factor(:, :)
      !> Set when C is not positive definite or memory is short.
      type(error_type), allocatable, intent(out) :: error
      integer :: m, n, i, j, stat, elements
      m = size(nodes)
      n = size(factor, 2)
      elements = ubound(x_nodes, 1)
      self%m = m
      self%node = nodes
      self%unknown = 2*nodes - 1
      self%x = x_nodes(nodes)
      self%lift = lift_nodes(nodes)
      where (nodes == elements) self%lift = 0
      self%tip = 0
      do j = 1, m
         if (nodes(j) == elements) self%tip = j
      end do
      self%lower = lower
      self%upper = upper
      allocate (self%z(n, m), self%c(m, m), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, 'not enough memory for the columns A^-1 P of the stops along the span: '// &
            & fmt_int(int(m, ik))//' stops x '//fmt_int(int(n, ik))//' unknowns, '// &
            & fmt_real(8*real(m, wp)*real(n, wp)/1.0e9_wp, 4)//' GB (&stops nodes or x, &mesh elements); allowed: '// &
            & 'fewer stops or elements')
         return
      end if
      do j = 1, m
         self%z(:, j) = 0
         self%z(self%unknown(j), j) = 1
         call cholesky_solve(factor, self%z(:, j))
      end do
      do j = 1, m
         do i = 1, m
            self%c(i, j) = self%z(self%unknown(i), j)
         end do
      end do
   end subroutine new_span_stops

   !> The step-to-step part of the stops: the program on C and the work arrays.
   subroutine new_span_work(work, stops, error)
      !> Work, built.
      type(span_work_type), intent(out) :: work
      !> The stops of the model.
      type(span_stops_type), intent(in) :: stops
      !> Set when C is not positive definite (stops too close together for the mesh).
      type(error_type), allocatable, intent(out) :: error
      integer :: m
      m = stops%m
      call new_box_qp(work%qp, stops%c, error)
      if (allocated(error)) then
         error%message = 'stops along the span: '//error%message//' (stops too close together?)'
         return
      end if
      allocate (work%trial(m), work%lo(m), work%hi(m), work%lambda(m), work%y(m), work%u_prev(m), work%d_prev(m), &
         & work%record_u(m), work%record_reaction(m), work%vlo(m), work%vhi(m), work%s_u(m), work%s_d_prev(m), &
         & work%reaction(m), work%taken(m))
      work%taken = 0
      work%s_u = 0
      work%s_d_prev = 0
      work%reaction = 0
      work%record_u = 0
      work%record_reaction = 0
      work%info = qp_solved
      allocate (work%scratch(size(stops%z, 1)))
      work%lambda = 0
      work%y = 0
      work%contact = .false.
   end subroutine new_span_work

   !> The contact of a step: the trial values u^n + d^{n-1} + x at the stops (x = A^{-1} rhs),
   !> the bounds at phi = phi(t_{n+1}), and the multipliers (zero when no trial value is out).
   !> Also keeps u^n and d^{n-1} at the stops for the record and the energy. Without `enforce`
   !> (law 'none') only that. info: qp_solved or the failure of the program (contact/box_qp.f90).
   !> With a restitution coefficient e > 0 (Paoli-Schatzman, SPEC 9) the program bounds the
   !> combination (u~^{n+1} + e u~^{n-1})/(1+e) of the physical displacements, that is u^{n+1} at
   !> each stop between (1+e) lower - e u^{n-1} - h (phi_{n+1} + e phi_{n-1}) and the same with upper.
   subroutine span_contact(stops, work, u, d, x, phi, enforce, info, e, phi_prev)
      !> The stops.
      type(span_stops_type), intent(in) :: stops
      !> Work; lambda, y, contact set.
      type(span_work_type), intent(inout) :: work
      !> u^n, d^{n-1} and the unconstrained increment x = A^{-1} rhs (n).
      real(wp), intent(in) :: u(:), d(:), x(:)
      !> Support position at t_{n+1} (m).
      real(wp), intent(in) :: phi
      !> Whether the stops act (law 'signorini').
      logical, intent(in) :: enforce
      !> qp_solved, or why the program failed.
      integer, intent(out) :: info
      !> Restitution coefficient e in [0, 1].
      real(wp), intent(in) :: e
      !> Support position at t_{n-1} (m; used when e > 0).
      real(wp), intent(in) :: phi_prev
      integer :: i, k
      logical :: out
      info = qp_solved
      out = .false.
      do i = 1, stops%m
         k = stops%unknown(i)
         work%u_prev(i) = u(k)
         work%d_prev(i) = d(k)
         work%trial(i) = u(k) + (d(k) + x(k))
         work%lo(i) = stops%lower(i) - stops%lift(i)*phi
         work%hi(i) = stops%upper(i) - stops%lift(i)*phi
         work%vlo(i) = work%lo(i)
         work%vhi(i) = work%hi(i)
         if (e > 0) then
            work%lo(i) = (1 + e)*stops%lower(i) - e*(u(k) - d(k)) - stops%lift(i)*(phi + e*phi_prev)
            work%hi(i) = (1 + e)*stops%upper(i) - e*(u(k) - d(k)) - stops%lift(i)*(phi + e*phi_prev)
         end if
         out = out .or. work%trial(i) < work%lo(i) .or. work%trial(i) > work%hi(i)
      end do
      if (.not. (out .and. enforce)) then
         if (work%contact) then
            work%lambda = 0
            work%qp%n_active = 0
         end if
         work%contact = .false.
         return
      end if
      call work%qp%solve(work%trial, work%lo, work%hi, work%lambda, work%y, info)
      work%contact = work%qp%n_active > 0
   end subroutine span_contact

   !> The correction A^{-1} P lambda of the step, in the form the time loop applies: with one
   !> active stop, its column (col > 0) and multiplier c, for the loop's rank-one update
   !> d = d + x + c Z(:, col) (the tip's update, to the bit); with more, the correction is
   !> added to x (columns up to max_columns active stops, else one banded solve) and col = 0,
   !> c = 0; with none, col = 0, c = 0.
   subroutine span_correction(stops, work, solver, x, c, col)
      !> The stops.
      type(span_stops_type), intent(in) :: stops
      !> Work from span_contact.
      type(span_work_type), intent(inout) :: work
      !> Factor of A for the fused solve (beyond max_columns active stops).
      type(band_solver), intent(in) :: solver
      !> The unconstrained increment x = A^{-1} rhs (n); plus the correction when col = 0.
      real(wp), intent(inout), contiguous :: x(:)
      !> Multiplier of the single active stop (0 otherwise).
      real(wp), intent(out) :: c
      !> Its column in stops%z, or 0.
      integer, intent(out) :: col
      integer :: i, j, a, k
      real(wp) :: acc
      c = 0
      col = 0
      k = 0
      if (work%contact) k = work%qp%n_active
      if (k == 0) return
      if (k == 1) then
         col = work%qp%active(1)
         c = work%lambda(col)
      else if (k <= max_columns) then
         do i = 1, size(x)
            acc = x(i)
            do j = 1, k
               a = work%qp%active(j)
               acc = acc + work%lambda(a)*stops%z(i, a)
            end do
            x(i) = acc
         end do
      else
         work%scratch = 0
         do j = 1, k
            a = work%qp%active(j)
            work%scratch(stops%unknown(a)) = work%lambda(a)
         end do
         call fused_solve(solver, work%scratch)
         x = x + work%scratch
      end if
   end subroutine span_correction

   !> The active stops exactly on their bounds, with d^n their exact increment there (as the
   !> tip's: a stop resting on a bound has exactly zero velocity), and the largest violation of
   !> a bound by the values of u at the stops (u's frame, the bounds of the step; 0 but for
   !> round-off).
   !> Without `exact` (mass redistribution: d stays the primary variable) the values are left as
   !> the update made them. The violation is that of u^{n+1} itself (with restitution too).
   subroutine span_settle(stops, work, u, d, worst, exact)
      !> The stops.
      type(span_stops_type), intent(in) :: stops
      !> Work from span_contact.
      type(span_work_type), intent(in) :: work
      !> u^{n+1} and d^n (n).
      real(wp), intent(inout) :: u(:), d(:)
      !> Largest violation (m).
      real(wp), intent(inout) :: worst
      !> Whether the active stops are set exactly on their bounds.
      logical, intent(in) :: exact
      integer :: j, a, k
      if (work%contact .and. exact) then
         do j = 1, work%qp%n_active
            a = work%qp%active(j)
            k = stops%unknown(a)
            u(k) = work%y(a)
            d(k) = work%y(a) - work%u_prev(a)
         end do
      end if
      do j = 1, stops%m
         k = stops%unknown(j)
         worst = max(worst, u(k) - work%vhi(j), work%vlo(j) - u(k))
      end do
   end subroutine span_settle

   !> The energy the stops take during the step (>= 0) and the work the moving support does
   !> through them, per unit mass, added to the loop's sums, from d^n (after the update and
   !> span_settle) and the values kept by span_contact; dphi = phi(t_{n+1}) - phi(t_{n-1}).
   !> At the tip (h = 0) the expression is the tip path's, so that the sums are its bits. Each
   !> stop's share goes to work%taken (the sum's increment by it: the shares add up to the sum).
   pure subroutine span_energy(stops, work, d, dt2, dphi, dissipated, support_work)
      !> The stops.
      type(span_stops_type), intent(in) :: stops
      !> Work after span_contact; its `taken` set.
      type(span_work_type), intent(inout) :: work
      !> d^n (n).
      real(wp), intent(in) :: d(:)
      !> dt^2.
      real(wp), intent(in) :: dt2
      !> phi(t_{n+1}) - phi(t_{n-1}).
      real(wp), intent(in) :: dphi
      !> Energy taken by the stops so far; plus -1/2 sum r_i (u~^{n+1}_i - u~^{n-1}_i).
      real(wp), intent(inout) :: dissipated
      !> Work of the load and the support so far; plus -1/2 sum r_i h_i dphi.
      real(wp), intent(inout) :: support_work
      integer :: j, a, k
      real(wp) :: r, before
      work%taken = 0
      if (.not. work%contact) return
      do j = 1, work%qp%n_active
         a = work%qp%active(j)
         k = stops%unknown(a)
         r = work%lambda(a)/dt2
         before = dissipated
         if (stops%lift(a) == 0) then
            dissipated = dissipated - 0.5_wp*r*(d(k) + work%d_prev(a))
         else
            dissipated = dissipated - 0.5_wp*r*((d(k) + work%d_prev(a)) + stops%lift(a)*dphi)
            support_work = support_work - 0.5_wp*r*stops%lift(a)*dphi
         end if
         work%taken(a) = dissipated - before
      end do
   end subroutine span_energy

   !> span_energy for massless stop unknowns (mass redistribution, SPEC 10): the reaction of
   !> every stop is given (work%reaction, the residual of its row, nonzero a few steps after a
   !> contact), so the sums run over all stops; each stop's share goes to work%taken.
   pure subroutine span_energy_massless(stops, work, d, dphi, dissipated, support_work)
      !> The stops.
      type(span_stops_type), intent(in) :: stops
      !> Work after span_contact, with the reactions of the step; its `taken` set.
      type(span_work_type), intent(inout) :: work
      !> d^n (n).
      real(wp), intent(in) :: d(:)
      !> phi(t_{n+1}) - phi(t_{n-1}).
      real(wp), intent(in) :: dphi
      !> Energy taken by the stops so far.
      real(wp), intent(inout) :: dissipated
      !> Work of the load and the support so far.
      real(wp), intent(inout) :: support_work
      integer :: a, k
      real(wp) :: r, before
      do a = 1, stops%m
         k = stops%unknown(a)
         r = work%reaction(a)
         work%taken(a) = 0
         if (r == 0) cycle
         before = dissipated
         if (stops%lift(a) == 0) then
            ! the tip path's expression, so that a stop at the tip gives its bits
            dissipated = dissipated - 0.5_wp*r*(d(k) + work%d_prev(a))
         else
            dissipated = dissipated - 0.5_wp*r*((d(k) + work%d_prev(a)) + stops%lift(a)*dphi)
            support_work = support_work - 0.5_wp*r*stops%lift(a)*dphi
         end if
         work%taken(a) = dissipated - before
      end do
   end subroutine span_energy_massless
end module beamstops_contact_span_stops
