!> A whole run of a validated scene: model, stability check, start, time loop.
!> Shared by the program (HDF5 recorder) and the Python wrapper (array recorder),
!> so both give the same numbers by construction.
!> The time loop runs in blocks that end on checkpoint steps; between two blocks the
!> recorder is flushed, then the loop's state is saved (beamstops_checkpoint): the recorder
!> never sees the state, and a checkpoint never refers to records that are not stored.
module beamstops_run
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use, intrinsic :: iso_c_binding, only: c_int
   use beamstops_strings, only: fmt_int
   use beamstops_stop_signals, only: catch_stop_signals, release_stop_signals, stop_signal
   use beamstops_scene, only: scene_type, steps_of
   use beamstops_model, only: model_type, build_model, check_stability
   use beamstops_scheme, only: state_type, start_state, run_scheme
   use beamstops_recorder, only: recorder_type
   use beamstops_checkpoint, only: write_checkpoint
   use beamstops_summary, only: run_summary, status_running, status_failed, status_complete, mark_interrupted
   use beamstops_ensemble, only: run_members
   use beamstops_reduced, only: reduced_model_type, reduce_model
   use beamstops_reduced_scheme, only: start_reduced, reduced_state_type, run_reduced
   use beamstops_reduced_checkpoint, only: write_reduced_checkpoint
   implicit none
   private
   public :: prepare_run, check_run, simulate, continue_run, close_run, continue_reduced
   public :: run_limit_type, run_limit

   !> The linear stability limit of the model a run steps: the full model, or with &mesh modes > 0
   !> its reduced (Craig-Bampton) model, whose kappa is smaller.
   type :: run_limit_type
      !> Largest generalized eigenvalue of that model, with the compliance spring (1/s^2); 0 when
      !> not computed (a reduced model with beta >= 1/4).
      real(wp) :: kappa = 0
      !> 2/sqrt((1 - 4 beta) kappa) for beta < 1/4, +Inf otherwise (s).
      real(wp) :: dt_newmark = 0
      !> Which model: 'full model' or 'reduced model of r modes'.
      character(len=:), allocatable :: model
   end type run_limit_type

contains

   !> Build the model of a scene and refuse an unstable explicit scheme (check_run): the one
   !> preparation of `beamstops run`, `beamstops info` and the Python engine, so that all three
   !> refuse the same scenes with the same message.
   subroutine prepare_run(scene, source, model, error, reduced)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Where the scene came from, for messages.
      character(len=*), intent(in) :: source
      !> Model built.
      type(model_type), intent(out) :: model
      !> Set when the scene cannot run.
      type(error_type), allocatable, intent(out) :: error
      !> With &mesh modes > 0, the reduced model the run steps (built and checked either way).
      type(reduced_model_type), intent(out), optional :: reduced
      call build_model(scene, model, error)
      if (allocated(error)) then
         ! the model's messages name group and key; the file is named here, as the reader does
         error%message = source//': '//error%message
         return
      end if
      call check_run(scene, source, model, error, reduced)
   end subroutine prepare_run

   !> Refuse a scene whose time step exceeds the linear stability limit (beta < 1/4, unless
   !> allow_unstable) of the model its run steps: the full model (check_stability), or with
   !> &mesh modes > 0 the reduced model, built here from `model` (reduce_model).
   subroutine check_run(scene, source, model, error, reduced)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Where the scene came from, for messages.
      character(len=*), intent(in) :: source
      !> Its full model (build_model).
      type(model_type), intent(in) :: model
      !> Set when the scene cannot run.
      type(error_type), allocatable, intent(out) :: error
      !> With &mesh modes > 0, the reduced model the run steps.
      type(reduced_model_type), intent(out), optional :: reduced
      type(reduced_model_type) :: built
      if (scene%modes == 0) then
         call check_stability(scene, model, source, error)
      else if (present(reduced)) then
         call reduce_model(scene, model, source, reduced, error)
      else
         call reduce_model(scene, model, source, built, error)
      end if
   end subroutine check_run

   !> The linear stability limit check_run applies: the full model's, or with &mesh modes > 0 that
   !> of `reduced` (from prepare_run or check_run).
   function run_limit(scene, model, reduced) result(limit)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Its full model.
      type(model_type), intent(in) :: model
      !> Its reduced model (used only with &mesh modes > 0).
      type(reduced_model_type), intent(in) :: reduced
      type(run_limit_type) :: limit
      if (scene%modes == 0) then
         limit = run_limit_type(model%kappa_contact, model%dt_newmark, 'full model')
      else
         limit = run_limit_type(reduced%kappa, reduced%dt_newmark, 'reduced model of '// &
            & fmt_int(int(reduced%r, ik))//' modes')
      end if
   end function run_limit

   !> Run a prepared scene from t = 0 to t_end, feeding `recorder` (no checkpoints); a scene with
   !> &mesh modes > 0 runs its reduced (Craig-Bampton) model. A recorder
   !> that cannot write ends the run with status 'failed' and its message in the summary.
   recursive subroutine simulate(scene, model, recorder, summary, error, reduced, stop_signals)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Its model (from prepare_run).
      type(model_type), intent(in) :: model
      !> Receives records and snapshots.
      class(recorder_type), intent(inout) :: recorder
      !> Outcome.
      type(run_summary), intent(out) :: summary
      !> Set when the run cannot start.
      type(error_type), allocatable, intent(out) :: error
      !> With &mesh modes > 0, its reduced model (from prepare_run; built here when absent).
      type(reduced_model_type), intent(in), optional :: reduced
      !> Catch SIGINT and SIGTERM while the time loop runs (continue_run): a signal stops it
      !> between two blocks with status 'interrupted' (the Python layer then raises the signal
      !> again for its own handler).
      logical, intent(in), optional :: stop_signals
      type(state_type) :: state
      type(reduced_state_type) :: reduced_state
      type(error_type), allocatable :: write_error
      type(reduced_model_type) :: built
      if (scene%modes > 0) then
         if (.not. present(reduced)) then
            call reduce_model(scene, model, 'scene', built, error)
            if (allocated(error)) return
            call simulate(scene, model, recorder, summary, error, built, stop_signals)
            return
         end if
         call start_reduced(scene, reduced, reduced_state, recorder, error)
         if (allocated(error)) return
         call continue_reduced(scene, reduced, reduced_state, recorder, summary, write_error, &
            & stop_signals=stop_signals)
         return
      end if
      call start_state(scene, model, state, recorder, error)
      if (allocated(error)) return
      call continue_run(scene, model, state, recorder, summary, write_error, stop_signals=stop_signals)
   end subroutine simulate

   !> Run from the state's step (start_state's, or a checkpoint's) to t_end. With `checkpoint`
   !> and scene%checkpoint_every > 0, every checkpoint_every steps: flush the recorder, then
   !> save the state with the records and snapshots stored so far to `checkpoint` (atomically).
   !> A stop signal noted (beamstops_stop_signals: the program catches SIGINT and SIGTERM) stops
   !> the loop between two of its blocks: flushed, a checkpoint saved, status 'interrupted'.
   subroutine continue_run(scene, model, state, recorder, summary, error, checkpoint, stop_signals)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Its model (from prepare_run).
      type(model_type), intent(in) :: model
      !> State, advanced to the end of the run (or to where it stopped).
      type(state_type), intent(inout) :: state
      !> Receives records and snapshots.
      class(recorder_type), intent(inout) :: recorder
      !> Outcome: 'complete', 'diverged', 'failed' or 'interrupted' (with a message).
      type(run_summary), intent(inout) :: summary
      !> Set when the recorder or a checkpoint could not be written (the run stopped there,
      !> with status 'failed' and the same message in the summary).
      type(error_type), allocatable, intent(out) :: error
      !> Checkpoint file (none without it).
      character(len=*), intent(in), optional :: checkpoint
      !> Catch SIGINT and SIGTERM while the time loop runs, to stop it politely (`beamstops run`;
      !> default: a signal has its usual effect).
      logical, intent(in), optional :: stop_signals
      call run_blocks(scene, recorder, summary, error, checkpoint, stop_signals, model=model, state=state)
      if (allocated(error)) return
      call close_run(scene, model, recorder, summary, error, stop_signals)
   end subroutine continue_run

   !> What follows the time loop of a run (continue_run's, or a lockstep group's for each of its
   !> members): a complete run of an &ensemble runs its members 2..K (members that cannot run make
   !> it 'failed' with their message; a stop signal caught while they run, 'interrupted'); a
   !> recorder that could not write makes the run 'failed' with the recorder's message.
   subroutine close_run(scene, model, recorder, summary, error, stop_signals)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> The run's recorder.
      class(recorder_type), intent(inout) :: recorder
      !> Outcome of the time loop; gains the ensemble's table, or status 'failed'.
      type(run_summary), intent(inout) :: summary
      !> Set when the ensemble's members cannot run or the recorder could not write.
      type(error_type), allocatable, intent(out) :: error
      !> Catch SIGINT and SIGTERM while the members run, to stop them politely between two of
      !> their blocks (as continue_run's; default: a signal has its usual effect).
      logical, intent(in), optional :: stop_signals
      logical :: catch
      if (summary%status == status_complete .and. scene%members > 1 .and. scene%statistics .and. &
         & .not. recorder%failed) then
         catch = .false.
         if (present(stop_signals)) catch = stop_signals
         if (catch) call catch_stop_signals()
         call run_members(scene, model, summary, error)
         if (catch) call release_stop_signals()
         if (allocated(error)) then
            ! the output says so: its status was written 'complete' though the run failed
            summary%status = status_failed
            summary%message = error%message
            return
         end if
      end if
      call recorder_outcome(recorder, summary, error)
   end subroutine close_run

   !> continue_run for a reduced model (scene%modes > 0): from the state's step (start_reduced's,
   !> or a checkpoint's) to t_end, with `checkpoint` every checkpoint_every steps (the recorder
   !> flushed, then the state saved atomically), and the same stop on a signal.
   subroutine continue_reduced(scene, reduced, state, recorder, summary, error, checkpoint, stop_signals)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Its reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> State, advanced to the end of the run (or to where it stopped).
      type(reduced_state_type), intent(inout) :: state
      !> Receives records and snapshots.
      class(recorder_type), intent(inout) :: recorder
      !> Outcome: 'complete', 'diverged', 'failed' or 'interrupted' (with a message).
      type(run_summary), intent(inout) :: summary
      !> Set when the recorder or a checkpoint could not be written (the run stopped there,
      !> with status 'failed' and the same message in the summary).
      type(error_type), allocatable, intent(out) :: error
      !> Checkpoint file (none without it).
      character(len=*), intent(in), optional :: checkpoint
      !> Catch SIGINT and SIGTERM while the time loop runs, to stop it politely (`beamstops run`;
      !> default: a signal has its usual effect).
      logical, intent(in), optional :: stop_signals
      call run_blocks(scene, recorder, summary, error, checkpoint, stop_signals, reduced=reduced, &
         & reduced_state=state)
      if (allocated(error)) return
      call recorder_outcome(recorder, summary, error)
   end subroutine continue_reduced

   !> The time loop of continue_run (model and state) or continue_reduced (reduced and
   !> reduced_state), in blocks that end on checkpoint steps or on a stop signal. Signals are
   !> caught (stop_signals) for the loop only: the members of an ensemble and the file's end take
   !> a signal's usual effect.
   subroutine run_blocks(scene, recorder, summary, error, checkpoint, stop_signals, model, state, reduced, &
      & reduced_state)
      type(scene_type), intent(in) :: scene
      class(recorder_type), intent(inout) :: recorder
      type(run_summary), intent(inout) :: summary
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: checkpoint
      logical, intent(in), optional :: stop_signals
      type(model_type), intent(in), optional :: model
      type(state_type), intent(inout), optional :: state
      type(reduced_model_type), intent(in), optional :: reduced
      type(reduced_state_type), intent(inout), optional :: reduced_state
      integer(ik) :: steps, every, until, records, snapshots, first
      integer(c_int) :: signum
      steps = steps_of(scene)
      if (present(stop_signals)) then
         if (stop_signals) call catch_stop_signals()
      end if
      every = 0
      if (present(checkpoint)) every = scene%checkpoint_every
      do
         if (present(state)) then
            first = state%step
         else
            first = reduced_state%step
         end if
         until = steps
         if (every > 0) until = min(steps, ((first - 1)/every + 1)*every)
         if (present(state)) then
            call run_scheme(scene, model, state, recorder, summary, until)
         else
            call run_reduced(scene, reduced, reduced_state, recorder, summary, until)
         end if
         if (summary%status /= status_running .or. recorder%failed) exit
         ! a checkpoint step, or a stop signal noted (the loop stops between two of its blocks)
         signum = stop_signal()
         call recorder%flush(records, snapshots)
         if (recorder%failed) exit
         if (present(checkpoint) .and. present(state)) then
            call write_checkpoint(checkpoint, scene, state, records, snapshots, error)
         else if (present(checkpoint)) then
            call write_reduced_checkpoint(checkpoint, scene, reduced_state, records, snapshots, error)
         end if
         if (allocated(error)) then
            summary%status = status_failed
            summary%message = error%message
            exit
         end if
         if (signum /= 0) then
            if (present(checkpoint)) then
               call mark_interrupted(scene, signum, ' and a checkpoint saved', summary)
            else
               call mark_interrupted(scene, signum, '', summary)
            end if
            exit
         end if
      end do
      call release_stop_signals()
   end subroutine run_blocks


   !> A recorder that could not write makes the run 'failed' with the recorder's message.
   subroutine recorder_outcome(recorder, summary, error)
      class(recorder_type), intent(in) :: recorder
      type(run_summary), intent(inout) :: summary
      type(error_type), allocatable, intent(inout) :: error
      if (recorder%failed) then
         if (allocated(recorder%message)) then
            call fatal_error(error, recorder%message)
         else
            call fatal_error(error, 'the recorder could not write')
         end if
         summary%status = status_failed
         summary%message = error%message
      end if
   end subroutine recorder_outcome
end module beamstops_run
