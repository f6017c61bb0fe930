!> The contact law at the tip, chosen by the scene: exact projection (Signorini, SPEC 4),
!> normal compliance (SPEC 5) or none; and the tip step of the time loop built on it (the
!> update of d and u along z = A^{-1} e_tip and the bookkeeping), shared by the reference
!> and the fused paths. With a restitution coefficient e > 0 the projection acts on the
!> combination (u^{n+1} + e u^{n-1})/(1 + e) (Paoli-Schatzman, SPEC 9); with mass redistribution
!> (SPEC 10) the tip is massless, its reaction the residual of its row, and d stays the primary
!> variable (no exact fix-up of the tip).
module beamstops_contact_tip_contact
   use beamstops_kinds, only: wp
   use beamstops_scene, only: scene_type, law_none, law_signorini, law_compliance
   use beamstops_model, only: model_type
   use beamstops_state, only: state_type
   use beamstops_band_solve, only: load_work_product, diagonal_row
   use beamstops_contact_mass_redistribution, only: massless_reaction
   use beamstops_contact_tip_projection, only: project_tip
   use beamstops_contact_compliance, only: compliance_step
   use beamstops_newmark, only: newmark_explicit
   use beamstops_ledger, only: book_step, shift_loads
   implicit none
   private
   public :: spring_term, contact_law, tip_step, tip_step_massless, close_step, update, violation
   public :: tip_outcome, tip_law, settle_tip, fix_tip

   !> What the books of a step at the tip (settle_tip) need once the update is done.
   type :: tip_outcome
      !> Whether the stops act during the step.
      logical :: contact = .false.
      !> The reaction of the step per unit mass and the tip value of the contact law.
      real(wp) :: r_step = 0, tip_value = 0
      !> d^{n-1}_tip and u^n_tip.
      real(wp) :: d_tip_prev = 0, u_tip_prev = 0
   end type tip_outcome

contains

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
      !> Scene (law).
      type(scene_type), intent(in) :: scene
      !> Model (dt, beta).
      type(model_type), intent(in) :: model
      !> State (spring forces of u^{n-1}, u^n).
      type(state_type), intent(in) :: state
      real(wp) :: f
      f = 0
      if (scene%law == law_compliance) f = newmark_explicit(model%dt2, model%beta, state%p_now, state%p_prev)
   end function spring_term

   !> The contact law at the tip: from the trial tip value u^n_tip + (A^{-1} rhs + d^{n-1})_tip,
   !> the multiple c of z to add, the tip value, the reaction per unit mass of the step and
   !> whether the tip is in contact (SPEC 4, 5).
   subroutine contact_law(scene, model, state, trial, c, tip_value, r_step, contact)
      !> Scene (law, stops).
      type(scene_type), intent(in) :: scene
      !> Model (z, dt, beta).
      type(model_type), intent(in) :: model
      !> State (spring forces moved on under compliance).
      type(state_type), intent(inout) :: state
      !> Trial tip value.
      real(wp), intent(in) :: trial
      !> Multiple of z, tip value of u^{n+1}, reaction of the step.
      real(wp), intent(out) :: c, tip_value, r_step
      !> Whether the stops act.
      logical, intent(out) :: contact
      real(wp) :: e, u_old
      select case (scene%law)
      case (law_signorini)
         if (scene%restitution > 0) then
            ! (u^{n+1}_tip + e u^{n-1}_tip)/(1+e) in [g1, g2]: the projection of u^{n+1}_tip on the
            ! bounds (1+e) g - e u^{n-1}_tip (u^{n-1} = u^n - d^{n-1}; the state is still at step n).
            e = scene%restitution
            u_old = state%u(model%tip) - state%d(model%tip)
            call project_tip(trial, (1 + e)*scene%lower - e*u_old, (1 + e)*scene%upper - e*u_old, &
               & model%z(model%tip), c, tip_value)
         else
            call project_tip(trial, scene%lower, scene%upper, model%z(model%tip), c, tip_value)
         end if
         contact = c /= 0
         r_step = c/model%dt2
      case (law_compliance)
         call compliance_step(trial, scene%lower, scene%upper, scene%stiffness_per_mass, model%dt2, model%beta, &
            & model%z(model%tip), state%p_prev, state%p_now, tip_value, c, r_step, contact)
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
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Model.
      type(model_type), intent(in) :: model
      !> State: rhs holds A^{-1} rhs on entry; u, d and the sums of step n on return.
      type(state_type), intent(inout) :: state
      !> Load average weight of the step and sigma_{n+1}.
      real(wp), intent(in) :: weight, sigma_next
      !> u^n_tip, d^{n-1}_tip and the reaction recorded with u^n.
      real(wp), intent(out) :: u_tip_prev, d_tip_prev, r_prev
      type(tip_outcome) :: outcome
      real(wp) :: gd, c
      call tip_law(scene, model, state, outcome, c)
      call update(state%rhs, c, model%z, state%d, state%u)
      r_prev = state%reaction
      gd = load_work_product(model%load, state%d)
      call fix_tip(scene, model, state, outcome%contact, outcome%tip_value, outcome%u_tip_prev, .true.)
      call settle_tip(scene, model, state, outcome, gd, weight)
      call shift_loads(state, sigma_next)
      u_tip_prev = outcome%u_tip_prev
      d_tip_prev = outcome%d_tip_prev
   end subroutine tip_step

   !> The contact law at the tip (tip_step's first part; the update of d and u with c follows,
   !> then fix_tip sets the tip exactly on the stop and settle_tip books the step). Needs only
   !> the tip row of x = A^{-1} rhs in state%rhs.
   subroutine tip_law(scene, model, state, outcome, c)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Model.
      type(model_type), intent(in) :: model
      !> State at step n: state%rhs(tip) holds the tip row of A^{-1} rhs.
      type(state_type), intent(inout) :: state
      !> The step's contact, reaction and tip values (for fix_tip and settle_tip).
      type(tip_outcome), intent(out) :: outcome
      !> Multiple of z in the update.
      real(wp), intent(out) :: c
      real(wp) :: trial
      outcome%d_tip_prev = state%d(model%tip)
      outcome%u_tip_prev = state%u(model%tip)
      trial = outcome%u_tip_prev + (outcome%d_tip_prev + state%rhs(model%tip))
      call contact_law(scene, model, state, trial, c, outcome%tip_value, outcome%r_step, outcome%contact)
   end subroutine tip_law

   !> tip_step with a massless tip (mass redistribution, SPEC 10): the same law and update (the
   !> tip's row of rhs already holds its equilibrium), then the reaction of the step as the
   !> residual of the tip's Newmark row (massless_reaction), and no exact fix-up of the tip: d
   !> stays the primary variable. That residual makes the energy balance exact (the stops'
   !> energy of the step is -1/2 r (d^n + d^{n-1})), but it is also nonzero for two steps after
   !> the tip leaves a stop (the Newmark average still holds the contact's levels) and carries
   !> rounding when the tip is free: the reaction recorded (state%reaction) is that residual
   !> where the stop acts, 0 elsewhere (SPEC 4: zero off the stops).
   subroutine tip_step_massless(scene, model, state, weight, sigma_next, u_tip_prev, d_tip_prev, r_prev)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Model.
      type(model_type), intent(in) :: model
      !> State: rhs holds A^{-1} rhs on entry; u, d and the sums of step n on return.
      type(state_type), intent(inout) :: state
      !> Load average weight of the step and sigma_{n+1}.
      real(wp), intent(in) :: weight, sigma_next
      !> u^n_tip, d^{n-1}_tip and the reaction recorded with u^n.
      real(wp), intent(out) :: u_tip_prev, d_tip_prev, r_prev
      real(wp) :: trial, c, tip_value, r_step, s_u, s_d_prev
      logical :: contact
      d_tip_prev = state%d(model%tip)
      u_tip_prev = state%u(model%tip)
      s_u = diagonal_row(model%stiffness_diagonals, state%u, model%tip)
      s_d_prev = diagonal_row(model%stiffness_diagonals, state%d, model%tip)
      trial = u_tip_prev + (d_tip_prev + state%rhs(model%tip))
      call contact_law(scene, model, state, trial, c, tip_value, r_step, contact)
      call update(state%rhs, c, model%z, state%d, state%u)
      r_step = massless_reaction(model%beta, weight, model%load(model%tip), s_u, s_d_prev, &
         & diagonal_row(model%stiffness_diagonals, state%d, model%tip))
      r_prev = state%reaction
      call close_step(scene, model, state, contact, tip_value, load_work_product(model%load, state%d), weight, r_step, &
         & d_tip_prev, u_tip_prev, sigma_next, .false.)
      if (.not. contact) state%reaction = 0
   end subroutine tip_step_massless

   !> After the update: the exact tip value (Signorini), the violation of the stops, the energy
   !> taken by the stops, and the sums of every path (beamstops_ledger's move_on).
   pure subroutine close_step(scene, model, state, contact, tip_value, gd, weight, r_step, d_tip_prev, u_tip_prev, &
      & sigma_next, exact)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Model.
      type(model_type), intent(in) :: model
      !> State after the update.
      type(state_type), intent(inout) :: state
      !> Whether the stops act.
      logical, intent(in) :: contact
      !> Tip value of the law, g.d^n, weight, reaction, d^{n-1}_tip, u^n_tip and sigma_{n+1}.
      real(wp), intent(in) :: tip_value, gd, weight, r_step, d_tip_prev, u_tip_prev, sigma_next
      !> Whether a tip in contact is set exactly on the stop (not with a massless tip).
      logical, intent(in) :: exact
      call fix_tip(scene, model, state, contact, tip_value, u_tip_prev, exact)
      call settle_tip(scene, model, state, tip_outcome(contact, r_step, tip_value, d_tip_prev, u_tip_prev), gd, weight)
      call shift_loads(state, sigma_next)
   end subroutine close_step

   !> The tip exactly on the stop after a Signorini contact, and d^n its exact increment (a tip
   !> resting on a stop then has exactly zero velocity); with `exact` false (a massless tip) nothing.
   pure subroutine fix_tip(scene, model, state, contact, tip_value, u_tip_prev, exact)
      !> Scene (law).
      type(scene_type), intent(in) :: scene
      !> Model (tip).
      type(model_type), intent(in) :: model
      !> State after the update.
      type(state_type), intent(inout) :: state
      !> Whether the stops act.
      logical, intent(in) :: contact
      !> Tip value of the law and u^n_tip.
      real(wp), intent(in) :: tip_value, u_tip_prev
      !> Whether a tip in contact is set exactly on the stop.
      logical, intent(in) :: exact
      if (scene%law == law_signorini .and. contact .and. exact) then
         state%u(model%tip) = tip_value
         state%d(model%tip) = tip_value - u_tip_prev
      end if
   end subroutine fix_tip

   !> The books of a step at the tip once u^{n+1} and d^n are final (they may wait while the next
   !> step's forward pass runs; the load averages are moved on apart, shift_loads): the violation
   !> of the stops, impacts, work and reaction (book_step) and the energy taken by the stops.
   pure subroutine settle_tip(scene, model, state, outcome, gd, weight)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Model.
      type(model_type), intent(in) :: model
      !> State after the update (u^{n+1}, d^n).
      type(state_type), intent(inout) :: state
      !> The step's contact, reaction and tip values before it.
      type(tip_outcome), intent(in) :: outcome
      !> g.d^n and the load average weight of the step.
      real(wp), intent(in) :: gd, weight
      if (scene%law /= law_none) state%max_violation = max(state%max_violation, violation(state%u(model%tip), scene))
      call book_step(state, outcome%contact, gd, weight, outcome%r_step)
      state%dissipated = state%dissipated - 0.5_wp*outcome%r_step*(state%d(model%tip) + outcome%d_tip_prev)
   end subroutine settle_tip

   !> Violation of the stops by a tip value (m).
   pure function violation(u_tip, scene) result(v)
      !> Tip value (m).
      real(wp), intent(in) :: u_tip
      !> Scene (stops).
      type(scene_type), intent(in) :: scene
      real(wp) :: v
      v = max(u_tip - scene%upper, scene%lower - u_tip, 0.0_wp)
   end function violation
end module beamstops_contact_tip_contact
