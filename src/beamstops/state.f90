!> The state of the time loop: everything carried from step n to step n+1.
!> A run resumes from it (checkpoints), and a recorder may save it.
module beamstops_state
   use beamstops_kinds, only: wp
   use beamstops_contact_span_stops, only: span_work_type
   use beamstops_observe_observer, only: observer_type
   use beamstops_loop_scalars, only: loop_scalars_type
   implicit none
   private
   public :: state_type

   !> Everything the loop carries from step n to step n+1: with it, a run can be resumed.
   !> Its scalars (step, loads, energies, contact, impacts, ...) are those of the parent type.
   type, extends(loop_scalars_type) :: state_type
      !> u^n (n).
      real(wp), allocatable :: u(:)
      !> d^{n-1} = u^n - u^{n-1} (n).
      real(wp), allocatable :: d(:)
      !> S u^n (n).
      real(wp), allocatable :: su(:)
      !> Scratch vectors (n) and the snapshot buffer (J+1).
      real(wp), allocatable :: rhs(:), scratch(:), shape(:)
      !> With damping: C d^{n-1} (n; unallocated without damping).
      real(wp), allocatable :: cd(:)
      !> Reaction per unit mass of each stop along the span (m; unallocated without them).
      real(wp), allocatable :: stop_reaction(:)
      !> Stops along the span: the program on C and its work arrays, built from the model
      !> (start_state, or the loop itself after a checkpoint).
      type(span_work_type) :: span
      !> The shock log and the running statistics, fed every step (when &statistics enabled).
      type(observer_type) :: observer
      !> Solve with LAPACK's dpbtrs and separate updates: the reference path of the tests.
      logical :: lapack_solve = .false.
   end type state_type
end module beamstops_state
