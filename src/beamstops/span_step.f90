!> The step with stops along the span (SPEC 7; contact/span_stops.f90) after its two
!> substitutions, shared by the one-scene loop (beamstops_scheme's advance_span) and the lockstep
!> loop (beamstops_lockstep_span, member after member on each member's own state): the block's
!> start, the step's load and support values, the step after the substitutions, the block's end.
!> What the loop carries from step to step is a span_loop_type.
module beamstops_span_step
   use beamstops_kinds, only: wp, ik
   use beamstops_scene, only: scene_type, law_signorini
   use beamstops_model, only: model_type
   use beamstops_state, only: state_type
   use beamstops_newmark, only: newmark_average
   use beamstops_band_solve, only: diagonal_matvec, diagonal_row, load_work_product, energy_dots
   use beamstops_contact_mass_redistribution, only: massless_reaction
   use beamstops_contact_tip_contact, only: update
   use beamstops_contact_span_stops, only: span_contact, span_correction, span_settle, span_energy, &
      & span_energy_massless
   use beamstops_contact_box_qp, only: qp_solved
   use beamstops_forcing, only: support_position, load_rotation, start_loads, next_load
   use beamstops_ledger, only: energy, move_on, damping_loss, fill_row, take_snapshot, first_events
   use beamstops_recorder, only: recorder_type, n_columns, col_energy
   implicit none
   private
   public :: span_loop_type, start_span_block, next_span_step, span_step, end_span_block

   !> What the loop carries from step to step within a block.
   type :: span_loop_type
      !> The next step recorded, the next snapshot, the last step done.
      integer(ik) :: next_record = 0, next_snapshot = 0, done = 0
      !> A record row waits for the next forward pass's energy; the block goes on.
      logical :: pending = .false., live = .false.
      !> u^n.S u^n, support positions phi_{n-1}, phi_n, phi_{n+1}, sigma_{n+1}, the load weight.
      real(wp) :: u_old_su = 0, phi_prev = 0, phi_now = 0, phi_next = 0, sigma_next = 0, weight = 0
      !> The waiting record row.
      real(wp) :: row(n_columns) = 0
      !> The load averages by rotation.
      type(load_rotation) :: loads
   end type span_loop_type

contains

   !> The start of a block at state%step.
   subroutine start_span_block(scene, model, state, lp)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State at the start of the block.
      type(state_type), intent(in) :: state
      !> Set up for the block.
      type(span_loop_type), intent(out) :: lp
      lp%live = .true.
      call first_events(scene, state%step, lp%next_record, lp%next_snapshot)
      lp%pending = .false.
      lp%u_old_su = 0
      lp%done = state%step - 1
      lp%phi_prev = support_position(real(state%step - 1, wp)*model%dt, scene%amplitude, scene%omega)
      lp%phi_now = support_position(real(state%step, wp)*model%dt, scene%amplitude, scene%omega)
      call start_loads(lp%loads, state%step + 1, model%dt, scene%omega, scene%centered_load)
   end subroutine start_span_block

   !> The values of step n before its forward pass: sigma_{n+1}, phi_{n+1} and the load weight.
   subroutine next_span_step(scene, model, state, lp, step)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State at step n.
      type(state_type), intent(in) :: state
      !> Moved on to step n.
      type(span_loop_type), intent(inout) :: lp
      !> Step n.
      integer(ik), intent(in) :: step
      lp%sigma_next = lp%loads%sigma
      call next_load(lp%loads)
      lp%phi_next = support_position(real(step + 1, wp)*model%dt, scene%amplitude, scene%omega)
      lp%weight = newmark_average(model%beta, lp%sigma_next, state%sigma_now, state%sigma_prev)
   end subroutine next_span_step

   !> The step after the substitutions (state%rhs holds x = A^{-1} rhs): the record waiting for
   !> this step's energy, the trial values at the stops against the bounds of t_{n+1}, the QP on C
   !> only when some are out, the correction and the update (with one active stop the tip's
   !> rank-one update along its column, so that a single stop at the tip is the tip-only path to
   !> the bit; with more the correction folded into x), the stops settled on their bounds, the
   !> ledger, the observer, the record and snapshot of the step, the support positions moved on.
   !> A failed QP ends the block before the step (live false; state%span%info says why).
   subroutine span_step(scene, model, state, lp, recorder, step, usu, dsu, dmd)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State, advanced by the step.
      type(state_type), intent(inout) :: state
      !> What the loop carries from step to step.
      type(span_loop_type), intent(inout) :: lp
      !> Receives the records.
      class(recorder_type), intent(inout) :: recorder
      !> Step n.
      integer(ik), intent(in) :: step
      !> u.S u, d.S u and d.M d of this step's forward pass (0 when it did not compute them).
      real(wp), intent(in) :: usu, dsu, dmd
      integer :: tip, col, i
      real(wp) :: c, gd, d_tip_prev, u_tip_prev, r_tip, r_prev
      logical :: contact, enforce

      tip = model%tip
      enforce = scene%law == law_signorini
      if (lp%pending) then
         lp%row(col_energy) = scene%mass_per_length*energy(model, dmd, usu, dsu, lp%u_old_su)
         call recorder%record_stops(state%span%record_u, state%span%record_reaction)
         call recorder%record(lp%row)
         lp%pending = .false.
      end if
      lp%u_old_su = usu
      d_tip_prev = state%d(tip)
      u_tip_prev = state%u(tip)
      if (model%redistributed) then
         do i = 1, model%stops%m
            state%span%s_u(i) = diagonal_row(model%stiffness_diagonals, state%u, model%stops%unknown(i))
            state%span%s_d_prev(i) = diagonal_row(model%stiffness_diagonals, state%d, model%stops%unknown(i))
         end do
      end if
      call span_contact(model%stops, state%span, state%u, state%d, state%rhs, lp%phi_next, enforce, state%span%info, &
         & scene%restitution, lp%phi_prev)
      if (state%span%info /= qp_solved) then
         lp%live = .false.
         return
      end if
      call span_correction(model%stops, state%span, model%solver, state%rhs, c, col)
      if (col > 0) then
         call update(state%rhs, c, model%stops%z(:, col), state%d, state%u)
      else
         call update(state%rhs, 0.0_wp, model%z, state%d, state%u)
      end if
      gd = load_work_product(model%load, state%d)
      contact = state%span%contact
      if (enforce) call span_settle(model%stops, state%span, state%u, state%d, state%max_violation, &
         & .not. model%redistributed)
      r_prev = state%reaction
      r_tip = 0
      if (model%redistributed) then
         do i = 1, model%stops%m
            state%span%reaction(i) = massless_reaction(model%beta, lp%weight, model%load(model%stops%unknown(i)), &
               & state%span%s_u(i), state%span%s_d_prev(i), &
               & diagonal_row(model%stiffness_diagonals, state%d, model%stops%unknown(i)))
         end do
         ! recorded only where the stop acts (tip_step_massless)
         if (model%stops%tip > 0) then
            if (state%span%lambda(model%stops%tip) /= 0) r_tip = state%span%reaction(model%stops%tip)
         end if
      else
         if (model%stops%tip > 0) r_tip = state%span%lambda(model%stops%tip)/model%dt2
      end if
      call move_on(state, contact, gd, lp%weight, r_tip, lp%sigma_next)
      if (model%redistributed) then
         call span_energy_massless(model%stops, state%span, state%d, lp%phi_next - lp%phi_prev, state%dissipated, &
            & state%work)
      else
         call span_energy(model%stops, state%span, state%d, model%dt2, lp%phi_next - lp%phi_prev, state%dissipated, &
            & state%work)
      end if
      if (model%damped) call damping_loss(model, state)
      if (step == lp%next_record) then
         lp%next_record = lp%next_record + scene%record_every
         call fill_row(scene, model, state, step, u_tip_prev, d_tip_prev, r_prev, lp%row)
         state%span%record_u = state%span%u_prev + model%stops%lift*lp%phi_now
         state%span%record_reaction = scene%mass_per_length*state%stop_reaction
         lp%pending = .true.
      end if
      if (model%redistributed) then
         state%stop_reaction = merge(state%span%reaction, 0.0_wp, state%span%lambda /= 0)
      else
         state%stop_reaction = state%span%lambda/model%dt2
      end if
      if (state%observer%takes(real(step + 1, wp)*model%dt)) call state%observer%span_indexed(real(step + 1, wp)* &
         & model%dt, state%u, &
         & model%stops%unknown, model%stops%lift, lp%phi_next, state%stop_reaction, state%span%lambda, &
         & state%u(tip), state%span%taken)
      if (step == lp%next_snapshot) then
         lp%next_snapshot = lp%next_snapshot + scene%snapshot_every
         call take_snapshot(scene, model, state, step, recorder)
      end if
      lp%done = step
      lp%phi_prev = lp%phi_now
      lp%phi_now = lp%phi_next
   end subroutine span_step

   !> The end of a block: S u^{last+1}, the waiting record completed, the state's step moved on.
   subroutine end_span_block(scene, model, state, lp, recorder)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State at the end of the block.
      type(state_type), intent(inout) :: state
      !> What the loop carried.
      type(span_loop_type), intent(inout) :: lp
      !> Receives the waiting record.
      class(recorder_type), intent(inout) :: recorder
      real(wp) :: usu, dsu, dmd
      call diagonal_matvec(model%stiffness_diagonals, state%u, state%su)
      if (lp%pending) then
         call energy_dots(model%mass_diagonals, state%u, state%d, state%su, usu, dsu, dmd)
         lp%row(col_energy) = scene%mass_per_length*energy(model, dmd, usu, dsu, lp%u_old_su)
         call recorder%record_stops(state%span%record_u, state%span%record_reaction)
         call recorder%record(lp%row)
         lp%pending = .false.
      end if
      lp%live = .false.
      state%step = lp%done + 1
   end subroutine end_span_block
end module beamstops_span_step
