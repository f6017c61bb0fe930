!> The members of a lockstep group (SPEC 13): the state of K members with the member index first
!> and the shared operators, for both loops, beamstops_lockstep's advance_members (the paper's
!> scheme) and beamstops_lockstep_general's advance_members_general (damping, restitution, a
!> massless tip); the pieces of a step both loops use (lane, chunk, snapshots; beamstops_ledger's
!> first_events and energy handed on); and the general loop's pieces of a step over the members'
!> arrays (the tip's contact law, the close of a step, the record row fill_row_members, the load
!> rotation). The plain loop keeps a step's values in fixed-size lanes instead
!> (beamstops_lockstep_lanes, with its own contact law, close and load rotation, and
!> lockstep.f90's fill_row_lanes). Each is the one-scene routine of beamstops_scheme /
!> beamstops_ledger / beamstops_contact_tip_contact, per member, with the same operations in the
!> same order (tests/fortran/test_lockstep.f90 and test_lockstep_general.f90 compare whole runs to
!> the bit).
module beamstops_lockstep_members
   use beamstops_kinds, only: wp, ik
   use beamstops_scene, only: scene_type, law_none, law_signorini, law_compliance
   use beamstops_model, only: model_type
   use beamstops_band_solve, only: band_solver, band_diagonals
   use beamstops_band, only: kd
   use beamstops_band_solve_lockstep, only: lockstep_lanes
   use beamstops_newmark, only: newmark_work
   use beamstops_forcing, only: load_average, support_position, restart_every
   use beamstops_contact_compliance, only: compliance_step
   use beamstops_observe_observer, only: observer_type
   use beamstops_ledger, only: energy, first_events
   use beamstops_recorder, only: recorder_type, n_columns, col_t, col_u, col_v, col_reaction, col_energy, &
      & col_work, col_dissipated, col_damped
   implicit none
   private
   public :: operators_type, members_type, lane, chunk, take_snapshot
   !> beamstops_ledger's, handed on to both loops.
   public :: first_events, energy
   public :: contact_law, close_steps, project_lanes, fill_row_members, start_loads, next_loads

   !> The operators of the fused loop, shared by the members.
   type :: operators_type
      !> Factor of A in the form of the fused substitutions.
      type(band_solver) :: solver
      !> S and M by diagonals.
      type(band_diagonals) :: stiffness, mass
      !> C by diagonals (Rayleigh damping; n = 0 without).
      type(band_diagonals) :: damping
      !> Whether the interior rows of S repeat with period 2 (a uniform mesh: always, unless
      !> rounding made two sums differ), and its two interior rows' coefficients
      !> (lockstep_periodic_rows): the product by S then keeps them in registers.
      logical :: periodic = .false.
      real(wp) :: stiffness_rows(2*kd + 1, 2) = 0
   end type operators_type

   !> The state of K members, the member index first: what advance_fused keeps in a
   !> state_type and in its local variables, once per member.
   type :: members_type
      !> Members K, unknowns n, chunks of lockstep_lanes members, lanes in all (K padded), index
      !> of the next step (shared).
      integer :: k = 0, n = 0, chunks = 0, p = 0
      integer(ik) :: step = 1
      !> u^n, d^{n-1}, S u^n, load vector g of each member (lanes, n, chunks): member k is lane
      !> lane(k) of chunk chunk(k); the padding lanes stay zero. During a block of the plain or the
      !> general loop they are in the loop's aligned store (beamstops_lockstep_store), and these
      !> arrays get u, d and S u back at its end.
      real(wp), allocatable :: u(:, :, :), d(:, :, :), su(:, :, :), g(:, :, :)
      !> Work array of the kernels (lanes, lockstep_work_columns).
      real(wp), allocatable :: partial(:, :)
      !> Per member, padded to p lanes (the plain loop: between blocks; during a block the chunks'
      !> lanes hold them, beamstops_lockstep_lanes): load averages sigma_{n-1}, sigma_n; g.d^{n-1};
      !> spring forces p(u^{n-1}), p(u^n); work, energy taken by the stops, E^{1/2}, reaction of
      !> the last step, largest violation (per unit mass).
      real(wp), allocatable :: sigma_prev(:), sigma_now(:), gd_prev(:), p_prev(:), p_now(:), work(:), &
         & dissipated(:), energy0(:), reaction(:), max_violation(:)
      !> Whether the last step was in contact; whether the member still runs (K).
      logical, allocatable :: in_contact(:), active(:)
      !> Impacts so far (K).
      integer(ik), allocatable :: impacts(:)
      !> A record waiting for its energy (K).
      logical, allocatable :: pending(:)
      !> Next record and snapshot step of each member (K).
      integer(ik), allocatable :: next_record(:), next_snapshot(:)
      !> Record rows waiting for their energy (n_columns, K).
      real(wp), allocatable :: rows(:, :)
      !> The shock log and statistics of each member (K; inactive unless its scene asks).
      type(observer_type), allocatable :: observers(:)
      !> One member's vectors, contiguous (n), and its snapshot buffer (J+1).
      real(wp), allocatable :: vec_u(:), vec_d(:), vec_su(:), vec_s(:), shape(:)
      !> The general loop (lockstep_general.f90): damping, restitution or a massless tip.
      logical :: general = .false.
      !> The rest is the general loop's, allocated only when `general` (the plain loop keeps a
      !> step's values in its chunks' lanes). The load rotation of each member
      !> (beamstops_forcing's load_rotation): its step index (shared), f sin and f cos of
      !> omega c_k, cos and sin of omega dt (K).
      integer(ik) :: load_k = 0
      real(wp), allocatable :: sigma(:), cosine(:), cos_step(:), sin_step(:)
      !> Tip stops of each member (padding lanes: -1, 1) (K).
      real(wp), allocatable :: lower(:), upper(:)
      !> Tip value and increment after the update (K).
      real(wp), allocatable :: u_tip(:), d_tip(:)
      !> Values of the step (K).
      real(wp), allocatable :: sigma_next(:), weight(:), coef(:), spring(:), trial(:), c(:), tip_value(:), &
         & r_step(:), u_tip_prev(:), d_tip_prev(:), r_prev(:), usu(:), dsu(:), dmd(:), u_old_su(:), gd(:)
      !> Contact in the step (K).
      logical, allocatable :: contact(:)
      !> With damping: C d^{n-1} of every member (lanes, n, chunks; unallocated without).
      real(wp), allocatable :: cd(:, :, :)
      !> Per member (padded): energy the damping took, d^{n-1}.C d^{n-1}, and the step's d^n.C d^{n-1}
      !> and d^n.C d^n (per unit mass); the restitution coefficient e; with a massless tip,
      !> (S u^n)_tip and (S d^{n-1})_tip; the bounds of the step's projection (restitution).
      real(wp), allocatable :: damped(:), dcd_prev(:), cross(:), dcd(:), restitution(:), s_u_tip(:), &
         & s_d_prev_tip(:), bound_lower(:), bound_upper(:)
   end type members_type

contains

   !> The lane of member k in its chunk.
   pure integer function lane(k)
      integer, intent(in) :: k
      lane = mod(k - 1, lockstep_lanes) + 1
   end function lane

   !> The chunk of member k.
   pure integer function chunk(k)
      integer, intent(in) :: k
      chunk = (k - 1)/lockstep_lanes + 1
   end function chunk

   !> The contact law at the tip of every member (beamstops_scheme's contact_law and the
   !> projection of beamstops_contact_tip_projection, written over the members): from the
   !> trial tip values, the multiple c of z, the tip value, the reaction of the step, contact.
   !> Padding lanes: trial 0 between their stops -1 and 1, so c = 0.
   subroutine contact_law(law, scenes, model, ms)
      integer, intent(in) :: law
      type(scene_type), intent(in) :: scenes(:)
      type(model_type), intent(in) :: model
      type(members_type), intent(inout) :: ms
      real(wp) :: z_tip
      integer :: k, c, lo, hi
      z_tip = model%z(model%tip)
      select case (law)
      case (law_signorini)
         do c = 1, ms%chunks
            lo = (c - 1)*lockstep_lanes + 1
            hi = c*lockstep_lanes
            call project_lanes(ms%trial(lo:hi), ms%lower(lo:hi), ms%upper(lo:hi), z_tip, model%dt2, &
               & ms%tip_value(lo:hi), ms%c(lo:hi), ms%contact(lo:hi), ms%r_step(lo:hi))
         end do
      case (law_compliance)
         do k = 1, ms%k
            call compliance_step(ms%trial(k), scenes(k)%lower, scenes(k)%upper, scenes(k)%stiffness_per_mass, &
               & model%dt2, model%beta, z_tip, ms%p_prev(k), ms%p_now(k), ms%tip_value(k), ms%c(k), ms%r_step(k), &
               & ms%contact(k))
         end do
      case default
         ms%c = 0
         ms%tip_value = ms%trial
         ms%r_step = 0
         ms%contact = .false.
      end select
   end subroutine contact_law

   !> After the update, for every member (beamstops_scheme's close_step, written over the
   !> members, on the gathered tip values u_tip, d_tip): the exact tip value (Signorini), the
   !> violation, impacts, the work of the load and the energy the stops take, the load averages
   !> moved on.
   subroutine close_steps(law, ms)
      integer, intent(in) :: law
      type(members_type), intent(inout) :: ms
      integer :: c, lo, hi
      do c = 1, ms%chunks
         lo = (c - 1)*lockstep_lanes + 1
         hi = c*lockstep_lanes
         call close_lanes(law, ms%contact(lo:hi), ms%tip_value(lo:hi), ms%u_tip_prev(lo:hi), ms%d_tip_prev(lo:hi), &
            & ms%lower(lo:hi), ms%upper(lo:hi), ms%weight(lo:hi), ms%gd(lo:hi), ms%r_step(lo:hi), &
            & ms%sigma_next(lo:hi), ms%u_tip(lo:hi), ms%d_tip(lo:hi), ms%max_violation(lo:hi), ms%impacts(lo:hi), &
            & ms%in_contact(lo:hi), ms%work(lo:hi), ms%dissipated(lo:hi), ms%reaction(lo:hi), ms%gd_prev(lo:hi), &
            & ms%sigma_prev(lo:hi), ms%sigma_now(lo:hi))
      end do
   end subroutine close_steps

   !> The projection of the trial tip values on the stops of a chunk of lanes (beamstops_contact_
   !> tip_projection's project_tip): tip value, multiple c of z, contact, reaction of the step.
   pure subroutine project_lanes(trial, lower, upper, z_tip, dt2, tip_value, c, contact, r_step)
      real(wp), intent(in) :: trial(lockstep_lanes), lower(lockstep_lanes), upper(lockstep_lanes), z_tip, dt2
      real(wp), intent(out) :: tip_value(lockstep_lanes), c(lockstep_lanes), r_step(lockstep_lanes)
      logical, intent(out) :: contact(lockstep_lanes)
      integer :: k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         tip_value(k) = min(max(trial(k), lower(k)), upper(k))
         c(k) = (tip_value(k) - trial(k))/z_tip
         contact(k) = c(k) /= 0
         r_step(k) = c(k)/dt2
      end do
   end subroutine project_lanes

   !> close_steps for a chunk of lanes.
   pure subroutine close_lanes(law, contact, tip_value, u_tip_prev, d_tip_prev, lower, upper, weight, gd, r_step, &
      & sigma_next, u_tip, d_tip, max_violation, impacts, in_contact, work, dissipated, reaction, gd_prev, &
      & sigma_prev, sigma_now)
      integer, intent(in) :: law
      logical, intent(in) :: contact(lockstep_lanes)
      real(wp), intent(in) :: tip_value(lockstep_lanes), u_tip_prev(lockstep_lanes), d_tip_prev(lockstep_lanes), &
         & lower(lockstep_lanes), upper(lockstep_lanes), weight(lockstep_lanes), gd(lockstep_lanes), &
         & r_step(lockstep_lanes), sigma_next(lockstep_lanes)
      real(wp), intent(inout) :: u_tip(lockstep_lanes), d_tip(lockstep_lanes), max_violation(lockstep_lanes), &
         & work(lockstep_lanes), dissipated(lockstep_lanes), reaction(lockstep_lanes), gd_prev(lockstep_lanes), &
         & sigma_prev(lockstep_lanes), sigma_now(lockstep_lanes)
      integer(ik), intent(inout) :: impacts(lockstep_lanes)
      logical, intent(inout) :: in_contact(lockstep_lanes)
      integer :: k
      if (law == law_signorini) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            if (contact(k)) then
               u_tip(k) = tip_value(k)
               d_tip(k) = tip_value(k) - u_tip_prev(k)
            end if
         end do
      end if
      if (law /= law_none) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            max_violation(k) = max(max_violation(k), max(u_tip(k) - upper(k), lower(k) - u_tip(k), 0.0_wp))
         end do
      end if
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         if (contact(k) .and. .not. in_contact(k)) impacts(k) = impacts(k) + 1
         in_contact(k) = contact(k)
         work(k) = newmark_work(work(k), weight(k), gd(k), gd_prev(k))
         dissipated(k) = dissipated(k) - 0.5_wp*r_step(k)*(d_tip(k) + d_tip_prev(k))
         reaction(k) = r_step(k)
         gd_prev(k) = gd(k)
         sigma_prev(k) = sigma_now(k)
         sigma_now(k) = sigma_next(k)
      end do
   end subroutine close_lanes

   !> Member k's record row of step n from the members' arrays (the general loop's; the plain
   !> loop's is lockstep.f90's fill_row_lanes), the energy column left for later (fill_row).
   subroutine fill_row_members(scene, model, ms, d_tip, k, step, row)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(members_type), intent(in) :: ms
      !> Member k's d^n at the tip (the loop's vectors are in its store during a block).
      real(wp), intent(in) :: d_tip
      integer, intent(in) :: k
      integer(ik), intent(in) :: step
      real(wp), intent(out) :: row(n_columns)
      row(col_t) = real(step, wp)*model%dt
      row(col_u) = ms%u_tip_prev(k)
      row(col_v) = (d_tip + ms%d_tip_prev(k))/(2*model%dt)
      row(col_reaction) = scene%mass_per_length*ms%r_prev(k)
      row(col_energy) = 0
      row(col_work) = scene%mass_per_length*ms%work(k)
      row(col_dissipated) = scene%mass_per_length*ms%dissipated(k)
      row(col_damped) = scene%mass_per_length*ms%damped(k)
   end subroutine fill_row_members

   !> Snapshot of member k's u^n (= u^{n+1} - d^n) at t_n (take_snapshot, physical_shape).
   subroutine take_snapshot(scene, model, ms, k, step, recorder)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(members_type), intent(inout) :: ms
      integer, intent(in) :: k
      integer(ik), intent(in) :: step
      class(recorder_type), intent(inout) :: recorder
      real(wp) :: phi, t
      ms%vec_s = ms%u(lane(k), :, chunk(k)) - ms%d(lane(k), :, chunk(k))
      t = real(step, wp)*model%dt
      phi = support_position(t, scene%amplitude, scene%omega)
      ms%shape = model%lift*phi
      ms%shape(2:) = ms%shape(2:) + ms%vec_s(1::2)
      call recorder%snapshot(real(step, wp)*model%dt, ms%shape)
   end subroutine take_snapshot

   !> The load rotation of every member at step k (start_loads): from load_average at the last
   !> multiple of restart_every, then rotated.
   subroutine start_loads(ms, k, scenes, model)
      type(members_type), intent(inout) :: ms
      integer(ik), intent(in) :: k
      type(scene_type), intent(in) :: scenes(:)
      type(model_type), intent(in) :: model
      call restart_loads(ms, (k/restart_every)*restart_every, scenes, model)
      do while (ms%load_k < k)
         call next_loads(ms, scenes, model)
      end do
   end subroutine start_loads

   !> The load rotation of every member at step k, exact (restart_loads).
   subroutine restart_loads(ms, k, scenes, model)
      type(members_type), intent(inout) :: ms
      integer(ik), intent(in) :: k
      type(scene_type), intent(in) :: scenes(:)
      type(model_type), intent(in) :: model
      real(wp) :: centre, x, factor
      integer :: m
      ms%load_k = k
      do m = 1, ms%k
         centre = real(k, wp)*model%dt
         if (.not. scenes(m)%centered_load) centre = (real(k, wp) + 0.5_wp)*model%dt
         x = 0.5_wp*scenes(m)%omega*model%dt
         if (abs(x) < 1.0e-8_wp) then
            factor = 1 - x**2/6
         else
            factor = sin(x)/x
         end if
         ms%sigma(m) = load_average(k, model%dt, scenes(m)%omega, scenes(m)%centered_load)
         ms%cosine(m) = factor*cos(scenes(m)%omega*centre)
         ms%cos_step(m) = cos(scenes(m)%omega*model%dt)
         ms%sin_step(m) = sin(scenes(m)%omega*model%dt)
      end do
   end subroutine restart_loads

   !> The load rotation of every member moved on by one step (next_load).
   subroutine next_loads(ms, scenes, model)
      type(members_type), intent(inout) :: ms
      type(scene_type), intent(in) :: scenes(:)
      type(model_type), intent(in) :: model
      real(wp) :: sigma
      integer :: m
      if (mod(ms%load_k + 1, restart_every) == 0) then
         call restart_loads(ms, ms%load_k + 1, scenes, model)
         return
      end if
      do m = 1, ms%p
         sigma = ms%sigma(m)*ms%cos_step(m) + ms%cosine(m)*ms%sin_step(m)
         ms%cosine(m) = ms%cosine(m)*ms%cos_step(m) - ms%sigma(m)*ms%sin_step(m)
         ms%sigma(m) = sigma
      end do
      ms%load_k = ms%load_k + 1
   end subroutine next_loads
end module beamstops_lockstep_members
