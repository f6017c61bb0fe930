!> The paper's scheme in its three-level form, without stops: a reference for studies only.
!>
!>   A u^{n+1} = (2M - dt^2 (1-2 beta) S) u^n - (M + dt^2 beta S) u^{n-1} + dt^2 G^n
!>
!> Algebraically identical to the increment form of beamstops_scheme, but the second
!> difference of u is rebuilt from u^{n+1}, u^n, u^{n-1} at every step, so the round-off
!> of each step (relative to |u|) accumulates over the N steps of a run (SPEC 4). The
!> engine runs the increment form; this module exists to measure that round-off floor
!> (scripts/convergence.py --three-level). Same model, same load averages and the same
!> start (start_state) as the engine, so the two forms differ by round-off only.
module beamstops_three_level
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type, steps_of, record_count, law_none
   use beamstops_model, only: model_type
   use beamstops_band, only: band_matvec, cholesky_solve
   use beamstops_forcing, only: load_average
   use beamstops_scheme, only: state_type, start_state, block_steps
   use beamstops_stop_signals, only: catch_stop_signals, release_stop_signals, stop_signal, interrupted_at
   use beamstops_recorder_array, only: array_recorder
   implicit none
   private
   public :: run_three_level

contains

   !> Run a scene without stops in the three-level form, recording the tip displacement
   !> u^n_tip at t_n = n dt every scene%record_every steps (n = 0 included), as the
   !> engine's records do. The scene's law must be 'none'. With `stop_signals`, SIGINT and SIGTERM
   !> are caught during the loop, which looks for them every block_steps steps: a signal ends the
   !> run with an error that names it, and `stopped_by` says which it was.
   subroutine run_three_level(scene, model, t, tip_u, cpu_seconds, error, stop_signals, stopped_by)
      !> Validated scene (law_none).
      type(scene_type), intent(in) :: scene
      !> Its model (build_model).
      type(model_type), intent(in) :: model
      !> Record times t_n (s), record_count(scene) of them.
      real(wp), allocatable, intent(out) :: t(:)
      !> Tip displacement u^n_tip at the record times (m).
      real(wp), allocatable, intent(out) :: tip_u(:)
      !> CPU time of the time loop (s).
      real(wp), intent(out) :: cpu_seconds
      !> Set when the scene has stops or the start fails, or a stop signal ended the loop.
      type(error_type), allocatable, intent(out) :: error
      !> Catch SIGINT and SIGTERM during the loop (default: they keep their handlers).
      logical, intent(in), optional :: stop_signals
      !> The signal that ended the loop (0: none).
      integer, intent(out), optional :: stopped_by
      type(scene_type) :: quiet
      type(state_type) :: state
      type(array_recorder) :: recorder
      real(wp), allocatable :: a_band(:, :), u_prev(:), u_now(:), u_next(:), mu(:), su(:), au(:)
      real(wp) :: sigma_prev, sigma_now, sigma_next, weight, t0, t1
      integer(ik) :: step, steps, filled
      integer :: tip, signum
      logical :: catching

      cpu_seconds = 0
      if (present(stopped_by)) stopped_by = 0
      allocate (t(record_count(scene)), tip_u(record_count(scene)))
      t = 0
      tip_u = 0
      if (scene%law /= law_none) then
         call fatal_error(error, 'scene: the three-level form runs without stops only; allowed: &stops law = ''none''')
         return
      end if
      if (model%damped .or. model%redistributed) then
         call fatal_error(error, 'scene: the three-level form runs the paper''s scheme only; allowed: no &damping '// &
            & 'and &stops redistributed_mass = .false.')
         return
      end if
      ! The engine's start (u^1, Taylor or Euler), without records beyond t = 0.
      quiet = scene
      quiet%snapshot_every = 0
      call recorder%reserve(1_ik, 0_ik, size(model%x))
      call start_state(quiet, model, state, recorder, error)
      if (allocated(error)) return

      tip = model%tip
      steps = steps_of(scene)
      a_band = model%mass + model%dt2*model%beta*model%stiffness
      u_prev = model%u0
      u_now = state%u
      allocate (u_next(model%n), mu(model%n), su(model%n), au(model%n))
      sigma_prev = load_average(0_ik, model%dt, scene%omega, scene%centered_load)
      sigma_now = load_average(1_ik, model%dt, scene%omega, scene%centered_load)
      t(1) = 0
      tip_u(1) = model%u0(tip)
      filled = 1

      catching = .false.
      if (present(stop_signals)) catching = stop_signals
      if (catching) call catch_stop_signals()
      signum = 0
      call cpu_time(t0)
      do step = 1, steps
         if (catching .and. mod(step, block_steps) == 0) then
            signum = stop_signal()
            if (signum /= 0) exit
         end if
         if (mod(step, int(scene%record_every, ik)) == 0) then
            filled = filled + 1
            t(filled) = real(step, wp)*model%dt
            tip_u(filled) = u_now(tip)
         end if
         sigma_next = load_average(step + 1, model%dt, scene%omega, scene%centered_load)
         weight = model%beta*sigma_next + (1 - 2*model%beta)*sigma_now + model%beta*sigma_prev
         ! F^n = (2M - dt^2 (1-2 beta) S) u^n - (M + dt^2 beta S) u^{n-1} + dt^2 G^n
         call band_matvec(model%mass, u_now, mu)
         call band_matvec(model%stiffness, u_now, su)
         call band_matvec(a_band, u_prev, au)
         u_next = (2*mu - model%dt2*(1 - 2*model%beta)*su) - au + model%dt2*weight*model%load
         call cholesky_solve(model%factor, u_next)
         u_prev = u_now
         u_now = u_next
         sigma_prev = sigma_now
         sigma_now = sigma_next
      end do
      call cpu_time(t1)
      cpu_seconds = t1 - t0
      if (catching) call release_stop_signals()
      if (present(stopped_by)) stopped_by = signum
      if (signum /= 0) call fatal_error(error, interrupted_at(signum, real(step - 1, wp)*model%dt))
   end subroutine run_three_level
end module beamstops_three_level
