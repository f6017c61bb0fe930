!> What a run reports when it ends: status, counts, extremes and cost.
module beamstops_summary
   use beamstops_kinds, only: wp, ik
   use beamstops_observe_statistics, only: statistics_table
   implicit none
   private
   public :: run_summary, status_complete, status_diverged, status_running, status_failed

   !> Status texts written to the output's `status` attribute.
   character(len=*), parameter :: status_complete = 'complete', status_diverged = 'diverged', &
      & status_running = 'running', status_failed = 'failed'

   !> Summary of a run.
   type :: run_summary
      !> 'complete', 'diverged', 'failed' or 'running' (interrupted).
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
end module beamstops_summary
