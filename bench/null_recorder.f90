!> A recorder that keeps nothing (but touches what it is given), so that a timed
!> step loop measures the engine and not the output. Used by bench_kernels.f90 and
!> compiled by scripts/bench_ext.py for the per-step extension (scripts/bench_step_state.f90).
module bench_null_recorder
   use beamstops_kinds, only: wp
   use beamstops_recorder, only: recorder_type, n_columns
   implicit none
   private
   public :: null_recorder

   type, extends(recorder_type) :: null_recorder
      real(wp) :: sink = 0
   contains
      procedure :: record
      procedure :: snapshot
   end type null_recorder

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
end module bench_null_recorder
