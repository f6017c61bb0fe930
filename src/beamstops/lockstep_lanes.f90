!> The per-member values of one chunk of lockstep lanes (beamstops_lockstep) and the
!> bookkeeping of a step over them: the load rotation, the contact law at the tip, the
!> update's tip values, the energy ledger. Fixed-size arrays (lockstep_lanes), so that each
!> statement is a couple of whole-register operations with no loop, descriptor or
!> reallocation check of its own to pay (over arrays of K members, those cost more than the
!> arithmetic).
!>
!> Bit for bit: each routine performs, per lane, the floating-point operations of the one-scene
!> step (beamstops_forcing's load rotation, beamstops_contact_tip_contact's contact_law and
!> close_step, beamstops_ledger's move_on) with the same expressions in the same order.
module beamstops_lockstep_lanes
   use beamstops_kinds, only: wp, ik
   use beamstops_scene, only: law_none, law_signorini, law_compliance
   use beamstops_forcing, only: load_average
   use beamstops_contact_compliance, only: compliance_step
   use beamstops_band_solve_lockstep, only: lockstep_lanes
   use beamstops_newmark, only: newmark_average, newmark_explicit, newmark_work
   implicit none
   private
   public :: lanes_type, lanes_restart_loads, lanes_next_loads, lanes_begin_step, lanes_contact, lanes_close

   !> One chunk of members: what a member carries from step to step, its constants, and the
   !> values of the current step. Padding lanes (beyond the last member) stay at rest: zero
   !> loads and state, stops -1 and 1.
   type :: lanes_type
      !> Whether the lane holds a member (padding lanes: false).
      logical :: member(lockstep_lanes) = .false.
      !> Angular frequency of the support (rad/s), load rule centred, tip stops (m), compliance
      !> stiffness per unit mass (1/s^2).
      real(wp) :: omega(lockstep_lanes) = 0, lower(lockstep_lanes) = -1, upper(lockstep_lanes) = 1, &
         & stiffness(lockstep_lanes) = 0
      logical :: centered(lockstep_lanes) = .true.
      !> Carried: load averages sigma_{n-1}, sigma_n; g.d^{n-1}; spring forces p(u^{n-1}), p(u^n);
      !> work, energy taken by the stops, reaction of the last step, largest violation (per unit
      !> mass).
      real(wp) :: sigma_prev(lockstep_lanes) = 0, sigma_now(lockstep_lanes) = 0, gd_prev(lockstep_lanes) = 0, &
         & p_prev(lockstep_lanes) = 0, p_now(lockstep_lanes) = 0, work(lockstep_lanes) = 0, &
         & dissipated(lockstep_lanes) = 0, reaction(lockstep_lanes) = 0, max_violation(lockstep_lanes) = 0
      !> Carried: whether the last step was in contact; impacts so far.
      logical :: in_contact(lockstep_lanes) = .false.
      integer(ik) :: impacts(lockstep_lanes) = 0
      !> The load rotation (beamstops_forcing's load_rotation): f sin and f cos of omega c_k,
      !> cos and sin of omega dt.
      real(wp) :: sigma(lockstep_lanes) = 0, cosine(lockstep_lanes) = 0, cos_step(lockstep_lanes) = 0, &
         & sin_step(lockstep_lanes) = 0
      !> The step: sigma_{n+1}, the load weight and dt^2 times it, the spring term of the tip row.
      real(wp) :: sigma_next(lockstep_lanes) = 0, weight(lockstep_lanes) = 0, coef(lockstep_lanes) = 0, &
         & spring(lockstep_lanes) = 0
      !> The step: u^n_tip, d^{n-1}_tip, the trial tip value, the multiple c of z, the tip value of
      !> the law, the reaction of the step and of the last step, g.d^n, u^{n+1}_tip.
      real(wp) :: u_tip_prev(lockstep_lanes) = 0, d_tip_prev(lockstep_lanes) = 0, trial(lockstep_lanes) = 0, &
         & c(lockstep_lanes) = 0, tip_value(lockstep_lanes) = 0, r_step(lockstep_lanes) = 0, &
         & r_prev(lockstep_lanes) = 0, gd(lockstep_lanes) = 0, u_tip(lockstep_lanes) = 0
      !> The step (Signorini): d^n_tip on the stop, the tip value less u^n_tip (taken where the
      !> stops act).
      real(wp) :: d_stop(lockstep_lanes) = 0
      !> The step: whether the stops act.
      logical :: contact(lockstep_lanes) = .false.
      !> The energy sums of the step (u.S u, d.S u, d.M d) and u^{n-1}.S u^{n-1} (0 when not wanted).
      real(wp) :: usu(lockstep_lanes) = 0, dsu(lockstep_lanes) = 0, dmd(lockstep_lanes) = 0, &
         & u_old_su(lockstep_lanes) = 0
   end type lanes_type

contains

   !> The load rotation of every member lane at step k, exact (beamstops_forcing's restart_loads).
   pure subroutine lanes_restart_loads(lanes, k, dt)
      !> The chunk.
      type(lanes_type), intent(inout) :: lanes
      !> Step index.
      integer(ik), intent(in) :: k
      !> Time step (s).
      real(wp), intent(in) :: dt
      real(wp) :: centre, x, factor
      integer :: i
      do i = 1, lockstep_lanes
         if (.not. lanes%member(i)) cycle
         centre = real(k, wp)*dt
         if (.not. lanes%centered(i)) centre = (real(k, wp) + 0.5_wp)*dt
         x = 0.5_wp*lanes%omega(i)*dt
         if (abs(x) < 1.0e-8_wp) then
            factor = 1 - x**2/6
         else
            factor = sin(x)/x
         end if
         lanes%sigma(i) = load_average(k, dt, lanes%omega(i), lanes%centered(i))
         lanes%cosine(i) = factor*cos(lanes%omega(i)*centre)
         lanes%cos_step(i) = cos(lanes%omega(i)*dt)
         lanes%sin_step(i) = sin(lanes%omega(i)*dt)
      end do
   end subroutine lanes_restart_loads

   !> The load rotation moved on to step `next`: rotated, or restarted from exact values when
   !> `restart` (beamstops_forcing's next_load).
   pure subroutine lanes_next_loads(lanes, restart, next, dt)
      !> The chunk.
      type(lanes_type), intent(inout) :: lanes
      !> Whether the rotation restarts from exact values at step `next`.
      logical, intent(in) :: restart
      !> Step index the rotation moves to.
      integer(ik), intent(in) :: next
      !> Time step (s).
      real(wp), intent(in) :: dt
      real(wp) :: sigma(lockstep_lanes)
      integer :: i
      if (restart) then
         call lanes_restart_loads(lanes, next, dt)
         return
      end if
!GCC$ ivdep
!GCC$ vector
      do i = 1, lockstep_lanes
         sigma(i) = lanes%sigma(i)*lanes%cos_step(i) + lanes%cosine(i)*lanes%sin_step(i)
         lanes%cosine(i) = lanes%cosine(i)*lanes%cos_step(i) - lanes%sigma(i)*lanes%sin_step(i)
         lanes%sigma(i) = sigma(i)
      end do
   end subroutine lanes_next_loads

   !> The start of a step: sigma_{n+1} taken from the rotation, the rotation moved on
   !> (lanes_next_loads), the load weight, dt^2 times it and the spring term of the tip row
   !> (compliance; beamstops_contact_tip_contact's spring_term).
   pure subroutine lanes_begin_step(lanes, law, beta, dt2, restart, next, dt)
      !> The chunk.
      type(lanes_type), intent(inout) :: lanes
      !> Contact law (shared).
      integer, intent(in) :: law
      !> Newmark beta and dt^2.
      real(wp), intent(in) :: beta, dt2
      !> Whether the rotation restarts from exact values at step `next`.
      logical, intent(in) :: restart
      !> Step index the rotation moves to.
      integer(ik), intent(in) :: next
      !> Time step (s).
      real(wp), intent(in) :: dt
      integer :: i
      lanes%sigma_next = lanes%sigma
      call lanes_next_loads(lanes, restart, next, dt)
      do i = 1, lockstep_lanes
         lanes%weight(i) = newmark_average(beta, lanes%sigma_next(i), lanes%sigma_now(i), lanes%sigma_prev(i))
      end do
      lanes%coef = dt2*lanes%weight
      if (law == law_compliance) then
         do i = 1, lockstep_lanes
            lanes%spring(i) = newmark_explicit(dt2, beta, lanes%p_now(i), lanes%p_prev(i))
         end do
      end if
   end subroutine lanes_begin_step

   !> The contact law at the tip of every lane (beamstops_contact_tip_contact's contact_law;
   !> Signorini: the projection of beamstops_contact_tip_projection): from u^n_tip, d^{n-1}_tip
   !> and the tip row x_tip of A^{-1} rhs, the trial value, the multiple c of z, the tip value,
   !> the reaction of the step and contact. Padding lanes: trial 0 between -1 and 1, so c = 0.
   pure subroutine lanes_contact(lanes, law, u_tip, d_tip, x_tip, z_tip, dt2, beta)
      !> The chunk.
      type(lanes_type), intent(inout) :: lanes
      !> Contact law (shared).
      integer, intent(in) :: law
      !> u^n_tip, d^{n-1}_tip and x_tip of every lane.
      real(wp), intent(in) :: u_tip(lockstep_lanes), d_tip(lockstep_lanes), x_tip(lockstep_lanes)
      !> z_tip, dt^2 and beta.
      real(wp), intent(in) :: z_tip, dt2, beta
      integer :: i
      lanes%d_tip_prev = d_tip
      lanes%u_tip_prev = u_tip
      lanes%trial = lanes%u_tip_prev + (lanes%d_tip_prev + x_tip)
      select case (law)
      case (law_signorini)
!GCC$ ivdep
!GCC$ vector
         do i = 1, lockstep_lanes
            lanes%tip_value(i) = min(max(lanes%trial(i), lanes%lower(i)), lanes%upper(i))
            lanes%c(i) = (lanes%tip_value(i) - lanes%trial(i))/z_tip
            lanes%contact(i) = lanes%c(i) /= 0
            lanes%r_step(i) = lanes%c(i)/dt2
            lanes%d_stop(i) = lanes%tip_value(i) - lanes%u_tip_prev(i)
         end do
      case (law_compliance)
         do i = 1, lockstep_lanes
            call compliance_step(lanes%trial(i), lanes%lower(i), lanes%upper(i), lanes%stiffness(i), dt2, beta, z_tip, &
               & lanes%p_prev(i), lanes%p_now(i), lanes%tip_value(i), lanes%c(i), lanes%r_step(i), lanes%contact(i))
         end do
      case default
         lanes%c = 0
         lanes%tip_value = lanes%trial
         lanes%r_step = 0
         lanes%contact = .false.
      end select
   end subroutine lanes_contact

   !> After the update, with g.d^n in lanes%gd (beamstops_contact_tip_contact's close_step and
   !> beamstops_ledger's move_on, over the lanes): the exact tip value on contact (Signorini,
   !> written back into u_tip and d_tip), the violation, impacts, the work of the load and the
   !> energy the stops take, the load averages moved on.
   pure subroutine lanes_close(lanes, law, u_tip, d_tip)
      !> The chunk.
      type(lanes_type), intent(inout) :: lanes
      !> Contact law (shared).
      integer, intent(in) :: law
      !> u^{n+1}_tip and d^n_tip of every lane (set on the stop under Signorini contact).
      real(wp), intent(inout) :: u_tip(lockstep_lanes), d_tip(lockstep_lanes)
      integer :: i
      lanes%r_prev = lanes%reaction
      if (law == law_signorini) then
!GCC$ ivdep
!GCC$ vector
         do i = 1, lockstep_lanes
            ! selects, not a branch per lane: d_stop was taken in lanes_contact for every lane
            ! (a subtraction under the condition is not if-converted: it may trap), and the
            ! condition is contact's own, c /= 0, a compare of doubles beside the doubles it selects
            u_tip(i) = merge(lanes%tip_value(i), u_tip(i), lanes%c(i) /= 0)
            d_tip(i) = merge(lanes%d_stop(i), d_tip(i), lanes%c(i) /= 0)
         end do
      end if
      if (law /= law_none) then
!GCC$ ivdep
!GCC$ vector
         do i = 1, lockstep_lanes
            lanes%max_violation(i) = max(lanes%max_violation(i), max(u_tip(i) - lanes%upper(i), lanes%lower(i) - u_tip(i), &
               & 0.0_wp))
         end do
      end if
!GCC$ ivdep
!GCC$ vector
      do i = 1, lockstep_lanes
         if (lanes%contact(i) .and. .not. lanes%in_contact(i)) lanes%impacts(i) = lanes%impacts(i) + 1
         lanes%in_contact(i) = lanes%contact(i)
         lanes%work(i) = newmark_work(lanes%work(i), lanes%weight(i), lanes%gd(i), lanes%gd_prev(i))
         lanes%dissipated(i) = lanes%dissipated(i) - 0.5_wp*lanes%r_step(i)*(d_tip(i) + lanes%d_tip_prev(i))
         lanes%reaction(i) = lanes%r_step(i)
         lanes%gd_prev(i) = lanes%gd(i)
         lanes%sigma_prev(i) = lanes%sigma_now(i)
         lanes%sigma_now(i) = lanes%sigma_next(i)
      end do
      lanes%u_tip = u_tip
   end subroutine lanes_close
end module beamstops_lockstep_lanes
