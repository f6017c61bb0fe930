!> beamstops: an elastic beam clamped to a vibrating support, impacting rigid stops,
!> by the fully discretized scheme of Dumont & Paoli. The public API.
module beamstops
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type, validate_scene, steps_of, record_count, snapshot_count, output_bytes, &
      & law_none, law_signorini, law_compliance, &
      & law_name, law_code, stop_count, max_stops, scene_table, canonical_text
   use beamstops_namelist, only: read_scene, scene_from_text
   use beamstops_model, only: model_type, build_model, check_stability
   use beamstops_scheme, only: state_type, start_state, run_scheme
   use beamstops_recorder, only: recorder_type, n_columns
   use beamstops_recorder_array, only: array_recorder
   use beamstops_recorder_hdf5, only: hdf5_recorder
   use beamstops_summary, only: run_summary, status_complete, status_diverged, status_failed, status_interrupted
   use beamstops_run, only: prepare_run, check_run, simulate, run_limit_type, run_limit
   use beamstops_lockstep, only: check_lockstep, prepare_lockstep, simulate_lockstep
   use beamstops_version, only: version
   use beamstops_three_level, only: run_three_level
   use beamstops_reduced, only: reduced_model_type, prepare_reduced, build_reduced, validate_reduced, &
      & check_stability_reduced, stop_unknowns
   use beamstops_reduced_scheme, only: simulate_reduced
   implicit none
   private
   public :: wp, ik, error_type, fatal_error
   public :: scene_type, validate_scene, steps_of, law_none, law_signorini, law_compliance, law_name, law_code
   public :: stop_count, max_stops
   public :: scene_table, canonical_text, scene_from_text
   public :: read_scene, model_type, build_model, check_stability
   public :: state_type, start_state, run_scheme
   public :: recorder_type, n_columns, array_recorder, hdf5_recorder
   public :: run_summary, status_complete, status_diverged, status_failed, status_interrupted
   public :: prepare_run, check_run, simulate, run_limit_type, run_limit, record_count, snapshot_count, output_bytes, version
   public :: run_three_level
   public :: check_lockstep, prepare_lockstep, simulate_lockstep
   public :: reduced_model_type, prepare_reduced, build_reduced, validate_reduced, check_stability_reduced
   public :: stop_unknowns, simulate_reduced
end module beamstops
