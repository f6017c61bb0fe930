!> The state of the time loop: everything carried from step n to step n+1.
!> A run resumes from it (checkpoints), and a recorder may save it.
module beamstops_state
   use beamstops_kinds, only: wp, ik
   use beamstops_contact_span_stops, only: span_work_type
   use beamstops_observe_observer, only: observer_type
   implicit none
   private
   public :: state_type

   !> Everything the loop carries from step n to step n+1: with it, a run can be resumed.
   type :: state_type
      !> Index n of the next step (the step that computes u^{n+1}).
      integer(ik) :: step = 1
      !> u^n (n).
      real(wp), allocatable :: u(:)
      !> d^{n-1} = u^n - u^{n-1} (n).
      real(wp), allocatable :: d(:)
      !> S u^n (n).
      real(wp), allocatable :: su(:)
      !> Scratch vectors (n) and the snapshot buffer (J+1).
      real(wp), allocatable :: rhs(:), scratch(:), shape(:)
      !> Load averages sigma_{n-1}, sigma_n.
      real(wp) :: sigma_prev = 0, sigma_now = 0
      !> g . d^{n-1}.
      real(wp) :: gd_prev = 0
      !> Spring forces p(u^{n-1}), p(u^n) at the tip (compliance).
      real(wp) :: p_prev = 0, p_now = 0
      !> Work of the load W_{n-1} and energy taken by the stops D_{n-1}, per unit mass.
      real(wp) :: work = 0, dissipated = 0
      !> Energy taken by the Rayleigh damping so far, per unit mass (SPEC 8).
      real(wp) :: damped = 0
      !> With damping: C d^{n-1} (n; unallocated without damping).
      real(wp), allocatable :: cd(:)
      !> With damping: d^{n-1}.C d^{n-1}.
      real(wp) :: dcd_prev = 0
      !> Discrete energy E^{1/2} per unit mass (reference for the divergence check).
      real(wp) :: energy0 = 0
      !> Reaction per unit mass of the step that gave u^n (r_{n-1}; recorded with u^n).
      real(wp) :: reaction = 0
      !> The same for each stop along the span (m; unallocated without them).
      real(wp), allocatable :: stop_reaction(:)
      !> Stops along the span: the program on C and its work arrays, built from the model
      !> (start_state, or the loop itself after a checkpoint).
      type(span_work_type) :: span
      !> Whether the previous step was in contact.
      logical :: in_contact = .false.
      !> Impacts so far.
      integer(ik) :: impacts = 0
      !> CPU time of the time loop so far (s).
      real(wp) :: cpu_seconds = 0
      !> Largest violation of the stops so far (m).
      real(wp) :: max_violation = 0
      !> The shock log and the running statistics, fed every step (when &statistics enabled).
      type(observer_type) :: observer
      !> Solve with LAPACK's dpbtrs and separate updates: the reference path of the tests.
      logical :: lapack_solve = .false.
   end type state_type
end module beamstops_state
