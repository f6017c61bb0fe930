!> The observers of one chunk of lockstep lanes (beamstops_lockstep): the quiet samples of every
!> member at once, the others by the member's own observer.
!>
!> Most samples of a run are quiet: the tip off the stops (no reaction), no energy taken, in the
!> same batch and histogram bin as the sample before, and before the shock log's next deadline.
!> The observer's tip then only counts the sample, shifts the tip's last two values and adds to
!> the tip's sums and extremes. Here those few values are kept lane by lane (the member index
!> innermost, as the lanes of the step), so that a quiet sample of the chunk is a few
!> whole-register operations instead of a call per member. A lane whose sample is not quiet
!> hands its values back to its member's observer, which takes the sample (observer_type's tip)
!> and gives them again.
!>
!> Bit for bit: a quiet sample performs the operations of the statistics' tip_sample and the
!> log's step_tip on the same values in the same order; which samples are quiet is decided
!> conservatively (anything else goes to the member's observer: contact, energy, a new batch or
!> bin, a deadline, a value not finite). tests/fortran/test_lockstep.f90 checks the shock logs
!> and statistics of whole lockstep runs against the same scenes run alone.
module beamstops_observe_lanes
   use beamstops_kinds, only: wp, ik
   use beamstops_band_solve_lockstep, only: lockstep_lanes
   use beamstops_observe_observer, only: observer_type
   use beamstops_observe_statistics, only: quiet_tip_stats
   implicit none
   private
   public :: observer_lanes, gather_observers, scatter_observers, observe_lanes, quiet_pass, count_quiet

   !> The values quiet samples read and change, per lane of a chunk. Each test of a quiet sample is
   !> a compare of doubles (so that the chunk's test is a few whole-register compares): a lane
   !> without a live observer passes every test (gather_observers: no deadline, batch end or last
   !> sample time, at rest in bin 0), so that a chunk whose live lanes are quiet is counted in one
   !> pass over all its lanes; the histogram's current bin is the interval
   !> [bin_low, bin_low + 1) of (u - lower) scale, and the shock log's deadline is counted down
   !> in `left` = deadline - k - 1, the quiet samples still allowed (exact below 2^53; a deadline
   !> of huge stays above 0).
   type :: observer_lanes
      !> Member index of each lane (0: no member) and whether its observer takes samples now
      !> (the member runs and observes).
      integer :: member(lockstep_lanes) = 0
      logical :: live(lockstep_lanes) = .false.
      !> The observer's last sample time (s; huge for a lane without a live observer) and the
      !> stops' energy it has seen (per unit mass).
      real(wp) :: t_stop(lockstep_lanes) = -huge(1.0_wp), seen(lockstep_lanes) = 0
      !> The shock log: samples seen; quiet samples left before the deadline; the tip's last two
      !> values.
      integer(ik) :: k(lockstep_lanes) = 0
      real(wp) :: left(lockstep_lanes) = 0, u1(lockstep_lanes) = 0, u2(lockstep_lanes) = 0
      !> The statistics (quiet_tip_stats, lane by lane; bin_low: the current run's bin).
      real(wp) :: next_edge(lockstep_lanes) = 0, lower(lockstep_lanes) = 0, scale(lockstep_lanes) = 0, &
         & top(lockstep_lanes) = 0, bin_low(lockstep_lanes) = 0, su(lockstep_lanes) = 0, suu(lockstep_lanes) = 0, &
         & umin(lockstep_lanes) = 0, umax(lockstep_lanes) = 0
      integer(ik) :: n(lockstep_lanes) = 0
   end type observer_lanes

contains

   !> The lanes of every chunk (lockstep_lanes members each, in order) from the members'
   !> observers, live for the members that run and observe; the other lanes (and the padding
   !> lanes of the last chunk) are made to pass quiet_fails' tests at rest (observe_lanes counts
   !> their samples in values no observer takes back).
   subroutine gather_observers(lanes, observers, running)
      !> The chunks' lanes, one per chunk.
      type(observer_lanes), allocatable, intent(out) :: lanes(:)
      !> Every member's observer (K).
      type(observer_type), intent(in) :: observers(:)
      !> Whether each member runs (K).
      logical, intent(in) :: running(:)
      integer :: c, i, k
      allocate (lanes((size(observers) + lockstep_lanes - 1)/lockstep_lanes))
      do c = 1, size(lanes)
         lanes(c)%t_stop = huge(1.0_wp)
         lanes(c)%left = huge(1.0_wp)
         lanes(c)%next_edge = huge(1.0_wp)
         do i = 1, lockstep_lanes
            k = (c - 1)*lockstep_lanes + i
            if (k > size(observers)) exit
            lanes(c)%member(i) = k
            lanes(c)%live(i) = running(k) .and. observers(k)%active
            if (lanes(c)%live(i)) call take(lanes(c), i, observers(k))
         end do
      end do
   end subroutine gather_observers

   !> The lanes' values back into their members' observers.
   subroutine scatter_observers(lanes, observers)
      !> The chunks' lanes.
      type(observer_lanes), intent(in) :: lanes(:)
      !> Every member's observer.
      type(observer_type), intent(inout) :: observers(:)
      integer :: c, i
      do c = 1, size(lanes)
         do i = 1, lockstep_lanes
            if (lanes(c)%live(i)) call give(lanes(c), i, observers(lanes(c)%member(i)))
         end do
      end do
   end subroutine scatter_observers

   !> The sample of t_{n+1} of every live lane: u^{n+1}_tip, the reaction of step n and the
   !> stops' energy so far, per unit mass (observer_type's tip, lane by lane).
   subroutine observe_lanes(lanes, observers, t, u_tip, reaction, dissipated)
      !> The chunk's lanes.
      type(observer_lanes), intent(inout) :: lanes
      !> Every member's observer.
      type(observer_type), intent(inout) :: observers(:)
      !> t_{n+1} (s).
      real(wp), intent(in) :: t
      !> Tip displacement (m), reaction and energy taken so far per unit mass, of every lane.
      real(wp), intent(in) :: u_tip(lockstep_lanes), reaction(lockstep_lanes), dissipated(lockstep_lanes)
      integer(ik) :: fails(lockstep_lanes), total
      integer :: i
      ! quiet_fails lane by lane: whole-register compares, masks and adds
      total = 0
!GCC$ ivdep
!GCC$ vector
      do i = 1, lockstep_lanes
         fails(i) = quiet_fails(t, u_tip(i), reaction(i), dissipated(i), lanes%seen(i), lanes%left(i), &
            & lanes%next_edge(i), lanes%lower(i), lanes%scale(i), lanes%top(i), lanes%bin_low(i), lanes%t_stop(i))
         total = total + fails(i)
      end do
      if (total == 0) then
         ! every lane quiet (most steps): count_quiet over all the lanes, whole-register operations
         ! with no select (a select of the counts by lane is not vectorized by gfortran 12: the
         ! arithmetic of the lanes that keep their values would be speculated, and it may trap)
         call count_quiet(u_tip, lanes%k, lanes%left, lanes%u1, lanes%u2, lanes%su, lanes%suu, lanes%umin, lanes%umax, &
            & lanes%n)
         return
      end if
      do i = 1, lockstep_lanes
         if (fails(i) == 0) then
            call count_quiet(u_tip(i), lanes%k(i), lanes%left(i), lanes%u1(i), lanes%u2(i), lanes%su(i), lanes%suu(i), &
               & lanes%umin(i), lanes%umax(i), lanes%n(i))
         else if (lanes%live(i) .and. t <= lanes%t_stop(i)) then
            associate (observer => observers(lanes%member(i)))
               call give(lanes, i, observer)
               call observer%tip(t, u_tip(i), reaction(i), dissipated(i))
               call take(lanes, i, observer)
            end associate
         end if
      end do
   end subroutine observe_lanes

   !> 1 when the sample of t is quiet for an observer with these values (observer_lanes'
   !> components), else 0: quiet_fails finds no failed test. beamstops_observe_quiet uses it for
   !> one scene.
   elemental real(wp) function quiet_pass(t, u_tip, reaction, dissipated, seen, left, next_edge, lower, scale, top, &
      & bin_low, t_stop) result(pass)
      !> The sample: t (s), tip (m), reaction and energy taken so far (per unit mass).
      real(wp), intent(in) :: t, u_tip, reaction, dissipated
      !> The observer's values (observer_lanes).
      real(wp), intent(in) :: seen, left, next_edge, lower, scale, top, bin_low, t_stop
      pass = merge(1.0_wp, 0.0_wp, quiet_fails(t, u_tip, reaction, dissipated, seen, left, next_edge, lower, scale, &
         & top, bin_low, t_stop) == 0)
   end function quiet_pass

   !> The number of tests the sample of t (tip u_tip, the reaction, the stops' energy so far) fails
   !> for an observer with these values (0: quiet): taken (t <= t_stop), no reaction, no energy
   !> (dissipated == seen), before the deadline and the batch's end, in the run's bin (tip_sample's
   !> bin is int(x), x clamped to [0, bins - 1/2]), finite. Each test is 0 or 1 by an integer merge
   !> and the results are added: whole-register compares, masks and integer adds for a chunk's
   !> lanes (observe_lanes). A product of real merges is branches per lane and test with gfortran
   !> 12: an operation on a merge's result is folded into both arms of a select, and a
   !> floating-point operation in an arm may trap, so the select is not if-converted.
   elemental integer(ik) function quiet_fails(t, u_tip, reaction, dissipated, seen, left, next_edge, lower, scale, &
      & top, bin_low, t_stop) result(fails)
      !> The sample: t (s), tip (m), reaction and energy taken so far (per unit mass).
      real(wp), intent(in) :: t, u_tip, reaction, dissipated
      !> The observer's values (observer_lanes).
      real(wp), intent(in) :: seen, left, next_edge, lower, scale, top, bin_low, t_stop
      real(wp) :: x
      x = min(max((u_tip - lower)*scale, 0.0_wp), top)
      fails = merge(0_ik, 1_ik, reaction == 0) + merge(0_ik, 1_ik, dissipated == seen) &
         & + merge(0_ik, 1_ik, left > 0) + merge(0_ik, 1_ik, t < next_edge) &
         & + merge(0_ik, 1_ik, x >= bin_low) + merge(0_ik, 1_ik, x < bin_low + 1) &
         & + merge(0_ik, 1_ik, abs(u_tip) <= huge(1.0_wp)) + merge(0_ik, 1_ik, t <= t_stop)
   end function quiet_fails

   !> A quiet sample u_tip: what the shock log's step_tip and the statistics' tip_sample do with it
   !> (count it, shift the tip's last two values, add to the sums and extremes), in their order.
   elemental subroutine count_quiet(u_tip, k, left, u1, u2, su, suu, umin, umax, n)
      !> The tip (m).
      real(wp), intent(in) :: u_tip
      !> The log's samples seen and quiet samples left; the tip's last two values.
      integer(ik), intent(inout) :: k
      real(wp), intent(inout) :: left, u1, u2
      !> The statistics' sum, sum of squares, extremes and count.
      real(wp), intent(inout) :: su, suu, umin, umax
      integer(ik), intent(inout) :: n
      k = k + 1
      left = left - 1
      u2 = u1
      u1 = u_tip
      su = su + u_tip
      suu = suu + u_tip*u_tip
      umin = min(umin, u_tip)
      umax = max(umax, u_tip)
      n = n + 1
   end subroutine count_quiet

   !> Lane i's values from its member's observer.
   subroutine take(lanes, i, observer)
      type(observer_lanes), intent(inout) :: lanes
      integer, intent(in) :: i
      type(observer_type), intent(in) :: observer
      type(quiet_tip_stats) :: q
      integer(ik) :: deadline
      lanes%t_stop(i) = observer%t_stop
      lanes%seen(i) = observer%dissipated_seen
      call observer%shocks%quiet_tip(lanes%k(i), lanes%u1(i), lanes%u2(i), deadline)
      lanes%left(i) = real(deadline - lanes%k(i) - 1, wp)
      q = observer%stats%quiet_tip()
      lanes%next_edge(i) = q%next_edge
      lanes%lower(i) = q%lower
      lanes%scale(i) = q%scale
      lanes%top(i) = q%top
      lanes%bin_low(i) = real(q%run_bin, wp)
      lanes%su(i) = q%su
      lanes%suu(i) = q%suu
      lanes%umin(i) = q%umin
      lanes%umax(i) = q%umax
      lanes%n(i) = q%n
   end subroutine take

   !> Lane i's values into its member's observer.
   subroutine give(lanes, i, observer)
      type(observer_lanes), intent(in) :: lanes
      integer, intent(in) :: i
      type(observer_type), intent(inout) :: observer
      type(quiet_tip_stats) :: q
      call observer%shocks%set_quiet_tip(lanes%k(i), lanes%u1(i), lanes%u2(i))
      q%su = lanes%su(i)
      q%suu = lanes%suu(i)
      q%umin = lanes%umin(i)
      q%umax = lanes%umax(i)
      q%n = lanes%n(i)
      call observer%stats%set_quiet_tip(q)
   end subroutine give
end module beamstops_observe_lanes
