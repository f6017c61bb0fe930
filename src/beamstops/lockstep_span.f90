!> The lockstep loop with stops along the span (SPEC 13 with SPEC 7): K members that share A and
!> the stops' nodes (hence P, the columns Z = A^{-1} P and C = P^T A^{-1} P) advance together
!> through the two band substitutions of a step, the member index innermost; then, member after
!> member, the contact work of advance_span of beamstops_scheme on that member's own vectors: the
!> trial values at the stops, the box QP on C when some are out (span_contact), the correction and
!> the update, the stops settled on their bounds (span_settle), the ledger (move_on, span_energy,
!> damping_loss), the observer's span_indexed hook, the records and snapshots. Each member keeps a
!> whole one-scene state (state_type, from the one-scene start_state) and a model of its own (built
!> from its scene: its load vector, initial velocity and its stops' bounds), so that every operation
!> after the substitutions is the one-scene path's own routine on the same numbers.
!>
!> Per step and member, the operations of advance_span in the same order:
!> - the forward pass (lockstep_matvec_rhs, with -dt C d^{n-1} lockstep_matvec_rhs_damped; the rows
!>   of the massless unknowns by equilibrium_rows, lane by lane), the forward substitution with its
!>   energy sums on the steps that want them (a member that does not gets 0, as forward_pass gives);
!> - the whole back substitution (lockstep_back), x handed to the member's state (rhs);
!> - the rest of the step on the member's state: beamstops_span_step's span_step, the routine advance_span calls.
!> A member's u, d (and C d^{n-1}) go into the lanes at the start of each step and its x comes
!> back (O(n) copies per member and step beside the O(n) contact work). A member whose QP fails
!> ends its block there (advance_span's exit) and leaves the group with run_scheme's status; the
!> others go on. Members may differ in what advance_span reads from the scene and from the parts of
!> the model that do not enter A: the support (amplitude, omega), the stops' bounds (&stops lower,
!> upper per stop), the restitution coefficient, the load rule, the start, the output cadence.
module beamstops_lockstep_span
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type
   use beamstops_strings, only: fmt_int, fmt_real
   use beamstops_scene, only: scene_type, steps_of
   use beamstops_model, only: model_type, build_model
   use beamstops_band, only: band_matvec
   use beamstops_band_solve_lockstep, only: lockstep_lanes, lockstep_matvec_rhs, &
      & lockstep_forward, lockstep_energy_dots, lockstep_back
   use beamstops_band_solve_lockstep_general, only: lockstep_matvec_rhs_damped
   use beamstops_contact_mass_redistribution, only: equilibrium_rows
   use beamstops_contact_box_qp, only: qp_solved, qp_message
   use beamstops_state, only: state_type
   use beamstops_scheme, only: start_state, block_steps, close_ledger
   use beamstops_clock, only: thread_cpu_seconds
   use beamstops_lockstep_members, only: operators_type, lane, chunk
   use beamstops_span_step, only: span_loop_type, start_span_block, next_span_step, span_step, end_span_block
   use beamstops_recorder, only: recorder_type
   use beamstops_stop_signals, only: stop_signal
   use beamstops_summary, only: mark_interrupted, lockstep_no_checkpoint, run_summary, status_complete, status_failed, status_running, &
      & check_divergence
   implicit none
   private
   public :: simulate_span_lockstep

   !> The lanes of a step (lanes, n, chunks) and the per-member values the substitutions give.
   type :: span_lanes_type
      real(wp), allocatable :: u(:, :, :), d(:, :, :), su(:, :, :), rhs(:, :, :), g(:, :, :), cd(:, :, :)
      real(wp), allocatable :: coef(:), spring(:), usu(:), dsu(:), dmd(:)
   end type span_lanes_type


contains

   !> Run K members with stops along the span from t = 0 to their (common) end in lockstep (the
   !> group checked by check_lockstep); each member's records, snapshots and summary are those of
   !> simulate(scenes(k), ...) run alone. cpu_seconds of a summary is the member's share (1/K).
   subroutine simulate_span_lockstep(scenes, model, ops, recorders, summaries, error, initial_displacement)
      !> The members' validated scenes (K).
      type(scene_type), intent(in) :: scenes(:)
      !> The model built from scenes(1).
      type(model_type), intent(in) :: model
      !> The shared operators (S, M, C by diagonals, the factor of A).
      type(operators_type), intent(in) :: ops
      !> One recorder per member (K).
      class(recorder_type), intent(inout) :: recorders(:)
      !> One summary per member (K).
      type(run_summary), intent(inout) :: summaries(:)
      !> Set when a member's model or start fails.
      type(error_type), allocatable, intent(out) :: error
      !> Initial displacement of each member (n, K), in place of the model's.
      real(wp), intent(in), optional :: initial_displacement(:, :)
      type(model_type), allocatable :: models(:)
      type(state_type), allocatable :: states(:)
      type(span_lanes_type) :: lanes
      logical, allocatable :: active(:)
      integer(ik) :: steps, last, first
      real(wp) :: t0, kinetic
      integer :: k, nk

      nk = size(scenes)
      allocate (models(nk), states(nk), active(nk))
      do k = 1, nk
         if (k == 1) then
            models(k) = model
         else
            call build_model(scenes(k), models(k), error)
         end if
         if (.not. allocated(error)) then
            if (present(initial_displacement)) models(k)%u0 = initial_displacement(:, k)
            call start_state(scenes(k), models(k), states(k), recorders(k), error)
         end if
         if (allocated(error)) then
            error%message = 'lockstep: member '//fmt_int(int(k, ik))//': '//error%message
            return
         end if
      end do
      call new_lanes(model, nk, lanes)
      do k = 1, nk
         lanes%g(lane(k), :, chunk(k)) = models(k)%load
      end do
      steps = steps_of(scenes(1))
      do k = 1, nk
         summaries(k)%status = status_running
      end do
      active = .true.
      t0 = thread_cpu_seconds()
      do while (any(active))
         first = minval(states%step, mask=active)
         last = min(steps, first + block_steps - 1)
         call advance_span_members(scenes, models, ops, states, lanes, recorders, active, last)
         do k = 1, nk
            if (.not. active(k)) cycle
            ! run_scheme's checks between blocks
            if (recorders(k)%failed) then
               summaries(k)%status = status_failed
               summaries(k)%message = 'the recorder could not write'
            else if (states(k)%span%info /= qp_solved) then
               summaries(k)%status = status_failed
               summaries(k)%message = qp_message(states(k)%span%info)//' at t = '// &
                  & fmt_real(real(states(k)%step, wp)*model%dt, 6)//' s'
            else
               call band_matvec(models(k)%mass, states(k)%d, states(k)%scratch)
               kinetic = 0.5_wp*dot_product(states(k)%d, states(k)%scratch)/model%dt2
               call check_divergence(scenes(k), kinetic, states(k)%energy0, states(k)%work, states(k)%dissipated, &
                  & real(states(k)%step - 1, wp)*model%dt, recorders(k)%blew_up, recorders(k)%blew_up_at, summaries(k))
            end if
            if (summaries(k)%status == status_running) then
               if (states(k)%observer%active) call states(k)%observer%drain()
               call recorders(k)%progress(states(k)%step - 1, steps)
               if (states(k)%step <= steps) cycle
            end if
            call finish_member(scenes(k), models(k), states(k), summaries(k), (thread_cpu_seconds() - t0)/nk)
            active(k) = .false.
            lanes%u(lane(k), :, chunk(k)) = 0
            lanes%d(lane(k), :, chunk(k)) = 0
            lanes%g(lane(k), :, chunk(k)) = 0
            if (allocated(lanes%cd)) lanes%cd(lane(k), :, chunk(k)) = 0
         end do
         if (stop_signal() /= 0) exit
      end do
      ! stopped by a signal (beamstops_stop_signals, caught by simulate_group's caller)
      do k = 1, nk
         if (.not. active(k)) cycle
         call finish_member(scenes(k), models(k), states(k), summaries(k), (thread_cpu_seconds() - t0)/nk)
         call mark_interrupted(scenes(k), stop_signal(), lockstep_no_checkpoint, summaries(k))
      end do
   end subroutine simulate_span_lockstep

   !> run_scheme's summary of a member that leaves the group (counts, close_ledger, the observer's
   !> shocks and statistics).
   subroutine finish_member(scene, model, state, summary, cpu_seconds)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(state_type), intent(inout) :: state
      type(run_summary), intent(inout) :: summary
      real(wp), intent(in) :: cpu_seconds
      summary%cpu_seconds = cpu_seconds
      summary%steps = state%step - 1
      summary%t_final = real(summary%steps, wp)*model%dt
      summary%impacts = state%impacts
      summary%max_violation = state%max_violation
      summary%contact_phases = state%impacts
      call close_ledger(scene, model, state, summary)
      if (summary%status == status_running .and. state%step > steps_of(scene)) summary%status = status_complete
      call state%observer%book_summary(summary)
   end subroutine finish_member

   !> The lanes of the group, zero (padding lanes stay at rest).
   subroutine new_lanes(model, nk, lanes)
      type(model_type), intent(in) :: model
      integer, intent(in) :: nk
      type(span_lanes_type), intent(out) :: lanes
      integer :: chunks, p, n
      n = model%n
      chunks = (nk + lockstep_lanes - 1)/lockstep_lanes
      p = chunks*lockstep_lanes
      allocate (lanes%u(lockstep_lanes, n, chunks), lanes%d(lockstep_lanes, n, chunks), &
         & lanes%su(lockstep_lanes, n, chunks), lanes%rhs(lockstep_lanes, n, chunks), &
         & lanes%g(lockstep_lanes, n, chunks))
      allocate (lanes%coef(p), lanes%spring(p), lanes%usu(p), lanes%dsu(p), lanes%dmd(p))
      lanes%u = 0
      lanes%d = 0
      lanes%su = 0
      lanes%rhs = 0
      lanes%g = 0
      lanes%coef = 0
      lanes%spring = 0
      lanes%usu = 0
      lanes%dsu = 0
      lanes%dmd = 0
      if (model%damped) then
         allocate (lanes%cd(lockstep_lanes, n, chunks))
         lanes%cd = 0
      end if
   end subroutine new_lanes

   !> Advance every active member from its state's step through step `last` (advance_span of
   !> beamstops_scheme per member, the substitutions in lockstep). A member whose QP fails stops
   !> at the step before (its state's step says where, its span%info why).
   subroutine advance_span_members(scenes, models, ops, states, lanes, recorders, active, last)
      type(scene_type), intent(in) :: scenes(:)
      type(model_type), intent(in) :: models(:)
      type(operators_type), intent(in) :: ops
      type(state_type), intent(inout) :: states(:)
      type(span_lanes_type), intent(inout) :: lanes
      class(recorder_type), intent(inout) :: recorders(:)
      logical, intent(in) :: active(:)
      integer(ik), intent(in) :: last
      type(span_loop_type) :: loop(size(scenes))
      integer(ik) :: step, first
      integer :: k, nk, c, chunks, lo, hi
      logical :: energy_wanted, damped, massless

      nk = size(scenes)
      chunks = size(lanes%u, 3)
      damped = models(1)%damped
      massless = models(1)%redistributed
      first = huge(1_ik)
      do k = 1, nk
         if (.not. active(k)) cycle
         call start_span_block(scenes(k), models(k), states(k), loop(k))
         first = min(first, states(k)%step)
      end do
      do step = first, last
         if (.not. any(loop%live)) exit
         energy_wanted = .false.
         do k = 1, nk
            if (.not. loop(k)%live) cycle
            call next_span_step(scenes(k), models(k), states(k), loop(k), step)
            associate (state => states(k), lp => loop(k), model => models(k))
               lanes%coef(k) = model%dt2*lp%weight
               lanes%u(lane(k), :, chunk(k)) = state%u
               lanes%d(lane(k), :, chunk(k)) = state%d
               if (damped) lanes%cd(lane(k), :, chunk(k)) = state%cd
               energy_wanted = energy_wanted .or. lp%pending .or. step == lp%next_record
            end associate
         end do
         ! the forward pass of every chunk (forward_pass, spring 0)
         do c = 1, chunks
            lo = (c - 1)*lockstep_lanes + 1
            hi = c*lockstep_lanes
            if (damped) then
               call lockstep_matvec_rhs_damped(ops%stiffness, lanes%u(:, :, c), lanes%coef(lo:hi), lanes%g(:, :, c), &
                  & models(1)%dt2, lanes%spring(lo:hi), lanes%cd(:, :, c), models(1)%dt, lanes%su(:, :, c), &
                  & lanes%rhs(:, :, c))
            else
               call lockstep_matvec_rhs(ops%stiffness, lanes%u(:, :, c), lanes%coef(lo:hi), lanes%g(:, :, c), &
                  & models(1)%dt2, lanes%spring(lo:hi), lanes%su(:, :, c), lanes%rhs(:, :, c))
            end if
            if (massless) then
               do k = lo, min(hi, nk)
                  if (.not. loop(k)%live) cycle
                  call equilibrium_rows(models(k)%massless, models(k)%row_scale, loop(k)%sigma_next, &
                     & lanes%g(lane(k), :, c), lanes%su(lane(k), :, c), ops%stiffness, lanes%d(lane(k), :, c), &
                     & lanes%rhs(lane(k), :, c))
               end do
            end if
            if (energy_wanted) then
               call lockstep_energy_dots(ops%mass, lanes%u(:, :, c), lanes%d(:, :, c), lanes%su(:, :, c), &
                  & lanes%usu(lo:hi), lanes%dsu(lo:hi), lanes%dmd(lo:hi))
            end if
            call lockstep_forward(ops%solver, lanes%rhs(:, :, c))
            call lockstep_back(ops%solver, lanes%rhs(:, :, c))
         end do
         ! each member's contact work, on its own state
         do k = 1, nk
            if (.not. loop(k)%live) cycle
            if (.not. (energy_wanted .and. (loop(k)%pending .or. step == loop(k)%next_record))) then
               lanes%usu(k) = 0
               lanes%dsu(k) = 0
               lanes%dmd(k) = 0
            end if
            ! x back (S u^n is not read again before end_span_block computes S u^{last+1})
            states(k)%rhs = lanes%rhs(lane(k), :, chunk(k))
            call span_step(scenes(k), models(k), states(k), loop(k), recorders(k), step, lanes%usu(k), &
               & lanes%dsu(k), lanes%dmd(k))
            if (.not. loop(k)%live) call end_span_block(scenes(k), models(k), states(k), loop(k), recorders(k))
         end do
      end do
      do k = 1, nk
         if (loop(k)%live) call end_span_block(scenes(k), models(k), states(k), loop(k), recorders(k))
      end do
   end subroutine advance_span_members
end module beamstops_lockstep_span
