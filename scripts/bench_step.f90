! The engine one step per call, for scripts/bench.py (the cost of crossing from Python to
! Fortran and back at every step), and the band solves and whole runs that
! tests/python/test_speed_fused.py compares. Plain subroutines: f2py wraps them as the
! extension module _bench_step (built by scripts/bench_ext.py); the derived types live in
! bench_step_state.

!> Build the paper's scene with J elements, dt, beta, a contact law (0 none, 1 Signorini,
!> 2 compliance with 1/epsilon = stiffness per unit mass), record every `every` steps (0:
!> never), on the fused path or (lapack /= 0) the reference path; status 0 when ready.
subroutine init(elements, dt, t_end, beta, law, stiffness, every, lapack, status)
   use beamstops_kinds, only: wp
   use beamstops_error, only: error_type
   use beamstops_scene, only: scene_type, validate_scene
   use beamstops_model, only: build_model
   use beamstops_scheme, only: start_state
   use bench_step_state, only: scene, model, state, recorder, ready
   implicit none
   integer, intent(in) :: elements, law, every, lapack
   real(8), intent(in) :: dt, t_end, beta, stiffness
   integer, intent(out) :: status
   type(error_type), allocatable :: error
   ready = .false.
   status = 1
   scene = scene_type()
   scene%elements = elements
   scene%dt = dt
   scene%t_end = t_end
   scene%beta = beta
   scene%law = law
   if (law == 2) scene%stiffness_per_mass = stiffness
   scene%record_every = huge(1)
   if (every > 0) scene%record_every = every
   scene%output_file = 'unused.h5'
   call validate_scene(scene, 'bench_step', error)
   if (allocated(error)) return
   call build_model(scene, model, error)
   if (allocated(error)) return
   call start_state(scene, model, state, recorder, error)
   if (allocated(error)) return
   state%lapack_solve = lapack /= 0
   ready = .true.
   status = 0
end subroutine init

!> One step of the engine (advance through the next step); the tip displacement u^{n+1}_tip.
subroutine step(tip_u)
   use beamstops_scheme, only: advance
   use bench_step_state, only: scene, model, state, recorder, ready
   implicit none
   real(8), intent(out) :: tip_u
   tip_u = 0
   if (.not. ready) return
   call advance(scene, model, state, recorder, state%step)
   tip_u = state%u(model%tip)
end subroutine step

!> `count` steps in one call (the same loop without the crossings); the last tip displacement.
subroutine steps(count, tip_u)
   use beamstops_scheme, only: advance
   use bench_step_state, only: scene, model, state, recorder, ready
   implicit none
   integer, intent(in) :: count
   real(8), intent(out) :: tip_u
   tip_u = 0
   if (.not. ready) return
   call advance(scene, model, state, recorder, state%step + count - 1)
   tip_u = state%u(model%tip)
end subroutine steps

!> Solve A x = b for a symmetric positive definite band matrix (kd = 3, LAPACK upper band
!> storage ab(4, n)): factor by dpbtrf, then x_lapack by dpbtrs and x_fused by the fused
!> substitutions of the engine; status = dpbtrf's info.
subroutine solve_both(n, ab, b, x_lapack, x_fused, status)
   use beamstops_error, only: error_type
   use beamstops_band, only: cholesky_factor, cholesky_solve
   use beamstops_band_solve, only: band_solver, prepare_solver, fused_solve
   implicit none
   integer, intent(in) :: n
   real(8), intent(in) :: ab(4, n), b(n)
   real(8), intent(out) :: x_lapack(n), x_fused(n)
   integer, intent(out) :: status
   real(8) :: factor(4, n)
   type(band_solver) :: solver
   type(error_type), allocatable :: error
   factor = ab
   call cholesky_factor(factor, 'A', error)
   status = 0
   x_lapack = 0
   x_fused = 0
   if (allocated(error)) then
      status = 1
      return
   end if
   x_lapack = b
   call cholesky_solve(factor, x_lapack)
   call prepare_solver(factor, solver)
   x_fused = b
   call fused_solve(solver, x_fused)
end subroutine solve_both

!> A whole run of the scene set by init, from its start, with the records kept: rows(7, :)
!> = t, tip u, tip v, reaction, energy, work, dissipated of steps 0, every, 2 every, ...
subroutine run_records(capacity, rows, filled, status)
   use beamstops_kinds, only: ik
   use beamstops_error, only: error_type
   use beamstops_scene, only: steps_of
   use beamstops_scheme, only: state_type, start_state, advance
   use beamstops_recorder_array, only: array_recorder
   use bench_step_state, only: scene, model, state, ready
   implicit none
   integer, intent(in) :: capacity
   real(8), intent(out) :: rows(7, capacity)
   integer, intent(out) :: filled, status
   type(array_recorder) :: keep
   type(state_type) :: fresh
   type(error_type), allocatable :: error
   logical :: lapack
   rows = 0
   filled = 0
   status = 1
   if (.not. ready) return
   lapack = state%lapack_solve
   call keep%reserve(int(capacity, ik), 0_ik, scene%elements + 1)
   call start_state(scene, model, fresh, keep, error)
   if (allocated(error)) return
   fresh%lapack_solve = lapack
   ! two calls, so that a call boundary falls inside the run
   call advance(scene, model, fresh, keep, steps_of(scene)/3)
   call advance(scene, model, fresh, keep, steps_of(scene))
   if (keep%failed) return
   filled = int(keep%filled)
   rows(:, :filled) = keep%rows(:, :filled)
   status = 0
end subroutine run_records
