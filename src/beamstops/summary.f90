!> What a run reports when it ends: status, counts, extremes and cost.
module beamstops_summary
   use beamstops_kinds, only: wp, ik
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use beamstops_observe_statistics, only: statistics_table
   use beamstops_scene, only: scene_type, steps_of
   use beamstops_strings, only: fmt_real, fmt_int
   use beamstops_stop_signals, only: signal_name
   use, intrinsic :: iso_c_binding, only: c_int
   implicit none
   private
   public :: run_summary, status_complete, status_diverged, status_running, status_failed, status_interrupted, &
      & check_divergence, mark_interrupted, lockstep_no_checkpoint

   !> Status texts written to the output's `status` attribute.
   character(len=*), parameter :: status_complete = 'complete', status_diverged = 'diverged', &
      & status_running = 'running', status_failed = 'failed', status_interrupted = 'interrupted'
   !> The end of the message of a lockstep member that a signal stopped (mark_interrupted).
   character(len=*), parameter :: lockstep_no_checkpoint = '; no checkpoint (a member of a lockstep group has none)'

   !> Summary of a run.
   type :: run_summary
      !> 'complete', 'diverged', 'failed', 'interrupted' (stopped by SIGINT or SIGTERM, a checkpoint
      !> saved) or 'running' (still running, or killed).
      character(len=:), allocatable :: status
      !> Explanation when the status is not 'complete'.
      character(len=:), allocatable :: message
      !> Time steps done.
      integer(ik) :: steps = 0
      !> Time reached (s).
      real(wp) :: t_final = 0
      !> CPU time of the time loop (s).
      real(wp) :: cpu_seconds = 0
      !> Number of impacts: shocks (contact phases merged by &statistics rest_time) when the
      !> statistics are kept, contact phases otherwise.
      integer(ik) :: impacts = 0
      !> Largest violation of the stops max(u_tip - upper, lower - u_tip, 0) (m).
      real(wp) :: max_violation = 0
      !> Energy ledger (J): work of the support's load, energy taken by the stops and by the
      !> damping since t = 0, and the scheme's own balance residual
      !> E(t_final) - E(0) - (work - dissipated - damped), round-off without contact.
      real(wp) :: work = 0, dissipated = 0, damped = 0, energy_residual = 0
      !> Contact phases (free-flight steps followed by a contact step, at any stop).
      integer(ik) :: contact_phases = 0
      !> The statistics of the run (&statistics enabled; no quantities otherwise).
      type(statistics_table) :: statistics
      !> With &ensemble members > 1: the statistics across the members that completed (mean and
      !> t s/sqrt(K)), and their number K.
      type(statistics_table) :: ensemble
      integer :: ensemble_members = 0
      !> Its shocks, one column each in the order of shock_column_names (unallocated: none kept).
      real(wp), allocatable :: shocks(:, :)
      !> Records and snapshots written.
      integer(ik) :: records = 0, snapshots = 0
   end type run_summary
contains

   !> The divergence check of the time loops (full, reduced and lockstep), between blocks: status
   !> 'diverged' with its message when a recorder was handed values that are not finite
   !> (`blew_up`, at `blew_up_at`: it kept nothing from then on), or when the kinetic energy is
   !> not finite or beyond 1e8 times the energy the run has seen (the support's scale, E^{1/2},
   !> the work, the stops' energy).
   subroutine check_divergence(scene, kinetic, energy0, work, dissipated, t, blew_up, blew_up_at, summary)
      !> Scene (length, support amplitude and frequency).
      type(scene_type), intent(in) :: scene
      !> Kinetic energy 1/2 d.M d/dt^2, E^{1/2}, work and stops' energy so far, per unit mass.
      real(wp), intent(in) :: kinetic, energy0, work, dissipated
      !> Time reached (s), for the message.
      real(wp), intent(in) :: t
      !> Whether the recorder was handed values that are not finite, and their time (s).
      logical, intent(in) :: blew_up
      real(wp), intent(in) :: blew_up_at
      !> Set to 'diverged' when the solution blew up.
      type(run_summary), intent(inout) :: summary
      real(wp) :: cap
      if (blew_up) then
         summary%status = status_diverged
         summary%message = 'the solution blew up (values not finite at t = '//fmt_real(blew_up_at, 6)// &
            & ' s; the records stop before them)'
         return
      end if
      cap = 1.0e8_wp*(0.5_wp*scene%length*(scene%amplitude*scene%omega)**2 + abs(energy0) + abs(work) + abs(dissipated))
      if (ieee_is_finite(kinetic) .and. kinetic <= cap) return
      summary%status = status_diverged
      summary%message = 'the solution blew up (kinetic energy beyond 1e8 times the energy supplied) before t = '// &
         & fmt_real(t, 6)//' s'
   end subroutine check_divergence

   !> Status 'interrupted' and its message: the loop stopped on `signum` after summary%steps of
   !> the scene's steps, its records flushed, then `after` (what became of the checkpoint).
   subroutine mark_interrupted(scene, signum, after, summary)
      !> Scene (dt and the number of steps).
      type(scene_type), intent(in) :: scene
      !> The signal (beamstops_stop_signals).
      integer(c_int), intent(in) :: signum
      !> The end of the message (e.g. ' and a checkpoint saved').
      character(len=*), intent(in) :: after
      !> Summary of the run, steps set.
      type(run_summary), intent(inout) :: summary
      summary%status = status_interrupted
      summary%message = 'stopped by '//signal_name(signum)//' at t = '// &
         & fmt_real(real(summary%steps, wp)*scene%dt, 12)//' s (step '//fmt_int(summary%steps)//' of '// &
         & fmt_int(steps_of(scene))//'), its records flushed'//after
   end subroutine mark_interrupted
end module beamstops_summary
