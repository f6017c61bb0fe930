!> The time loop of a reduced (modal) model (SPEC 11; beamstops_reduced): the paper's scheme in
!> increment form on q = (modal amplitudes, stop values),
!>   A_r (d^n - d^{n-1}) = dt^2 (G^n l_r - S_r q^n),  q^{n+1} = q^n + d^n,
!> with the load rules, starts, contact laws and energy bookkeeping of the full loop (scheme.f90):
!> the tip projection (Lemma 4.1 with z_r = A_r^{-1} e_tip), the compliance spring at the tip, the
!> box QP of the stops along the span on C_r = P_r^T A_r^{-1} P_r, or none. The stops are physical
!> coordinates of q, so the laws are exact; T being a change of basis, the energy
!>   E^{n+1/2} = 1/2 d^T M_r d/dt^2 + 1/2 [beta q^{n+1} S_r q^{n+1} + beta q^n S_r q^n
!>               + (1 - 2 beta) q^n S_r q^{n+1}]
!> is the full model's energy of u = T q, and its balance (SPEC 6) holds as in the full loop.
!> A step costs O(r m + m^2) (the block solve of A_r and S_r q): the modal block is diagonal.
!> With mass redistribution (reduced%massless) the loop is advance_massless: the massless tip
!> stepped as the full model's equilibrium row (its kernels in reduced_massless.f90).
!> Records go to the same recorder interface, snapshots expanded to the nodes (u = T q).
!> The loop allocates nothing and writes nothing itself.
module beamstops_reduced_scheme
   use beamstops_kinds, only: wp, ik
   use beamstops_strings, only: fmt_real
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type, steps_of, law_none, law_signorini, law_compliance
   use beamstops_reduced, only: reduced_model_type, block_solver_type, block_solve, reduced_stiffness_product, &
      & reduced_mass_product, reduced_damping_product
   use beamstops_clock, only: thread_cpu_seconds
   use beamstops_loop_scalars, only: loop_scalars_type
   use beamstops_ledger, only: first_events
   use beamstops_forcing, only: load_average, support_position, load_rotation, start_loads, next_load
   use beamstops_contact_tip_projection, only: project_tip
   use beamstops_contact_tip_contact, only: violation
   use beamstops_contact_compliance, only: spring_force, compliance_step
   use beamstops_contact_span_stops, only: span_work_type, new_span_work, span_contact, span_settle, span_energy, &
      & span_energy_massless
   use beamstops_contact_box_qp, only: qp_solved, qp_message
   use beamstops_contact_mass_redistribution, only: massless_reaction
   use beamstops_reduced_massless, only: coupling_dots, massless_rhs, massless_update, equilibrium_start, &
      & span_massless_rhs, span_massless_update
   use beamstops_observe_observer, only: observer_type, observe_scene
   use beamstops_recorder, only: recorder_type, n_columns, col_t, col_u, col_v, col_reaction, col_energy, &
      & col_work, col_dissipated, col_damped
   use beamstops_stop_signals, only: stop_signal
   use beamstops_summary, only: run_summary, status_complete, status_diverged, status_failed, status_running, &
      & check_divergence
   implicit none
   private
   public :: reduced_state_type, start_reduced, advance_reduced, run_reduced, simulate_reduced, reduced_block_steps
   public :: resume_reduced

   !> Steps between progress reports and divergence checks.
   integer(ik), parameter :: reduced_block_steps = 8192_ik

   !> Everything the reduced loop carries from step n to step n + 1 (its scalars: the parent type's).
   type, extends(loop_scalars_type) :: reduced_state_type
      !> q^n and d^{n-1} = q^n - q^{n-1} (r + m).
      real(wp), allocatable :: q(:), d(:)
      !> S_r q^n, and the right-hand side / increment of a step (r + m).
      real(wp), allocatable :: sq(:), x(:)
      !> B^T D^{-1} y_a of a step, and the multipliers of the stops acting in it (m).
      real(wp), allocatable :: acc(:), multiplier(:)
      !> The stop coordinates (1..m) acting in a step: active(1:n_active) (m).
      integer, allocatable :: active(:)
      !> Number of stops acting in the step.
      integer :: n_active = 0
      !> Snapshot buffer: physical displacement at the nodes x_0..x_J (J + 1).
      real(wp), allocatable :: shape(:)
      !> With damping: C_r d^{n-1} (r + m; unallocated without damping).
      real(wp), allocatable :: cd(:)
      !> Reaction per unit mass of each stop along the span (m; unallocated without them).
      real(wp), allocatable :: stop_reaction(:)
      !> Stops along the span: the program on C_r and its work arrays.
      type(span_work_type) :: span
      !> The shock log and the running statistics (&statistics enabled).
      type(observer_type) :: observer
   end type reduced_state_type

contains

   !> Run a reduced model from t = 0 to t_end, feeding `recorder` (the entry run.f90 dispatches to
   !> when scene%modes > 0, with the model from prepare_reduced).
   subroutine simulate_reduced(scene, reduced, recorder, summary, error)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Its reduced model (prepare_reduced).
      type(reduced_model_type), intent(in) :: reduced
      !> Receives records and snapshots.
      class(recorder_type), intent(inout) :: recorder
      !> Outcome.
      type(run_summary), intent(out) :: summary
      !> Set when the run cannot start.
      type(error_type), allocatable, intent(out) :: error
      type(reduced_state_type) :: state
      call start_reduced(scene, reduced, state, recorder, error)
      if (allocated(error)) return
      call run_reduced(scene, reduced, state, recorder, summary)
   end subroutine simulate_reduced

   !> Start: q^0 = q0 and q^1 by the Taylor start (M_r a0 = G(0) l_r - S_r q0 + p(u0_tip) e_tip) or
   !> the Euler start, projected into K; hands the record (and snapshot) of t = 0 to the recorder.
   subroutine start_reduced(scene, reduced, state, recorder, error)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> State at n = 1 on return.
      type(reduced_state_type), intent(out) :: state
      !> Receives the record of t = 0.
      class(recorder_type), intent(inout) :: recorder
      !> Set when the start's contact problem fails.
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: c, tip_value, row(n_columns), dt
      integer :: s, pt

      s = reduced%size
      dt = reduced%dt
      pt = tip_coordinate(reduced)
      call allocate_work(reduced, state)
      state%q = reduced%q0 + dt*reduced%v0
      if (scene%taylor_start) then
         call reduced_stiffness_product(reduced, reduced%q0, state%sq)
         state%x = support_position(0.0_wp, 1.0_wp, scene%omega)*reduced%load - state%sq
         if (scene%law == law_compliance .and. pt > 0) state%x(pt) = state%x(pt) + &
            & spring_force(reduced%q0(pt), scene%lower, scene%upper, scene%stiffness_per_mass)
         if (reduced%damped) then
            call reduced_damping_product(reduced, reduced%v0, state%sq)
            state%x = state%x - state%sq
         end if
         ! The massless boundary: M_r = diag(I, 0); the stop coordinates' accelerations 0 (their
         ! values follow from their equilibrium below), as the full model's start.
         if (reduced%massless) state%x(reduced%r + 1:) = 0
         call block_solve(reduced%m_solver, state%x)
         state%q = state%q + 0.5_wp*reduced%dt2*state%x
      end if
      if (reduced%massless) call equilibrium_start(reduced%r, reduced%m, reduced%stiffness_coupling, &
         & reduced%stiffness_pp, reduced%load, load_average(1_ik, dt, scene%omega, scene%centered_load), state%q)
      if (reduced%stops%m > 0) then
         call start_span(scene, reduced, state, error)
         if (allocated(error)) return
      else if (scene%law == law_signorini) then
         call project_tip(state%q(pt), scene%lower, scene%upper, reduced%z(pt, reduced%tip_stop), c, tip_value)
         state%q = state%q + c*reduced%z(:, reduced%tip_stop)
         state%q(pt) = tip_value
      end if
      state%d = state%q - reduced%q0
      state%sigma_prev = load_average(0_ik, dt, scene%omega, scene%centered_load)
      state%sigma_now = load_average(1_ik, dt, scene%omega, scene%centered_load)
      state%gd_prev = dot_product(reduced%load, state%d)
      if (scene%law == law_compliance .and. pt > 0) then
         state%p_prev = spring_force(reduced%q0(pt), scene%lower, scene%upper, scene%stiffness_per_mass)
         state%p_now = spring_force(state%q(pt), scene%lower, scene%upper, scene%stiffness_per_mass)
      end if
      if (scene%law /= law_none .and. reduced%stops%m == 0) state%max_violation = violation(state%q(pt), scene)
      if (reduced%damped) then
         allocate (state%cd(s))
         call reduced_damping_product(reduced, state%d, state%cd)
         state%dcd_prev = dot_product(state%d, state%cd)
         state%damped = 0
      end if
      call reduced_stiffness_product(reduced, reduced%q0, state%x)
      call reduced_stiffness_product(reduced, state%q, state%sq)
      state%energy0 = energy(reduced, reduced_mass_product(reduced, state%d), dot_product(state%q, state%sq), &
         & dot_product(state%d, state%sq), dot_product(reduced%q0, state%x))
      row = 0
      row(col_u) = dot_product(reduced%tip_row, reduced%q0)
      row(col_v) = dot_product(reduced%tip_row, reduced%v0)
      row(col_energy) = scene%mass_per_length*state%energy0
      if (reduced%stops%m > 0) then
         state%span%record_u = reduced%q0(reduced%r + 1:) + reduced%stops%lift*support_position(0.0_wp, &
            & scene%amplitude, scene%omega)
         state%span%record_reaction = 0
         call recorder%record_stops(state%span%record_u, state%span%record_reaction)
      end if
      call recorder%record(row)
      if (scene%snapshot_every > 0) then
         call physical_shape(reduced, reduced%q0, 0.0_wp, scene, state%shape)
         call recorder%snapshot(0.0_wp, state%shape)
      end if
      state%step = 1
      if (scene%statistics) then
         if (reduced%stops%m > 0) then
            call observe_scene(state%observer, scene, dt, .true., reduced%q0(reduced%r + 1:) + reduced%stops%lift* &
               & support_position(0.0_wp, scene%amplitude, scene%omega), state%q(reduced%r + 1:) + &
               & reduced%stops%lift*support_position(dt, scene%amplitude, scene%omega), state%stop_reaction, &
               & dot_product(reduced%tip_row, state%q), state%dissipated, error)
         else
            call observe_scene(state%observer, scene, dt, .false., [dot_product(reduced%tip_row, reduced%q0)], &
               & [dot_product(reduced%tip_row, state%q)], [state%reaction], dot_product(reduced%tip_row, state%q), &
               & state%dissipated, error)
         end if
      end if
   end subroutine start_reduced

   !> The work arrays of the loop (q and d allocated too).
   subroutine allocate_work(reduced, state)
      type(reduced_model_type), intent(in) :: reduced
      type(reduced_state_type), intent(inout) :: state
      integer :: s
      s = reduced%size
      if (.not. allocated(state%q)) allocate (state%q(s))
      if (.not. allocated(state%d)) allocate (state%d(s))
      allocate (state%sq(s), state%x(s), state%shape(size(reduced%x)))
      allocate (state%acc(reduced%m), state%multiplier(reduced%m), state%active(reduced%m))
   end subroutine allocate_work

   !> A state read from a checkpoint (q, d, the scalars, the stops' reactions and the observer
   !> set) made ready to run: the work arrays, the stops' program, and with damping C_r d^{n-1}
   !> and d^{n-1}.C_r d^{n-1}, rebuilt from d by the loop's own operations (so to the bit).
   subroutine resume_reduced(reduced, state, error)
      !> Reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> State with q, d and the scalars of a checkpoint; ready to run on return.
      type(reduced_state_type), intent(inout) :: state
      !> Set when the stops' program cannot be set up.
      type(error_type), allocatable, intent(out) :: error
      call allocate_work(reduced, state)
      if (reduced%stops%m > 0) then
         if (.not. allocated(state%stop_reaction)) then
            allocate (state%stop_reaction(reduced%stops%m))
            state%stop_reaction = 0
         end if
         call new_span_work(state%span, reduced%stops, error)
         if (allocated(error)) return
      end if
      if (reduced%damped) then
         allocate (state%cd(reduced%size))
         call reduced_damping_product(reduced, state%d, state%cd)
         state%dcd_prev = dot_product(state%d, state%cd)
      end if
   end subroutine resume_reduced

   !> The stops along the span at the start: their work arrays, and q^1 projected on the bounds of
   !> t_1 (the QP on the trial values of q^1 at the stops).
   subroutine start_span(scene, reduced, state, error)
      type(scene_type), intent(in) :: scene
      type(reduced_model_type), intent(in) :: reduced
      type(reduced_state_type), intent(inout) :: state
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: c, worst
      integer :: col
      allocate (state%stop_reaction(reduced%stops%m))
      state%stop_reaction = 0
      call new_span_work(state%span, reduced%stops, error)
      if (allocated(error)) return
      if (scene%law /= law_signorini) return
      state%x = 0
      call span_contact(reduced%stops, state%span, state%q, state%x, state%x, &
         & support_position(reduced%dt, scene%amplitude, scene%omega), .true., state%span%info, 0.0_wp, 0.0_wp)
      if (state%span%info /= qp_solved) then
         call fatal_error(error, 'the start q^1: '//qp_message(state%span%info))
         return
      end if
      call correction(reduced, state%span, state%x, c, col)
      if (col > 0) then
         state%q = state%q + c*reduced%z(:, col)
      else
         state%q = state%q + state%x
      end if
      worst = 0
      state%x = 0
      call span_settle(reduced%stops, state%span, state%q, state%x, worst, .true.)
      state%max_violation = worst
   end subroutine start_span

   !> Run from the state's step to the scene's last step (or to step `until`) in blocks; between
   !> blocks the divergence check, progress and a look for a stop signal (beamstops_stop_signals;
   !> the loop stops there). Fills the summary; a call that ends before the last step (at `until`,
   !> or on a stop signal) leaves the status 'running' (the caller saves a checkpoint and
   !> continues with another call).
   subroutine run_reduced(scene, reduced, state, recorder, summary, until)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> State (from start_reduced), advanced to the end.
      type(reduced_state_type), intent(inout) :: state
      !> Receives the records.
      class(recorder_type), intent(inout) :: recorder
      !> Outcome of the run.
      type(run_summary), intent(inout) :: summary
      !> Last step of this call (default: the scene's last).
      integer(ik), intent(in), optional :: until
      integer(ik) :: steps, last, done, final
      real(wp) :: t0, kinetic
      steps = steps_of(scene)
      final = steps
      if (present(until)) final = min(steps, until)
      summary%status = status_running
      t0 = thread_cpu_seconds() - state%cpu_seconds
      do while (state%step <= final)
         last = min(final, state%step + reduced_block_steps - 1)
         call advance_reduced(scene, reduced, state, recorder, last, done)
         state%cpu_seconds = thread_cpu_seconds() - t0
         if (recorder%failed) then
            summary%status = status_failed
            summary%message = 'the recorder could not write'
            exit
         end if
         if (state%span%info /= qp_solved) then
            summary%status = status_failed
            summary%message = qp_message(state%span%info)//' at t = '// &
               & fmt_real(real(state%step, wp)*reduced%dt, 6)//' s'
            exit
         end if
         kinetic = 0.5_wp*reduced_mass_product(reduced, state%d)/reduced%dt2
         call check_divergence(scene, kinetic, state%energy0, state%work, state%dissipated, &
            & real(state%step - 1, wp)*reduced%dt, recorder%blew_up, recorder%blew_up_at, summary)
         if (summary%status == status_diverged) exit
         if (state%observer%active) call state%observer%drain()
         call recorder%progress(state%step - 1, steps)
         if (stop_signal() /= 0) exit
      end do
      summary%cpu_seconds = state%cpu_seconds
      summary%steps = state%step - 1
      summary%t_final = real(summary%steps, wp)*reduced%dt
      summary%impacts = state%impacts
      summary%contact_phases = state%impacts
      summary%max_violation = state%max_violation
      if (summary%status == status_running .and. state%step > steps) summary%status = status_complete
      call close_ledger(scene, reduced, state, summary)
      call state%observer%book_summary(summary)
   end subroutine run_reduced

   !> The energy ledger of the summary (J): work, the stops' and the damping's losses and the
   !> balance residual E^{N+1/2} - E^{1/2} - (work - dissipated - damped) (as the full loop's).
   subroutine close_ledger(scene, reduced, state, summary)
      type(scene_type), intent(in) :: scene
      type(reduced_model_type), intent(in) :: reduced
      type(reduced_state_type), intent(inout) :: state
      type(run_summary), intent(inout) :: summary
      real(wp) :: usu, dsu, e_end
      if (.not. allocated(state%d)) return
      call reduced_stiffness_product(reduced, state%q, state%sq)
      usu = dot_product(state%q, state%sq)
      dsu = dot_product(state%d, state%sq)
      e_end = energy(reduced, reduced_mass_product(reduced, state%d), usu, dsu, &
         & usu - 2*dsu + stiffness_norm2(reduced, state%d))
      summary%work = scene%mass_per_length*state%work
      summary%dissipated = scene%mass_per_length*state%dissipated
      summary%damped = scene%mass_per_length*state%damped
      summary%energy_residual = scene%mass_per_length*((e_end - state%energy0) &
         & - (state%work - state%dissipated - state%damped))
   end subroutine close_ledger

   !> Advance from state%step through step `last` (computing q^{last+1}), recording on the way.
   !> `done` is the last step done: `last`, unless the QP of a step fails (state%span%info).
   subroutine advance_reduced(scene, reduced, state, recorder, last, done)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> State, advanced.
      type(reduced_state_type), intent(inout) :: state
      !> Receives the records.
      class(recorder_type), intent(inout) :: recorder
      !> Last step to do.
      integer(ik), intent(in) :: last
      !> Last step done.
      integer(ik), intent(out) :: done
      integer(ik) :: step, next_record, next_snapshot
      integer :: pt
      real(wp) :: sigma_next, weight, c, gd, tip_value, r_step, r_prev, old_tip, old_dtip
      real(wp) :: u_tip_prev, d_tip_prev, u_old_su, phi_prev, phi_now, phi_next, dt2, row(n_columns)
      real(wp) :: usu, dsu, dmd
      logical :: contact, recording, span, enforce, damped
      type(load_rotation) :: loads

      if (reduced%massless .and. reduced%stops%m > 0) then
         call advance_massless_span(scene, reduced, state, recorder, last, done)
         return
      else if (reduced%massless) then
         call advance_massless(scene, reduced, state, recorder, last, done)
         return
      end if
      dt2 = reduced%dt2
      pt = tip_coordinate(reduced)
      span = reduced%stops%m > 0
      enforce = scene%law == law_signorini
      damped = reduced%damped
      call first_events(scene, state%step, next_record, next_snapshot)
      done = state%step - 1
      u_old_su = 0
      u_tip_prev = 0
      d_tip_prev = 0
      phi_prev = support_position(real(state%step - 1, wp)*reduced%dt, scene%amplitude, scene%omega)
      phi_now = support_position(real(state%step, wp)*reduced%dt, scene%amplitude, scene%omega)
      call start_loads(loads, state%step + 1, reduced%dt, scene%omega, scene%centered_load)
      do step = state%step, last
         sigma_next = loads%sigma
         call next_load(loads)
         weight = reduced%beta*sigma_next + (1 - 2*reduced%beta)*state%sigma_now + reduced%beta*state%sigma_prev
         recording = step == next_record
         if (recording) then
            u_old_su = stiffness_norm2(reduced, state%q)
            u_tip_prev = tip_value_of(reduced, state%q)
            d_tip_prev = tip_value_of(reduced, state%d)
         end if
         ! x = A_r^{-1} dt^2 (weight l_r - S_r q): the modal part left as D^{-1} y_a (modal_rhs), the
         ! stop part complete; the modal part is finished by modal_update with the contact's
         ! correction.
         if (damped) then
            ! The damped variant: y_a gains -dt (C_r d^{n-1})_a, the stop rows -dt (C_r d^{n-1})_p.
            call modal_rhs_damped(reduced%r, reduced%m, reduced%a_solver%dinv, reduced%a_solver%b, reduced%lambda, &
               & reduced%load, state%q, state%cd, dt2, reduced%dt, weight, state%x, state%acc)
            call stop_rhs(reduced, state%q, dt2, weight, state%acc, state%x)
            call damp_stop_rhs(reduced%r, reduced%m, reduced%dt, state%cd, state%x)
         else
            call modal_rhs(reduced%r, reduced%m, reduced%a_solver%dinv, reduced%a_solver%b, reduced%lambda, &
               & reduced%load, state%q, dt2, weight, state%x, state%acc)
            call stop_rhs(reduced, state%q, dt2, weight, state%acc, state%x)
         end if
         r_prev = state%reaction
         if (span) then
            phi_next = support_position(real(step + 1, wp)*reduced%dt, scene%amplitude, scene%omega)
            call stop_solve(reduced%a_solver, state%x)
            ! The box QP on u^{n+1}, or on (u^{n+1} + e u^{n-1})/(1 + e) with restitution (SPEC 9).
            call span_contact(reduced%stops, state%span, state%q, state%d, state%x, phi_next, enforce, &
               & state%span%info, scene%restitution, phi_prev)
            if (state%span%info /= qp_solved) exit
            state%n_active = 0
            if (state%span%contact) then
               state%n_active = state%span%qp%n_active
               state%active(:state%n_active) = state%span%qp%active(:state%n_active)
               state%multiplier(:state%n_active) = state%span%lambda(state%active(:state%n_active))
            end if
            call modal_update(reduced%r, reduced%m, reduced%size, reduced%a_solver%w, reduced%z, reduced%load, &
               & state%n_active, state%active, state%multiplier, state%x, state%d, state%q, gd)
            contact = state%span%contact
            if (enforce) call span_settle(reduced%stops, state%span, state%q, state%d, state%max_violation, .true.)
            r_step = 0
            if (reduced%stops%tip > 0) r_step = state%span%lambda(reduced%stops%tip)/dt2
            if (contact .and. .not. state%in_contact) state%impacts = state%impacts + 1
            state%in_contact = contact
            state%work = state%work + 0.5_wp*weight*(gd + state%gd_prev)
            call span_energy(reduced%stops, state%span, state%d, dt2, phi_next - phi_prev, state%dissipated, &
               & state%work)
            if (damped) call damping_loss(reduced, state)
            state%reaction = r_step
            if (recording) then
               state%span%record_u = state%span%u_prev + reduced%stops%lift*phi_now
               state%span%record_reaction = scene%mass_per_length*state%stop_reaction
               call recorder%record_stops(state%span%record_u, state%span%record_reaction)
            end if
            state%stop_reaction = state%span%lambda/dt2
            if (state%observer%takes(real(step + 1, wp)*reduced%dt)) call state%observer%span(real(step + 1, wp)* &
               & reduced%dt, &
               & state%q(reduced%r + 1:) + reduced%stops%lift*phi_next, state%stop_reaction, &
               & dot_product(reduced%tip_row, state%q), state%span%taken)
            phi_prev = phi_now
            phi_now = phi_next
         else
            if (scene%law == law_compliance) state%x(pt) = state%x(pt) + &
               & dt2*((1 - 2*reduced%beta)*state%p_now + reduced%beta*state%p_prev)
            call stop_solve(reduced%a_solver, state%x)
            old_tip = state%q(pt)
            old_dtip = state%d(pt)
            call contact_law(scene, reduced, state, old_tip + (old_dtip + state%x(pt)), c, tip_value, r_step, contact)
            state%n_active = 0
            if (c /= 0) then
               state%n_active = 1
               state%active(1) = reduced%tip_stop
               state%multiplier(1) = c
            end if
            call modal_update(reduced%r, reduced%m, reduced%size, reduced%a_solver%w, reduced%z, reduced%load, &
               & state%n_active, state%active, state%multiplier, state%x, state%d, state%q, gd)
            if (scene%law == law_signorini .and. contact) then
               state%q(pt) = tip_value
               state%d(pt) = tip_value - old_tip
            end if
            if (scene%law /= law_none) state%max_violation = max(state%max_violation, violation(state%q(pt), scene))
            if (contact .and. .not. state%in_contact) state%impacts = state%impacts + 1
            state%in_contact = contact
            state%work = state%work + 0.5_wp*weight*(gd + state%gd_prev)
            state%dissipated = state%dissipated - 0.5_wp*r_step*(state%d(pt) + old_dtip)
            if (damped) call damping_loss(reduced, state)
            state%reaction = r_step
            if (state%observer%takes(real(step + 1, wp)*reduced%dt)) call state%observer%tip(real(step + 1, wp)* &
               & reduced%dt, state%q(pt), r_step, state%dissipated)
         end if
         state%gd_prev = gd
         state%sigma_prev = state%sigma_now
         state%sigma_now = sigma_next
         if (recording) then
            next_record = next_record + scene%record_every
            call fill_row(scene, reduced, state, step, u_tip_prev, tip_value_of(reduced, state%d), d_tip_prev, &
               & r_prev, row)
            call energy_terms(reduced%r, reduced%m, reduced%lambda, reduced%coupling, state%q, state%d, state%acc, &
               & usu, dsu, dmd)
            call stop_energy_terms(reduced, state%q, state%d, usu, dsu, dmd)
            row(col_energy) = scene%mass_per_length*energy(reduced, dmd, usu, dsu, u_old_su)
            call recorder%record(row)
         end if
         if (step == next_snapshot) then
            next_snapshot = next_snapshot + scene%snapshot_every
            call take_snapshot(scene, reduced, state, step, recorder)
         end if
         done = step
      end do
      state%step = done + 1
   end subroutine advance_reduced

   !> advance_reduced with the massless boundary (mass redistribution, SPEC 10; the tip-only
   !> scene, m = 1): the stop coordinate p carries no mass and is stepped as the equilibrium of
   !> its row at t_{n+1}, as the full model's massless tip (equilibrium_rows):
   !>   rhs_p = dt^2 beta (sigma_{n+1} l_p - (S_r q^n)_p - (S_r d^{n-1})_p),
   !> the modal rows as the plain loop's with the stiffness coupling G p in S_r q; then the same
   !> contact law at p, no exact fix-up of p (d stays the primary variable), and the reaction
   !> of the step as the residual of p's Newmark row (massless_reaction). O(r) a step.
   subroutine advance_massless(scene, reduced, state, recorder, last, done)
      type(scene_type), intent(in) :: scene
      type(reduced_model_type), intent(in) :: reduced
      type(reduced_state_type), intent(inout) :: state
      class(recorder_type), intent(inout) :: recorder
      integer(ik), intent(in) :: last
      integer(ik), intent(out) :: done
      integer(ik) :: step, next_record, next_snapshot
      integer :: pt, r
      real(wp) :: sigma_next, weight, c, gd, tip_value, r_step, r_prev, old_tip, old_dtip, sbb, s_u, s_d_prev, acc
      real(wp) :: u_tip_prev, d_tip_prev, u_old_su, row(n_columns), g_q, g_d, y_p
      logical :: contact, recording
      type(load_rotation) :: loads

      r = reduced%r
      pt = r + 1
      sbb = reduced%stiffness_pp(1, 1)
      call first_events(scene, state%step, next_record, next_snapshot)
      done = state%step - 1
      u_old_su = 0
      u_tip_prev = 0
      d_tip_prev = 0
      call start_loads(loads, state%step + 1, reduced%dt, scene%omega, scene%centered_load)
      do step = state%step, last
         sigma_next = loads%sigma
         call next_load(loads)
         weight = reduced%beta*sigma_next + (1 - 2*reduced%beta)*state%sigma_now + reduced%beta*state%sigma_prev
         recording = step == next_record
         if (recording) then
            u_old_su = stiffness_norm2(reduced, state%q)
            u_tip_prev = state%q(pt)
            d_tip_prev = state%d(pt)
         end if
         ! G.a and G.d_a, then (S_r q^n)_p, (S_r d^{n-1})_p and the tip's equilibrium row.
         call coupling_dots(r, reduced%stiffness_coupling(:, 1), state%q, state%d, g_q, g_d)
         s_u = g_q + sbb*state%q(pt)
         s_d_prev = g_d + sbb*state%d(pt)
         y_p = reduced%row_scale*(sigma_next*reduced%load(pt) - (s_u + s_d_prev))
         ! x_a = D^{-1} (y_a - G y_p/S_bb) with y_a = dt^2 (weight l_a - (S_r q)_a) [- dt (C_r d)_a],
         ! (S_r q)_a = Lambda_c a + G s_u/S_bb; x_p = (y_p/(dt^2 beta) - G.x_a)/S_bb (massless_solve).
         if (reduced%damped) then
            call massless_rhs(r, reduced%a_solver%dinv, reduced%a_solver%b(:, 1), reduced%lambda, &
               & reduced%stiffness_coupling(:, 1), reduced%load, state%q, reduced%dt2, weight, s_u, y_p, state%x, &
               & acc, state%cd, reduced%dt)
         else
            call massless_rhs(r, reduced%a_solver%dinv, reduced%a_solver%b(:, 1), reduced%lambda, &
               & reduced%stiffness_coupling(:, 1), reduced%load, state%q, reduced%dt2, weight, s_u, y_p, state%x, acc)
         end if
         state%x(pt) = (y_p/reduced%row_scale - acc)/sbb
         r_prev = state%reaction
         old_tip = state%q(pt)
         old_dtip = state%d(pt)
         call contact_law(scene, reduced, state, old_tip + (old_dtip + state%x(pt)), c, tip_value, r_step, contact)
         call massless_update(r, reduced%z(:, 1), reduced%load, reduced%stiffness_coupling(:, 1), c, state%x, &
            & state%d, state%q, gd, g_d)
         r_step = massless_reaction(reduced%beta, weight, reduced%load(pt), s_u, s_d_prev, g_d + sbb*state%d(pt))
         if (scene%law /= law_none) state%max_violation = max(state%max_violation, violation(state%q(pt), scene))
         if (contact .and. .not. state%in_contact) state%impacts = state%impacts + 1
         state%in_contact = contact
         state%work = state%work + 0.5_wp*weight*(gd + state%gd_prev)
         state%dissipated = state%dissipated - 0.5_wp*r_step*(state%d(pt) + old_dtip)
         if (reduced%damped) call damping_loss(reduced, state)
         ! recorded only where the stop acts (tip_step_massless)
         state%reaction = merge(r_step, 0.0_wp, contact)
         if (state%observer%takes(real(step + 1, wp)*reduced%dt)) call state%observer%tip(real(step + 1, wp)* &
            & reduced%dt, state%q(pt), state%reaction, state%dissipated)
         state%gd_prev = gd
         state%sigma_prev = state%sigma_now
         state%sigma_now = sigma_next
         if (recording) then
            next_record = next_record + scene%record_every
            call fill_row(scene, reduced, state, step, u_tip_prev, state%d(pt), d_tip_prev, r_prev, row)
            ! M_r = diag(I, 0): d.M_r d = d_a.d_a.
            call reduced_stiffness_product(reduced, state%q, state%sq)
            row(col_energy) = scene%mass_per_length*energy(reduced, dot_product(state%d(1:r), state%d(1:r)), &
               & dot_product(state%q, state%sq), dot_product(state%d, state%sq), u_old_su)
            call recorder%record(row)
         end if
         if (step == next_snapshot) then
            next_snapshot = next_snapshot + scene%snapshot_every
            call take_snapshot(scene, reduced, state, step, recorder)
         end if
         done = step
      end do
      state%step = done + 1
   end subroutine advance_massless

   !> advance_massless with m stops along the span (the full model's advance_span with massless
   !> stop values): each stop coordinate stepped as the equilibrium of its row at t_{n+1}, the box
   !> QP on the reduced C_r, d the primary variable (no exact fix-up), the reactions the
   !> residuals of the stop rows' Newmark equation (massless_reaction). O(r m) a step.
   subroutine advance_massless_span(scene, reduced, state, recorder, last, done)
      type(scene_type), intent(in) :: scene
      type(reduced_model_type), intent(in) :: reduced
      type(reduced_state_type), intent(inout) :: state
      class(recorder_type), intent(inout) :: recorder
      integer(ik), intent(in) :: last
      integer(ik), intent(out) :: done
      integer(ik) :: step, next_record, next_snapshot
      integer :: r, m, j
      real(wp) :: sigma_next, weight, gd, r_prev, r_step, u_tip_prev, d_tip_prev, u_old_su, row(n_columns)
      real(wp) :: phi_prev, phi_now, phi_next
      logical :: contact, recording, enforce
      type(load_rotation) :: loads

      r = reduced%r
      m = reduced%m
      enforce = scene%law == law_signorini
      call first_events(scene, state%step, next_record, next_snapshot)
      done = state%step - 1
      u_old_su = 0
      u_tip_prev = 0
      d_tip_prev = 0
      phi_prev = support_position(real(state%step - 1, wp)*reduced%dt, scene%amplitude, scene%omega)
      phi_now = support_position(real(state%step, wp)*reduced%dt, scene%amplitude, scene%omega)
      call start_loads(loads, state%step + 1, reduced%dt, scene%omega, scene%centered_load)
      do step = state%step, last
         sigma_next = loads%sigma
         call next_load(loads)
         phi_next = support_position(real(step + 1, wp)*reduced%dt, scene%amplitude, scene%omega)
         weight = reduced%beta*sigma_next + (1 - 2*reduced%beta)*state%sigma_now + reduced%beta*state%sigma_prev
         recording = step == next_record
         if (recording) then
            u_old_su = stiffness_norm2(reduced, state%q)
            u_tip_prev = tip_value_of(reduced, state%q)
            d_tip_prev = tip_value_of(reduced, state%d)
         end if
         if (reduced%damped) then
            call span_massless_rhs(r, m, reduced%a_solver%dinv, reduced%a_solver%b, reduced%lambda, &
               & reduced%stiffness_coupling, reduced%stiffness_pp, reduced%load, state%q, state%d, reduced%dt2, &
               & reduced%row_scale, weight, sigma_next, state%span%s_u, state%span%s_d_prev, state%x, state%cd, reduced%dt)
         else
            call span_massless_rhs(r, m, reduced%a_solver%dinv, reduced%a_solver%b, reduced%lambda, &
               & reduced%stiffness_coupling, reduced%stiffness_pp, reduced%load, state%q, state%d, reduced%dt2, &
               & reduced%row_scale, weight, sigma_next, state%span%s_u, state%span%s_d_prev, state%x)
         end if
         call span_contact(reduced%stops, state%span, state%q, state%d, state%x, phi_next, enforce, &
            & state%span%info, scene%restitution, phi_prev)
         if (state%span%info /= qp_solved) exit
         state%n_active = 0
         if (state%span%contact) then
            state%n_active = state%span%qp%n_active
            state%active(:state%n_active) = state%span%qp%active(:state%n_active)
         end if
         call span_massless_update(state%n_active, state%active, state%span%lambda, reduced%z, reduced%load, state%x, &
            & state%d, state%q, gd)
         contact = state%span%contact
         if (enforce) call span_settle(reduced%stops, state%span, state%q, state%d, state%max_violation, .false.)
         r_prev = state%reaction
         do j = 1, m
            state%span%reaction(j) = massless_reaction(reduced%beta, weight, reduced%load(r + j), state%span%s_u(j), &
               & state%span%s_d_prev(j), dot_product(reduced%stiffness_coupling(:, j), state%d(1:r)) + &
               & reduced%stiffness_pp(j, j)*state%d(r + j))
         end do
         r_step = 0
         ! recorded only where the stop acts (tip_step_massless)
         if (reduced%stops%tip > 0) then
            if (state%span%lambda(reduced%stops%tip) /= 0) r_step = state%span%reaction(reduced%stops%tip)
         end if
         if (contact .and. .not. state%in_contact) state%impacts = state%impacts + 1
         state%in_contact = contact
         state%work = state%work + 0.5_wp*weight*(gd + state%gd_prev)
         call span_energy_massless(reduced%stops, state%span, state%d, phi_next - phi_prev, state%dissipated, &
            & state%work)
         if (reduced%damped) call damping_loss(reduced, state)
         state%reaction = r_step
         if (recording) then
            state%span%record_u = state%span%u_prev + reduced%stops%lift*phi_now
            state%span%record_reaction = scene%mass_per_length*state%stop_reaction
            call recorder%record_stops(state%span%record_u, state%span%record_reaction)
         end if
         ! (with massless stops a free stop's row residual is not a contact: only the active ones count)
         state%stop_reaction = merge(state%span%reaction, 0.0_wp, state%span%lambda /= 0)
         if (state%observer%takes(real(step + 1, wp)*reduced%dt)) call state%observer%span(real(step + 1, wp)* &
            & reduced%dt, &
            & state%q(r + 1:) + reduced%stops%lift*phi_next, state%stop_reaction, &
            & tip_value_of(reduced, state%q), state%span%taken)
         state%gd_prev = gd
         state%sigma_prev = state%sigma_now
         state%sigma_now = sigma_next
         if (recording) then
            next_record = next_record + scene%record_every
            call fill_row(scene, reduced, state, step, u_tip_prev, tip_value_of(reduced, state%d), d_tip_prev, &
               & r_prev, row)
            ! M_r = diag(I, 0): d.M_r d = d_a.d_a.
            call reduced_stiffness_product(reduced, state%q, state%sq)
            row(col_energy) = scene%mass_per_length*energy(reduced, dot_product(state%d(1:r), state%d(1:r)), &
               & dot_product(state%q, state%sq), dot_product(state%d, state%sq), u_old_su)
            call recorder%record(row)
         end if
         if (step == next_snapshot) then
            next_snapshot = next_snapshot + scene%snapshot_every
            call take_snapshot(scene, reduced, state, step, recorder)
         end if
         phi_prev = phi_now
         phi_now = phi_next
         done = step
      end do
      state%step = done + 1
   end subroutine advance_massless_span

   !> The record row of step n (t_n, u, v, reaction, work, stops, damping), the energy column 0
   !> (each loop completes it from its own terms). d_tip_now is the tip's value of d^n.
   pure subroutine fill_row(scene, reduced, state, step, u_tip_prev, d_tip_now, d_tip_prev, r_prev, row)
      type(scene_type), intent(in) :: scene
      type(reduced_model_type), intent(in) :: reduced
      type(reduced_state_type), intent(in) :: state
      integer(ik), intent(in) :: step
      real(wp), intent(in) :: u_tip_prev, d_tip_now, d_tip_prev, r_prev
      real(wp), intent(out) :: row(n_columns)
      row = 0
      row(col_t) = real(step, wp)*reduced%dt
      row(col_u) = u_tip_prev
      row(col_v) = (d_tip_now + d_tip_prev)/(2*reduced%dt)
      row(col_reaction) = scene%mass_per_length*r_prev
      row(col_work) = scene%mass_per_length*state%work
      row(col_dissipated) = scene%mass_per_length*state%dissipated
      row(col_damped) = scene%mass_per_length*state%damped
   end subroutine fill_row

   !> Snapshot of u^n = q^{n+1} - d^n at t_n, expanded to the nodes.
   subroutine take_snapshot(scene, reduced, state, step, recorder)
      type(scene_type), intent(in) :: scene
      type(reduced_model_type), intent(in) :: reduced
      type(reduced_state_type), intent(inout) :: state
      integer(ik), intent(in) :: step
      class(recorder_type), intent(inout) :: recorder
      state%x = state%q - state%d
      call physical_shape(reduced, state%x, real(step, wp)*reduced%dt, scene, state%shape)
      call recorder%snapshot(real(step, wp)*reduced%dt, state%shape)
   end subroutine take_snapshot

   !> The tip value of a reduced vector: its tip coordinate when the tip is a stop, else T(tip, :) q.
   pure function tip_value_of(reduced, q) result(u)
      type(reduced_model_type), intent(in) :: reduced
      real(wp), intent(in) :: q(:)
      real(wp) :: u
      if (reduced%tip_stop > 0) then
         u = q(reduced%r + reduced%tip_stop)
      else
         u = dot_product(reduced%tip_row, q)
      end if
   end function tip_value_of

   !> q^T S_r q = sum lambda_k a_k^2 + p^T K_pp p.
   pure function stiffness_norm2(reduced, q) result(qsq)
      type(reduced_model_type), intent(in) :: reduced
      real(wp), intent(in) :: q(:)
      real(wp) :: qsq
      integer :: r, i, j
      real(wp) :: acc
      r = reduced%r
      qsq = 0
      do i = 1, r
         qsq = qsq + reduced%lambda(i)*q(i)*q(i)
      end do
      do j = 1, reduced%m
         acc = 0
         do i = 1, reduced%m
            acc = acc + reduced%stiffness_pp(i, j)*q(r + i)
         end do
         qsq = qsq + q(r + j)*acc
      end do
      ! The massless boundary: + sum_j (G_j.a)^2/S_jj + 2 p_j G_j.a (S_bb diagonal).
      if (reduced%massless) then
         do j = 1, reduced%m
            acc = dot_product(reduced%stiffness_coupling(:, j), q(1:r))
            qsq = qsq + acc*(acc/reduced%stiffness_pp(j, j) + 2*q(r + j))
         end do
      end if
   end function stiffness_norm2

   !> The modal parts of q.S_r q, d.S_r q and d.M_r d in one sweep (the coupling's B d_a kept in
   !> dmd as d_p . (B^T d_a), twice).
   pure subroutine energy_terms(r, m, lambda, b, q, d, bd, usu, dsu, dmd)
      integer, intent(in) :: r, m
      real(wp), intent(in) :: lambda(r), b(r, m), q(r + m), d(r + m)
      !> Workspace (m).
      real(wp), intent(out) :: bd(m)
      real(wp), intent(out) :: usu, dsu, dmd
      integer :: i, j
      real(wp) :: b1
      usu = 0
      dsu = 0
      dmd = 0
      bd = 0
      b1 = 0
      do i = 1, r
         usu = usu + lambda(i)*q(i)*q(i)
         dsu = dsu + lambda(i)*d(i)*q(i)
         dmd = dmd + d(i)*d(i)
         b1 = b1 + b(i, 1)*d(i)
      end do
      bd(1) = b1
      do j = 2, m
         bd(j) = dot_product(b(:, j), d(1:r))
      end do
      do j = 1, m
         dmd = dmd + 2*d(r + j)*bd(j)
      end do
   end subroutine energy_terms

   !> The stop block's parts of q.S_r q, d.S_r q and d.M_r d, added (O(m^2)).
   pure subroutine stop_energy_terms(reduced, q, d, usu, dsu, dmd)
      type(reduced_model_type), intent(in) :: reduced
      real(wp), intent(in) :: q(:), d(:)
      real(wp), intent(inout) :: usu, dsu, dmd
      integer :: r, i, j
      real(wp) :: kq, md
      r = reduced%r
      do j = 1, reduced%m
         kq = 0
         md = 0
         do i = 1, reduced%m
            kq = kq + reduced%stiffness_pp(i, j)*q(r + i)
            md = md + reduced%mass_pp(i, j)*d(r + i)
         end do
         usu = usu + q(r + j)*kq
         dsu = dsu + d(r + j)*kq
         dmd = dmd + d(r + j)*md
      end do
   end subroutine stop_energy_terms

   !> First pass over the modal coordinates: x_a = D^{-1} dt^2 (weight l_a - Lambda a) and
   !> acc = B^T x_a, in one sweep (O(r m)).
   pure subroutine modal_rhs(r, m, dinv, b, lambda, load, q, dt2, weight, x, acc)
      integer, intent(in) :: r, m
      real(wp), intent(in) :: dinv(r), b(r, m), lambda(r), load(r + m), q(r + m), dt2, weight
      real(wp), intent(inout) :: x(r + m)
      real(wp), intent(out) :: acc(m)
      integer :: i, j
      real(wp) :: xi, a1
      if (m == 1) then
         a1 = 0
         do i = 1, r
            xi = dinv(i)*(dt2*(weight*load(i) - lambda(i)*q(i)))
            x(i) = xi
            a1 = a1 + b(i, 1)*xi
         end do
         acc(1) = a1
      else
         do i = 1, r
            x(i) = dinv(i)*(dt2*(weight*load(i) - lambda(i)*q(i)))
         end do
         do j = 1, m
            a1 = 0
            do i = 1, r
               a1 = a1 + b(i, j)*x(i)
            end do
            acc(j) = a1
         end do
      end if
   end subroutine modal_rhs

   !> The stop part of the right-hand side less B^T D^{-1} y_a: dt^2 (weight l_p - K_pp p) - acc.
   pure subroutine stop_rhs(reduced, q, dt2, weight, acc, x)
      type(reduced_model_type), intent(in) :: reduced
      real(wp), intent(in) :: q(:), dt2, weight, acc(:)
      real(wp), intent(inout) :: x(:)
      integer :: j, k, r
      real(wp) :: kq
      r = reduced%r
      do j = 1, reduced%m
         kq = 0
         do k = 1, reduced%m
            kq = kq + reduced%stiffness_pp(j, k)*q(r + k)
         end do
         x(r + j) = dt2*(weight*reduced%load(r + j) - kq) - acc(j)
      end do
   end subroutine stop_rhs

   !> modal_rhs with damping: x_a = D^{-1} (dt^2 (weight l_a - Lambda a) - dt (C_r d^{n-1})_a) and
   !> acc = B^T x_a (B the coupling block of A_r), in one sweep (O(r m)).
   pure subroutine modal_rhs_damped(r, m, dinv, b, lambda, load, q, cd, dt2, dt, weight, x, acc)
      integer, intent(in) :: r, m
      real(wp), intent(in) :: dinv(r), b(r, m), lambda(r), load(r + m), q(r + m), cd(r + m), dt2, dt, weight
      real(wp), intent(inout) :: x(r + m)
      real(wp), intent(out) :: acc(m)
      integer :: i, j
      real(wp) :: a1
      do i = 1, r
         x(i) = dinv(i)*(dt2*(weight*load(i) - lambda(i)*q(i)) - dt*cd(i))
      end do
      do j = 1, m
         a1 = 0
         do i = 1, r
            a1 = a1 + b(i, j)*x(i)
         end do
         acc(j) = a1
      end do
   end subroutine modal_rhs_damped

   !> The stop rows of the damped right-hand side: x_p = x_p - dt (C_r d^{n-1})_p.
   pure subroutine damp_stop_rhs(r, m, dt, cd, x)
      integer, intent(in) :: r, m
      real(wp), intent(in) :: dt, cd(r + m)
      real(wp), intent(inout) :: x(r + m)
      integer :: j
      do j = r + 1, r + m
         x(j) = x(j) - dt*cd(j)
      end do
   end subroutine damp_stop_rhs

   !> The energy the Rayleigh damping takes in step n (SPEC 8), once d^n is final:
   !> (d^n.C_r d^n + 2 d^n.C_r d^{n-1} + d^{n-1}.C_r d^{n-1})/(4 dt) >= 0, added to state%damped;
   !> state%cd becomes C_r d^n (the next step's right-hand side term). As beamstops_ledger's
   !> damping_loss for the full model.
   pure subroutine damping_loss(reduced, state)
      type(reduced_model_type), intent(in) :: reduced
      type(reduced_state_type), intent(inout) :: state
      real(wp) :: cross, dcd
      cross = dot_product(state%d, state%cd)
      call reduced_damping_product(reduced, state%d, state%cd)
      dcd = dot_product(state%d, state%cd)
      state%damped = state%damped + (dcd + 2*cross + state%dcd_prev)/(4*reduced%dt)
      state%dcd_prev = dcd
   end subroutine damping_loss

   !> x_p = H^{-1} x_p (R^T R = H) in place.
   pure subroutine stop_solve(solver, x)
      type(block_solver_type), intent(in) :: solver
      real(wp), intent(inout) :: x(:)
      integer :: i, j, r, m
      real(wp) :: acc
      r = solver%r
      m = solver%m
      if (m == 1) then
         x(r + 1) = x(r + 1)*(solver%rdiag(1)*solver%rdiag(1))
         return
      end if
      do j = 1, m
         acc = x(r + j)
         do i = 1, j - 1
            acc = acc - solver%hfac(i, j)*x(r + i)
         end do
         x(r + j) = acc*solver%rdiag(j)
      end do
      do j = m, 1, -1
         acc = x(r + j)
         do i = j + 1, m
            acc = acc - solver%hfac(j, i)*x(r + i)
         end do
         x(r + j) = acc*solver%rdiag(j)
      end do
   end subroutine stop_solve

   !> Second pass, the update: x_a = D^{-1} y_a - W x_p, plus the contact's correction
   !> sum_k multiplier_k z(:, active_k) on every coordinate; d^n = d^{n-1} + x, q^{n+1} = q^n + d^n,
   !> and gd = l_r . d^n, in one sweep (O(r (m + n_active))).
   pure subroutine modal_update(r, m, s, w, z, load, n_active, active, multiplier, x, d, q, gd)
      integer, intent(in) :: r, m, s, n_active
      real(wp), intent(in) :: w(r, m), z(s, m), load(s)
      integer, intent(in) :: active(m)
      real(wp), intent(in) :: multiplier(m)
      real(wp), intent(inout) :: x(s), d(s), q(s)
      real(wp), intent(out) :: gd
      integer :: i, j, a
      real(wp) :: xi, xp, c
      gd = 0
      if (m == 1 .and. n_active == 0) then
         xp = x(r + 1)
         do i = 1, r
            d(i) = d(i) + (x(i) - w(i, 1)*xp)
            q(i) = q(i) + d(i)
            gd = gd + load(i)*d(i)
         end do
      else if (m == 1) then
         xp = x(r + 1)
         c = multiplier(1)
         do i = 1, r
            d(i) = d(i) + ((x(i) - w(i, 1)*xp) + c*z(i, 1))
            q(i) = q(i) + d(i)
            gd = gd + load(i)*d(i)
         end do
      else
         do j = 1, m
            xp = x(r + j)
            do i = 1, r
               x(i) = x(i) - w(i, j)*xp
            end do
         end do
         do j = 1, n_active
            a = active(j)
            c = multiplier(j)
            do i = 1, r
               x(i) = x(i) + c*z(i, a)
            end do
         end do
         do i = 1, r
            d(i) = d(i) + x(i)
            q(i) = q(i) + d(i)
            gd = gd + load(i)*d(i)
         end do
      end if
      do i = r + 1, s
         xi = x(i)
         do j = 1, n_active
            xi = xi + multiplier(j)*z(i, active(j))
         end do
         d(i) = d(i) + xi
         q(i) = q(i) + d(i)
         gd = gd + load(i)*d(i)
      end do
   end subroutine modal_update

   !> The correction A_r^{-1} P_r lambda of a step with stops along the span: one active stop, its
   !> column `col` and multiplier c (the loop's rank-one update, as the tip's); more, the
   !> correction folded into x (col = 0, c = 0); none, col = 0, c = 0.
   pure subroutine correction(reduced, work, x, c, col)
      type(reduced_model_type), intent(in) :: reduced
      type(span_work_type), intent(in) :: work
      real(wp), intent(inout) :: x(:)
      real(wp), intent(out) :: c
      integer, intent(out) :: col
      integer :: i, j, a, k
      real(wp) :: acc
      c = 0
      col = 0
      k = 0
      if (work%contact) k = work%qp%n_active
      if (k == 1) then
         col = work%qp%active(1)
         c = work%lambda(col)
      else if (k > 1) then
         do i = 1, size(x)
            acc = x(i)
            do j = 1, k
               a = work%qp%active(j)
               acc = acc + work%lambda(a)*reduced%z(i, a)
            end do
            x(i) = acc
         end do
      end if
   end subroutine correction

   !> The contact law at the tip coordinate: from the trial tip value, the multiple c of z_r to
   !> add, the tip value, the reaction per unit mass of the step and whether it is in contact.
   subroutine contact_law(scene, reduced, state, trial, c, tip_value, r_step, contact)
      type(scene_type), intent(in) :: scene
      type(reduced_model_type), intent(in) :: reduced
      type(reduced_state_type), intent(inout) :: state
      real(wp), intent(in) :: trial
      real(wp), intent(out) :: c, tip_value, r_step
      logical, intent(out) :: contact
      real(wp) :: z_tip, lower, upper, e, u_old
      integer :: pt
      pt = tip_coordinate(reduced)
      z_tip = reduced%z(pt, reduced%tip_stop)
      select case (scene%law)
      case (law_signorini)
         lower = scene%lower
         upper = scene%upper
         if (scene%restitution > 0) then
            ! (u^{n+1}_tip + e u^{n-1}_tip)/(1+e) in [g1, g2] (SPEC 9): the projection of u^{n+1}_tip on
            ! the bounds (1+e) g - e u^{n-1}_tip (u^{n-1} = q^n - d^{n-1}: the state is still at step n).
            e = scene%restitution
            u_old = state%q(pt) - state%d(pt)
            lower = (1 + e)*scene%lower - e*u_old
            upper = (1 + e)*scene%upper - e*u_old
         end if
         if (trial >= lower .and. trial <= upper) then
            ! Between the stops: project_tip's c = 0 and tip value = trial, without its division.
            c = 0
            tip_value = trial
         else
            call project_tip(trial, lower, upper, z_tip, c, tip_value)
         end if
         contact = c /= 0
         r_step = c/reduced%dt2
      case (law_compliance)
         call compliance_step(trial, scene%lower, scene%upper, scene%stiffness_per_mass, reduced%dt2, reduced%beta, &
            & z_tip, state%p_prev, state%p_now, tip_value, c, r_step, contact)
      case default
         c = 0
         tip_value = trial
         r_step = 0
         contact = .false.
      end select
   end subroutine contact_law

   !> Index of the tip value in q (r + tip_stop), 0 when the tip is not a stop coordinate.
   pure function tip_coordinate(reduced) result(pt)
      type(reduced_model_type), intent(in) :: reduced
      integer :: pt
      pt = 0
      if (reduced%tip_stop > 0) pt = reduced%r + reduced%tip_stop
   end function tip_coordinate

   !> Discrete energy E^{n+1/2} per unit mass from d.M_r d, q.S_r q, d.S_r q (q = q^{n+1}, d = d^n)
   !> and q^n.S_r q^n.
   pure function energy(reduced, dmd, usu, dsu, u_old_s_u_old) result(e)
      type(reduced_model_type), intent(in) :: reduced
      real(wp), intent(in) :: dmd, usu, dsu, u_old_s_u_old
      real(wp) :: e
      e = 0.5_wp*dmd/reduced%dt2 + 0.5_wp*(reduced%beta*usu + reduced%beta*u_old_s_u_old &
         & + (1 - 2*reduced%beta)*(usu - dsu))
   end function energy

   !> Physical displacement (T q)(x_i) + h(x_i) phi(t) at the nodes x_0..x_J, O(J (r + m)).
   pure subroutine physical_shape(reduced, q, t, scene, shape)
      type(reduced_model_type), intent(in) :: reduced
      real(wp), intent(in) :: q(:), t
      type(scene_type), intent(in) :: scene
      real(wp), intent(out) :: shape(:)
      integer :: k, i
      shape = reduced%lift*support_position(t, scene%amplitude, scene%omega)
      do k = 1, reduced%size
         do i = 2, size(shape)
            shape(i) = shape(i) + reduced%basis(2*i - 3, k)*q(k)
         end do
      end do
   end subroutine physical_shape

end module beamstops_reduced_scheme
