!> State of the per-step extension of scripts/bench_step.f90: the engine's scene, model,
!> state and a recorder, kept on the Fortran side (f2py cannot pass derived types).
!> Compiled by scripts/bench_ext.py against a meson build of the engine.
module bench_step_state
   use beamstops_kinds, only: wp
   use beamstops_scene, only: scene_type
   use beamstops_model, only: model_type
   use beamstops_scheme, only: state_type
   use beamstops_recorder, only: recorder_type, n_columns
   implicit none
   private
   public :: null_recorder, scene, model, state, recorder, ready

   !> A recorder that keeps nothing (the loop's records are not the subject of the benchmark).
   type, extends(recorder_type) :: null_recorder
      real(wp) :: sink = 0
   contains
      procedure :: record
      procedure :: snapshot
   end type null_recorder

   type(scene_type), save :: scene
   type(model_type), save :: model
   type(state_type), save :: state
   type(null_recorder), save :: recorder
   logical, save :: ready = .false.

contains

   subroutine record(self, row)
      class(null_recorder), intent(inout) :: self
      real(wp), intent(in) :: row(n_columns)
      self%sink = self%sink + row(2)
   end subroutine record

   subroutine snapshot(self, t, u)
      class(null_recorder), intent(inout) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: u(:)
      self%sink = self%sink + u(1)
   end subroutine snapshot
end module bench_step_state
