!> Ensembles (&ensemble members = K, perturbation = delta, seed): K runs of one scene whose
!> initial displacements differ by delta-sized random perturbations. Member 1 is the scene
!> itself (the run that writes the records); members 2..K start from u0 + delta*xi, xi uniform
!> in [-1, 1] at every nodal value (slopes untouched), drawn by the minimal-standard generator
!> from (seed, member), and keep only their statistics. After a few impacts the members
!> decorrelate and are independent samples of the same statistics: across them each quantity
!> has mean +- t_{0.975, K-1} s / sqrt(K) (beamstops_observe_statistics' ensemble_table),
!> beside the batch-means intervals of each run. The members run in lockstep (beamstops_lockstep)
!> when they can share the loop, one after the other otherwise.
module beamstops_ensemble
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type
   use beamstops_scene, only: scene_type
   use beamstops_model, only: model_type
   use beamstops_state, only: state_type
   use beamstops_start, only: start_state
   use beamstops_scheme, only: run_scheme
   use beamstops_recorder, only: recorder_type, n_columns
   use beamstops_summary, only: run_summary, status_complete, status_interrupted
   use beamstops_stop_signals, only: stop_signal, signal_name
   use beamstops_strings, only: fmt_int
   use beamstops_lockstep, only: check_lockstep, simulate_lockstep
   use beamstops_observe_statistics, only: statistics_table, ensemble_table
   implicit none
   private
   public :: run_members, perturbation_of

   !> A recorder that keeps nothing (the members other than the first).
   type, extends(recorder_type) :: no_records
   contains
      procedure :: record => ignore_row
      procedure :: snapshot => ignore_snapshot
   end type no_records

contains

   !> Run members 2..K of a scene whose member 1 gave `summary` (complete, with statistics), and
   !> put the ensemble's statistics into summary%ensemble.
   subroutine run_members(scene, model, summary, error)
      !> Scene (members > 1).
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> Member 1's summary; gains the ensemble's table.
      type(run_summary), intent(inout) :: summary
      !> Set when a member cannot run.
      type(error_type), allocatable, intent(out) :: error
      type(statistics_table), allocatable :: tables(:)
      type(model_type) :: member_model
      type(scene_type) :: member_scene
      type(scene_type), allocatable :: scenes(:)
      type(state_type) :: state
      type(no_records) :: recorder
      type(no_records), allocatable :: recorders(:)
      type(run_summary) :: member
      type(run_summary), allocatable :: members(:)
      type(error_type), allocatable :: refusal
      real(wp), allocatable :: u0(:, :)
      integer :: k
      allocate (tables(scene%members))
      tables(1) = summary%statistics
      member_scene = scene
      member_scene%members = 1
      member_scene%snapshot_every = 0
      member_scene%record_every = huge(1)
      summary%ensemble_members = 1
      ! Members 2..K in lockstep (beamstops_lockstep, each bit for bit its run alone) when they
      ! can share the loop; one after the other otherwise.
      allocate (scenes(scene%members - 1), source=member_scene)
      call check_lockstep(scenes, model, refusal)
      if (.not. allocated(refusal)) then
         allocate (u0(size(model%u0), scene%members - 1), recorders(scene%members - 1), members(scene%members - 1))
         do k = 2, scene%members
            u0(:, k - 1) = model%u0 + perturbation_of(scene%perturbation, scene%seed, k, size(model%u0))
         end do
         call simulate_lockstep(scenes, model, recorders, members, error, initial_displacement=u0)
         if (allocated(error)) return
         if (interrupted()) return
         do k = 1, size(members)
            if (members(k)%status /= status_complete) cycle
            summary%ensemble_members = summary%ensemble_members + 1
            tables(summary%ensemble_members) = members(k)%statistics
         end do
      else
         do k = 2, scene%members
            member_model = model
            member_model%u0 = model%u0 + perturbation_of(scene%perturbation, scene%seed, k, size(model%u0))
            call start_state(member_scene, member_model, state, recorder, error)
            if (allocated(error)) return
            member = run_summary()
            call run_scheme(member_scene, member_model, state, recorder, member)
            if (interrupted()) return
            if (member%status /= status_complete) cycle
            summary%ensemble_members = summary%ensemble_members + 1
            tables(summary%ensemble_members) = member%statistics
         end do
      end if
      call ensemble_table(tables(:summary%ensemble_members), summary%ensemble, error)

   contains

      !> Whether a stop signal was caught (close_run catches them while the members run): then
      !> the run is 'interrupted', member 1's records whole and no ensemble table.
      logical function interrupted()
         interrupted = stop_signal() /= 0
         if (.not. interrupted) return
         summary%status = status_interrupted
         summary%message = 'stopped by '//signal_name(stop_signal())//' while the ensemble''s members 2..'// &
            & fmt_int(int(scene%members, ik))//' ran (member 1 complete, its records flushed; the members have no '// &
            & 'checkpoint: they run again from their start)'
      end function interrupted
   end subroutine run_members

   !> delta*xi at the nodal values (odd unknowns; slopes 0), xi uniform in [-1, 1], from the
   !> minimal-standard generator x <- 16807 x mod (2^31 - 1) seeded by (seed, member).
   pure function perturbation_of(delta, seed, member, n) result(p)
      !> Size of the perturbation (m), seed and member, number of unknowns.
      real(wp), intent(in) :: delta
      integer, intent(in) :: seed, member, n
      real(wp) :: p(n)
      integer(ik), parameter :: modulus = 2147483647_ik
      integer(ik) :: x
      integer :: i, warm
      x = modulo(int(seed, ik)*1000003_ik + int(member, ik)*7919_ik, modulus - 1) + 1
      do warm = 1, 8
         x = modulo(16807_ik*x, modulus)
      end do
      p = 0
      do i = 1, n, 2
         x = modulo(16807_ik*x, modulus)
         p(i) = delta*(2*real(x, wp)/real(modulus, wp) - 1)
      end do
   end function perturbation_of

   subroutine ignore_row(self, row)
      class(no_records), intent(inout) :: self
      real(wp), intent(in) :: row(n_columns)
   end subroutine ignore_row

   subroutine ignore_snapshot(self, t, u)
      class(no_records), intent(inout) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: u(:)
   end subroutine ignore_snapshot
end module beamstops_ensemble
