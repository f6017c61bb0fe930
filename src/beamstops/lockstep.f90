!> Lockstep ensembles (SPEC 13): K members that share A = M + dt/2 C + dt^2 beta S (the same
!> mesh, beam, time step, beta, damping, mass law, contact law and number of steps) advance
!> together, the member index innermost (arrays (K, n)), so that each multiply-add of the two
!> substitutions of a step serves K members and the dependency chain of a step is paid once for
!> all of them.
!>
!> A member may differ from the others in what does not enter A: the support (amplitude,
!> omega, hence its load vector and initial velocity), the tip stops (lower, upper), the load
!> rule, the start, the restitution coefficient, what it records (record_every, snapshot_every)
!> and where (its recorder).
!> Each member keeps its own load averages, contact state, energy ledger, record cadence and
!> recorder, and gets its own summary.
!>
!> Bit for bit: every member's records, snapshots and summary are those of the same scene run
!> alone (beamstops_run's simulate, the fused path advance_fused of beamstops_scheme): the
!> start is the one-scene start itself (start_state); each step does, per member, the
!> floating-point operations of advance_fused in the same order (the load rotation and its
!> restarts, the forward pass with its energy sums, the back substitution, the contact law of
!> the tip, the update, the work and the energy the stops take), with the substitutions of
!> beamstops_band_solve_lockstep; the runs are cut into the same blocks (block_steps), so that
!> the delayed energy record of a block's last step is completed the same way. Each member
!> feeds its own observer (shock log and statistics) every step, as run_scheme does, and gets
!> run_scheme's summary (ledger, shocks, statistics). tests/fortran/test_lockstep.f90 compares
!> every column, snapshot and summary value to the bit.
!>
!> Laws: Signorini and compliance at the tip, or none. Rayleigh damping (SPEC 8), restitution
!> (SPEC 9) and the massless tip of mass redistribution (SPEC 10) run in the general loop of
!> beamstops_lockstep_general (lockstep_general.f90), advance_fused_general per member; the
!> members' state and the pieces of a step both loops share are beamstops_lockstep_members'.
!> The plain loop here (advance_members) keeps a step's per-member values in fixed-size lanes
!> during a block (beamstops_lockstep_lanes, gathered and scattered at the block's ends).
!> Stops along the span (SPEC 7) run in the span loop of beamstops_lockstep_span (lockstep_span.f90,
!> advance_span per member): the members share the stops' nodes, their bounds may differ.
module beamstops_lockstep
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_strings, only: fmt_real, fmt_int
   use beamstops_scene, only: scene_type, steps_of, stop_count, law_compliance, law_name
   use beamstops_model, only: model_type, build_model, check_stability
   use beamstops_hermite, only: hermite_basis, gauss_points, gauss_weights
   use beamstops_band, only: band_matvec
   use beamstops_band_solve, only: prepare_solver, prepare_diagonals, energy_dots
   use beamstops_band_solve_lockstep, only: lockstep_forward, lockstep_energy_dots, lockstep_back_edge, &
      & lockstep_back_update, lockstep_matvec, lockstep_min_unknowns, lockstep_work_columns, &
      & lockstep_lanes, lockstep_matvec_rhs, lockstep_periodic_rows, lockstep_matvec_rhs_forward
   use beamstops_lockstep_lanes, only: lanes_type, lanes_restart_loads, lanes_next_loads, lanes_begin_step, &
      & lanes_contact, lanes_close
   use beamstops_state, only: state_type
   use beamstops_scheme, only: start_state, block_steps
   use beamstops_clock, only: thread_cpu_seconds
   use beamstops_forcing, only: lift_shape, lift_slope, restart_every
   use beamstops_lockstep_physics, only: check_shared_physics
   use beamstops_lockstep_store, only: chunk_store, fill_store, give_back, put_lane, part_u, part_d, part_su, &
      & part_rhs, part_g
   use beamstops_lockstep_members, only: operators_type, members_type, lane, chunk, take_snapshot, first_events, &
      & energy
   use beamstops_lockstep_general, only: advance_members_general
   use beamstops_observe_lanes, only: observer_lanes, gather_observers, scatter_observers, observe_lanes
   use beamstops_lockstep_span, only: simulate_span_lockstep
   use beamstops_recorder, only: recorder_type, n_columns, col_t, col_u, col_v, col_reaction, col_energy, &
      & col_work, col_dissipated, col_damped
   use beamstops_stop_signals, only: stop_signal
   use beamstops_summary, only: mark_interrupted, lockstep_no_checkpoint, run_summary, status_complete, status_diverged, status_failed, status_running, &
      & check_divergence
   implicit none
   private
   public :: check_lockstep, prepare_lockstep, simulate_lockstep


contains

   !> Whether K scenes can run in lockstep with `model` (built from the first of them): the
   !> same A (mesh, beam, dt, beta, Rayleigh damping, mass law), the same law and compliance
   !> stiffness, the same number of steps, the full model (no reduced model), the stops along
   !> the span on the same nodes (or none), J >= 4 (beamstops_lockstep_physics's check_shared_physics for damping and the
   !> mass law; the restitution coefficient may differ). The message names the first member
   !> and key that differ.
   subroutine check_lockstep(scenes, model, error)
      !> The members' validated scenes (K >= 1).
      type(scene_type), intent(in) :: scenes(:)
      !> The model built from scenes(1).
      type(model_type), intent(in) :: model
      !> Set when a member cannot join the others.
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      if (size(scenes) < 1) then
         call fatal_error(error, 'lockstep: no members')
         return
      end if
      if (model%n /= 2*scenes(1)%elements .or. model%dt /= scenes(1)%dt .or. model%beta /= scenes(1)%beta) then
         call fatal_error(error, 'lockstep: the model was not built from the first member''s scene')
         return
      end if
      if (model%redistributed .neqv. scenes(1)%redistributed_mass) then
         call fatal_error(error, 'lockstep: the model was not built from the first member''s scene')
         return
      end if
      if (.not. scenes(1)%damping_by_ratio .and. (model%damping_a /= scenes(1)%damping_mass .or. &
         & model%damping_b /= scenes(1)%damping_stiffness)) then
         call fatal_error(error, 'lockstep: the model was not built from the first member''s scene')
         return
      end if
      if (model%n < lockstep_min_unknowns) then
         call fatal_error(error, 'lockstep: &mesh elements = '//fmt_int(int(scenes(1)%elements, ik))// &
            & ' is out of range for the lockstep path; allowed: elements >= '// &
            & fmt_int(int(lockstep_min_unknowns/2, ik)))
         return
      end if
      do k = 1, size(scenes)
         if (k > 1) call same_stops(k)
         if (allocated(error)) return
         if (scenes(k)%modes > 0) then
            call fatal_error(error, 'lockstep: member '//fmt_int(int(k, ik))//' is a reduced model (&mesh modes = '// &
               & fmt_int(int(scenes(k)%modes, ik))//'); the lockstep path runs the full model: run it alone')
            return
         end if
         if (k == 1) cycle
         call differ(k, 'mesh', 'elements', real(scenes(k)%elements, wp), real(scenes(1)%elements, wp))
         call differ(k, 'beam', 'length', scenes(k)%length, scenes(1)%length)
         call differ(k, 'beam', 'k2', scenes(k)%k2, scenes(1)%k2)
         call differ(k, 'beam', 'mass_per_length', scenes(k)%mass_per_length, scenes(1)%mass_per_length)
         call differ(k, 'time', 'dt', scenes(k)%dt, scenes(1)%dt)
         call differ(k, 'time', 'beta', scenes(k)%beta, scenes(1)%beta)
         call differ(k, 'time', 'steps (t_end/dt)', real(steps_of(scenes(k)), wp), real(steps_of(scenes(1)), wp))
         if (allocated(error)) return
         if (scenes(k)%law /= scenes(1)%law) then
            call fatal_error(error, 'lockstep: member '//fmt_int(int(k, ik))//': &stops law = '''// &
               & law_name(scenes(k)%law)//''' differs from member 1''s '''//law_name(scenes(1)%law)// &
               & '''; lockstep members share the contact law')
            return
         end if
         if (scenes(1)%law == law_compliance) &
            & call differ(k, 'stops', 'stiffness_per_mass', scenes(k)%stiffness_per_mass, scenes(1)%stiffness_per_mass)
         if (allocated(error)) return
         call check_shared_physics(k, scenes(k), scenes(1), error)
         if (allocated(error)) return
      end do

   contains

      !> Refuse member k when its stops along the span are not on member 1's nodes: the nodes
      !> give P, hence Z = A^{-1} P and C = P^T A^{-1} P, which the members share (their bounds
      !> may differ).
      subroutine same_stops(k)
         integer, intent(in) :: k
         integer :: m, m1
         m = stop_count(scenes(k))
         m1 = stop_count(scenes(1))
         if (m /= m1) then
            call fatal_error(error, 'lockstep: member '//fmt_int(int(k, ik))//': &stops nodes (or x) gives '// &
               & fmt_int(int(m, ik))//' stops along the span, member 1''s '//fmt_int(int(m1, ik))// &
               & '; lockstep members share the stops'' nodes (they shape C = P^T A^{-1} P): run it in another group')
            return
         end if
         if (m == 0) return
         if (any(scenes(k)%stop_nodes /= scenes(1)%stop_nodes)) then
            call fatal_error(error, 'lockstep: member '//fmt_int(int(k, ik))//': &stops nodes = '// &
               & node_list(scenes(k)%stop_nodes)//' differs from member 1''s '//node_list(scenes(1)%stop_nodes)// &
               & '; lockstep members share the stops'' nodes (they shape C = P^T A^{-1} P; the bounds lower, '// &
               & 'upper may differ): run it in another group')
         end if
      end subroutine same_stops

      !> Refuse member k when a value of its scene differs from member 1's.
      subroutine differ(k, group, key, value, first)
         integer, intent(in) :: k
         character(len=*), intent(in) :: group, key
         real(wp), intent(in) :: value, first
         if (allocated(error)) return
         if (value == first) return
         call fatal_error(error, 'lockstep: member '//fmt_int(int(k, ik))//': &'//group//' '//key//' = '// &
            & fmt_real(value)//' differs from member 1''s '//fmt_real(first)// &
            & '; lockstep members share A = M + dt^2 beta S, the contact law and the steps: run it in another group')
      end subroutine differ
   end subroutine check_lockstep

   !> The nodes of the stops along the span as text (messages): "3, 7, 10".
   function node_list(nodes) result(text)
      integer, intent(in) :: nodes(:)
      character(len=:), allocatable :: text
      integer :: i
      text = ''
      do i = 1, size(nodes)
         if (i > 1) text = text//', '
         text = text//fmt_int(int(nodes(i), ik))
      end do
   end function node_list

   !> Build the model once from the first member, refuse members that cannot join it
   !> (check_lockstep) and members beyond the stability limit of their scene (check_stability).
   subroutine prepare_lockstep(scenes, source, model, error)
      !> The members' validated scenes.
      type(scene_type), intent(in) :: scenes(:)
      !> Where the scenes came from, for messages.
      character(len=*), intent(in) :: source
      !> The shared model, built from scenes(1).
      type(model_type), intent(out) :: model
      !> Set when the group cannot run.
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      if (size(scenes) < 1) then
         call fatal_error(error, 'lockstep: no members')
         return
      end if
      call build_model(scenes(1), model, error)
      if (allocated(error)) return
      call check_lockstep(scenes, model, error)
      if (allocated(error)) return
      do k = 1, size(scenes)
         call check_stability(scenes(k), model, source//' (member '//fmt_int(int(k, ik))//')', error)
         if (allocated(error)) return
      end do
   end subroutine prepare_lockstep

   !> Run K members from t = 0 to their (common) end in lockstep, each feeding its recorder;
   !> each member's records, snapshots and summary are those of simulate(scenes(k), ...) run
   !> alone. A member whose recorder fails or whose solution blows up stops (its summary says
   !> why) and the others go on. cpu_seconds of a summary is the member's share (1/K) of the
   !> group's time loop.
   subroutine simulate_lockstep(scenes, model, recorders, summaries, error, initial_displacement)
      !> The members' validated scenes (K).
      type(scene_type), intent(in) :: scenes(:)
      !> The model built from scenes(1) (prepare_lockstep).
      type(model_type), intent(in) :: model
      !> One recorder per member (K), all of one type.
      class(recorder_type), intent(inout) :: recorders(:)
      !> One summary per member (K).
      type(run_summary), intent(out) :: summaries(:)
      !> Set when the group cannot start (a member refused, or its start failed).
      type(error_type), allocatable, intent(out) :: error
      !> Initial displacement u0 of the homogeneous unknown of each member (n, K), in place of
      !> the model's (the members of an &ensemble: model%u0 plus their perturbation).
      real(wp), intent(in), optional :: initial_displacement(:, :)
      type(operators_type) :: ops
      type(members_type) :: ms
      integer(ik) :: steps, last
      real(wp) :: t0, kinetic
      integer :: k, nk

      nk = size(scenes)
      if (size(recorders) /= nk .or. size(summaries) /= nk) then
         call fatal_error(error, 'lockstep: '//fmt_int(int(nk, ik))//' scenes need as many recorders and summaries')
         return
      end if
      call check_lockstep(scenes, model, error)
      if (allocated(error)) return
      call prepare_solver(model%factor, ops%solver)
      call prepare_diagonals(model%stiffness, ops%stiffness)
      call prepare_diagonals(model%mass, ops%mass)
      call lockstep_periodic_rows(ops%stiffness, ops%periodic, ops%stiffness_rows)
      if (model%damped) call prepare_diagonals(model%damping, ops%damping)
      if (present(initial_displacement)) then
         if (size(initial_displacement, 1) /= model%n .or. size(initial_displacement, 2) /= nk) then
            call fatal_error(error, 'lockstep: the initial displacements must be (n, K) = ('// &
               & fmt_int(int(model%n, ik))//', '//fmt_int(int(nk, ik))//')')
            return
         end if
      end if
      if (model%stops%m > 0) then
         ! stops along the span: the span loop (beamstops_lockstep_span), advance_span per member
         call simulate_span_lockstep(scenes, model, ops, recorders, summaries, error, initial_displacement)
         return
      end if
      call start_members(scenes, model, recorders, ms, error, initial_displacement)
      if (allocated(error)) return

      steps = steps_of(scenes(1))
      do k = 1, nk
         summaries(k)%status = status_running
      end do
      t0 = thread_cpu_seconds()
      do while (ms%step <= steps .and. any(ms%active))
         last = min(steps, ms%step + block_steps - 1)
         if (ms%general) then
            call advance_members_general(scenes, model, ops, ms, recorders, last)
         else
            call advance_members(scenes, model, ops, ms, recorders, last)
         end if
         ms%step = last + 1
         do k = 1, nk
            if (.not. ms%active(k)) cycle
            if (recorders(k)%failed) then
               summaries(k)%status = status_failed
               summaries(k)%message = 'the recorder could not write'
               call finish_member(k, scenes(k), ms, model, summaries(k), t0)
               cycle
            end if
            ms%vec_d = ms%d(lane(k), :, chunk(k))
            call band_matvec(model%mass, ms%vec_d, ms%vec_s)
            kinetic = 0.5_wp*dot_product(ms%vec_d, ms%vec_s)/model%dt2
            call check_divergence(scenes(k), kinetic, ms%energy0(k), ms%work(k), ms%dissipated(k), &
               & real(ms%step - 1, wp)*model%dt, recorders(k)%blew_up, recorders(k)%blew_up_at, summaries(k))
            if (summaries(k)%status == status_diverged) then
               call finish_member(k, scenes(k), ms, model, summaries(k), t0)
               cycle
            end if
            if (ms%observers(k)%active) call ms%observers(k)%drain()
            call recorders(k)%progress(ms%step - 1, steps)
         end do
         if (stop_signal() /= 0) exit
      end do
      do k = 1, nk
         if (ms%active(k)) call finish_member(k, scenes(k), ms, model, summaries(k), t0)
      end do
      ! stopped by a signal (beamstops_stop_signals, caught by simulate_group's caller)
      do k = 1, nk
         if (summaries(k)%status == status_running) call mark_interrupted(scenes(k), stop_signal(), lockstep_no_checkpoint, &
            & summaries(k))
      end do
   end subroutine simulate_lockstep

   !> A member leaves the group: its summary (run_scheme's: counts, the energy ledger of
   !> close_ledger, the shock log and statistics of its observer), and its lanes set to rest
   !> (zeros stay zeros).
   subroutine finish_member(k, scene, ms, model, summary, t0)
      integer, intent(in) :: k
      type(scene_type), intent(in) :: scene
      type(members_type), intent(inout) :: ms
      type(model_type), intent(in) :: model
      type(run_summary), intent(inout) :: summary
      real(wp), intent(in) :: t0
      real(wp) :: dmd, usu, dsu, dsd, e_end, damped
      summary%cpu_seconds = (thread_cpu_seconds() - t0)/ms%k
      summary%steps = ms%step - 1
      summary%t_final = real(summary%steps, wp)*model%dt
      summary%impacts = ms%impacts(k)
      summary%max_violation = ms%max_violation(k)
      summary%contact_phases = ms%impacts(k)
      ! the ledger (close_ledger)
      damped = 0
      if (ms%general) damped = ms%damped(k)
      ms%vec_u = ms%u(lane(k), :, chunk(k))
      ms%vec_d = ms%d(lane(k), :, chunk(k))
      call band_matvec(model%mass, ms%vec_d, ms%vec_s)
      dmd = dot_product(ms%vec_d, ms%vec_s)
      call band_matvec(model%stiffness, ms%vec_u, ms%vec_s)
      usu = dot_product(ms%vec_u, ms%vec_s)
      dsu = dot_product(ms%vec_d, ms%vec_s)
      call band_matvec(model%stiffness, ms%vec_d, ms%vec_s)
      dsd = dot_product(ms%vec_d, ms%vec_s)
      e_end = energy(model, dmd, usu, dsu, usu - 2*dsu + dsd)
      summary%work = scene%mass_per_length*ms%work(k)
      summary%dissipated = scene%mass_per_length*ms%dissipated(k)
      summary%damped = scene%mass_per_length*damped
      summary%energy_residual = scene%mass_per_length*((e_end - ms%energy0(k)) &
         & - (ms%work(k) - ms%dissipated(k) - damped))
      if (summary%status == status_running .and. ms%step > steps_of(scene)) summary%status = status_complete
      if (ms%observers(k)%active .and. summary%status /= status_running) then
         call ms%observers(k)%finish(summary%shocks, summary%statistics)
         summary%impacts = ms%observers(k)%shocks%shock_count()
         summary%contact_phases = ms%observers(k)%shocks%phase_count()
      end if
      ms%active(k) = .false.
      ms%u(lane(k), :, chunk(k)) = 0
      ms%d(lane(k), :, chunk(k)) = 0
      ms%g(lane(k), :, chunk(k)) = 0
      ms%p_prev(k) = 0
      ms%p_now(k) = 0
      if (allocated(ms%cd)) ms%cd(lane(k), :, chunk(k)) = 0
      if (ms%general) ms%dcd_prev(k) = 0
   end subroutine finish_member

   !> Start every member by the one-scene start (start_state, which hands each recorder its
   !> record of t = 0) with the member's load vector and initial velocity, and gather the
   !> states into the members' arrays (with the general loop's own, start_general).
   subroutine start_members(scenes, model, recorders, ms, error, initial_displacement)
      type(scene_type), intent(in) :: scenes(:)
      type(model_type), intent(in) :: model
      class(recorder_type), intent(inout) :: recorders(:)
      type(members_type), intent(out) :: ms
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: initial_displacement(:, :)
      type(model_type) :: member
      type(state_type) :: state
      real(wp), allocatable :: bh(:), b1(:)
      integer :: k, nk, n

      nk = size(scenes)
      n = model%n
      ms%k = nk
      ms%n = n
      ms%chunks = (nk + lockstep_lanes - 1)/lockstep_lanes
      ms%p = ms%chunks*lockstep_lanes
      allocate (ms%u(lockstep_lanes, n, ms%chunks), ms%d(lockstep_lanes, n, ms%chunks), &
         & ms%su(lockstep_lanes, n, ms%chunks), &
         & ms%g(lockstep_lanes, n, ms%chunks), ms%partial(lockstep_lanes, lockstep_work_columns))
      ms%u = 0
      ms%d = 0
      ms%su = 0
      ms%g = 0
      nk = ms%p
      allocate (ms%sigma_prev(nk), ms%sigma_now(nk), ms%gd_prev(nk), ms%p_prev(nk), ms%p_now(nk), ms%work(nk), &
         & ms%dissipated(nk), ms%energy0(nk), ms%reaction(nk), ms%max_violation(nk), ms%in_contact(nk), &
         & ms%active(nk), ms%impacts(nk))
      allocate (ms%pending(nk), ms%next_record(nk), ms%next_snapshot(nk), ms%rows(n_columns, nk))
      allocate (ms%vec_u(n), ms%vec_d(n), ms%vec_su(n), ms%vec_s(n), ms%shape(size(model%x)))
      allocate (ms%observers(ms%k))
      call zero_members(ms)
      ms%general = model%damped .or. model%redistributed .or. any(scenes%restitution > 0)
      if (ms%general) call start_general(model%damped, ms)
      ms%active = .false.
      ms%active(:ms%k) = .true.
      nk = ms%k

      call load_shapes(scenes(1)%elements, model%h, scenes(1)%length, bh, b1)
      member = model
      do k = 1, nk
         member%load = member_load(scenes(k), bh, b1)
         if (k == 1) then
            if (any(member%load /= model%load)) then
               call fatal_error(error, 'lockstep: internal: the members'' load vectors differ from the model''s')
               return
            end if
         end if
         member%v0(1::2) = -scenes(k)%amplitude*scenes(k)%omega*lift_shape(model%x(2:), scenes(k)%length)
         member%v0(2::2) = -scenes(k)%amplitude*scenes(k)%omega*lift_slope(model%x(2:), scenes(k)%length)
         if (present(initial_displacement)) member%u0 = initial_displacement(:, k)
         call start_state(scenes(k), member, state, recorders(k), error)
         if (allocated(error)) then
            error%message = 'lockstep: member '//fmt_int(int(k, ik))//': '//error%message
            return
         end if
         ms%g(lane(k), :, chunk(k)) = member%load
         ms%u(lane(k), :, chunk(k)) = state%u
         ms%d(lane(k), :, chunk(k)) = state%d
         ms%su(lane(k), :, chunk(k)) = state%su
         ms%sigma_prev(k) = state%sigma_prev
         ms%sigma_now(k) = state%sigma_now
         ms%gd_prev(k) = state%gd_prev
         ms%p_prev(k) = state%p_prev
         ms%p_now(k) = state%p_now
         ms%work(k) = state%work
         ms%dissipated(k) = state%dissipated
         ms%energy0(k) = state%energy0
         ms%reaction(k) = state%reaction
         ms%max_violation(k) = state%max_violation
         ms%in_contact(k) = state%in_contact
         ms%impacts(k) = state%impacts
         ms%observers(k) = state%observer
         ms%step = state%step
         if (ms%general) then
            ms%lower(k) = scenes(k)%lower
            ms%upper(k) = scenes(k)%upper
            ms%restitution(k) = scenes(k)%restitution
         end if
         if (model%damped) then
            ms%cd(lane(k), :, chunk(k)) = state%cd
            ms%dcd_prev(k) = state%dcd_prev
            ms%damped(k) = state%damped
         end if
      end do
   end subroutine start_members

   !> Every per-member value zero (the padding lanes keep them).
   subroutine zero_members(ms)
      type(members_type), intent(inout) :: ms
      ms%sigma_prev = 0
      ms%sigma_now = 0
      ms%gd_prev = 0
      ms%p_prev = 0
      ms%p_now = 0
      ms%work = 0
      ms%dissipated = 0
      ms%energy0 = 0
      ms%reaction = 0
      ms%max_violation = 0
      ms%in_contact = .false.
      ms%impacts = 0
      ms%pending = .false.
      ms%next_record = huge(1_ik)
      ms%next_snapshot = huge(1_ik)
   end subroutine zero_members

   !> The general loop's per-member arrays (beamstops_lockstep_general: it keeps a step's values
   !> per member, where the plain loop keeps them in its chunks' lanes), zero; the stops -1 and 1
   !> (the padding lanes keep them); C d^{n-1} with damping.
   subroutine start_general(damped, ms)
      logical, intent(in) :: damped
      type(members_type), intent(inout) :: ms
      integer :: nk
      nk = ms%p
      allocate (ms%sigma(nk), ms%cosine(nk), ms%cos_step(nk), ms%sin_step(nk))
      allocate (ms%sigma_next(nk), ms%weight(nk), ms%coef(nk), ms%spring(nk), ms%trial(nk), ms%c(nk), &
         & ms%tip_value(nk), ms%r_step(nk), ms%u_tip_prev(nk), ms%d_tip_prev(nk), ms%r_prev(nk), ms%usu(nk), &
         & ms%dsu(nk), ms%dmd(nk), ms%u_old_su(nk), ms%gd(nk), ms%contact(nk))
      allocate (ms%lower(nk), ms%upper(nk), ms%u_tip(nk), ms%d_tip(nk))
      allocate (ms%damped(nk), ms%dcd_prev(nk), ms%cross(nk), ms%dcd(nk), ms%restitution(nk), ms%s_u_tip(nk), &
         & ms%s_d_prev_tip(nk), ms%bound_lower(nk), ms%bound_upper(nk))
      ms%sigma = 0
      ms%cosine = 0
      ms%cos_step = 0
      ms%sin_step = 0
      ms%sigma_next = 0
      ms%weight = 0
      ms%coef = 0
      ms%spring = 0
      ms%trial = 0
      ms%c = 0
      ms%tip_value = 0
      ms%r_step = 0
      ms%u_tip_prev = 0
      ms%d_tip_prev = 0
      ms%r_prev = 0
      ms%usu = 0
      ms%dsu = 0
      ms%dmd = 0
      ms%u_old_su = 0
      ms%gd = 0
      ms%contact = .false.
      ms%lower = -1
      ms%upper = 1
      ms%u_tip = 0
      ms%d_tip = 0
      ms%damped = 0
      ms%dcd_prev = 0
      ms%cross = 0
      ms%dcd = 0
      ms%restitution = 0
      ms%s_u_tip = 0
      ms%s_d_prev_tip = 0
      ms%bound_lower = -1
      ms%bound_upper = 1
      if (damped) then
         allocate (ms%cd(lockstep_lanes, ms%n, ms%chunks))
         ms%cd = 0
      end if
   end subroutine start_general

   !> A member's load vector g = a (omega^2 (h, phi_i) + 8 k^2/L^4 (1, phi_i)), as build_model
   !> forms it.
   function member_load(scene, bh, b1) result(g)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: bh(:), b1(:)
      real(wp) :: g(size(bh))
      real(wp) :: forcing_scale
      forcing_scale = 8*scene%k2/scene%length**4
      g = scene%amplitude*(scene%omega**2*bh + forcing_scale*b1)
   end function member_load

   !> Load shapes (h, phi_i) and (1, phi_i) by 4-point Gauss quadrature per element (the
   !> quadrature of beamstops_model, whose routine is private there).
   pure subroutine load_shapes(elements, h, length, bh, b1)
      integer, intent(in) :: elements
      real(wp), intent(in) :: h, length
      real(wp), allocatable, intent(out) :: bh(:), b1(:)
      real(wp) :: full_h(2*elements + 2), full_1(2*elements + 2), nq(4), xq
      integer :: e, q
      full_h = 0
      full_1 = 0
      do e = 1, elements
         do q = 1, 4
            nq = hermite_basis(gauss_points(q), h)*gauss_weights(q)*h
            xq = (e - 1 + gauss_points(q))*h
            full_h(2*e - 1:2*e + 2) = full_h(2*e - 1:2*e + 2) + nq*lift_shape(xq, length)
            full_1(2*e - 1:2*e + 2) = full_1(2*e - 1:2*e + 2) + nq
         end do
      end do
      bh = full_h(3:)
      b1 = full_1(3:)
   end subroutine load_shapes

   !> Advance every member from ms%step through step `last` (advance_fused of beamstops_scheme,
   !> per member, the member index innermost). The members' values live in the chunks' lanes
   !> (beamstops_lockstep_lanes) during the block. Per step and chunk: the load rotation, S u and
   !> the right-hand side, the forward substitution (with the energy sums when a record wants
   !> them); then the tip rows of the back substitution, the contact law of each lane, the rest
   !> of the back substitution with the update riding on it, g.d and the bookkeeping.
   subroutine advance_members(scenes, model, ops, ms, recorders, last)
      type(scene_type), intent(in) :: scenes(:)
      type(model_type), intent(in) :: model
      type(operators_type), intent(in) :: ops
      type(members_type), intent(inout) :: ms
      class(recorder_type), intent(inout) :: recorders(:)
      integer(ik), intent(in) :: last
      type(lanes_type), allocatable :: lanes(:)
      type(observer_lanes), allocatable :: watch(:)
      type(chunk_store) :: w
      integer(ik) :: step, next_record, next_snapshot, load_k
      integer :: k, c, tip, law, tip_row
      !> The index in w%store of each chunk's vectors (first(part, c) = w%at(part, c)), for the
      !> steps of the block: at is a type-bound function, called through the type's table.
      integer, allocatable :: first(:, :)
      logical :: energy_wanted, pending, observing, restart
      real(wp) :: z_tip, sums(3)

      tip = model%tip
      z_tip = model%z(tip)
      law = scenes(1)%law
      do k = 1, ms%k
         call first_events(scenes(k), ms%step, ms%next_record(k), ms%next_snapshot(k))
      end do
      next_record = minval(ms%next_record)
      next_snapshot = minval(ms%next_snapshot)
      observing = any(ms%observers%active)
      ms%pending = .false.
      pending = .false.
      allocate (lanes(ms%chunks))
      call gather_lanes(scenes, ms, lanes)
      call fill_store(w, ms%u, ms%d, ms%su, ms%g)
      allocate (first(part_u:part_g, ms%chunks))
      do c = 1, ms%chunks
         do k = part_u, part_g
            first(k, c) = w%at(k, c)
         end do
      end do
      tip_row = (tip - 1)*lockstep_lanes
      if (observing) call gather_observers(watch, ms%observers, ms%active(:ms%k))
      load_k = start_lanes_loads(lanes, ms%step + 1, model%dt)
      do step = ms%step, last
         restart = mod(load_k + 1, restart_every) == 0
         energy_wanted = pending .or. step == next_record
         ! the forward pass, a chunk of members after the other
         do c = 1, ms%chunks
            call lanes_begin_step(lanes(c), law, model%beta, model%dt2, restart, load_k + 1, model%dt)
            if (ops%periodic) then
               call lockstep_matvec_rhs_forward(ops%stiffness, ops%solver, ops%stiffness_rows, w%store(first(part_u, c)), &
                  & lanes(c)%coef, w%store(first(part_g, c)), model%dt2, lanes(c)%spring, w%store(first(part_su, c)), &
                  & w%store(first(part_rhs, c)))
            else
               call lockstep_matvec_rhs(ops%stiffness, w%store(first(part_u, c)), lanes(c)%coef, w%store(first(part_g, c)), &
                  & model%dt2, lanes(c)%spring, w%store(first(part_su, c)), w%store(first(part_rhs, c)))
               call lockstep_forward(ops%solver, w%store(first(part_rhs, c)))
            end if
            if (energy_wanted) then
               call lockstep_energy_dots(ops%mass, w%store(first(part_u, c)), w%store(first(part_d, c)), &
                  & w%store(first(part_su, c)), lanes(c)%usu, lanes(c)%dsu, lanes(c)%dmd)
            end if
         end do
         load_k = load_k + 1
         if (pending) then
            do k = 1, ms%k
               if (.not. ms%pending(k)) cycle
               associate (ln => lanes(chunk(k)), i => lane(k))
                  ms%rows(col_energy, k) = scenes(k)%mass_per_length*energy(model, ln%dmd(i), ln%usu(i), ln%dsu(i), &
                     & ln%u_old_su(i))
               end associate
               if (ms%active(k)) call recorders(k)%record(ms%rows(:, k))
               ms%pending(k) = .false.
            end do
            pending = .false.
         end if
         ! the back substitution and the tip step: the contact law, the update and the
         ! bookkeeping (tip_step, close_step)
         do c = 1, ms%chunks
            if (energy_wanted) then
               lanes(c)%u_old_su = lanes(c)%usu
            else
               lanes(c)%u_old_su = 0
            end if
            call lockstep_back_edge(ops%solver, w%store(first(part_rhs, c)))
            call lanes_contact(lanes(c), law, w%store(first(part_u, c) + tip_row), w%store(first(part_d, c) + tip_row), &
               & w%store(first(part_rhs, c) + tip_row), z_tip, model%dt2, model%beta)
            call lockstep_back_update(ops%solver, w%store(first(part_rhs, c)), lanes(c)%c, model%z, &
               & w%store(first(part_g, c)), w%store(first(part_d, c)), w%store(first(part_u, c)), lanes(c)%gd)
            call lanes_close(lanes(c), law, w%store(first(part_u, c) + tip_row), w%store(first(part_d, c) + tip_row))
         end do
         ! the shock log and statistics of each member that keeps them (its quiet samples lane by
         ! lane, beamstops_observe_lanes)
         if (observing) then
            do c = 1, ms%chunks
               call observe_lanes(watch(c), ms%observers, real(step + 1, wp)*model%dt, lanes(c)%u_tip, &
                  & lanes(c)%reaction, lanes(c)%dissipated)
            end do
         end if
         ! records and snapshots
         if (step == next_record .or. step == next_snapshot) then
            do k = 1, ms%k
               if (step == ms%next_record(k)) then
                  ms%next_record(k) = ms%next_record(k) + scenes(k)%record_every
                  call fill_row_lanes(scenes(k), model, w%store(w%row(part_d, chunk(k), tip) + lane(k) - 1), &
                     & lanes(chunk(k)), k, step, ms%rows(:, k))
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
      call scatter_lanes(lanes, ms)
      call give_back(w, ms%u, ms%d, ms%su)
      if (observing) call scatter_observers(watch, ms%observers)
      ! S u^{last+1}; it also completes the waiting records, as advance_fused does (one member
      ! at a time, with the one-member products and dot products).
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
         ms%rows(col_energy, k) = scenes(k)%mass_per_length*energy(model, sums(3), sums(1), sums(2), &
            & lanes(chunk(k))%u_old_su(lane(k)))
         call recorders(k)%record(ms%rows(:, k))
      end do
   end subroutine advance_members

   !> The chunks' lanes at the start of a block: each member's constants and the values it
   !> carries from step to step (padding lanes keep the lanes' defaults: at rest).
   subroutine gather_lanes(scenes, ms, lanes)
      type(scene_type), intent(in) :: scenes(:)
      type(members_type), intent(in) :: ms
      type(lanes_type), intent(out) :: lanes(:)
      integer :: k
      do k = 1, ms%k
         associate (ln => lanes(chunk(k)), i => lane(k))
            ln%member(i) = .true.
            ln%omega(i) = scenes(k)%omega
            ln%centered(i) = scenes(k)%centered_load
            ln%lower(i) = scenes(k)%lower
            ln%upper(i) = scenes(k)%upper
            ln%stiffness(i) = scenes(k)%stiffness_per_mass
            ln%sigma_prev(i) = ms%sigma_prev(k)
            ln%sigma_now(i) = ms%sigma_now(k)
            ln%gd_prev(i) = ms%gd_prev(k)
            ln%p_prev(i) = ms%p_prev(k)
            ln%p_now(i) = ms%p_now(k)
            ln%work(i) = ms%work(k)
            ln%dissipated(i) = ms%dissipated(k)
            ln%reaction(i) = ms%reaction(k)
            ln%max_violation(i) = ms%max_violation(k)
            ln%in_contact(i) = ms%in_contact(k)
            ln%impacts(i) = ms%impacts(k)
         end associate
      end do
   end subroutine gather_lanes

   !> The values the members carry from step to step, back from the lanes at the end of a block.
   subroutine scatter_lanes(lanes, ms)
      type(lanes_type), intent(in) :: lanes(:)
      type(members_type), intent(inout) :: ms
      integer :: k
      do k = 1, ms%k
         associate (ln => lanes(chunk(k)), i => lane(k))
            ms%sigma_prev(k) = ln%sigma_prev(i)
            ms%sigma_now(k) = ln%sigma_now(i)
            ms%gd_prev(k) = ln%gd_prev(i)
            ms%p_prev(k) = ln%p_prev(i)
            ms%p_now(k) = ln%p_now(i)
            ms%work(k) = ln%work(i)
            ms%dissipated(k) = ln%dissipated(i)
            ms%reaction(k) = ln%reaction(i)
            ms%max_violation(k) = ln%max_violation(i)
            ms%in_contact(k) = ln%in_contact(i)
            ms%impacts(k) = ln%impacts(i)
         end associate
      end do
   end subroutine scatter_lanes

   !> The load rotation of every chunk at step k (beamstops_forcing's start_loads): from
   !> load_average at the last multiple of restart_every, then rotated. Returns k.
   function start_lanes_loads(lanes, k, dt) result(load_k)
      type(lanes_type), intent(inout) :: lanes(:)
      integer(ik), intent(in) :: k
      real(wp), intent(in) :: dt
      integer(ik) :: load_k
      integer :: c
      load_k = (k/restart_every)*restart_every
      do c = 1, size(lanes)
         call lanes_restart_loads(lanes(c), load_k, dt)
      end do
      do while (load_k < k)
         do c = 1, size(lanes)
            call lanes_next_loads(lanes(c), mod(load_k + 1, restart_every) == 0, load_k + 1, dt)
         end do
         load_k = load_k + 1
      end do
   end function start_lanes_loads

   !> Member k's record row of step n from its chunk's lanes, the energy column left for later
   !> (beamstops_ledger's fill_row; the general loop's, on the members' arrays, is
   !> beamstops_lockstep_members' fill_row_members).
   subroutine fill_row_lanes(scene, model, d_tip, lanes, k, step, row)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      !> Member k's d^n at the tip.
      real(wp), intent(in) :: d_tip
      !> Member k's chunk.
      type(lanes_type), intent(in) :: lanes
      integer, intent(in) :: k
      integer(ik), intent(in) :: step
      real(wp), intent(out) :: row(n_columns)
      integer :: i
      i = lane(k)
      row(col_t) = real(step, wp)*model%dt
      row(col_u) = lanes%u_tip_prev(i)
      row(col_v) = (d_tip + lanes%d_tip_prev(i))/(2*model%dt)
      row(col_reaction) = scene%mass_per_length*lanes%r_prev(i)
      row(col_energy) = 0
      row(col_work) = scene%mass_per_length*lanes%work(i)
      row(col_dissipated) = scene%mass_per_length*lanes%dissipated(i)
      row(col_damped) = scene%mass_per_length*0.0_wp
   end subroutine fill_row_lanes
end module beamstops_lockstep
