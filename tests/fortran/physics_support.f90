!> Helpers of the physics suites (damping, restitution, mass redistribution): the tube scene, a
!> run stepped one step at a time, the modes of a model, peaks of a sampled signal.
module physics_support
   use testing, only: wp, error_type, fatal_error, int_text
   use beamstops, only: ik, scene_type, model_type, build_model, state_type, start_state, array_recorder, &
      & steps_of, record_count
   use beamstops_scheme, only: advance
   use beamstops_recorder, only: col_t, col_u
   use beamstops_lapack, only: dsbgv, dsbgv_message
   implicit none
   private
   public :: tube_scene, open_run, step_once, modes, peaks, tip_decrement

contains

   !> The tube of input/tube_supports.nml (30 elements, three stops along the span, beta = 1/4)
   !> with the given step and duration; the suites add the law they test.
   function tube_scene(dt, t_end) result(scene)
      !> Time step (s).
      real(wp), intent(in) :: dt
      !> Duration (s).
      real(wp), intent(in) :: t_end
      type(scene_type) :: scene
      scene%length = 1.5_wp
      scene%k2 = 2.0e11_wp*1.6881e-10_wp/(8.0e3_wp*1.4923e-5_wp)
      scene%mass_per_length = 8.0e3_wp*1.4923e-5_wp
      scene%amplitude = 0.002_wp
      scene%omega = 40.0_wp
      scene%elements = 30
      scene%stop_nodes = [10, 20, 30]
      scene%stop_lower = [-0.002_wp, -0.002_wp, -0.004_wp]
      scene%stop_upper = [0.002_wp, 0.002_wp, 0.004_wp]
      scene%dt = dt
      scene%t_end = t_end
      scene%beta = 0.25_wp
   end function tube_scene

   !> Build the model of a scene (optionally with the initial data replaced) and start a run whose
   !> recorder keeps every record.
   subroutine open_run(scene, model, state, rec, error, u0, v0)
      !> Scene (not validated here: the suites build valid ones).
      type(scene_type), intent(in) :: scene
      !> Model built.
      type(model_type), intent(out) :: model
      !> State at n = 1.
      type(state_type), intent(out) :: state
      !> Recorder with room for every record.
      type(array_recorder), intent(out) :: rec
      !> Set when the model or the start fails.
      type(error_type), allocatable, intent(out) :: error
      !> Initial displacement and velocity of the homogeneous unknown, replacing the scene's (n).
      real(wp), intent(in), optional :: u0(:), v0(:)
      call build_model(scene, model, error)
      if (allocated(error)) return
      if (present(u0)) model%u0 = u0
      if (present(v0)) model%v0 = v0
      call rec%reserve(record_count(scene), 0_ik, scene%elements + 1)
      call start_state(scene, model, state, rec, error)
   end subroutine open_run

   !> One step of the engine (the path the state selects).
   subroutine step_once(scene, model, state, rec)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Model.
      type(model_type), intent(in) :: model
      !> State, advanced by one step.
      type(state_type), intent(inout) :: state
      !> Recorder.
      type(array_recorder), intent(inout) :: rec
      call advance(scene, model, state, rec, state%step)
   end subroutine step_once

   !> Eigenvalues (ascending) and M-normalized eigenvectors of S v = kappa M v (M positive definite).
   subroutine modes(model, kappa, vectors, error)
      !> Model.
      type(model_type), intent(in) :: model
      !> Eigenvalues (n).
      real(wp), allocatable, intent(out) :: kappa(:)
      !> Eigenvectors (n, n), v^T M v = 1.
      real(wp), allocatable, intent(out) :: vectors(:, :)
      !> Set when LAPACK fails.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: sa(:, :), ma(:, :), work(:)
      integer :: n, info
      n = model%n
      allocate (sa, source=model%stiffness)
      allocate (ma, source=model%mass)
      allocate (kappa(n), vectors(n, n), work(3*n))
      call dsbgv('V', 'U', n, 3, 3, sa, 4, ma, 4, kappa, vectors, n, work, info)
      if (info /= 0) call fatal_error(error, dsbgv_message(info, n))
   end subroutine modes

   !> Times and values of the local maxima of samples y(t) (three-point parabola through each).
   subroutine peaks(t, y, tp, yp)
      !> Sample times (equally spaced) and values.
      real(wp), intent(in) :: t(:), y(:)
      !> Peak times and values.
      real(wp), allocatable, intent(out) :: tp(:), yp(:)
      real(wp) :: a, b, s, h
      integer :: i
      allocate (tp(0), yp(0))
      h = t(2) - t(1)
      do i = 2, size(y) - 1
         if (y(i) > y(i - 1) .and. y(i) >= y(i + 1)) then
            a = 0.5_wp*(y(i + 1) + y(i - 1)) - y(i)
            b = 0.5_wp*(y(i + 1) - y(i - 1))
            s = -b/(2*a)
            tp = [tp, t(i) + s*h]
            yp = [yp, y(i) + b*s + a*s**2]
         end if
      end do
   end subroutine peaks

   !> Log decrement of the recorded tip displacement over its peaks: log(y_1/y_k)/(k - 1) for
   !> the k peaks (peaks); an error with fewer than 3.
   subroutine tip_decrement(rec, decrement, error)
      !> The records of a free decay.
      type(array_recorder), intent(in) :: rec
      !> Log decrement per period.
      real(wp), intent(out) :: decrement
      !> Set with fewer than 3 peaks.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: tp(:), yp(:)
      integer :: k
      decrement = 0
      call peaks(rec%rows(col_t, 1:rec%filled), rec%rows(col_u, 1:rec%filled), tp, yp)
      k = size(yp)
      if (k < 3) then
         call fatal_error(error, 'fewer than 3 peaks')
         return
      end if
      decrement = log(yp(1)/yp(k))/(k - 1)
   end subroutine tip_decrement
end module physics_support
