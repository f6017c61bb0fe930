!> Several scenes in one process (`beamstops run A.nml B.nml ...`; a sweep's batches): the
!> scenes are partitioned into groups that share one lockstep loop (beamstops_lockstep) by the
!> lockstep path's own rule (check_lockstep: the same A, contact law and steps, and what the
!> path runs), and each group runs in lockstep, every scene with its own recorder and summary.
!> A scene that can join no other runs alone (a group of one, which the caller runs by the
!> one-scene path). Every member's records and summary are those of the scene run alone (the
!> lockstep path is bit for bit the one-scene path); after the loop each member goes through
!> close_run, as a scene run alone does (its &ensemble members, a recorder that failed).
module beamstops_batch
   use beamstops_error, only: error_type
   use beamstops_scene, only: scene_type
   use beamstops_model, only: model_type
   use beamstops_recorder, only: recorder_type
   use beamstops_summary, only: run_summary
   use beamstops_lockstep, only: check_lockstep, simulate_lockstep
   use beamstops_run, only: close_run
   use beamstops_stop_signals, only: catch_stop_signals, release_stop_signals
   implicit none
   private
   public :: lockstep_groups, simulate_group, min_group_members

   !> The fewest members a group runs in lockstep with; the scenes of a smaller group run one
   !> after the other by the one-scene path (the same results, to the bit). Measured on the
   !> paper's scene recording every step (`beamstops run` of K scenes): K = 2 costs 1.6x one at a
   !> time per member-step, K = 4 breaks even, K = 8 saves 1.7x (docs/lockstep.md).
   integer, parameter :: min_group_members = 4

contains

   !> The lockstep group of every scene: scene i joins the first group, in order of their first
   !> scenes, that check_lockstep accepts with it (the group's scenes and scene i, with the model
   !> of the group's first scene); otherwise it starts a group. Scenes that checkpoint
   !> (&output checkpoint_every > 0: a lockstep loop cannot save one member's state), or that the
   !> caller marks `alone` (e.g. a run resumed from its checkpoint), form groups of their own.
   subroutine lockstep_groups(scenes, models, group, alone)
      !> Validated scenes (N).
      type(scene_type), intent(in) :: scenes(:)
      !> The model of each scene (N, from prepare_run).
      type(model_type), intent(in) :: models(:)
      !> Group of each scene (N): 1, 2, ... in order of their first scenes.
      integer, allocatable, intent(out) :: group(:)
      !> Scenes that must run alone (N; default: none).
      logical, intent(in), optional :: alone(:)
      type(error_type), allocatable :: refusal
      integer, allocatable :: first(:)
      logical, allocatable :: closed(:)
      integer :: i, g, groups
      allocate (group(size(scenes)), first(size(scenes)), closed(size(scenes)))
      groups = 0
      do i = 1, size(scenes)
         group(i) = 0
         if (.not. must_be_alone(i)) then
            do g = 1, groups
               if (closed(g)) cycle
               call check_lockstep([members(g), scenes(i)], models(first(g)), refusal)
               if (allocated(refusal)) cycle
               group(i) = g
               exit
            end do
         end if
         if (group(i) > 0) cycle
         groups = groups + 1
         group(i) = groups
         first(groups) = i
         closed(groups) = must_be_alone(i)
         if (.not. closed(groups)) then
            ! a scene the lockstep path does not run at all stays alone
            call check_lockstep([scenes(i)], models(i), refusal)
            closed(groups) = allocated(refusal)
         end if
      end do

   contains

      logical function must_be_alone(i)
         integer, intent(in) :: i
         must_be_alone = scenes(i)%checkpoint_every > 0
         if (present(alone)) must_be_alone = must_be_alone .or. alone(i)
      end function must_be_alone

      !> The scenes of group g so far.
      function members(g) result(list)
         integer, intent(in) :: g
         type(scene_type), allocatable :: list(:)
         integer :: j
         list = [(scenes(j), j=1, i - 1)]
         list = pack(list, group(:i - 1) == g)
      end function members
   end subroutine lockstep_groups

   !> Run one group (scenes that lockstep_groups put together) in lockstep from t = 0, each
   !> scene feeding its recorder, then close each member's run as a scene run alone is closed
   !> (close_run). `error` says the group could not start (then nothing ran: the caller may run
   !> the scenes alone); `failures(k)` holds member k's error from close_run (its &ensemble
   !> members could not run, or its recorder could not write).
   subroutine simulate_group(scenes, models, recorders, summaries, failures, error, stop_signals)
      !> The group's validated scenes (K).
      type(scene_type), intent(in) :: scenes(:)
      !> Their models (K); the first is the group's (they share A).
      type(model_type), intent(in) :: models(:)
      !> One recorder per scene (K).
      class(recorder_type), intent(inout) :: recorders(:)
      !> One summary per scene (K).
      type(run_summary), intent(out) :: summaries(:)
      !> One error per scene (K; message unallocated: none).
      type(error_type), intent(out) :: failures(:)
      !> Set when the group cannot start.
      type(error_type), allocatable, intent(out) :: error
      !> Catch SIGINT and SIGTERM while the lockstep loop runs: a signal stops it between two
      !> blocks, every member still running 'interrupted' (without a checkpoint).
      logical, intent(in), optional :: stop_signals
      type(error_type), allocatable :: failure
      integer :: k
      if (present(stop_signals)) then
         if (stop_signals) call catch_stop_signals()
      end if
      call simulate_lockstep(scenes, models(1), recorders, summaries, error)
      ! the ensembles' members and the files' ends take a signal's usual effect
      call release_stop_signals()
      if (allocated(error)) return
      do k = 1, size(scenes)
         call close_run(scenes(k), models(k), recorders(k), summaries(k), failure)
         if (allocated(failure)) call move_alloc(failure%message, failures(k)%message)
      end do
   end subroutine simulate_group
end module beamstops_batch
