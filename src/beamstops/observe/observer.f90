!> The observers the time loop feeds every step: the shock log and the running statistics
!> (beamstops_observe_shocks, beamstops_observe_statistics), in physical units. The loop hands
!> each step's sample — t_{n+1}, the stops' physical displacement, their reactions of step n and
!> the energy the stops took in step n, per unit mass — and, between blocks, the finished shocks
!> are drained to the recorder and into the statistics.
module beamstops_observe_observer
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_observe_shocks, only: shock_log, shock_row, new_shock_log, shock_row_values, n_shock_columns
   use beamstops_observe_statistics, only: statistics_type, statistics_table, new_statistics
   use beamstops_scene, only: scene_type, steps_of, shock_log_rows
   use beamstops_summary, only: run_summary, status_running
   implicit none
   private
   public :: observer_type, new_observer, observe_scene

   !> Shock log and statistics of a run, fed by the loop.
   type :: observer_type
      !> Whether the run observes (&statistics enabled).
      logical :: active = .false.
      !> Number of stops m (1 for the tip-only scene).
      integer :: m = 0
      !> Mass per length: reactions and energies per unit mass times it give N and J.
      real(wp) :: rho = 1
      !> Time step (s).
      real(wp) :: dt = 0
      !> Energy taken by the stops, per unit mass, up to the last sample.
      real(wp) :: dissipated_seen = 0
      !> Samples after this time are not taken: (N + 1/2) dt, N the steps of the run, so that the
      !> samples are t_1 .. t_N, the times of the records (the loop's last step computes
      !> u^{N+1} only to complete the record of t_N).
      real(wp) :: t_stop = huge(1.0_wp)
      !> The shock log.
      type(shock_log) :: shocks
      !> The running statistics.
      type(statistics_type) :: stats
      !> Samples of the stops (m): displacement, reaction, energy taken.
      real(wp), allocatable :: u(:), r(:), e(:)
      !> The finished shocks so far, one column each (n_shock_columns, shocks); `shocks_kept` used.
      real(wp), allocatable :: rows(:, :)
      !> Number of finished shocks kept in rows.
      integer :: shocks_kept = 0
   contains
      !> Whether it takes the sample of a time (ask before tip).
      procedure :: takes
      !> The sample of a step of the tip-only scene.
      procedure :: tip
      !> The sample of a step with stops along the span.
      procedure :: span
      !> The same sample from the loop's arrays and the stops' indices (no temporary).
      procedure :: span_indexed
      !> Take the finished shocks out (into the statistics and the kept rows).
      procedure :: drain
      !> Close the open shocks and the last batch at the end of the run; the table of statistics.
      procedure :: finish
      !> The observer's counts (and, once the run has ended, its tables) in the loop's summary.
      procedure :: book_summary
      !> The whole observer as one vector of reals (checkpoints).
      procedure :: pack => pack_observer
      !> The observer from a vector of pack.
      procedure :: unpack => unpack_observer
   end type observer_type

contains

   !> An observer of m stops whose values are u0 at t = 0, over [transient, t_end] in `batches`
   !> batches, the tip histogram with `bins` bins over [lower, upper].
   subroutine new_observer(self, m, u0, rho, dt, rest_time, transient, t_end, batches, bins, lower, upper, &
      & dissipated0, samples, error)
      !> The observer, active on return.
      type(observer_type), intent(out) :: self
      !> Number of stops.
      integer, intent(in) :: m
      !> Stops' physical displacement at t = 0 (m) (m).
      real(wp), intent(in) :: u0(:)
      !> Mass per length (kg/m), time step (s), rest time (s), window (s).
      real(wp), intent(in) :: rho, dt, rest_time, transient, t_end
      !> Batches and bins.
      integer, intent(in) :: batches, bins
      !> Histogram range of the tip (m).
      real(wp), intent(in) :: lower, upper
      !> Energy the stops took before the first sample, per unit mass (the start).
      real(wp), intent(in) :: dissipated0
      !> N: the samples taken are those of t_1 .. t_N = N dt.
      integer(ik), intent(in) :: samples
      !> Set on a value out of range.
      type(error_type), allocatable, intent(out) :: error
      self%m = m
      self%t_stop = (real(samples, wp) + 0.5_wp)*dt
      self%rho = rho
      self%dt = dt
      self%dissipated_seen = dissipated0
      allocate (self%u(m), self%r(m), self%e(m))
      ! Drained every block of 8192 steps: a capacity of m (4096 + 1) rows never drops one.
      call new_shock_log(self%shocks, m, rest_time, u0, error, capacity=shock_log_rows(m))
      if (allocated(error)) return
      call new_statistics(self%stats, m, transient, t_end, batches, bins, lower, upper, error)
      if (allocated(error)) return
      self%active = .true.
   end subroutine new_observer

   !> The observer of a run of `scene` from t = 0 (the scene's window, batches, bins, rest time;
   !> the full and the reduced loops alike): new_observer with the stops' physical values at t = 0,
   !> then the start's sample at t_1 = dt (the stops along the span, or the tip alone).
   subroutine observe_scene(self, scene, dt, span, u0, u1, reaction, tip1, dissipated, error)
      !> The observer, active on return.
      type(observer_type), intent(out) :: self
      !> Scene (&statistics settings, mass per length).
      type(scene_type), intent(in) :: scene
      !> Time step (s).
      real(wp), intent(in) :: dt
      !> Stops along the span (.true.) or the tip alone.
      logical, intent(in) :: span
      !> Physical values of the stops (or of the tip) at t = 0 and t_1 (m) (m, or 1).
      real(wp), intent(in) :: u0(:), u1(:)
      !> Reactions per unit mass of the start (m, or 1).
      real(wp), intent(in) :: reaction(:)
      !> Tip value at t_1 (m) and the stops' energy of the start per unit mass.
      real(wp), intent(in) :: tip1, dissipated
      !> Set on a value out of range.
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: weight
      call new_observer(self, size(u0), u0, scene%mass_per_length, dt, scene%rest_time, scene%transient, &
         & scene%t_end, scene%batches, scene%bins, scene%histogram_lower, scene%histogram_upper, 0.0_wp, &
         & steps_of(scene), error)
      if (allocated(error)) return
      if (span) then
         ! the start's energy (a projection of u^1, if any) shared in proportion to |r|
         weight = sum(abs(reaction))
         if (weight > 0) then
            call self%span(dt, u1, reaction, tip1, dissipated*abs(reaction)/weight)
         else
            call self%span(dt, u1, reaction, tip1, 0*reaction)
         end if
      else
         call self%tip(dt, u1(1), reaction(1), dissipated)
      end if
   end subroutine observe_scene

   !> Whether the observer takes the sample of time t: active, and t within the samples t_1 .. t_N.
   !> The loops ask before calling tip, span or span_indexed (tip then stays small enough for the
   !> compiler to inline the statistics' update into it, and a span sample's array arguments are
   !> not built for nothing).
   pure logical function takes(self, t)
      !> Observer.
      class(observer_type), intent(in) :: self
      !> t_{n+1} (s).
      real(wp), intent(in) :: t
      takes = self%active .and. t <= self%t_stop
   end function takes

   !> The sample of step n of the tip-only scene (when takes(t)): t_{n+1}, u^{n+1}_tip (physical:
   !> the lifting is 0 at the tip), the reaction of step n and the stops' energy so far, both per
   !> unit mass.
   subroutine tip(self, t, u_tip, reaction, dissipated)
      !> Observer.
      class(observer_type), intent(inout) :: self
      !> t_{n+1} (s), u^{n+1}_tip (m), reaction per unit mass, energy taken so far per unit mass.
      real(wp), intent(in) :: t, u_tip, reaction, dissipated
      real(wp) :: r, e
      r = self%rho*reaction
      e = self%rho*(dissipated - self%dissipated_seen)
      self%dissipated_seen = dissipated
      call self%shocks%step_tip(t, self%dt, u_tip, r, e)
      call self%stats%step_tip(t, self%dt, u_tip, r, e)
   end subroutine tip

   !> The sample of step n with stops along the span (when takes(t)): t_{n+1}, the stops'
   !> physical displacement, their reactions per unit mass, the tip displacement and the energy
   !> each stop took in the step per unit mass (span_energy's `taken`:
   !> -1/2 r_i (u~^{n+1}_i - u~^{n-1}_i)).
   subroutine span(self, t, u, reaction, u_tip, taken)
      !> Observer.
      class(observer_type), intent(inout) :: self
      !> t_{n+1} (s).
      real(wp), intent(in) :: t
      !> Stops' physical displacement (m) and reactions per unit mass (m each).
      real(wp), intent(in) :: u(:), reaction(:)
      !> Tip displacement (m).
      real(wp), intent(in) :: u_tip
      !> Energy each stop took in the step, per unit mass (m each).
      real(wp), intent(in) :: taken(:)
      self%u = u
      self%r = self%rho*reaction
      call span_sample(self, t, u_tip, taken)
   end subroutine span

   !> span from the loop's own arrays, so that the hot loop passes no array expression (each
   !> would be a temporary a step): stop i's displacement is u(unknown(i)) + lift(i) phi and its
   !> reaction reaction(i) where lambda(i) /= 0 (an active stop), else 0.
   subroutine span_indexed(self, t, u, unknown, lift, phi, reaction, lambda, u_tip, taken)
      !> Observer.
      class(observer_type), intent(inout) :: self
      !> t_{n+1} (s).
      real(wp), intent(in) :: t
      !> u^{n+1}, all the unknowns (relative to the support).
      real(wp), intent(in) :: u(:)
      !> The stops' unknowns (m).
      integer, intent(in) :: unknown(:)
      !> The lifting at the stops (m) and the support's position phi(t_{n+1}) (m).
      real(wp), intent(in) :: lift(:), phi
      !> The stops' reactions per unit mass (m) and their multipliers (m; 0: the stop is free).
      real(wp), intent(in) :: reaction(:), lambda(:)
      !> Tip displacement (m).
      real(wp), intent(in) :: u_tip
      !> Energy each stop took in the step, per unit mass (m).
      real(wp), intent(in) :: taken(:)
      integer :: i
      do i = 1, self%m
         self%u(i) = u(unknown(i)) + lift(i)*phi
         if (lambda(i) /= 0) then
            self%r(i) = self%rho*reaction(i)
         else
            self%r(i) = 0
         end if
      end do
      call span_sample(self, t, u_tip, taken)
   end subroutine span_indexed

   !> The rest of span: self%u and self%r set; each stop's energy in physical units, the log and
   !> the statistics fed.
   subroutine span_sample(self, t, u_tip, taken)
      class(observer_type), intent(inout) :: self
      real(wp), intent(in) :: t, u_tip, taken(:)
      self%e = self%rho*taken
      call self%shocks%step(t, self%dt, self%u, self%r, self%e)
      call self%stats%step(t, self%dt, u_tip, self%r, self%e)
   end subroutine span_sample

   !> Take the finished shocks out of the log into the statistics and `rows` (grown as needed).
   subroutine drain(self)
      !> Observer.
      class(observer_type), intent(inout) :: self
      type(shock_row) :: row
      real(wp), allocatable :: grown(:, :)
      if (.not. allocated(self%rows)) allocate (self%rows(n_shock_columns, 256))
      do while (self%shocks%ready())
         call self%shocks%pop(row)
         call self%stats%add_shock(row)
         if (self%shocks_kept == size(self%rows, 2)) then
            allocate (grown(n_shock_columns, 2*size(self%rows, 2)))
            grown(:, :self%shocks_kept) = self%rows(:, :self%shocks_kept)
            call move_alloc(grown, self%rows)
         end if
         self%shocks_kept = self%shocks_kept + 1
         self%rows(:, self%shocks_kept) = shock_row_values(row)
      end do
   end subroutine drain

   !> At the end of the run: close the open shocks, take them out, close the last batch; the
   !> shocks (one column each) and the table of statistics.
   subroutine finish(self, shocks, table)
      !> Observer.
      class(observer_type), intent(inout) :: self
      !> Every shock of the run (n_shock_columns, shocks).
      real(wp), allocatable, intent(out) :: shocks(:, :)
      !> The statistics of the run.
      type(statistics_table), intent(out) :: table
      call self%shocks%finish()
      call self%drain()
      call self%stats%finish()
      table = self%stats%results()
      shocks = self%rows(:, :self%shocks_kept)
   end subroutine finish

   !> The observer's part of a time loop's summary (the full loop's, the reduced one's, a lockstep
   !> member's): the shocks closed so far and the contact phases, an interrupted run's too (its
   !> count had been the contact phases'), after the shock log and the statistics are finished
   !> once the run has ended (its status no longer running). Nothing when the observer is off.
   subroutine book_summary(self, summary)
      !> Observer.
      class(observer_type), intent(inout) :: self
      !> The loop's summary.
      type(run_summary), intent(inout) :: summary
      if (.not. self%active) return
      if (summary%status /= status_running) call self%finish(summary%shocks, summary%statistics)
      summary%impacts = self%shocks%shock_count()
      summary%contact_phases = self%shocks%phase_count()
   end subroutine book_summary

   !> The whole observer as reals: [m, rho, dt, dissipated_seen, t_stop, kept, size of the log's
   !> vector, the log's vector (shock_log%pack), size of the statistics' vector, its vector
   !> (statistics_type%pack), the kept rows (13 per shock)].
   subroutine pack_observer(self, values)
      !> Observer (active).
      class(observer_type), intent(in) :: self
      !> Its state.
      real(wp), allocatable, intent(out) :: values(:)
      real(wp), allocatable :: log(:), stats(:)
      call self%shocks%pack(log)
      call self%stats%pack(stats)
      values = [real(self%m, wp), self%rho, self%dt, self%dissipated_seen, self%t_stop, &
         & real(self%shocks_kept, wp), real(size(log), wp), log, real(size(stats), wp), stats]
      if (self%shocks_kept > 0) values = [values, reshape(self%rows(:, :self%shocks_kept), [n_shock_columns* &
         & self%shocks_kept])]
   end subroutine pack_observer

   !> Restore an observer from the vector of pack_observer.
   subroutine unpack_observer(self, values, error)
      !> Observer, active on return.
      class(observer_type), intent(inout) :: self
      !> The vector of pack_observer.
      real(wp), intent(in) :: values(:)
      !> Set when the vector is not an observer's.
      type(error_type), allocatable, intent(out) :: error
      integer :: at, n_log, n_stats
      if (size(values) < 8) then
         call fatal_error(error, 'the checkpoint''s shock log is damaged')
         return
      end if
      self%m = nint(values(1))
      self%rho = values(2)
      self%dt = values(3)
      self%dissipated_seen = values(4)
      self%t_stop = values(5)
      self%shocks_kept = nint(values(6))
      n_log = nint(values(7))
      at = 8
      if (at + n_log > size(values)) then
         call fatal_error(error, 'the checkpoint''s shock log is damaged')
         return
      end if
      call self%shocks%unpack(values(at:at + n_log - 1), error)
      if (allocated(error)) return
      at = at + n_log
      n_stats = nint(values(at))
      if (at + n_stats + n_shock_columns*self%shocks_kept /= size(values)) then
         call fatal_error(error, 'the checkpoint''s statistics are damaged')
         return
      end if
      call self%stats%unpack(values(at + 1:at + n_stats), error)
      if (allocated(error)) return
      at = at + n_stats + 1
      allocate (self%rows(n_shock_columns, max(256, self%shocks_kept)))
      if (self%shocks_kept > 0) self%rows(:, :self%shocks_kept) = reshape(values(at:), &
         & [n_shock_columns, self%shocks_kept])
      if (allocated(self%u)) deallocate (self%u, self%r, self%e)
      allocate (self%u(self%m), self%r(self%m), self%e(self%m))
      self%active = .true.
   end subroutine unpack_observer
end module beamstops_observe_observer
