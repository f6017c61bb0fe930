!> State of the per-step extension of scripts/bench_step.f90: the engine's scene, model,
!> state and a recorder, kept on the Fortran side (f2py cannot pass derived types).
!> Compiled by scripts/bench_ext.py against a meson build of the engine, after
!> bench/null_recorder.f90.
module bench_step_state
   use beamstops_scene, only: scene_type
   use beamstops_model, only: model_type
   use beamstops_scheme, only: state_type
   use bench_null_recorder, only: null_recorder
   implicit none
   private
   public :: null_recorder, scene, model, state, recorder, ready

   type(scene_type), save :: scene
   type(model_type), save :: model
   type(state_type), save :: state
   !> Keeps nothing: the loop's records are not the subject of the benchmark.
   type(null_recorder), save :: recorder
   logical, save :: ready = .false.
end module bench_step_state
