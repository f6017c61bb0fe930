!> The start of a run (SPEC 4): u^0 = u0 and u^1 by the Taylor (or Euler) start, projected into
!> K (at the tip, or by the program of the stops along the span); the record of t = 0.
module beamstops_start
   use beamstops_kinds, only: wp, ik
   use beamstops_scene, only: scene_type, law_none, law_signorini, law_compliance
   use beamstops_model, only: model_type
   use beamstops_error, only: error_type, fatal_error
   use beamstops_band, only: kd, band_matvec, cholesky_factor, cholesky_solve
   use beamstops_band_solve, only: diagonal_matvec, dot
   use beamstops_state, only: state_type
   use beamstops_forcing, only: load_average, support_position
   use beamstops_contact_tip_projection, only: project_tip
   use beamstops_contact_compliance, only: spring_force
   use beamstops_contact_tip_contact, only: violation
   use beamstops_contact_span_stops, only: new_span_work, span_contact, span_correction, span_settle
   use beamstops_contact_box_qp, only: qp_solved, qp_message
   use beamstops_recorder, only: recorder_type, n_columns, col_u, col_v, col_energy
   use beamstops_ledger, only: energy, physical_shape
   use beamstops_observe_observer, only: observe_scene
   implicit none
   private
   public :: start_state

contains

   !> Start a run: u^0 = u0 and u^1 by the Taylor (or Euler) start, projected into K;
   !> hands the record (and snapshot) of step 0 to the recorder.
   subroutine start_state(scene, model, state, recorder, error)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State at n = 1 on return.
      type(state_type), intent(out) :: state
      !> Receives the record of t = 0.
      class(recorder_type), intent(inout) :: recorder
      !> Set when M cannot be factored.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: mfac(:, :), a0(:), su0(:)
      real(wp) :: c, tip_value, r(n_columns)
      integer :: n, tip

      n = model%n
      tip = model%tip
      allocate (state%u(n), state%d(n), state%su(n), state%rhs(n), state%scratch(n), state%shape(size(model%x)))
      state%u = model%u0 + model%dt*model%v0
      if (scene%taylor_start) then
         ! M a0 = G(0) - S u0 + p(u0) e_tip - C v0
         allocate (a0(n), su0(n))
         call band_matvec(model%stiffness, model%u0, su0)
         a0 = support_position(0.0_wp, 1.0_wp, scene%omega)*model%load - su0
         if (scene%law == law_compliance) a0(tip) = a0(tip) + &
            & spring_force(model%u0(tip), scene%lower, scene%upper, scene%stiffness_per_mass)
         if (model%damped) then
            call band_matvec(model%damping, model%v0, su0)
            a0 = a0 - su0
         end if
         mfac = model%mass
         if (model%redistributed) then
            ! M^rho: the massless rows and columns are zero; a unit diagonal there leaves the
            ! others' accelerations and gives the massless ones 0 (their values follow below).
            mfac(kd + 1, model%massless) = 1
            a0(model%massless) = 0
         end if
         call cholesky_factor(mfac, 'M', error)
         if (allocated(error)) return
         call cholesky_solve(mfac, a0)
         state%u = state%u + 0.5_wp*model%dt2*a0
      end if
      if (model%redistributed) call equilibrium_start(model, load_average(1_ik, model%dt, scene%omega, &
         & scene%centered_load), state%u)
      if (model%stops%m > 0) then
         call start_span(scene, model, state, error)
         if (allocated(error)) return
      else if (scene%law == law_signorini) then
         call project_tip(state%u(tip), scene%lower, scene%upper, model%z(tip), c, tip_value)
         state%u = state%u + c*model%z
         state%u(tip) = tip_value
      end if
      state%d = state%u - model%u0
      call band_matvec(model%stiffness, state%u, state%su)
      state%sigma_prev = load_average(0_ik, model%dt, scene%omega, scene%centered_load)
      state%sigma_now = load_average(1_ik, model%dt, scene%omega, scene%centered_load)
      state%gd_prev = dot_product(model%load, state%d)
      if (scene%law == law_compliance) then
         state%p_prev = spring_force(model%u0(tip), scene%lower, scene%upper, scene%stiffness_per_mass)
         state%p_now = spring_force(state%u(tip), scene%lower, scene%upper, scene%stiffness_per_mass)
      end if
      if (scene%law /= law_none .and. model%stops%m == 0) state%max_violation = violation(state%u(tip), scene)
      if (model%damped) then
         allocate (state%cd(n))
         call diagonal_matvec(model%damping_diagonals, state%d, state%cd)
         state%dcd_prev = dot(state%d, state%cd)
         state%damped = 0
      end if
      call band_matvec(model%mass, state%d, state%scratch)
      state%energy0 = energy(model, dot_product(state%d, state%scratch), dot_product(state%u, state%su), &
         & dot_product(state%d, state%su), dot_product(model%u0, matmul_band(model, model%u0)))
      r = 0
      r(col_u) = model%u0(tip)
      r(col_v) = model%v0(tip)
      r(col_energy) = scene%mass_per_length*state%energy0
      if (model%stops%m > 0) then
         state%span%record_u = model%u0(model%stops%unknown) + model%stops%lift*support_position(0.0_wp, &
            & scene%amplitude, scene%omega)
         state%span%record_reaction = 0
         call recorder%record_stops(state%span%record_u, state%span%record_reaction)
      end if
      call recorder%record(r)
      if (scene%snapshot_every > 0) then
         call physical_shape(model, model%u0, 0.0_wp, scene, state%shape)
         call recorder%snapshot(0.0_wp, state%shape)
      end if
      state%step = 1
      if (scene%statistics) call start_observer(scene, model, state, error)
   end subroutine start_state

   !> The shock log and the statistics from t = 0, with the start's u^1 as their first sample.
   subroutine start_observer(scene, model, state, error)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: phi0, phi1
      phi0 = support_position(0.0_wp, scene%amplitude, scene%omega)
      phi1 = support_position(model%dt, scene%amplitude, scene%omega)
      if (model%stops%m > 0) then
         call observe_scene(state%observer, scene, model%dt, .true., model%u0(model%stops%unknown) + &
            & model%stops%lift*phi0, state%u(model%stops%unknown) + model%stops%lift*phi1, state%stop_reaction, &
            & state%u(model%tip), state%dissipated, error)
      else
         call observe_scene(state%observer, scene, model%dt, .false., [model%u0(model%tip)], [state%u(model%tip)], &
            & [state%reaction], state%u(model%tip), state%dissipated, error)
      end if
   end subroutine start_observer

   !> The stops along the span at the start: their work, and u^1 projected on the bounds of t_1
   !> (the QP on the trial values u^1 at the stops; with one stop at the tip, the tip's projection).
   subroutine start_span(scene, model, state, error)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: c, worst
      integer :: col
      allocate (state%stop_reaction(model%stops%m))
      state%stop_reaction = 0
      call new_span_work(state%span, model%stops, error)
      if (allocated(error)) return
      if (scene%law /= law_signorini) return
      state%scratch = 0
      call span_contact(model%stops, state%span, state%u, state%scratch, state%scratch, &
         & support_position(model%dt, scene%amplitude, scene%omega), .true., state%span%info, 0.0_wp, 0.0_wp)
      if (state%span%info /= qp_solved) then
         call fatal_error(error, 'the start u^1: '//qp_message(state%span%info))
         return
      end if
      call span_correction(model%stops, state%span, model%solver, state%scratch, c, col)
      if (col > 0) then
         state%u = state%u + c*model%stops%z(:, col)
      else
         state%u = state%u + state%scratch
      end if
      worst = 0
      state%rhs = 0
      call span_settle(model%stops, state%span, state%u, state%rhs, worst, .true.)
      state%max_violation = worst
   end subroutine start_span

   !> Mass redistribution: each massless value of u^1 from the equilibrium of its row at t_1,
   !> (S u^1)_k = sigma_1 g_k, the others fixed (no two massless values share a row of S).
   pure subroutine equilibrium_start(model, sigma, u)
      type(model_type), intent(in) :: model
      real(wp), intent(in) :: sigma
      real(wp), intent(inout) :: u(:)
      integer :: i, j, k
      real(wp) :: others
      associate (a => model%stiffness_diagonals%a)
         do i = 1, size(model%massless)
            k = model%massless(i)
            others = 0
            do j = 1, kd
               if (k - j >= 1) others = others + a(k, j)*u(k - j)
               if (k + j <= model%n) others = others + a(k + j, j)*u(k + j)
            end do
            u(k) = (sigma*model%load(k) - others)/a(k, 0)
         end do
      end associate
   end subroutine equilibrium_start

   !> S x as a new array (start-up only).
   function matmul_band(model, x) result(y)
      type(model_type), intent(in) :: model
      real(wp), intent(in) :: x(:)
      real(wp) :: y(size(x))
      call band_matvec(model%stiffness, x, y)
   end function matmul_band
end module beamstops_start
