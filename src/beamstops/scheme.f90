!> The time loop of the paper's scheme in increment form (SPEC 4), with Rayleigh damping (SPEC 8):
!>   A (d^n - d^{n-1}) = dt^2 (G^n - S u^n) - dt C d^{n-1},  u^{n+1} = u^n + d^n,
!> A = M + dt/2 C + dt^2 beta S, followed by the contact law at the tip (or at the stops along
!> the span, SPEC 7; with restitution, SPEC 9), the rows of massless unknowns stepped as
!> equilibria (mass redistribution, SPEC 10), and the energy bookkeeping of SPEC 6 (beamstops_ledger).
!> The path is chosen once per call of advance: the paper's scheme (advance_fused, as before),
!> with damping or massless unknowns (advance_fused_general), the reference (LAPACK) path, or the
!> stops along the span. The start is beamstops_start's; the tip's contact law is in
!> contact/tip_contact.f90. The loop allocates nothing and writes nothing: records go to a recorder.
module beamstops_scheme
   use beamstops_kinds, only: wp, ik
   use beamstops_strings, only: fmt_real
   use beamstops_scene, only: scene_type, steps_of
   use beamstops_model, only: model_type
   use beamstops_error, only: error_type
   use beamstops_band, only: band_matvec, cholesky_solve
   use beamstops_band_solve, only: band_solver, forward_substitution, forward_substitution_energy, back_substitution, &
      & energy_dots, band_diagonals, diagonal_matvec, diagonal_matvec_rhs, dot, back_substitution_edge, back_substitution_update
   use beamstops_state, only: state_type
   use beamstops_clock, only: thread_cpu_seconds
   use beamstops_newmark, only: newmark_average
   use beamstops_forcing, only: load_average, load_rotation, start_loads, next_load
   use beamstops_contact_tip_contact, only: spring_term, tip_step, tip_step_massless, update, tip_outcome, tip_law, &
      & fix_tip, settle_tip
   use beamstops_contact_span_stops, only: new_span_work
   use beamstops_contact_box_qp, only: qp_solved, qp_message
   use beamstops_recorder, only: recorder_type, n_columns, col_energy
   use beamstops_ledger, only: energy, shift_loads, damping_loss, fill_row, take_snapshot, first_events
   use beamstops_contact_mass_redistribution, only: equilibrium_rows
   use beamstops_start, only: start_state
   use beamstops_span_step, only: span_loop_type, start_span_block, next_span_step, span_step, end_span_block
   use beamstops_observe_quiet, only: quiet_observer, take_quiet, give_quiet, observe_quiet
   use beamstops_stop_signals, only: stop_signal
   use beamstops_summary, only: run_summary, status_complete, status_diverged, status_failed, status_running, &
      & check_divergence
   implicit none
   private
   public :: state_type, start_state, advance, run_scheme, block_steps, close_ledger

   !> Steps between progress reports and divergence checks.
   integer(ik), parameter :: block_steps = 8192_ik

contains

   !> Run from the state's step to the scene's last step (or to step `until`), in blocks; fills
   !> the summary. Between blocks: the divergence check, progress and a look for a stop signal
   !> (beamstops_stop_signals; the loop stops there). A call that ends before the last step
   !> (at `until`, or on a stop signal) leaves the status 'running': the caller continues with
   !> another call.
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
      real(wp) :: t0, kinetic
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
               & fmt_real(real(state%step, wp)*model%dt, 6)//' s'
            exit
         end if
         call band_matvec(model%mass, state%d, state%scratch)
         kinetic = 0.5_wp*dot_product(state%d, state%scratch)/model%dt2
         call check_divergence(scene, kinetic, state%energy0, state%work, state%dissipated, &
            & real(state%step - 1, wp)*model%dt, recorder%blew_up, recorder%blew_up_at, summary)
         if (summary%status == status_diverged) exit
         if (state%observer%active) call state%observer%drain()
         call recorder%progress(state%step - 1, steps)
         if (stop_signal() /= 0) exit
      end do
      summary%cpu_seconds = state%cpu_seconds
      summary%steps = state%step - 1
      summary%t_final = real(summary%steps, wp)*model%dt
      summary%impacts = state%impacts
      summary%max_violation = state%max_violation
      summary%contact_phases = state%impacts
      call close_ledger(scene, model, state, summary)
      if (summary%status == status_running .and. state%step > steps) summary%status = status_complete
      call state%observer%book_summary(summary)
   end subroutine run_scheme

   !> The energy ledger of the summary (J): work, stops' and damping's losses, and the balance
   !> residual E^{N+1/2} - E^{1/2} - (work - dissipated - damped), E from u^{N+1}, d^N and S u^{N+1}.
   subroutine close_ledger(scene, model, state, summary)
      !> Scene (mass per length).
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> The state at the end of the run (its scratch vector used).
      type(state_type), intent(inout) :: state
      !> Receives the ledger.
      type(run_summary), intent(inout) :: summary
      real(wp) :: dmd, usu, dsu, dsd, e_end
      if (.not. allocated(state%d)) return
      call band_matvec(model%mass, state%d, state%scratch)
      dmd = dot_product(state%d, state%scratch)
      call band_matvec(model%stiffness, state%u, state%scratch)
      usu = dot_product(state%u, state%scratch)
      dsu = dot_product(state%d, state%scratch)
      call band_matvec(model%stiffness, state%d, state%scratch)
      dsd = dot_product(state%d, state%scratch)
      e_end = energy(model, dmd, usu, dsu, usu - 2*dsu + dsd)
      summary%work = scene%mass_per_length*state%work
      summary%dissipated = scene%mass_per_length*state%dissipated
      summary%damped = scene%mass_per_length*state%damped
      summary%energy_residual = scene%mass_per_length*((e_end - state%energy0) &
         & - (state%work - state%dissipated - state%damped))
   end subroutine close_ledger

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
      done = last
      if (model%damped .and. .not. allocated(state%cd)) call resume_damping(model, state)
      if (model%stops%m > 0) then
         call advance_span(scene, model, state, recorder, last, done)
      else if (state%lapack_solve) then
         call advance_reference(scene, model, state, recorder, last)
      else if (model%damped .or. model%redistributed) then
         call advance_fused_general(scene, model, state, recorder, last)
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
         weight = newmark_average(model%beta, sigma_next, state%sigma_now, state%sigma_prev)
         state%rhs = model%dt2*(weight*model%load - state%su)
         if (model%damped) state%rhs = state%rhs - model%dt*state%cd
         state%rhs(tip) = state%rhs(tip) + spring_term(scene, model, state)
         if (model%redistributed) call equilibrium_rows(model%massless, model%row_scale, sigma_next, model%load, &
            & state%su, model%stiffness_diagonals, state%d, state%rhs)
         call cholesky_solve(model%factor, state%rhs)
         if (model%redistributed) then
            call tip_step_massless(scene, model, state, weight, sigma_next, u_tip_prev, d_tip_prev, r_prev)
         else
            call tip_step(scene, model, state, weight, sigma_next, u_tip_prev, d_tip_prev, r_prev)
         end if
         if (state%observer%takes(real(step + 1, wp)*model%dt)) call state%observer%tip(real(step + 1, wp)*model%dt, &
            & state%u(tip), merge(state%reaction, 0.0_wp, state%in_contact), state%dissipated)
         if (model%damped) call damping_loss(model, state)
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
   !> forward pass (plain_forward_pass). The contact law runs as soon as the back substitution's
   !> edge rows give the tip value; the update and the terms of g.d^n then ride on the rest of
   !> the substitution (back_substitution_update), so that the next forward pass finds its first
   !> rows updated last and waits only for the tip set on the stop and the load averages moved
   !> on. The books of the step (the ledger, the observer, the record and the snapshot: settle_held)
   !> wait until the next forward pass is under way, where they run in the shadow of its chain;
   !> the record's energy comes from that pass's dot products. Same operations on the same values
   !> as tip_step then close_step: the same bits.
   subroutine advance_fused(scene, model, state, recorder, last)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      class(recorder_type), intent(inout) :: recorder
      integer(ik), intent(in) :: last
      integer(ik) :: step, next_record, next_snapshot
      real(wp) :: sigma_next, weight, held_weight, gd, c
      real(wp) :: sums(4)
      logical :: held
      type(tip_outcome) :: outcome
      type(load_rotation) :: loads
      type(quiet_observer) :: quiet

      call first_events(scene, state%step, next_record, next_snapshot)
      held = .false.
      held_weight = 0
      gd = 0
      ! sums: u.S u, d.S u and d.M d of this step's forward pass, and u.S u of the one before
      sums = 0
      call take_quiet(quiet, state%observer)
      call start_loads(loads, state%step + 1, model%dt, scene%omega, scene%centered_load)
      do step = state%step, last
         sigma_next = loads%sigma
         call next_load(loads)
         weight = newmark_average(model%beta, sigma_next, state%sigma_now, state%sigma_prev)
         call plain_forward_pass(model%stiffness_diagonals, model%mass_diagonals, model%solver, model%n, model%load, &
            & state%u, state%d, model%dt2*weight, model%dt2, spring_term(scene, model, state), &
            & (held .and. step - 1 == next_record) .or. step == next_record, &
            & state%su, state%rhs, sums(1), sums(2), sums(3))
         if (held) call settle_held(scene, model, state, recorder, quiet, step - 1, outcome, gd, held_weight, sums, &
            & next_record, next_snapshot)
         sums(4) = sums(1)
         call back_substitution_edge(model%solver, state%rhs)
         call tip_law(scene, model, state, outcome, c)
         call back_substitution_update(model%solver, state%rhs, c, model%z, model%load, state%d, state%u, gd)
         call fix_tip(scene, model, state, outcome%contact, outcome%tip_value, outcome%u_tip_prev, .true.)
         call shift_loads(state, sigma_next)
         held = .true.
         held_weight = weight
      end do
      ! The state carries S u^{last+1}; the books of the last step, its record's energy from it.
      call diagonal_matvec(model%stiffness_diagonals, state%u, state%su)
      if (held) then
         if (last == next_record) call energy_dots(model%mass_diagonals, state%u, state%d, state%su, sums(1), sums(2), &
            & sums(3))
         call settle_held(scene, model, state, recorder, quiet, last, outcome, gd, held_weight, sums, &
            & next_record, next_snapshot)
      end if
      call give_quiet(quiet, state%observer)
   end subroutine advance_fused

   !> The books of step n of advance_fused, done while the forward pass of step n+1 runs (it
   !> leaves u^{n+1} and d^n alone): settle_tip with g.d^n (taken by the back substitution's
   !> update, d^n_tip as the update left it, before fix_tip, as in tip_step), the observer, the record row (its energy from `sums`) and the
   !> snapshot.
   subroutine settle_held(scene, model, state, recorder, quiet, step, outcome, gd, weight, sums, next_record, &
      & next_snapshot)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State after step n (u^{n+1}, d^n; the load averages already moved on).
      type(state_type), intent(inout) :: state
      !> Receives the records.
      class(recorder_type), intent(inout) :: recorder
      !> The observer's quiet values (beamstops_observe_quiet).
      type(quiet_observer), intent(inout) :: quiet
      !> Step n.
      integer(ik), intent(in) :: step
      !> The step's contact, reaction and tip values (tip_update).
      type(tip_outcome), intent(in) :: outcome
      !> g.d^n (back_substitution_update) and the load average weight of the step.
      real(wp), intent(in) :: gd, weight
      !> u^{n+1}.S u^{n+1}, d^n.S u^{n+1}, d^n.M d^n and u^n.S u^n (when step n is recorded).
      real(wp), intent(in) :: sums(4)
      !> The next step recorded and the next snapshot, moved on past step n.
      integer(ik), intent(inout) :: next_record, next_snapshot
      real(wp) :: r_prev, row(n_columns)
      r_prev = state%reaction
      call settle_tip(scene, model, state, outcome, gd, weight)
      call observe_quiet(quiet, state%observer, real(step + 1, wp)*model%dt, state%u(model%tip), &
         & merge(state%reaction, 0.0_wp, state%in_contact), state%dissipated)
      if (step == next_record) then
         next_record = next_record + scene%record_every
         call fill_row(scene, model, state, step, outcome%u_tip_prev, outcome%d_tip_prev, r_prev, row)
         row(col_energy) = scene%mass_per_length*energy(model, sums(3), sums(1), sums(2), sums(4))
         call recorder%record(row)
      end if
      if (step == next_snapshot) then
         next_snapshot = next_snapshot + scene%snapshot_every
         call take_snapshot(scene, model, state, step, recorder)
      end if
   end subroutine settle_held

   !> advance_fused with Rayleigh damping (SPEC 8) and/or mass redistribution (SPEC 10): with
   !> damping, rhs gains -dt C d^{n-1} and each step ends with damping_loss (C d^n, the energy
   !> the damping took); with massless unknowns, their rows of rhs are their equilibria. A loop
   !> of its own, so that the loop of the paper's scheme is today's, unchanged (advance branches
   !> once per call).
   subroutine advance_fused_general(scene, model, state, recorder, last)
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
      call start_loads(loads, state%step + 1, model%dt, scene%omega, scene%centered_load)
      do step = state%step, last
         sigma_next = loads%sigma
         call next_load(loads)
         weight = newmark_average(model%beta, sigma_next, state%sigma_now, state%sigma_prev)
         call forward_pass(model%stiffness_diagonals, model%mass_diagonals, model%solver, model%load, state%u, state%d, &
            & model%dt2*weight, model%dt2, spring_term(scene, model, state), pending .or. step == next_record, &
            & state%su, state%rhs, usu, dsu, dmd, model%massless, model%row_scale, sigma_next, state%cd, model%dt)
         if (pending) then
            ! usu = u^n.S u^n, dsu = d^{n-1}.S u^n and dmd = d^{n-1}.M d^{n-1} complete the energy
            ! of step n-1.
            row(col_energy) = scene%mass_per_length*energy(model, dmd, usu, dsu, u_old_su)
            call recorder%record(row)
            pending = .false.
         end if
         u_old_su = usu
         call back_substitution(model%solver, state%rhs)
         if (model%redistributed) then
            call tip_step_massless(scene, model, state, weight, sigma_next, u_tip_prev, d_tip_prev, r_prev)
         else
            call tip_step(scene, model, state, weight, sigma_next, u_tip_prev, d_tip_prev, r_prev)
         end if
         if (state%observer%takes(real(step + 1, wp)*model%dt)) call state%observer%tip(real(step + 1, wp)*model%dt, &
            & state%u(tip), merge(state%reaction, 0.0_wp, state%in_contact), state%dissipated)
         if (model%damped) call damping_loss(model, state)
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
      call diagonal_matvec(model%stiffness_diagonals, state%u, state%su)
      if (pending) then
         call energy_dots(model%mass_diagonals, state%u, state%d, state%su, usu, dsu, dmd)
         row(col_energy) = scene%mass_per_length*energy(model, dmd, usu, dsu, u_old_su)
         call recorder%record(row)
      end if
   end subroutine advance_fused_general

   !> The fused step with stops along the span (SPEC 7; contact/span_stops.f90): the forward pass,
   !> the full back substitution x = A^{-1} rhs, then the rest of the step, beamstops_span_step's
   !> span_step (the routine the lockstep loop runs on each member). `done` is the last step
   !> done: `last`, unless the QP of a step fails (state%span%info), then the step before.
   subroutine advance_span(scene, model, state, recorder, last, done)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      class(recorder_type), intent(inout) :: recorder
      integer(ik), intent(in) :: last
      integer(ik), intent(out) :: done
      integer(ik) :: step
      real(wp) :: usu, dsu, dmd
      type(span_loop_type) :: lp

      if (.not. allocated(state%span%trial)) call resume_span(model, state)
      call start_span_block(scene, model, state, lp)
      do step = state%step, last
         call next_span_step(scene, model, state, lp, step)
         call forward_pass(model%stiffness_diagonals, model%mass_diagonals, model%solver, model%load, state%u, state%d, &
            & model%dt2*lp%weight, model%dt2, 0.0_wp, lp%pending .or. step == lp%next_record, &
            & state%su, state%rhs, usu, dsu, dmd, model%massless, model%row_scale, lp%sigma_next, state%cd, model%dt)
         call back_substitution(model%solver, state%rhs)
         call span_step(scene, model, state, lp, recorder, step, usu, dsu, dmd)
         if (.not. lp%live) exit
      end do
      call end_span_block(scene, model, state, lp, recorder)
      done = lp%done
   end subroutine advance_span

   !> The damping terms of the state after a checkpoint: C d^{n-1} and d^{n-1}.C d^{n-1}, from d
   !> by the same product as the loop's (so a resumed run continues with the same bits).
   subroutine resume_damping(model, state)
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      allocate (state%cd(model%n))
      call diagonal_matvec(model%damping_diagonals, state%d, state%cd)
      state%dcd_prev = dot(state%d, state%cd)
   end subroutine resume_damping

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

   !> Forward pass of a step: su = S u, rhs = a g - b su (- c_scale cd with damping) plus
   !> `spring` in the tip row (n-1), the rows of the massless unknowns replaced by their
   !> equilibrium (mass redistribution), then the forward substitution (rhs replaced by D^{-2} w);
   !> with `energy`, usu = u.su, dsu = d.su and dmd = d.M d (energy_dots).
   subroutine forward_pass(stiffness, mass, solver, g, u, d, a, b, spring, energy, su, rhs, usu, dsu, dmd, &
      & massless, row_scale, sigma_next, cd, c_scale)
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
      !> The massless unknowns (mass redistribution; absent or empty otherwise).
      integer, intent(in), optional :: massless(:)
      !> Their rows of A over those of S, and sigma_{n+1} (equilibrium_rows; with massless).
      real(wp), intent(in), optional :: row_scale, sigma_next
      !> C d^{n-1} (n), absent without damping.
      real(wp), intent(in), contiguous, optional :: cd(:)
      !> Its coefficient in rhs (dt).
      real(wp), intent(in), optional :: c_scale
      integer :: n
      n = solver%n
      call diagonal_matvec(stiffness, u, su)
      if (present(cd)) then
         rhs = a*g - b*su - c_scale*cd
      else
         rhs = a*g - b*su
      end if
      rhs(n - 1) = rhs(n - 1) + spring
      if (present(massless)) then
         if (size(massless) > 0) call equilibrium_rows(massless, row_scale, sigma_next, g, su, stiffness, d, rhs)
      end if
      call substitute_forward(solver, mass, n, u, d, su, energy, rhs, usu, dsu, dmd)
   end subroutine forward_pass

   !> forward_pass without its options (no massless rows, no damping), for advance_fused: arrays
   !> of explicit shape, so that a call passes addresses only (forward_pass builds and unpacks five
   !> array descriptors and five optional arguments at every call; docs/performance_notes.md, "The
   !> Figure 4 run against its targets", has the instruction counts). The same operations: the
   !> same bits.
   subroutine plain_forward_pass(stiffness, mass, solver, n, g, u, d, a, b, spring, energy, su, rhs, usu, dsu, dmd)
      !> S and M by diagonals.
      type(band_diagonals), intent(in) :: stiffness, mass
      !> Factor of A.
      type(band_solver), intent(in) :: solver
      !> Unknowns.
      integer, intent(in) :: n
      !> Load vector, u^n and d^{n-1}.
      real(wp), intent(in) :: g(n), u(n), d(n)
      !> Coefficients of rhs = a g - b S u, and the force added in the tip row.
      real(wp), intent(in) :: a, b, spring
      !> Whether the dot products are wanted.
      logical, intent(in) :: energy
      !> S u^n.
      real(wp), intent(out) :: su(n)
      !> D^{-2} w.
      real(wp), intent(out) :: rhs(n)
      !> u.S u, d.S u and d.M d (when energy; 0 otherwise).
      real(wp), intent(out) :: usu, dsu, dmd
      call diagonal_matvec_rhs(stiffness, u, a, g, b, su, rhs)
      rhs(n - 1) = rhs(n - 1) + spring
      call substitute_forward(solver, mass, n, u, d, su, energy, rhs, usu, dsu, dmd)
   end subroutine plain_forward_pass

   !> The forward substitution of a pass and the energy sums when they are wanted (0 otherwise).
   !> The sums are independent of the substitution's chain; taken after it, they stood between
   !> the two substitutions and a recorded step cost about their own instructions more, so they
   !> are taken halfway down it (forward_substitution_energy; docs/performance_notes.md).
   subroutine substitute_forward(solver, mass, n, u, d, su, energy, rhs, usu, dsu, dmd)
      !> Factor of A.
      type(band_solver), intent(in) :: solver
      !> M by diagonals.
      type(band_diagonals), intent(in) :: mass
      !> Unknowns.
      integer, intent(in) :: n
      !> u^n, d^{n-1} and S u^n.
      real(wp), intent(in) :: u(n), d(n), su(n)
      !> Whether the dot products are wanted.
      logical, intent(in) :: energy
      !> The right-hand side, replaced by D^{-2} w.
      real(wp), intent(inout) :: rhs(n)
      !> u.S u, d.S u and d.M d.
      real(wp), intent(out) :: usu, dsu, dmd
      if (energy) then
         call forward_substitution_energy(solver, mass, u, d, su, rhs, usu, dsu, dmd)
      else
         call forward_substitution(solver, rhs)
         usu = 0
         dsu = 0
         dmd = 0
      end if
   end subroutine substitute_forward

end module beamstops_scheme
