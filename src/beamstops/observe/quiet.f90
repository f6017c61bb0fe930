!> The observer of one scene's time loop (advance_fused) with its quiet samples taken in the
!> loop's own variables: the tip off the stops (no reaction), no energy taken, before the shock
!> log's deadline and the batch's end, in the histogram run's bin. Such a sample only counts and
!> adds (the tip's last two values, sums, extremes); every other sample goes to observer_type's
!> tip, with the quiet values handed back first and taken again after. The test and the count
!> are beamstops_observe_lanes' quiet_pass and count_quiet, which the lockstep lanes use (and the
!> lockstep tests compare with observer_type's tip): the same bits. In the loop, the observer's tip through its shock log
!> and statistics cost about 13 ns a step (the program on the paper's Figure 4 scene, A/B).
module beamstops_observe_quiet
   use beamstops_kinds, only: wp, ik
   use beamstops_observe_observer, only: observer_type
   use beamstops_observe_statistics, only: quiet_tip_stats
   use beamstops_observe_lanes, only: quiet_pass, count_quiet
   implicit none
   private
   public :: quiet_observer, take_quiet, give_quiet, observe_quiet

   !> What quiet samples read and change (observer_lanes' values for one lane).
   type :: quiet_observer
      !> The observer takes samples (active), up to t_stop (s); the stops' energy it has seen.
      logical :: live = .false.
      real(wp) :: t_stop = -huge(1.0_wp), seen = 0
      !> The shock log: samples seen, quiet samples left before its deadline, the tip's last two values.
      integer(ik) :: k = 0
      real(wp) :: left = 0, u1 = 0, u2 = 0
      !> The statistics: quiet_tip_stats, the current run's bin as a real.
      type(quiet_tip_stats) :: s
      real(wp) :: bin_low = 0
   end type quiet_observer

contains

   !> The quiet values from the observer (at the start of a loop).
   subroutine take_quiet(q, observer)
      !> Quiet values.
      type(quiet_observer), intent(out) :: q
      !> The scene's observer.
      type(observer_type), intent(in) :: observer
      integer(ik) :: deadline
      q%live = observer%active
      if (.not. q%live) return
      q%t_stop = observer%t_stop
      q%seen = observer%dissipated_seen
      call observer%shocks%quiet_tip(q%k, q%u1, q%u2, deadline)
      q%left = real(deadline - q%k - 1, wp)
      q%s = observer%stats%quiet_tip()
      q%bin_low = real(q%s%run_bin, wp)
   end subroutine take_quiet

   !> The quiet values back into the observer (at the end of a loop, or before a sample that is
   !> not quiet).
   subroutine give_quiet(q, observer)
      !> Quiet values.
      type(quiet_observer), intent(in) :: q
      !> The scene's observer.
      type(observer_type), intent(inout) :: observer
      if (.not. q%live) return
      call observer%shocks%set_quiet_tip(q%k, q%u1, q%u2)
      call observer%stats%set_quiet_tip(q%s)
   end subroutine give_quiet

   !> The sample of t_{n+1} (observer_type's tip, when the observer takes it): u^{n+1}_tip, the
   !> reaction of step n and the stops' energy so far, per unit mass.
   subroutine observe_quiet(q, observer, t, u_tip, reaction, dissipated)
      !> Quiet values.
      type(quiet_observer), intent(inout) :: q
      !> The scene's observer.
      type(observer_type), intent(inout) :: observer
      !> t_{n+1} (s), tip displacement (m), reaction and energy taken so far per unit mass.
      real(wp), intent(in) :: t, u_tip, reaction, dissipated
      if (.not. q%live .or. t > q%t_stop) return
      if (quiet_pass(t, u_tip, reaction, dissipated, q%seen, q%left, q%s%next_edge, q%s%lower, q%s%scale, q%s%top, &
         & q%bin_low, q%t_stop) > 0) then
         call count_quiet(u_tip, q%k, q%left, q%u1, q%u2, q%s%su, q%s%suu, q%s%umin, q%s%umax, q%s%n)
      else
         call give_quiet(q, observer)
         call observer%tip(t, u_tip, reaction, dissipated)
         call take_quiet(q, observer)
      end if
   end subroutine observe_quiet
end module beamstops_observe_quiet
