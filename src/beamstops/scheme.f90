!> The time loop of the paper's scheme in increment form (SPEC 4):
!>   A (d^n - d^{n-1}) = dt^2 (G^n - S u^n),  u^{n+1} = u^n + d^n,
!> followed by the contact law at the tip (or at the stops along the span, SPEC 7), with the
!> energy bookkeeping of SPEC 6. The law is chosen once per call of advance.
!> The loop allocates nothing and writes nothing: records go to a recorder.
module beamstops_scheme
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use beamstops_kinds, only: wp, ik
   use beamstops_scene, only: scene_type, steps_of, law_none, law_signorini, law_compliance, stop_count
   use beamstops_model, only: model_type
   use beamstops_error, only: error_type, fatal_error
   use beamstops_band, only: band_matvec, cholesky_factor, cholesky_solve
   use beamstops_band_solve, only: band_solver, prepare_solver, forward_substitution, back_substitution, &
      & forward_substitution_energy, &
      & band_diagonals, prepare_diagonals, diagonal_matvec, dot
   use beamstops_state, only: state_type
   use beamstops_clock, only: thread_cpu_seconds
   use beamstops_forcing, only: load_average, support_position
   use beamstops_contact_tip_projection, only: project_tip
   use beamstops_contact_compliance, only: spring_force, solve_spring_tip
   use beamstops_contact_span_stops, only: new_span_work, span_contact, span_correction, span_settle, span_energy
   use beamstops_contact_box_qp, only: qp_solved, qp_message
   use beamstops_recorder, only: recorder_type, n_columns, col_t, col_u, col_v, col_reaction, col_energy, &
      & col_work, col_dissipated
   use beamstops_summary, only: run_summary, status_complete, status_diverged, status_failed, status_running
   implicit none
   private
   public :: state_type, start_state, advance, run_scheme, block_steps

   !> Steps between progress reports and divergence checks.
   integer(ik), parameter :: block_steps = 8192_ik


   !> The load averages sigma_k = f sin(omega c_k) (forcing's load_average; f = sinc(omega dt/2),
   !> c_k the centre of step k's interval) step after step by rotating (f sin, f cos)(omega c_k)
   !> by omega dt: four multiply-adds instead of a sine. Every restart_every steps they restart
   !> from load_average itself, so they differ from it by a few ulps at most.
   type :: load_rotation
      !> Index k of the current value.
      integer(ik) :: k = 0
      !> sigma_k = f sin(omega c_k) and f cos(omega c_k).
      real(wp) :: sigma = 0, cosine = 0
      !> cos(omega dt), sin(omega dt).
      real(wp) :: cos_step = 1, sin_step = 0
   end type load_rotation

   !> Steps between two restarts of load_rotation from exact values.
   integer(ik), parameter :: restart_every = 64

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
         ! M a0 = G(0) - S u0 + p(u0) e_tip
         allocate (a0(n), su0(n))
         call band_matvec(model%stiffness, model%u0, su0)
         a0 = support_position(0.0_wp, 1.0_wp, scene%omega)*model%load - su0
         if (scene%law == law_compliance) a0(tip) = a0(tip) + &
            & spring_force(model%u0(tip), scene%lower, scene%upper, scene%stiffness_per_mass)
         mfac = model%mass
         call cholesky_factor(mfac, 'M', error)
         if (allocated(error)) return
         call cholesky_solve(mfac, a0)
         state%u = state%u + 0.5_wp*model%dt2*a0
      end if
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
      if (state%solver%n /= model%n) call prepare_operators(model, state)
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
   end subroutine start_state

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
      call prepare_operators(model, state)
      state%scratch = 0
      call span_contact(model%stops, state%span, state%u, state%scratch, state%scratch, &
         & support_position(model%dt, scene%amplitude, scene%omega), .true., state%span%info)
      if (state%span%info /= qp_solved) then
         call fatal_error(error, 'the start u^1: '//qp_message(state%span%info))
         return
      end if
      call span_correction(model%stops, state%span, state%solver, state%scratch, c, col)
      if (col > 0) then
         state%u = state%u + c*model%stops%z(:, col)
      else
         state%u = state%u + state%scratch
      end if
      worst = 0
      state%rhs = 0
      call span_settle(model%stops, state%span, state%u, state%rhs, worst)
      state%max_violation = worst
   end subroutine start_span

   !> S x as a new array (start-up only).
   function matmul_band(model, x) result(y)
      type(model_type), intent(in) :: model
      real(wp), intent(in) :: x(:)
      real(wp) :: y(size(x))
      call band_matvec(model%stiffness, x, y)
   end function matmul_band

   !> Run from the state's step to the scene's last step (or to step `until`), in blocks; fills
   !> the summary. Between blocks: the divergence check and progress. A call that ends at `until`
   !> before the last step leaves the status 'running': the caller continues with another call.
   subroutine run_scheme(scene, model, state, recorder, summary, until)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State (from start_state or a checkpoint), advanced to the end.
      type(state_type), intent(inout) :: state
      !> Receives the records.
      class(recorder_type), intent(inout) :: recorder
      !> Outcome of the run.
      type(run_summary), intent(inout) :: summary
      !> Last step of this call (default: the scene's last).
      integer(ik), intent(in), optional :: until
      integer(ik) :: steps, last, final
      real(wp) :: t0, kinetic, cap
      steps = steps_of(scene)
      final = steps
      if (present(until)) final = min(steps, until)
      summary%status = status_running
      t0 = thread_cpu_seconds() - state%cpu_seconds
      do while (state%step <= final)
         last = min(final, state%step + block_steps - 1)
         call advance(scene, model, state, recorder, last)
         state%cpu_seconds = thread_cpu_seconds() - t0
         if (recorder%failed) then
            summary%status = status_failed
            summary%message = 'the recorder could not write'
            exit
         end if
         if (state%span%info /= qp_solved) then
            summary%status = status_failed
            summary%message = qp_message(state%span%info)//' at t = '// &
               & trim(real_text(real(state%step, wp)*model%dt))//' s'
            exit
         end if
         call band_matvec(model%mass, state%d, state%scratch)
         kinetic = 0.5_wp*dot_product(state%d, state%scratch)/model%dt2
         cap = 1.0e8_wp*(0.5_wp*scene%length*(scene%amplitude*scene%omega)**2 + abs(state%energy0) &
            & + abs(state%work) + abs(state%dissipated))
         if (.not. ieee_is_finite(kinetic) .or. kinetic > cap) then
            summary%status = status_diverged
            summary%message = 'the solution blew up (kinetic energy beyond 1e8 times the energy supplied) '// &
               & 'before t = '//trim(real_text(real(state%step - 1, wp)*model%dt))//' s'
            exit
         end if
         call recorder%progress(state%step - 1, steps)
      end do
      summary%cpu_seconds = state%cpu_seconds
      summary%steps = state%step - 1
      summary%t_final = real(summary%steps, wp)*model%dt
      summary%impacts = state%impacts
      summary%max_violation = state%max_violation
      if (summary%status == status_running .and. state%step > steps) summary%status = status_complete
   end subroutine run_scheme

   !> Text of a real for messages.
   function real_text(x) result(s)
      real(wp), intent(in) :: x
      character(len=32) :: s
      write (s, '(g0.6)') x
   end function real_text

   !> Advance from state%step through step `last` (computing u^{last+1}), recording on the way.
   !> The fused path (default) or, with state%lapack_solve, the reference path; both compute
   !> the same step, to round-off. With stops along the span, advance_span (fused). A step whose
   !> contact problem fails (state%span%info) ends the call before it.
   subroutine advance(scene, model, state, recorder, last)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State, advanced.
      type(state_type), intent(inout) :: state
      !> Receives the records.
      class(recorder_type), intent(inout) :: recorder
      !> Last step to do.
      integer(ik), intent(in) :: last
      integer(ik) :: done
      if (state%solver%n /= model%n) call prepare_operators(model, state)
      done = last
      if (model%stops%m > 0) then
         call advance_span(scene, model, state, recorder, last, done)
      else if (state%lapack_solve) then
         call advance_reference(scene, model, state, recorder, last)
      else
         call advance_fused(scene, model, state, recorder, last)
      end if
      state%step = done + 1
   end subroutine advance

   !> The step as SPEC 4 writes it, one operation after the other: rhs = dt^2 (G^n - S u^n),
   !> LAPACK's dpbtrs, the contact law, d^n = d^{n-1} + A^{-1} rhs + c z, u^{n+1} = u^n + d^n,
   !> S u^{n+1}, the record. The reference of the tests and of scripts/bench.py.
   subroutine advance_reference(scene, model, state, recorder, last)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      class(recorder_type), intent(inout) :: recorder
      integer(ik), intent(in) :: last
      integer(ik) :: step, next_record, next_snapshot
      integer :: tip
      real(wp) :: sigma_next, weight, r_prev, d_tip_prev, u_tip_prev, u_old_su, dmd
      real(wp) :: row(n_columns)

      tip = model%tip
      call first_events(scene, state%step, next_record, next_snapshot)
      do step = state%step, last
         sigma_next = load_average(step + 1, model%dt, scene%omega, scene%centered_load)
         weight = model%beta*sigma_next + (1 - 2*model%beta)*state%sigma_now + model%beta*state%sigma_prev
         state%rhs = model%dt2*(weight*model%load - state%su)
         state%rhs(tip) = state%rhs(tip) + spring_term(scene, model, state)
         call cholesky_solve(model%factor, state%rhs)
         call tip_step(scene, model, state, weight, sigma_next, u_tip_prev, d_tip_prev, r_prev)
         if (step == next_record) u_old_su = dot_product(state%u, state%su) - dot_product(state%d, state%su)
         call band_matvec(model%stiffness, state%u, state%su)
         if (step == next_record) then
            next_record = next_record + scene%record_every
            call band_matvec(model%mass, state%d, state%scratch)
            dmd = dot_product(state%d, state%scratch)
            call fill_row(scene, model, state, step, u_tip_prev, d_tip_prev, r_prev, row)
            row(col_energy) = scene%mass_per_length*energy(model, dmd, dot_product(state%u, state%su), &
               & dot_product(state%d, state%su), u_old_su)
            call recorder%record(row)
         end if
         if (step == next_snapshot) then
            next_snapshot = next_snapshot + scene%snapshot_every
            call take_snapshot(scene, model, state, step, recorder)
         end if
      end do
   end subroutine advance_reference

   !> The same step with the fused substitutions of beamstops_band_solve (the dependency
   !> chain of the two triangular solves, 2n multiply-adds in a row, bounds a step) and the
   !> products and dot products vectorized over S and M by diagonals; the load averages by
   !> rotation (load_rotation) instead of a sine a step. S u^{n+1} is computed once, by the next
   !> forward pass: the record of a step, whose energy needs it, is handed to the recorder
   !> one step later (at the end of the call for the last step).
   subroutine advance_fused(scene, model, state, recorder, last)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      class(recorder_type), intent(inout) :: recorder
      integer(ik), intent(in) :: last
      integer(ik) :: step, next_record, next_snapshot
      integer :: tip
      real(wp) :: sigma_next, weight, d_tip_prev, u_tip_prev
      real(wp) :: usu, dsu, u_old_su, dmd, r_prev, row(n_columns)
      logical :: pending
      type(load_rotation) :: loads

      tip = model%tip
      call first_events(scene, state%step, next_record, next_snapshot)
      pending = .false.
      u_old_su = 0
      dmd = 0
      call start_loads(loads, state%step + 1, scene, model)
      do step = state%step, last
         sigma_next = loads%sigma
         call next_load(loads, scene, model)
         weight = model%beta*sigma_next + (1 - 2*model%beta)*state%sigma_now + model%beta*state%sigma_prev
         call forward_pass(state%stiffness, state%mass, state%solver, model%load, state%u, state%d, &
            & model%dt2*weight, model%dt2, spring_term(scene, model, state), pending .or. step == next_record, &
            & state%su, state%rhs, usu, dsu, dmd)
         if (pending) then
            ! usu = u^n.S u^n, dsu = d^{n-1}.S u^n and dmd = d^{n-1}.M d^{n-1} complete the energy
            ! of step n-1.
            row(col_energy) = scene%mass_per_length*energy(model, dmd, usu, dsu, u_old_su)
            call recorder%record(row)
            pending = .false.
         end if
         u_old_su = usu
         call back_substitution(state%solver, state%rhs)
         call tip_step(scene, model, state, weight, sigma_next, u_tip_prev, d_tip_prev, r_prev)
         if (step == next_record) then
            next_record = next_record + scene%record_every
            call fill_row(scene, model, state, step, u_tip_prev, d_tip_prev, r_prev, row)
            pending = .true.
         end if
         if (step == next_snapshot) then
            next_snapshot = next_snapshot + scene%snapshot_every
            call take_snapshot(scene, model, state, step, recorder)
         end if
      end do
      ! The state carries S u^{last+1}; it also completes a waiting record.
      call diagonal_matvec(state%stiffness, state%u, state%su)
      if (pending) then
         call diagonal_matvec(state%mass, state%d, state%scratch)
         row(col_energy) = scene%mass_per_length*energy(model, dot(state%d, state%scratch), dot(state%u, state%su), &
            & dot(state%d, state%su), u_old_su)
         call recorder%record(row)
      end if
   end subroutine advance_fused

   !> The fused step with stops along the span (SPEC 7; contact/span_stops.f90): the full back
   !> substitution gives x = A^{-1} rhs; the trial values u^n + d^{n-1} + x at the stops against
   !> the bounds of t_{n+1}; only when some are out, the QP on C; then the loop's update, with
   !> one active stop the tip's rank-one update along its column (so that a single stop at the
   !> tip is the tip-only path to the bit), with more the correction folded into x. Records as
   !> advance_fused, the stops' values handed just before each row. `done` is the last step
   !> done: `last`, unless the QP of a step fails (state%span%info), then the step before.
   subroutine advance_span(scene, model, state, recorder, last, done)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      class(recorder_type), intent(inout) :: recorder
      integer(ik), intent(in) :: last
      integer(ik), intent(out) :: done
      integer(ik) :: step, next_record, next_snapshot
      integer :: tip, col
      real(wp) :: sigma_next, weight, c, gd, d_tip_prev, u_tip_prev, r_tip
      real(wp) :: usu, dsu, u_old_su, dmd, r_prev, phi_prev, phi_now, phi_next, row(n_columns)
      logical :: contact, pending, enforce
      type(load_rotation) :: loads

      tip = model%tip
      enforce = scene%law == law_signorini
      if (.not. allocated(state%span%trial)) call resume_span(model, state)
      call first_events(scene, state%step, next_record, next_snapshot)
      pending = .false.
      u_old_su = 0
      dmd = 0
      done = state%step - 1
      phi_prev = support_position(real(state%step - 1, wp)*model%dt, scene%amplitude, scene%omega)
      phi_now = support_position(real(state%step, wp)*model%dt, scene%amplitude, scene%omega)
      call start_loads(loads, state%step + 1, scene, model)
      do step = state%step, last
         sigma_next = loads%sigma
         call next_load(loads, scene, model)
         phi_next = support_position(real(step + 1, wp)*model%dt, scene%amplitude, scene%omega)
         weight = model%beta*sigma_next + (1 - 2*model%beta)*state%sigma_now + model%beta*state%sigma_prev
         call forward_pass(state%stiffness, state%mass, state%solver, model%load, state%u, state%d, &
            & model%dt2*weight, model%dt2, 0.0_wp, pending .or. step == next_record, &
            & state%su, state%rhs, usu, dsu, dmd)
         if (pending) then
            row(col_energy) = scene%mass_per_length*energy(model, dmd, usu, dsu, u_old_su)
            call recorder%record_stops(state%span%record_u, state%span%record_reaction)
            call recorder%record(row)
            pending = .false.
         end if
         u_old_su = usu
         call back_substitution(state%solver, state%rhs)
         d_tip_prev = state%d(tip)
         u_tip_prev = state%u(tip)
         call span_contact(model%stops, state%span, state%u, state%d, state%rhs, phi_next, enforce, state%span%info)
         if (state%span%info /= qp_solved) exit
         call span_correction(model%stops, state%span, state%solver, state%rhs, c, col)
         if (col > 0) then
            call update(state%rhs, c, model%stops%z(:, col), state%d, state%u)
         else
            call update(state%rhs, 0.0_wp, model%z, state%d, state%u)
         end if
         gd = dot(model%load, state%d)
         contact = state%span%contact
         ! The stops on their bounds, the energy they take and the work of the support through them.
         if (enforce) call span_settle(model%stops, state%span, state%u, state%d, state%max_violation)
         r_prev = state%reaction
         r_tip = 0
         if (model%stops%tip > 0) r_tip = state%span%lambda(model%stops%tip)/model%dt2
         if (contact .and. .not. state%in_contact) state%impacts = state%impacts + 1
         state%in_contact = contact
         state%work = state%work + 0.5_wp*weight*(gd + state%gd_prev)
         call span_energy(model%stops, state%span, state%d, model%dt2, phi_next - phi_prev, state%dissipated, &
            & state%work)
         state%reaction = r_tip
         state%gd_prev = gd
         state%sigma_prev = state%sigma_now
         state%sigma_now = sigma_next
         if (step == next_record) then
            next_record = next_record + scene%record_every
            call fill_row(scene, model, state, step, u_tip_prev, d_tip_prev, r_prev, row)
            state%span%record_u = state%span%u_prev + model%stops%lift*phi_now
            state%span%record_reaction = scene%mass_per_length*state%stop_reaction
            pending = .true.
         end if
         state%stop_reaction = state%span%lambda/model%dt2
         if (step == next_snapshot) then
            next_snapshot = next_snapshot + scene%snapshot_every
            call take_snapshot(scene, model, state, step, recorder)
         end if
         done = step
         phi_prev = phi_now
         phi_now = phi_next
      end do
      call diagonal_matvec(state%stiffness, state%u, state%su)
      if (pending) then
         call diagonal_matvec(state%mass, state%d, state%scratch)
         row(col_energy) = scene%mass_per_length*energy(model, dot(state%d, state%scratch), dot(state%u, state%su), &
            & dot(state%d, state%su), u_old_su)
         call recorder%record_stops(state%span%record_u, state%span%record_reaction)
         call recorder%record(row)
      end if
   end subroutine advance_span

   !> The work of the stops along the span after a checkpoint (the state holds no QP).
   subroutine resume_span(model, state)
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      type(error_type), allocatable :: error
      call new_span_work(state%span, model%stops, error)
      if (.not. allocated(state%stop_reaction)) then
         allocate (state%stop_reaction(model%stops%m))
         state%stop_reaction = 0
      end if
   end subroutine resume_span

   !> Forward pass of a step: su = S u, rhs = a g - b su plus `spring` in the tip row (n-1),
   !> both vectorized, then the forward substitution (rhs replaced by D^{-2} w); with `energy`,
   !> usu = u.su, dsu = d.su and dmd = d.M d, accumulated beside the substitution.
   subroutine forward_pass(stiffness, mass, solver, g, u, d, a, b, spring, energy, su, rhs, usu, dsu, dmd)
      !> S and M by diagonals.
      type(band_diagonals), intent(in) :: stiffness, mass
      !> Factor of A.
      type(band_solver), intent(in) :: solver
      !> Load vector, u^n and d^{n-1} (n).
      real(wp), intent(in), contiguous :: g(:), u(:), d(:)
      !> Coefficients of rhs = a g - b S u, and the force added in the tip row.
      real(wp), intent(in) :: a, b, spring
      !> Whether the dot products are wanted.
      logical, intent(in) :: energy
      !> S u^n (n).
      real(wp), intent(out), contiguous :: su(:)
      !> D^{-2} w (n).
      real(wp), intent(out), contiguous :: rhs(:)
      !> u.S u, d.S u and d.M d (when energy).
      real(wp), intent(out) :: usu, dsu, dmd
      integer :: n
      n = solver%n
      call diagonal_matvec(stiffness, u, su)
      rhs = a*g - b*su
      rhs(n - 1) = rhs(n - 1) + spring
      if (energy) then
         call forward_substitution_energy(solver, mass, u, d, su, rhs, usu, dsu, dmd)
      else
         call forward_substitution(solver, rhs)
         usu = 0
         dsu = 0
         dmd = 0
      end if
   end subroutine forward_pass

   !> load_rotation at step k: from load_average at the last multiple of restart_every, then
   !> rotated, so that the value of every step is the same however the run is cut into calls.
   subroutine start_loads(loads, k, scene, model)
      type(load_rotation), intent(out) :: loads
      integer(ik), intent(in) :: k
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      call restart_loads(loads, (k/restart_every)*restart_every, scene, model)
      do while (loads%k < k)
         call next_load(loads, scene, model)
      end do
   end subroutine start_loads

   !> load_rotation at step k, exact: load_average and the same centre and factor for the cosine.
   subroutine restart_loads(loads, k, scene, model)
      type(load_rotation), intent(out) :: loads
      integer(ik), intent(in) :: k
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      real(wp) :: centre, x, factor
      centre = real(k, wp)*model%dt
      if (.not. scene%centered_load) centre = (real(k, wp) + 0.5_wp)*model%dt
      x = 0.5_wp*scene%omega*model%dt
      if (abs(x) < 1.0e-8_wp) then
         factor = 1 - x**2/6
      else
         factor = sin(x)/x
      end if
      loads%k = k
      loads%sigma = load_average(k, model%dt, scene%omega, scene%centered_load)
      loads%cosine = factor*cos(scene%omega*centre)
      loads%cos_step = cos(scene%omega*model%dt)
      loads%sin_step = sin(scene%omega*model%dt)
   end subroutine restart_loads

   !> load_rotation moved on to step k + 1.
   subroutine next_load(loads, scene, model)
      type(load_rotation), intent(inout) :: loads
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      real(wp) :: sigma
      if (mod(loads%k + 1, restart_every) == 0) then
         call restart_loads(loads, loads%k + 1, scene, model)
         return
      end if
      sigma = loads%sigma*loads%cos_step + loads%cosine*loads%sin_step
      loads%cosine = loads%cosine*loads%cos_step - loads%sigma*loads%sin_step
      loads%sigma = sigma
      loads%k = loads%k + 1
   end subroutine next_load

   !> The update of the step: d^n = d^{n-1} + x + c z, u^{n+1} = u^n + d^n.
   pure subroutine update(x, c, z, d, u)
      !> A^{-1} rhs and z = A^{-1} e_tip (n).
      real(wp), intent(in), contiguous :: x(:), z(:)
      !> Multiple of z (contact).
      real(wp), intent(in) :: c
      !> d^{n-1} and u^n on entry, d^n and u^{n+1} on return (n).
      real(wp), intent(inout), contiguous :: d(:), u(:)
      d = d + x + c*z
      u = u + d
   end subroutine update

   !> dt^2 times the explicit part of the Newmark-weighted spring force, added to the tip row of
   !> the right-hand side (normal compliance; zero otherwise).
   pure function spring_term(scene, model, state) result(f)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(in) :: state
      real(wp) :: f
      f = 0
      if (scene%law == law_compliance) f = model%dt2*((1 - 2*model%beta)*state%p_now + model%beta*state%p_prev)
   end function spring_term

   !> The contact law at the tip: from the trial tip value u^n_tip + (A^{-1} rhs + d^{n-1})_tip,
   !> the multiple c of z to add, the tip value, the reaction per unit mass of the step and
   !> whether the tip is in contact (SPEC 4, 5).
   subroutine contact_law(scene, model, state, trial, c, tip_value, r_step, contact)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      real(wp), intent(in) :: trial
      real(wp), intent(out) :: c, tip_value, r_step
      logical, intent(out) :: contact
      real(wp) :: p_next
      select case (scene%law)
      case (law_signorini)
         call project_tip(trial, scene%lower, scene%upper, model%z(model%tip), c, tip_value)
         contact = c /= 0
         r_step = c/model%dt2
      case (law_compliance)
         tip_value = solve_spring_tip(trial, scene%lower, scene%upper, scene%stiffness_per_mass, &
            & model%dt2*model%beta*model%z(model%tip))
         p_next = spring_force(tip_value, scene%lower, scene%upper, scene%stiffness_per_mass)
         c = model%dt2*model%beta*p_next
         r_step = model%beta*p_next + (1 - 2*model%beta)*state%p_now + model%beta*state%p_prev
         state%p_prev = state%p_now
         state%p_now = p_next
         contact = r_step /= 0
      case default
         c = 0
         tip_value = trial
         r_step = 0
         contact = .false.
      end select
   end subroutine contact_law

   !> The rest of a step once state%rhs holds A^{-1} rhs: the contact law at the tip, the
   !> update d^n = d^{n-1} + A^{-1} rhs + c z, u^{n+1} = u^n + d^n, and close_step. Returns
   !> u^n_tip, d^{n-1}_tip and the reaction r_{n-1} recorded with u^n.
   subroutine tip_step(scene, model, state, weight, sigma_next, u_tip_prev, d_tip_prev, r_prev)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      real(wp), intent(in) :: weight, sigma_next
      real(wp), intent(out) :: u_tip_prev, d_tip_prev, r_prev
      real(wp) :: trial, c, tip_value, r_step
      logical :: contact
      d_tip_prev = state%d(model%tip)
      u_tip_prev = state%u(model%tip)
      trial = u_tip_prev + (d_tip_prev + state%rhs(model%tip))
      call contact_law(scene, model, state, trial, c, tip_value, r_step, contact)
      call update(state%rhs, c, model%z, state%d, state%u)
      r_prev = state%reaction
      call close_step(scene, model, state, contact, tip_value, dot(model%load, state%d), weight, r_step, &
         & d_tip_prev, u_tip_prev, sigma_next)
   end subroutine tip_step

   !> After the update: the exact tip value (Signorini), the violation of the stops, impacts,
   !> the work of the load and the energy taken by the stops, the load averages moved on.
   subroutine close_step(scene, model, state, contact, tip_value, gd, weight, r_step, d_tip_prev, u_tip_prev, &
      & sigma_next)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      logical, intent(in) :: contact
      real(wp), intent(in) :: tip_value, gd, weight, r_step, d_tip_prev, u_tip_prev, sigma_next
      integer :: tip
      tip = model%tip
      if (scene%law == law_signorini .and. contact) then
         ! The tip exactly on the stop, and d^n its exact increment (a tip resting on a stop
         ! then has exactly zero velocity).
         state%u(tip) = tip_value
         state%d(tip) = tip_value - u_tip_prev
      end if
      if (scene%law /= law_none) state%max_violation = max(state%max_violation, violation(state%u(tip), scene))
      if (contact .and. .not. state%in_contact) state%impacts = state%impacts + 1
      state%in_contact = contact
      state%work = state%work + 0.5_wp*weight*(gd + state%gd_prev)
      state%dissipated = state%dissipated - 0.5_wp*r_step*(state%d(tip) + d_tip_prev)
      state%reaction = r_step
      state%gd_prev = gd
      state%sigma_prev = state%sigma_now
      state%sigma_now = sigma_next
   end subroutine close_step

   !> A record row of step n, the energy column left for the caller.
   subroutine fill_row(scene, model, state, step, u_tip_prev, d_tip_prev, r_step, row)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(in) :: state
      integer(ik), intent(in) :: step
      real(wp), intent(in) :: u_tip_prev, d_tip_prev, r_step
      real(wp), intent(out) :: row(n_columns)
      row(col_t) = real(step, wp)*model%dt
      row(col_u) = u_tip_prev
      row(col_v) = (state%d(model%tip) + d_tip_prev)/(2*model%dt)
      row(col_reaction) = scene%mass_per_length*r_step
      row(col_energy) = 0
      row(col_work) = scene%mass_per_length*state%work
      row(col_dissipated) = scene%mass_per_length*state%dissipated
   end subroutine fill_row

   !> Snapshot of u^n (= u^{n+1} - d^n) at t_n.
   subroutine take_snapshot(scene, model, state, step, recorder)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      integer(ik), intent(in) :: step
      class(recorder_type), intent(inout) :: recorder
      state%scratch = state%u - state%d
      call physical_shape(model, state%scratch, real(step, wp)*model%dt, scene, state%shape)
      call recorder%snapshot(real(step, wp)*model%dt, state%shape)
   end subroutine take_snapshot

   !> The first recorded step and the first snapshot step at or after `step`.
   pure subroutine first_events(scene, step, next_record, next_snapshot)
      type(scene_type), intent(in) :: scene
      integer(ik), intent(in) :: step
      integer(ik), intent(out) :: next_record, next_snapshot
      next_record = next_multiple(step, int(scene%record_every, ik))
      next_snapshot = huge(step)
      if (scene%snapshot_every > 0) next_snapshot = next_multiple(step, int(scene%snapshot_every, ik))
   end subroutine first_events

   !> The first multiple of `every` at or after `step`.
   pure function next_multiple(step, every) result(m)
      integer(ik), intent(in) :: step, every
      integer(ik) :: m
      m = ((step + every - 1)/every)*every
   end function next_multiple

   !> The factor of A, S and M in the layouts of the fused loop.
   subroutine prepare_operators(model, state)
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      call prepare_solver(model%factor, state%solver)
      call prepare_diagonals(model%stiffness, state%stiffness)
      call prepare_diagonals(model%mass, state%mass)
   end subroutine prepare_operators

   !> Discrete energy E^{n+1/2} per unit mass (SPEC 6) from d.M d, u.S u and d.S u (u = u^{n+1},
   !> d = d^n = u^{n+1} - u^n) and u^n.S u^n.
   pure function energy(model, dmd, usu, dsu, u_old_s_u_old) result(e)
      type(model_type), intent(in) :: model
      real(wp), intent(in) :: dmd, usu, dsu, u_old_s_u_old
      real(wp) :: e
      e = 0.5_wp*dmd/model%dt2 + 0.5_wp*(model%beta*usu + model%beta*u_old_s_u_old &
         & + (1 - 2*model%beta)*(usu - dsu))
   end function energy

   !> Violation of the stops by a tip value (m).
   pure function violation(u_tip, scene) result(v)
      real(wp), intent(in) :: u_tip
      type(scene_type), intent(in) :: scene
      real(wp) :: v
      v = max(u_tip - scene%upper, scene%lower - u_tip, 0.0_wp)
   end function violation

   !> Physical displacement u + h(x) phi(t) at the nodes x_0..x_J from the homogeneous unknown u.
   subroutine physical_shape(model, u, t, scene, shape)
      type(model_type), intent(in) :: model
      real(wp), intent(in) :: u(:), t
      type(scene_type), intent(in) :: scene
      real(wp), intent(out) :: shape(:)
      real(wp) :: phi
      phi = support_position(t, scene%amplitude, scene%omega)
      shape = model%lift*phi
      shape(2:) = shape(2:) + u(1::2)
   end subroutine physical_shape
end module beamstops_scheme
