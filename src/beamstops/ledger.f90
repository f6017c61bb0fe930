!> The bookkeeping of a step shared by every path of the time loop: the discrete energy of
!> SPEC 6, the sums carried from step to step (work of the load, impacts, load averages),
!> the record row, snapshots and the steps at which they fall.
module beamstops_ledger
   use beamstops_kinds, only: wp, ik
   use beamstops_scene, only: scene_type
   use beamstops_model, only: model_type
   use beamstops_state, only: state_type
   use beamstops_forcing, only: support_position
   use beamstops_recorder, only: recorder_type, n_columns, col_t, col_u, col_v, col_reaction, col_energy, &
      & col_work, col_dissipated, col_damped
   use beamstops_band_solve, only: diagonal_matvec, dot
   use beamstops_newmark, only: newmark_energy, newmark_work
   implicit none
   private
   public :: energy, move_on, book_step, shift_loads, damping_loss, fill_row, take_snapshot, physical_shape, first_events

contains

   !> Discrete energy E^{n+1/2} per unit mass (SPEC 6) from d.M d, u.S u and d.S u (u = u^{n+1},
   !> d = d^n = u^{n+1} - u^n) and u^n.S u^n.
   pure function energy(model, dmd, usu, dsu, u_old_s_u_old) result(e)
      !> The model (dt, beta).
      type(model_type), intent(in) :: model
      !> d.M d, u.S u, d.S u and u^n.S u^n.
      real(wp), intent(in) :: dmd, usu, dsu, u_old_s_u_old
      real(wp) :: e
      e = newmark_energy(model%dt2, model%beta, dmd, usu, dsu, u_old_s_u_old)
   end function energy

   !> The sums of a step once u^{n+1} is known, whatever the contact law: impacts, the work of
   !> the load 1/2 G^n.(u^{n+1} - u^{n-1}) = 1/2 weight (g.d^n + g.d^{n-1}), the reaction of the
   !> step, and the load averages moved on.
   pure subroutine move_on(state, contact, gd, weight, r_step, sigma_next)
      !> State after the update of the step.
      type(state_type), intent(inout) :: state
      !> Whether the stops act during the step.
      logical, intent(in) :: contact
      !> g.d^n, the load average weight of the step, its reaction (per unit mass) and sigma_{n+1}.
      real(wp), intent(in) :: gd, weight, r_step, sigma_next
      call book_step(state, contact, gd, weight, r_step)
      call shift_loads(state, sigma_next)
   end subroutine move_on

   !> move_on without the load averages: impacts, the work of the load and the reaction of the
   !> step (a loop that moves the load averages on at once may book the step later).
   pure subroutine book_step(state, contact, gd, weight, r_step)
      !> State after the update of the step.
      type(state_type), intent(inout) :: state
      !> Whether the stops act during the step.
      logical, intent(in) :: contact
      !> g.d^n, the load average weight of the step and its reaction (per unit mass).
      real(wp), intent(in) :: gd, weight, r_step
      if (contact .and. .not. state%in_contact) state%impacts = state%impacts + 1
      state%in_contact = contact
      state%work = newmark_work(state%work, weight, gd, state%gd_prev)
      state%reaction = r_step
      state%gd_prev = gd
   end subroutine book_step

   !> The load averages moved on: sigma_{n-1} <- sigma_n <- sigma_{n+1}.
   pure subroutine shift_loads(state, sigma_next)
      !> State after the step.
      type(state_type), intent(inout) :: state
      !> sigma_{n+1}.
      real(wp), intent(in) :: sigma_next
      state%sigma_prev = state%sigma_now
      state%sigma_now = sigma_next
   end subroutine shift_loads

   !> The energy the Rayleigh damping takes in step n (SPEC 8), once d^n is final:
   !>   (1/(4 dt)) (d^n + d^{n-1}).C (d^n + d^{n-1}) = (d^n.C d^n + 2 d^n.C d^{n-1} + d^{n-1}.C d^{n-1})/(4 dt)
   !> >= 0 (C is positive semi-definite), added to state%damped; state%cd becomes C d^n, the
   !> term of the next step's right-hand side (one product by C a step, no solve).
   pure subroutine damping_loss(model, state)
      !> Model (C by diagonals, dt).
      type(model_type), intent(in) :: model
      !> State after the step: d = d^n, cd = C d^{n-1} on entry, C d^n on return.
      type(state_type), intent(inout) :: state
      real(wp) :: cross, dcd
      cross = dot(state%d, state%cd)
      call diagonal_matvec(model%damping_diagonals, state%d, state%cd)
      dcd = dot(state%d, state%cd)
      state%damped = state%damped + (dcd + 2*cross + state%dcd_prev)/(4*model%dt)
      state%dcd_prev = dcd
   end subroutine damping_loss

   !> A record row of step n, the energy column left for the caller.
   pure subroutine fill_row(scene, model, state, step, u_tip_prev, d_tip_prev, r_step, row)
      !> Scene (mass per length).
      type(scene_type), intent(in) :: scene
      !> Model (dt, tip).
      type(model_type), intent(in) :: model
      !> State after the step.
      type(state_type), intent(in) :: state
      !> Step n.
      integer(ik), intent(in) :: step
      !> u^n_tip, d^{n-1}_tip and the reaction recorded with u^n.
      real(wp), intent(in) :: u_tip_prev, d_tip_prev, r_step
      !> The row.
      real(wp), intent(out) :: row(n_columns)
      row(col_t) = real(step, wp)*model%dt
      row(col_u) = u_tip_prev
      row(col_v) = (state%d(model%tip) + d_tip_prev)/(2*model%dt)
      row(col_reaction) = scene%mass_per_length*r_step
      row(col_energy) = 0
      row(col_work) = scene%mass_per_length*state%work
      row(col_dissipated) = scene%mass_per_length*state%dissipated
      row(col_damped) = scene%mass_per_length*state%damped
   end subroutine fill_row

   !> Snapshot of u^n (= u^{n+1} - d^n) at t_n.
   subroutine take_snapshot(scene, model, state, step, recorder)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Model.
      type(model_type), intent(in) :: model
      !> State after step n (its scratch is used).
      type(state_type), intent(inout) :: state
      !> Step n.
      integer(ik), intent(in) :: step
      !> Receives the snapshot.
      class(recorder_type), intent(inout) :: recorder
      state%scratch = state%u - state%d
      call physical_shape(model, state%scratch, real(step, wp)*model%dt, scene, state%shape)
      call recorder%snapshot(real(step, wp)*model%dt, state%shape)
   end subroutine take_snapshot

   !> The first recorded step and the first snapshot step at or after `step`.
   pure subroutine first_events(scene, step, next_record, next_snapshot)
      !> Scene (record_every, snapshot_every).
      type(scene_type), intent(in) :: scene
      !> First step of the call.
      integer(ik), intent(in) :: step
      !> First record and snapshot steps (huge when no snapshots).
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

   !> Physical displacement u + h(x) phi(t) at the nodes x_0..x_J from the homogeneous unknown u.
   pure subroutine physical_shape(model, u, t, scene, shape)
      !> Model (lifting shape).
      type(model_type), intent(in) :: model
      !> Homogeneous unknown (n) and time (s).
      real(wp), intent(in) :: u(:), t
      !> Scene (support motion).
      type(scene_type), intent(in) :: scene
      !> Physical displacement at the nodes (J+1).
      real(wp), intent(out) :: shape(:)
      real(wp) :: phi
      phi = support_position(t, scene%amplitude, scene%omega)
      shape = model%lift*phi
      shape(2:) = shape(2:) + u(1::2)
   end subroutine physical_shape
end module beamstops_ledger
