!> The general lockstep loop (SPEC 13 with SPEC 8-10): advance_members of beamstops_lockstep with
!> Rayleigh damping, restitution and/or the massless tip of mass redistribution, as
!> beamstops_scheme's advance_fused_general is advance_fused with them. A loop of its own, so that
!> the loop of the paper's scheme stays as it is (simulate_lockstep branches once per block); the
!> members' state and the shared pieces of a step are beamstops_lockstep_members'. Unlike the plain
!> loop (which keeps a step's values in fixed-size lanes, beamstops_lockstep_lanes), it keeps them
!> in the members' arrays (allocated only for a general group) and is not tuned for speed.
!>
!> Per member and step, the operations of advance_fused_general in the same order:
!> - the forward pass with -dt C d^{n-1} in the right-hand side (lockstep_matvec_rhs_damped) and,
!>   with a massless tip, the tip's row replaced by its equilibrium: equilibrium_rows itself, lane
!>   by lane (a lane-vectorized copy of it was correct alone but, inlined under LTO, rounded
!>   differently from the one-scene path's: the whole-run tests caught it);
!> - the back substitution and the tip's law: with restitution e > 0 (member's own e), the
!>   projection on the bounds (1 + e) g - e u^{n-1}_tip (contact_law of
!>   beamstops_contact_tip_contact); with a massless tip, the reaction of the step the residual of
!>   the tip's Newmark row (tip_step_massless) and no exact fix-up of the tip;
!> - the update, g.d, the bookkeeping (close_step), the observer fed with the reaction only in
!>   contact (merge(reaction, 0, in_contact), as every one-scene path does);
!> - damping_loss: d^n.C d^{n-1}, C d^n, d^n.C d^n and the energy the damping took (the
!>   /energy/damped column and the ledger's damped energy).
!> Members share C and the mass law (they enter A); e may differ per member.
module beamstops_lockstep_general
   use beamstops_kinds, only: wp, ik
   use beamstops_scene, only: scene_type, law_signorini, law_compliance
   use beamstops_model, only: model_type
   use beamstops_observe_lanes, only: observer_lanes, gather_observers, scatter_observers, observe_lanes
   use beamstops_band_solve, only: energy_dots
   use beamstops_newmark, only: newmark_average, newmark_explicit, newmark_work
   use beamstops_band_solve_lockstep, only: lockstep_lanes, lockstep_matvec_rhs, lockstep_forward, &
      & lockstep_matvec_rhs_forward, lockstep_energy_dots, lockstep_back, lockstep_update, lockstep_dot, lockstep_matvec, &
      & lockstep_load_work
   use beamstops_band_solve_lockstep_general, only: lockstep_matvec_rhs_damped, lockstep_row
   use beamstops_contact_mass_redistribution, only: massless_reaction, equilibrium_rows
   use beamstops_lockstep_store, only: chunk_store, fill_store, give_back, put_lane, part_u, part_d, part_su, &
      & part_rhs, part_g, part_cd
   use beamstops_lockstep_members, only: operators_type, members_type, lane, chunk, contact_law, close_steps, &
      & project_lanes, fill_row_members, take_snapshot, start_loads, next_loads, first_events, energy
   use beamstops_recorder, only: recorder_type, col_energy
   implicit none
   private
   public :: advance_members_general

contains

   !> Advance every member from ms%step through step `last`: advance_members of
   !> beamstops_lockstep with damping, restitution and/or a massless tip (advance_fused_general
   !> of beamstops_scheme, per member, the member index innermost).
   subroutine advance_members_general(scenes, model, ops, ms, recorders, last)
      !> The members' scenes (K).
      type(scene_type), intent(in) :: scenes(:)
      !> The shared model.
      type(model_type), intent(in) :: model
      !> The shared operators (S, M, C by diagonals, the factor of A).
      type(operators_type), intent(in) :: ops
      !> The members' state, advanced.
      type(members_type), intent(inout) :: ms
      !> One recorder per member (K).
      class(recorder_type), intent(inout) :: recorders(:)
      !> Last step to do.
      integer(ik), intent(in) :: last
      integer(ik) :: step, next_record, next_snapshot
      integer :: k, c, lo, hi, n, tip, law, i
      logical :: energy_wanted, pending, observing, damped, massless
      real(wp) :: sums(3), reaction(lockstep_lanes)
      type(observer_lanes), allocatable :: watch(:)
      type(chunk_store) :: w

      n = ms%n
      tip = model%tip
      law = scenes(1)%law
      damped = model%damped
      massless = model%redistributed
      do k = 1, ms%k
         call first_events(scenes(k), ms%step, ms%next_record(k), ms%next_snapshot(k))
      end do
      next_record = minval(ms%next_record)
      next_snapshot = minval(ms%next_snapshot)
      observing = any(ms%observers%active)
      if (observing) call gather_observers(watch, ms%observers, ms%active(:ms%k))
      ms%pending = .false.
      pending = .false.
      ms%u_old_su = 0
      ms%dmd = 0
      call start_loads(ms, ms%step + 1, scenes, model)
      if (damped) then
         call fill_store(w, ms%u, ms%d, ms%su, ms%g, ms%cd)
      else
         call fill_store(w, ms%u, ms%d, ms%su, ms%g)
      end if
      do step = ms%step, last
         ms%sigma_next = ms%sigma
         call next_loads(ms, scenes, model)
         do k = 1, size(ms%weight)
            ms%weight(k) = newmark_average(model%beta, ms%sigma_next(k), ms%sigma_now(k), ms%sigma_prev(k))
         end do
         ! the forward pass (forward_pass with cd, massless rows), a chunk of members after the other
         ms%coef = model%dt2*ms%weight
         if (law == law_compliance) then
            do k = 1, size(ms%spring)
               ms%spring(k) = newmark_explicit(model%dt2, model%beta, ms%p_now(k), ms%p_prev(k))
            end do
         end if
         energy_wanted = pending .or. step == next_record
         do c = 1, ms%chunks
            lo = (c - 1)*lockstep_lanes + 1
            hi = c*lockstep_lanes
            if (damped .and. ops%periodic) then
               call lockstep_matvec_rhs_damped(ops%stiffness, w%store(w%at(part_u, c)), ms%coef(lo:hi), &
                  & w%store(w%at(part_g, c)), model%dt2, ms%spring(lo:hi), w%store(w%at(part_cd, c)), model%dt, &
                  & w%store(w%at(part_su, c)), w%store(w%at(part_rhs, c)), ops%stiffness_rows)
            else if (damped) then
               call lockstep_matvec_rhs_damped(ops%stiffness, w%store(w%at(part_u, c)), ms%coef(lo:hi), &
                  & w%store(w%at(part_g, c)), model%dt2, ms%spring(lo:hi), w%store(w%at(part_cd, c)), model%dt, &
                  & w%store(w%at(part_su, c)), w%store(w%at(part_rhs, c)))
            else if (ops%periodic .and. .not. massless) then
               ! the product and the forward substitution in one pass
               call lockstep_matvec_rhs_forward(ops%stiffness, ops%solver, ops%stiffness_rows, &
                  & w%store(w%at(part_u, c)), ms%coef(lo:hi), w%store(w%at(part_g, c)), model%dt2, ms%spring(lo:hi), &
                  & w%store(w%at(part_su, c)), w%store(w%at(part_rhs, c)))
            else if (ops%periodic) then
               call lockstep_matvec_rhs(ops%stiffness, w%store(w%at(part_u, c)), ms%coef(lo:hi), &
                  & w%store(w%at(part_g, c)), model%dt2, ms%spring(lo:hi), w%store(w%at(part_su, c)), &
                  & w%store(w%at(part_rhs, c)), ops%stiffness_rows)
            else
               call lockstep_matvec_rhs(ops%stiffness, w%store(w%at(part_u, c)), ms%coef(lo:hi), &
                  & w%store(w%at(part_g, c)), model%dt2, ms%spring(lo:hi), w%store(w%at(part_su, c)), &
                  & w%store(w%at(part_rhs, c)))
            end if
            if (massless) then
               do k = lo, hi
                  ! member k's lane of each vector: every lockstep_lanes-th value of the chunk's
                  i = lane(k) - 1
                  call equilibrium_rows(model%massless, model%row_scale, ms%sigma_next(k), &
                     & w%store(w%at(part_g, c) + i:w%row_end(part_g, c, n):lockstep_lanes), &
                     & w%store(w%at(part_su, c) + i:w%row_end(part_su, c, n):lockstep_lanes), ops%stiffness, &
                     & w%store(w%at(part_d, c) + i:w%row_end(part_d, c, n):lockstep_lanes), &
                     & w%store(w%at(part_rhs, c) + i:w%row_end(part_rhs, c, n):lockstep_lanes))
               end do
            end if
            if (energy_wanted) then
               call lockstep_energy_dots(ops%mass, w%store(w%at(part_u, c)), w%store(w%at(part_d, c)), &
                  & w%store(w%at(part_su, c)), ms%usu(lo:hi), ms%dsu(lo:hi), ms%dmd(lo:hi))
            end if
            if (damped .or. massless .or. .not. ops%periodic) then
               call lockstep_forward(ops%solver, w%store(w%at(part_rhs, c)))
            end if
         end do
         if (pending) then
            do k = 1, ms%k
               if (.not. ms%pending(k)) cycle
               ms%rows(col_energy, k) = scenes(k)%mass_per_length*energy(model, ms%dmd(k), ms%usu(k), ms%dsu(k), &
                  & ms%u_old_su(k))
               if (ms%active(k)) call recorders(k)%record(ms%rows(:, k))
               ms%pending(k) = .false.
            end do
            pending = .false.
         end if
         if (energy_wanted) then
            ms%u_old_su = ms%usu
         else
            ms%u_old_su = 0
         end if
         ! the back substitution and the tip step (tip_step, tip_step_massless)
         do c = 1, ms%chunks
            lo = (c - 1)*lockstep_lanes + 1
            hi = c*lockstep_lanes
            call lockstep_back(ops%solver, w%store(w%at(part_rhs, c)))
            ms%d_tip_prev(lo:hi) = w%store(w%row(part_d, c, tip):w%row_end(part_d, c, tip))
            ms%u_tip_prev(lo:hi) = w%store(w%row(part_u, c, tip):w%row_end(part_u, c, tip))
            if (massless) then
               call lockstep_row(ops%stiffness, w%store(w%at(part_u, c)), tip, ms%s_u_tip(lo:hi))
               call lockstep_row(ops%stiffness, w%store(w%at(part_d, c)), tip, ms%s_d_prev_tip(lo:hi))
            end if
            ms%trial(lo:hi) = ms%u_tip_prev(lo:hi) + (ms%d_tip_prev(lo:hi) &
               & + w%store(w%row(part_rhs, c, tip):w%row_end(part_rhs, c, tip)))
         end do
         if (law == law_signorini) then
            do c = 1, ms%chunks
               lo = (c - 1)*lockstep_lanes + 1
               hi = c*lockstep_lanes
               call restitution_bounds(ms%restitution(lo:hi), ms%lower(lo:hi), ms%upper(lo:hi), &
                  & ms%u_tip_prev(lo:hi), ms%d_tip_prev(lo:hi), ms%bound_lower(lo:hi), ms%bound_upper(lo:hi))
               call project_lanes(ms%trial(lo:hi), ms%bound_lower(lo:hi), ms%bound_upper(lo:hi), model%z(tip), &
                  & model%dt2, ms%tip_value(lo:hi), ms%c(lo:hi), ms%contact(lo:hi), ms%r_step(lo:hi))
            end do
         else
            call contact_law(law, scenes, model, ms)
         end if
         do c = 1, ms%chunks
            lo = (c - 1)*lockstep_lanes + 1
            hi = c*lockstep_lanes
            call lockstep_update(n, w%store(w%at(part_rhs, c)), ms%c(lo:hi), model%z, w%store(w%at(part_d, c)), &
               & w%store(w%at(part_u, c)))
            call lockstep_load_work(n, w%store(w%at(part_g, c)), w%store(w%at(part_d, c)), ms%gd(lo:hi))
            ms%u_tip(lo:hi) = w%store(w%row(part_u, c, tip):w%row_end(part_u, c, tip))
            ms%d_tip(lo:hi) = w%store(w%row(part_d, c, tip):w%row_end(part_d, c, tip))
            if (massless) then
               ! the reaction of the step: the residual of the tip's Newmark row (massless_reaction)
               call lockstep_row(ops%stiffness, w%store(w%at(part_d, c)), tip, ms%cross(lo:hi))
               do k = lo, hi
                  ms%r_step(k) = massless_reaction(model%beta, ms%weight(k), &
                     & w%store(w%row(part_g, c, tip) + lane(k) - 1), ms%s_u_tip(k), &
                     & ms%s_d_prev_tip(k), ms%cross(k))
               end do
            end if
         end do
         ms%r_prev = ms%reaction
         if (massless) then
            call close_massless(ms)
         else
            call close_steps(law, ms)
            if (law == law_signorini) then
               do c = 1, ms%chunks
                  lo = (c - 1)*lockstep_lanes + 1
                  hi = c*lockstep_lanes
                  w%store(w%row(part_u, c, tip):w%row_end(part_u, c, tip)) = ms%u_tip(lo:hi)
                  w%store(w%row(part_d, c, tip):w%row_end(part_d, c, tip)) = ms%d_tip(lo:hi)
               end do
            end if
         end if
         ! the shock log and statistics of each member that keeps them
         if (observing) then
            do c = 1, ms%chunks
               lo = (c - 1)*lockstep_lanes + 1
               hi = c*lockstep_lanes
               reaction = merge(ms%reaction(lo:hi), 0.0_wp, ms%in_contact(lo:hi))
               call observe_lanes(watch(c), ms%observers, real(step + 1, wp)*model%dt, ms%u_tip(lo:hi), reaction, &
                  & ms%dissipated(lo:hi))
            end do
         end if
         ! the energy the damping took (damping_loss), C d^n for the next step
         if (damped) then
            do c = 1, ms%chunks
               lo = (c - 1)*lockstep_lanes + 1
               hi = c*lockstep_lanes
               call lockstep_dot(n, w%store(w%at(part_d, c)), w%store(w%at(part_cd, c)), ms%partial, ms%cross(lo:hi))
               call lockstep_matvec(ops%damping, w%store(w%at(part_d, c)), w%store(w%at(part_cd, c)))
               call lockstep_dot(n, w%store(w%at(part_d, c)), w%store(w%at(part_cd, c)), ms%partial, ms%dcd(lo:hi))
            end do
            call damping_lanes(model%dt, ms%cross, ms%dcd, ms%dcd_prev, ms%damped)
         end if
         ! records and snapshots
         if (step == next_record .or. step == next_snapshot) then
            do k = 1, ms%k
               if (step == ms%next_record(k)) then
                  ms%next_record(k) = ms%next_record(k) + scenes(k)%record_every
                  call fill_row_members(scenes(k), model, ms, w%store(w%row(part_d, chunk(k), tip) + lane(k) - 1), k, &
                     & step, ms%rows(:, k))
                  ms%pending(k) = .true.
                  pending = .true.
               end if
               if (step == ms%next_snapshot(k)) then
                  ms%next_snapshot(k) = ms%next_snapshot(k) + scenes(k)%snapshot_every
                  if (ms%active(k)) then
                     call put_lane(w, part_u, chunk(k), lane(k), ms%u)
                     call put_lane(w, part_d, chunk(k), lane(k), ms%d)
                     call take_snapshot(scenes(k), model, ms, k, step, recorders(k))
                  end if
               end if
            end do
            next_record = minval(ms%next_record)
            next_snapshot = minval(ms%next_snapshot)
         end if
      end do
      if (damped) then
         call give_back(w, ms%u, ms%d, ms%su, ms%cd)
      else
         call give_back(w, ms%u, ms%d, ms%su)
      end if
      if (observing) call scatter_observers(watch, ms%observers)
      ! S u^{last+1}; it also completes the waiting records (advance_members)
      do c = 1, ms%chunks
         call lockstep_matvec(ops%stiffness, ms%u(:, :, c), ms%su(:, :, c))
      end do
      do k = 1, ms%k
         if (.not. ms%pending(k)) cycle
         ms%pending(k) = .false.
         if (.not. ms%active(k)) cycle
         ms%vec_u = ms%u(lane(k), :, chunk(k))
         ms%vec_d = ms%d(lane(k), :, chunk(k))
         ms%vec_su = ms%su(lane(k), :, chunk(k))
         call energy_dots(ops%mass, ms%vec_u, ms%vec_d, ms%vec_su, sums(1), sums(2), sums(3))
         ms%rows(col_energy, k) = scenes(k)%mass_per_length*energy(model, sums(3), sums(1), sums(2), ms%u_old_su(k))
         call recorders(k)%record(ms%rows(:, k))
      end do
   end subroutine advance_members_general

   !> The bounds of the tip's projection of a chunk of lanes (contact_law of
   !> beamstops_contact_tip_contact): with restitution e > 0, (1 + e) g - e u^{n-1}_tip with
   !> u^{n-1}_tip = u^n_tip - d^{n-1}_tip (Paoli-Schatzman, SPEC 9); the stops themselves otherwise.
   pure subroutine restitution_bounds(e, lower, upper, u_tip, d_tip, bound_lower, bound_upper)
      real(wp), intent(in) :: e(lockstep_lanes), lower(lockstep_lanes), upper(lockstep_lanes), &
         & u_tip(lockstep_lanes), d_tip(lockstep_lanes)
      real(wp), intent(out) :: bound_lower(lockstep_lanes), bound_upper(lockstep_lanes)
      real(wp) :: u_old
      integer :: k
      do k = 1, lockstep_lanes
         if (e(k) > 0) then
            u_old = u_tip(k) - d_tip(k)
            bound_lower(k) = (1 + e(k))*lower(k) - e(k)*u_old
            bound_upper(k) = (1 + e(k))*upper(k) - e(k)*u_old
         else
            bound_lower(k) = lower(k)
            bound_upper(k) = upper(k)
         end if
      end do
   end subroutine restitution_bounds

   !> The energy the damping took in the step, for every lane (beamstops_ledger's damping_loss):
   !> damped += (d^n.C d^n + 2 d^n.C d^{n-1} + d^{n-1}.C d^{n-1})/(4 dt).
   pure subroutine damping_lanes(dt, cross, dcd, dcd_prev, damped)
      real(wp), intent(in) :: dt
      real(wp), intent(in) :: cross(:), dcd(:)
      real(wp), intent(inout) :: dcd_prev(:), damped(:)
      integer :: k
      do k = 1, size(damped)
         damped(k) = damped(k) + (dcd(k) + 2*cross(k) + dcd_prev(k))/(4*dt)
         dcd_prev(k) = dcd(k)
      end do
   end subroutine damping_lanes

   !> close_steps with a massless tip (close_step with exact = .false.): no fix-up of the tip
   !> (d stays the primary variable), then the violation, impacts, the work of the load, the
   !> energy the stops take and the load averages moved on.
   subroutine close_massless(ms)
      type(members_type), intent(inout) :: ms
      integer :: k
      do k = 1, ms%p
         ms%max_violation(k) = max(ms%max_violation(k), max(ms%u_tip(k) - ms%upper(k), ms%lower(k) - ms%u_tip(k), &
            & 0.0_wp))
         if (ms%contact(k) .and. .not. ms%in_contact(k)) ms%impacts(k) = ms%impacts(k) + 1
         ms%in_contact(k) = ms%contact(k)
         ms%work(k) = newmark_work(ms%work(k), ms%weight(k), ms%gd(k), ms%gd_prev(k))
         ! recorded only where the stop acts (tip_step_massless)
         ms%reaction(k) = merge(ms%r_step(k), 0.0_wp, ms%contact(k))
         ms%gd_prev(k) = ms%gd(k)
         ms%sigma_prev(k) = ms%sigma_now(k)
         ms%sigma_now(k) = ms%sigma_next(k)
         ms%dissipated(k) = ms%dissipated(k) - 0.5_wp*ms%r_step(k)*(ms%d_tip(k) + ms%d_tip_prev(k))
      end do
   end subroutine close_massless
end module beamstops_lockstep_general
