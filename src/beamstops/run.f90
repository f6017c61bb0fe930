!> A whole run of a validated scene: model, stability check, start, time loop.
!> Shared by the program (HDF5 recorder) and the Python wrapper (array recorder),
!> so both give the same numbers by construction.
module beamstops_run
   use beamstops_error, only: error_type
   use beamstops_scene, only: scene_type
   use beamstops_model, only: model_type, build_model, check_stability
   use beamstops_scheme, only: state_type, start_state, run_scheme
   use beamstops_recorder, only: recorder_type
   use beamstops_summary, only: run_summary
   implicit none
   private
   public :: prepare_run, simulate

contains

   !> Build the model of a scene and refuse an unstable explicit scheme.
   subroutine prepare_run(scene, source, model, error)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Where the scene came from, for messages.
      character(len=*), intent(in) :: source
      !> Model built.
      type(model_type), intent(out) :: model
      !> Set when the scene cannot run.
      type(error_type), allocatable, intent(out) :: error
      call build_model(scene, model, error)
      if (allocated(error)) return
      call check_stability(scene, model, source, error)
   end subroutine prepare_run

   !> Run a prepared scene from t = 0 to t_end, feeding `recorder`.
   subroutine simulate(scene, model, recorder, summary, error)
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
      type(state_type) :: state
      call start_state(scene, model, state, recorder, error)
      if (allocated(error)) return
      call run_scheme(scene, model, state, recorder, summary)
   end subroutine simulate
end module beamstops_run
