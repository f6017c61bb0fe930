!> The shock log of SPEC 12 (code_aster's impact counting, POST_DYNA_MODA_T / compt.F90 with
!> DUREE_REPOS): per stop, O(1) memory, updated every step; completed shocks wait in a small ring
!> of rows that the caller drains between blocks of steps.
!>
!> Samples. The loop hands the log one sample per step, k = 1, 2, ...: the time t_k, the
!> displacement u_k of each stop's node at t_k (the tip for the tip-only scene), the reaction r_k
!> of each stop in the step that brought u there (N; <= 0 at the upper stop, >= 0 at the lower,
!> 0 between) and the energy e_k that stop took in that step (J). For the time loop: at step n,
!> t = (n+1) dt, u = u^{n+1}, r = r_n, e = D^n (SPEC 6) -- the pairing of the record rows, whose
!> reaction is the one of the step that brought u there. u_0 (at t_0) is given at construction.
!>
!> Definitions (per stop; dt is the step, constant within a run):
!> - contact sample: r_k /= 0; contact phase: a maximal run a..b of consecutive contact samples
!>   of one sign; the phase starts at t_a and ends at t_{b+1} = t_b + dt, the first free sample
!>   (code_aster's idebut / ifin), so a phase of c samples lasts c dt;
!> - shock: contact phases of the same sign merged when the free time between them,
!>   (a' - b - 1) dt for a phase a'..b' after a phase ..b, is < rest_time (so rest_time = 0
!>   never merges); rebounds = phases - 1; a phase of the other sign always starts a new shock;
!> - t_start = t_a of the first phase, t_end = t_{b+1} of the last phase (duration =
!>   t_end - t_start, the rests between phases included);
!> - velocity_in = (u_a - u_{a-2}) / (2 dt): the centred difference at the last free sample a-1
!>   before the shock (the recorder's v column at t_{a-1}); u_{-1} = u_0 when a = 1;
!> - velocity_out = (u_{b+2} - u_b) / (2 dt): the centred difference at the first free sample
!>   b+1 after the last phase; NaN when the run ends before b+2 or the other stop is hit at b+1;
!> - impulse = sum of r_k dt over the shock's contact samples (N s, signed like r);
!> - peak_reaction = the r_k of largest |r_k| over the shock, signed as recorded (the first one
!>   on ties);
!> - energy_taken = sum of e_k over the shock's contact samples (J) (e_k is zero on free samples
!>   for every contact law of the engine);
!> - contact_steps = number of contact samples; contact_time = contact_steps dt.
!> A shock is known to be complete at the sample b + max(R, 2), R = the smallest integer with
!> R dt >= rest_time (no later phase can merge, and u_{b+2} is known), or earlier when a phase
!> that cannot merge starts; finish closes the open shocks at the end of a run and marks them
!> truncated (a later phase might have merged with them).
!>
!> Cost: the step adds one counter per call and, per stop, one test of r_k /= 0, one compare of
!> the sample counter against a deadline and two moves (the last two u); everything else
!> happens on contact samples and at the few samples after a phase, in procedures kept out of
!> line so that the common path stays a leaf without register saves.
module beamstops_observe_shocks
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: fmt_real, fmt_int
   use beamstops_observe_pack, only: put, ik_value, logical_value, take_header, take_real, take_int, take_ik, &
      & take_logical
   implicit none
   private
   public :: shock_log, shock_row, new_shock_log, shock_row_values
   public :: n_shock_columns, shock_column_names, shock_column_units
   public :: side_lower, side_upper

   !> Side of a shock: the sign of its reaction (+1 the lower stop pushes up, -1 the upper down).
   integer, parameter :: side_lower = 1, side_upper = -1

   !> Columns of shock_row_values, for a table of shocks (HDF5 /shocks, Python).
   integer, parameter :: n_shock_columns = 13
   !> Names of the columns of shock_row_values.
   character(len=*), parameter :: shock_column_names(n_shock_columns) = [character(len=14) :: &
      & 't_start', 't_end', 'stop', 'side', 'velocity_in', 'velocity_out', 'impulse', 'peak_reaction', &
      & 'energy_taken', 'rebounds', 'contact_steps', 'contact_time', 'truncated']
   !> Units of the columns of shock_row_values ('1': a number).
   character(len=*), parameter :: shock_column_units(n_shock_columns) = [character(len=5) :: &
      & 's', 's', '1', '1', 'm/s', 'm/s', 'N s', 'N', 'J', '1', '1', 's', '1']

   !> A completed shock.
   type :: shock_row
      !> Time of the first contact sample and of the first free sample after the last phase (s).
      real(wp) :: t_start = 0, t_end = 0
      !> Centred velocities just before and just after the shock (m/s; velocity_out may be NaN).
      real(wp) :: velocity_in = 0, velocity_out = 0
      !> Sum of r dt over the contact samples (N s, signed like the reaction).
      real(wp) :: impulse = 0
      !> Reaction of largest magnitude, signed as recorded (N).
      real(wp) :: peak_reaction = 0
      !> Energy the stop took over the shock (J).
      real(wp) :: energy_taken = 0
      !> Number of contact samples times dt (s).
      real(wp) :: contact_time = 0
      !> Stop index (1-based, in the order of the arrays given to step).
      integer :: stop = 0
      !> side_lower (+1, reaction > 0) or side_upper (-1, reaction < 0).
      integer :: side = 0
      !> Contact phases minus one.
      integer :: rebounds = 0
      !> Number of contact samples.
      integer(ik) :: contact_steps = 0
      !> Closed by finish before its rest time had passed (or while in contact).
      logical :: truncated = .false.
   end type shock_row

   !> The open shock of one stop and the state of its phase.
   type :: stop_track
      !> A shock is open.
      logical :: open = .false.
      !> The last sample was a contact sample of the open shock.
      logical :: in_phase = .false.
      !> Sample index of the last contact sample (b).
      integer(ik) :: last = 0
      !> Free samples that end the shock's chances of merging (R), set at the end of a phase.
      integer(ik) :: rest_steps = 0
      !> The shock being built.
      type(shock_row) :: row
      !> Time and step of the last contact sample.
      real(wp) :: t_last = 0, dt_last = 0
   end type stop_track

   !> Shock log of m stops.
   type :: shock_log
      private
      !> Number of stops.
      integer :: m = 0
      !> Rest time (s).
      real(wp) :: rest_time = 0
      !> Samples seen.
      integer(ik) :: k = 0
      !> Displacement at the last and the one-before-last sample (m).
      real(wp), allocatable :: u1(:), u2(:)
      !> Sample index at which a free sample of the stop needs attention (huge: none).
      integer(ik), allocatable :: deadline(:)
      !> Per stop: the open shock.
      type(stop_track), allocatable :: track(:)
      !> Per stop: shocks closed, contact phases started.
      integer(ik), allocatable :: shocks(:), phases(:)
      !> Ring of completed rows: storage, index of the oldest, number held.
      type(shock_row), allocatable :: ring(:)
      integer :: head = 1, held = 0
      !> Rows dropped because the ring was full.
      integer(ik) :: lost = 0
   contains
      !> Take one sample (every step).
      procedure :: step
      !> Take one sample of a log of one stop, from scalars (every step; the tip-only scene).
      procedure :: step_tip
      !> Energy a stop took in a step without contact, to its open shock.
      procedure :: trailing_energy
      !> What a quiet sample of the tip reads and changes: samples seen, the tip at the last two
      !> samples, the sample that needs attention (beamstops_observe_lanes).
      procedure :: quiet_tip
      !> Those values after quiet samples taken elsewhere.
      procedure :: set_quiet_tip
      !> Close the open shocks at the end of a run.
      procedure :: finish
      !> Whether a completed row waits.
      procedure :: ready
      !> Take the oldest completed row.
      procedure :: pop
      !> Shocks closed so far at a stop (or at all stops).
      procedure :: shock_count
      !> Contact phases started so far at a stop (or at all stops).
      procedure :: phase_count
      !> Rows dropped because the ring was full (drain more often).
      procedure :: lost_count
      !> Number of stops.
      procedure :: stop_count
      !> The complete state as a vector of reals (checkpoints).
      procedure :: pack => pack_log
      !> Restore the state from a vector of pack.
      procedure :: unpack => unpack_log
      ! The rare paths, bound so that calls go through the type's table and stay out of line:
      ! the common path of step is then a leaf without register saves.
      procedure, private :: contact_sample
      procedure, private :: free_sample
   end type shock_log

   !> Rest in samples beyond which no run reaches (2**60).
   integer(ik), parameter :: max_rest = 2_ik**60

   !> Ring size when none is given.
   integer, parameter :: default_capacity = 4096

   !> First two values of a packed shock log: its tag and the version of the layout.
   real(wp), parameter :: pack_tag = 7301, pack_version = 1
   !> Values of the header, of the scalars, per stop (u1, u2, deadline, shocks, phases and the
   !> track), per row.
   integer, parameter :: pack_header = 6, pack_scalars = 4, pack_per_stop = 5 + 6 + n_shock_columns, &
      & pack_per_row = n_shock_columns

contains

   !> A shock log for `stops` stops whose nodes are at u0 at t_0.
   subroutine new_shock_log(log, stops, rest_time, u0, error, capacity)
      !> The log, empty.
      type(shock_log), intent(out) :: log
      !> Number of stops m (>= 1).
      integer, intent(in) :: stops
      !> Rest time (s, >= 0): phases separated by less are one shock (code_aster DUREE_REPOS).
      real(wp), intent(in) :: rest_time
      !> Displacement of each stop's node at t_0 (m) (m).
      real(wp), intent(in) :: u0(:)
      !> Set when an argument is out of range.
      type(error_type), allocatable, intent(out) :: error
      !> Completed rows held before they are dropped (default 4096); with the caller draining every
      !> `block` steps, capacity >= m (block/2 + 1) can never drop a row.
      integer, intent(in), optional :: capacity
      integer :: cap
      cap = default_capacity
      if (present(capacity)) cap = capacity
      if (stops < 1) then
         call fatal_error(error, 'shock log: stops = '//fmt_int(int(stops, ik))//' is out of range; allowed: stops >= 1')
         return
      end if
      if (.not. (rest_time >= 0 .and. rest_time <= huge(rest_time))) then
         call fatal_error(error, 'shock log: rest_time = '//fmt_real(rest_time)// &
            & ' is out of range; allowed: rest_time >= 0 s')
         return
      end if
      if (size(u0) /= stops) then
         call fatal_error(error, 'shock log: u0 has '//fmt_int(int(size(u0), ik))//' values; allowed: one per stop ('// &
            & fmt_int(int(stops, ik))//')')
         return
      end if
      if (cap < 1) then
         call fatal_error(error, 'shock log: capacity = '//fmt_int(int(cap, ik))//' is out of range; allowed: capacity >= 1')
         return
      end if
      log%m = stops
      log%rest_time = rest_time
      log%u1 = u0
      log%u2 = u0
      allocate (log%deadline(stops), log%track(stops), log%shocks(stops), log%phases(stops), log%ring(cap))
      log%deadline = huge(1_ik)
      log%shocks = 0
      log%phases = 0
   end subroutine new_shock_log

   !> Take the sample of one step (see the module's definitions). No allocation, no I/O.
   subroutine step(self, t, dt, u, reaction, energy_taken)
      !> Log.
      class(shock_log), intent(inout) :: self
      !> Time of the sample t_k (s).
      real(wp), intent(in) :: t
      !> Time step (s).
      real(wp), intent(in) :: dt
      !> Displacement of each stop's node at t_k (m) (m).
      real(wp), intent(in), contiguous :: u(:)
      !> Reaction of each stop in the step that brought u there (N) (m).
      real(wp), intent(in), contiguous :: reaction(:)
      !> Energy each stop took in that step (J) (m).
      real(wp), intent(in), contiguous :: energy_taken(:)
      integer :: i
      integer(ik) :: k
      k = self%k + 1
      self%k = k
      do i = 1, self%m
         if (reaction(i) /= 0) then
            call self%contact_sample(i, k, t, dt, u(i), reaction(i), energy_taken(i))
         else
            if (energy_taken(i) /= 0) call self%trailing_energy(i, energy_taken(i))
            if (k >= self%deadline(i)) call self%free_sample(i, k, t, dt, u(i))
         end if
         self%u2(i) = self%u1(i)
         self%u1(i) = u(i)
      end do
   end subroutine step

   !> step for a log of one stop (m = 1), from scalars: the same update without array arguments.
   subroutine step_tip(self, t, dt, u, reaction, energy_taken)
      !> Log of one stop.
      class(shock_log), intent(inout) :: self
      !> Time of the sample t_k (s).
      real(wp), intent(in) :: t
      !> Time step (s).
      real(wp), intent(in) :: dt
      !> Displacement of the stop's node (the tip) at t_k (m).
      real(wp), intent(in) :: u
      !> Reaction of the stop in the step that brought u there (N).
      real(wp), intent(in) :: reaction
      !> Energy the stop took in that step (J).
      real(wp), intent(in) :: energy_taken
      integer(ik) :: k
      k = self%k + 1
      self%k = k
      if (reaction /= 0) then
         call self%contact_sample(1, k, t, dt, u, reaction, energy_taken)
      else
         if (energy_taken /= 0) call self%trailing_energy(1, energy_taken)
         if (k >= self%deadline(1)) call self%free_sample(1, k, t, dt, u)
      end if
      self%u2(1) = self%u1(1)
      self%u1(1) = u
   end subroutine step_tip

   !> What a quiet sample of the tip (no reaction, no energy taken, before the deadline: step_tip
   !> only counts it and shifts the tip's last two values) reads and changes.
   pure subroutine quiet_tip(self, k, u1, u2, deadline)
      !> Log of one stop.
      class(shock_log), intent(in) :: self
      !> Samples seen, the sample that needs attention.
      integer(ik), intent(out) :: k, deadline
      !> The tip at the last and the one-before-last sample (m).
      real(wp), intent(out) :: u1, u2
      k = self%k
      u1 = self%u1(1)
      u2 = self%u2(1)
      deadline = self%deadline(1)
   end subroutine quiet_tip

   !> The samples seen and the tip's last two values after quiet samples taken elsewhere.
   pure subroutine set_quiet_tip(self, k, u1, u2)
      !> Log of one stop.
      class(shock_log), intent(inout) :: self
      !> Samples seen.
      integer(ik), intent(in) :: k
      !> The tip at the last and the one-before-last sample (m).
      real(wp), intent(in) :: u1, u2
      self%k = k
      self%u1(1) = u1
      self%u2(1) = u2
   end subroutine set_quiet_tip

   !> A contact sample of stop i: continue the phase, merge a new phase into the open shock, or
   !> close the open shock and open a new one.
   subroutine contact_sample(self, i, k, t, dt, u, r, e)
      class(shock_log), intent(inout) :: self
      integer, intent(in) :: i
      integer(ik), intent(in) :: k
      real(wp), intent(in) :: t, dt, u, r, e
      integer :: side
      side = merge(side_lower, side_upper, r > 0)
      associate (tr => self%track(i))
         if (tr%open) then
            if (tr%in_phase) then
               if (side /= tr%row%side) then
                  ! The other stop right after: the phase ends here, no free sample for v_out.
                  tr%row%t_end = t
                  tr%row%velocity_out = nan()
                  call close_shock(self, i, .false.)
                  call open_shock(self, i, side, t, dt, u)
               end if
            else if (side == tr%row%side .and. k - tr%last - 1 < tr%rest_steps) then
               ! A rebound: the phase joins the open shock.
               tr%in_phase = .true.
               tr%row%rebounds = tr%row%rebounds + 1
               tr%row%velocity_out = nan()
               self%phases(i) = self%phases(i) + 1
            else
               if (k == tr%last + 2) tr%row%velocity_out = (u - self%u2(i))/(2*dt)
               call close_shock(self, i, .false.)
               call open_shock(self, i, side, t, dt, u)
            end if
         else
            call open_shock(self, i, side, t, dt, u)
         end if
         tr%row%impulse = tr%row%impulse + r*dt
         if (abs(r) > abs(tr%row%peak_reaction)) tr%row%peak_reaction = r
         tr%row%energy_taken = tr%row%energy_taken + e
         tr%row%contact_steps = tr%row%contact_steps + 1
         tr%row%contact_time = tr%row%contact_time + dt
         tr%last = k
         tr%t_last = t
         tr%dt_last = dt
      end associate
      self%deadline(i) = k + 1
   end subroutine contact_sample

   !> Energy a stop took in a step without contact: with massless stop unknowns (SPEC 10) the
   !> stops' energy of the two steps after a contact phase (the Newmark average of the stop's row
   !> still holds the reactions of that phase). It belongs to the shock still open (the rest time
   !> is at least two steps), so that the shocks' energies add up to the stops' energy. With no
   !> shock open it is the rounding of a free massless row's residual (about 1e-15 of the
   !> reactions), left out of the log (the statistics' power keeps every step's energy).
   subroutine trailing_energy(self, i, e)
      class(shock_log), intent(inout) :: self
      integer, intent(in) :: i
      real(wp), intent(in) :: e
      if (self%track(i)%open) self%track(i)%row%energy_taken = self%track(i)%row%energy_taken + e
   end subroutine trailing_energy

   !> Open a shock of stop i on `side` at its first contact sample (time t, displacement u).
   subroutine open_shock(self, i, side, t, dt, u)
      type(shock_log), intent(inout) :: self
      integer, intent(in) :: i, side
      real(wp), intent(in) :: t, dt, u
      associate (tr => self%track(i))
         tr%open = .true.
         tr%in_phase = .true.
         tr%rest_steps = 0
         tr%row = shock_row()
         tr%row%stop = i
         tr%row%side = side
         tr%row%t_start = t
         tr%row%velocity_in = (u - self%u2(i))/(2*dt)
         tr%row%velocity_out = nan()
         self%phases(i) = self%phases(i) + 1
      end associate
   end subroutine open_shock

   !> A free sample of stop i at or after its deadline: the end of a phase (k = b+1), the
   !> velocity after it (k = b+2), the end of the shock (k = b + max(R, 2)).
   subroutine free_sample(self, i, k, t, dt, u)
      class(shock_log), intent(inout) :: self
      integer, intent(in) :: i
      integer(ik), intent(in) :: k
      real(wp), intent(in) :: t, dt, u
      integer(ik) :: close_at
      associate (tr => self%track(i))
         if (.not. tr%open) then
            self%deadline(i) = huge(1_ik)
            return
         end if
         if (tr%in_phase) then
            tr%in_phase = .false.
            tr%row%t_end = t
            tr%rest_steps = rest_steps_of(self%rest_time, dt)
            self%deadline(i) = tr%last + 2
            return
         end if
         if (k == tr%last + 2) tr%row%velocity_out = (u - self%u2(i))/(2*dt)
         close_at = tr%last + max(tr%rest_steps, 2_ik)
         if (k >= close_at) then
            call close_shock(self, i, .false.)
         else
            self%deadline(i) = close_at
         end if
      end associate
   end subroutine free_sample

   !> The smallest integer R >= 0 with R dt >= rest_time (g free samples merge when g < R).
   pure function rest_steps_of(rest_time, dt) result(r)
      real(wp), intent(in) :: rest_time, dt
      integer(ik) :: r
      real(wp) :: q
      q = rest_time/dt
      if (q >= real(max_rest, wp)) then
         r = max_rest
         return
      end if
      r = max(0_ik, ceiling(q, ik))
      do while (r > 0)
         if (real(r - 1, wp)*dt < rest_time) exit
         r = r - 1
      end do
      do while (real(r, wp)*dt < rest_time)
         r = r + 1
      end do
   end function rest_steps_of

   !> Hand the open shock of stop i to the ring and reset its track.
   subroutine close_shock(self, i, truncated)
      type(shock_log), intent(inout) :: self
      integer, intent(in) :: i
      logical, intent(in) :: truncated
      integer :: slot
      associate (tr => self%track(i))
         tr%row%truncated = truncated
         if (self%held < size(self%ring)) then
            slot = mod(self%head - 1 + self%held, size(self%ring)) + 1
            self%ring(slot) = tr%row
            self%held = self%held + 1
         else
            self%lost = self%lost + 1
         end if
         self%shocks(i) = self%shocks(i) + 1
         tr%open = .false.
         tr%in_phase = .false.
      end associate
      self%deadline(i) = huge(1_ik)
   end subroutine close_shock

   !> Close the shocks still open at the end of a run (marked truncated): a shock still in
   !> contact ends at t_last + dt, and its velocity_out is NaN, as it is when u_{b+2} was not seen.
   subroutine finish(self)
      !> Log.
      class(shock_log), intent(inout) :: self
      integer :: i
      do i = 1, self%m
         associate (tr => self%track(i))
            if (.not. tr%open) cycle
            if (tr%in_phase) then
               tr%row%t_end = tr%t_last + tr%dt_last
               tr%row%velocity_out = nan()
            end if
         end associate
         call close_shock(self, i, .true.)
      end do
   end subroutine finish

   !> Whether a completed row waits in the ring.
   pure logical function ready(self)
      !> Log.
      class(shock_log), intent(in) :: self
      ready = self%held > 0
   end function ready

   !> Take the oldest completed row (rows come out in the order the shocks were closed).
   subroutine pop(self, row, found)
      !> Log.
      class(shock_log), intent(inout) :: self
      !> The row (default values when none waits).
      type(shock_row), intent(out) :: row
      !> A row was taken.
      logical, intent(out), optional :: found
      if (present(found)) found = self%held > 0
      if (self%held == 0) return
      row = self%ring(self%head)
      self%head = mod(self%head, size(self%ring)) + 1
      self%held = self%held - 1
   end subroutine pop

   !> Shocks closed so far at stop `i`, or at all stops.
   pure function shock_count(self, i) result(n)
      !> Log.
      class(shock_log), intent(in) :: self
      !> Stop (default: all).
      integer, intent(in), optional :: i
      integer(ik) :: n
      n = count_at(self%shocks, i)
   end function shock_count

   !> Contact phases started so far at stop `i`, or at all stops.
   pure function phase_count(self, i) result(n)
      !> Log.
      class(shock_log), intent(in) :: self
      !> Stop (default: all).
      integer, intent(in), optional :: i
      integer(ik) :: n
      n = count_at(self%phases, i)
   end function phase_count

   !> counts(i), or the sum of counts when i is absent.
   pure function count_at(counts, i) result(n)
      integer(ik), intent(in) :: counts(:)
      integer, intent(in), optional :: i
      integer(ik) :: n
      if (present(i)) then
         n = counts(i)
      else
         n = sum(counts)
      end if
   end function count_at

   !> Rows dropped because the ring was full.
   pure function lost_count(self) result(n)
      !> Log.
      class(shock_log), intent(in) :: self
      integer(ik) :: n
      n = self%lost
   end function lost_count

   !> Number of stops of the log.
   pure integer function stop_count(self)
      !> Log.
      class(shock_log), intent(in) :: self
      stop_count = self%m
   end function stop_count

   !> A row as the reals of a table in the order of shock_column_names (truncated: 1 or 0).
   pure function shock_row_values(row) result(v)
      !> Row.
      type(shock_row), intent(in) :: row
      real(wp) :: v(n_shock_columns)
      v = [row%t_start, row%t_end, real(row%stop, wp), real(row%side, wp), row%velocity_in, row%velocity_out, &
         & row%impulse, row%peak_reaction, row%energy_taken, real(row%rebounds, wp), real(row%contact_steps, wp), &
         & row%contact_time, merge(1.0_wp, 0.0_wp, row%truncated)]
   end function shock_row_values

   !> The complete state of the log as reals, for a checkpoint (unpack restores it; a log never
   !> constructed packs as its header alone, with m = 0). Integers are stored exactly as reals
   !> (counters stay far below 2**53; huge(1_ik), "no deadline", as +Infinity), logicals as 1 or
   !> 0, reals bit for bit (NaN included). Layout, version 1 (m stops, ring capacity C, H rows
   !> held):
   !> - header (6): 7301 (tag), 1 (version), total length, m, C, H;
   !> - scalars (4): rest_time, k (samples seen), head (ring slot of the oldest row), lost;
   !> - per stop, five arrays of m: u1, u2, deadline, shocks, phases;
   !> - per stop i = 1..m, its track (19): open, in_phase, last, rest_steps, t_last, dt_last, then
   !>   its open row (13);
   !> - the H rows held, oldest first (13 each).
   !> A row is its 13 values in the order of shock_column_names (shock_row_values).
   !> Total: 10 + 24 m + 13 H (6 when m = 0).
   subroutine pack_log(self, values)
      !> Log.
      class(shock_log), intent(in) :: self
      !> The state, in the layout above.
      real(wp), allocatable, intent(out) :: values(:)
      integer :: i, j, p, cap, n
      if (self%m == 0) then
         values = [pack_tag, pack_version, real(pack_header, wp), 0.0_wp, 0.0_wp, 0.0_wp]
         return
      end if
      cap = size(self%ring)
      n = pack_header + pack_scalars + pack_per_stop*self%m + pack_per_row*self%held
      allocate (values(n))
      p = 0
      call put(values, p, [pack_tag, pack_version, real(n, wp), real(self%m, wp), real(cap, wp), real(self%held, wp)])
      call put(values, p, [self%rest_time, ik_value(self%k), real(self%head, wp), ik_value(self%lost)])
      call put(values, p, self%u1)
      call put(values, p, self%u2)
      call put(values, p, ik_value(self%deadline))
      call put(values, p, ik_value(self%shocks))
      call put(values, p, ik_value(self%phases))
      do i = 1, self%m
         associate (tr => self%track(i))
            call put(values, p, [logical_value(tr%open), logical_value(tr%in_phase), ik_value(tr%last), &
               & ik_value(tr%rest_steps), tr%t_last, tr%dt_last])
            call put(values, p, shock_row_values(tr%row))
         end associate
      end do
      do j = 0, self%held - 1
         call put(values, p, shock_row_values(self%ring(mod(self%head - 1 + j, cap) + 1)))
      end do
   end subroutine pack_log

   !> Restore the log from a vector of pack (the layout of pack_log): afterwards it takes the
   !> same samples and gives the same rows and counts, bit for bit, as the log that was packed.
   !> On an error (a vector too short or too long for its header, another tag or version, a value
   !> that is not an integer or a logical where one is due, an index out of range) the log is
   !> left unchanged.
   subroutine unpack_log(self, values, error)
      !> Log (any state: it is replaced).
      class(shock_log), intent(inout) :: self
      !> The state, from pack.
      real(wp), intent(in) :: values(:)
      !> Set when the vector is not a packed shock log.
      type(error_type), allocatable, intent(out) :: error
      type(shock_log) :: new
      integer :: i, j, p, m, cap, held, head, n, bad, header(pack_header - 2)
      integer(ik) :: want
      call take_header(values, 'shock log', pack_tag, pack_version, header, error)
      if (allocated(error)) return
      n = header(1)
      m = header(2)
      cap = header(3)
      held = header(4)
      bad = 0
      if (m < 0 .or. cap < 0 .or. held < 0 .or. held > cap .or. ((m == 0) .neqv. (cap == 0))) then
         call fatal_error(error, 'shock log: unpack: header m = '//fmt_int(int(m, ik))//', capacity = '// &
            & fmt_int(int(cap, ik))//', held = '//fmt_int(int(held, ik))//' is inconsistent')
         return
      end if
      want = pack_header
      if (m > 0) want = pack_header + pack_scalars + pack_per_stop*int(m, ik) + pack_per_row*int(held, ik)
      if (n /= want .or. size(values) /= want) then
         call fatal_error(error, 'shock log: unpack: '//fmt_int(int(size(values), ik))//' values, header length '// &
            & fmt_int(int(n, ik))//'; the header (m = '//fmt_int(int(m, ik))//', held = '// &
            & fmt_int(int(held, ik))//') needs '//fmt_int(want))
         return
      end if
      if (m > 0) then
         new%m = m
         allocate (new%u1(m), new%u2(m), new%deadline(m), new%track(m), new%shocks(m), new%phases(m), new%ring(cap))
         p = pack_header
         call take_real(values, p, new%rest_time)
         call take_ik(values, p, new%k, bad)
         call take_int(values, p, head, bad)
         call take_ik(values, p, new%lost, bad)
         if (bad == 0 .and. .not. new%rest_time >= 0) bad = pack_header + 1
         if (bad == 0 .and. (head < 1 .or. head > cap)) bad = pack_header + 3
         do i = 1, m
            call take_real(values, p, new%u1(i))
         end do
         do i = 1, m
            call take_real(values, p, new%u2(i))
         end do
         do i = 1, m
            call take_ik(values, p, new%deadline(i), bad)
         end do
         do i = 1, m
            call take_ik(values, p, new%shocks(i), bad)
         end do
         do i = 1, m
            call take_ik(values, p, new%phases(i), bad)
         end do
         do i = 1, m
            call take_logical(values, p, new%track(i)%open, bad)
            call take_logical(values, p, new%track(i)%in_phase, bad)
            call take_ik(values, p, new%track(i)%last, bad)
            call take_ik(values, p, new%track(i)%rest_steps, bad)
            call take_real(values, p, new%track(i)%t_last)
            call take_real(values, p, new%track(i)%dt_last)
            call take_row(values, p, new%track(i)%row, bad)
         end do
         if (bad == 0) then
            new%head = head
            new%held = held
            do j = 0, held - 1
               call take_row(values, p, new%ring(mod(head - 1 + j, cap) + 1), bad)
            end do
         end if
         if (bad /= 0) then
            call fatal_error(error, 'shock log: unpack: value '//fmt_int(int(bad, ik))//' = '// &
               & fmt_real(values(bad))//' is out of range (expected an integer, a logical 0 or 1, an index '// &
               & 'in range, or rest_time >= 0)')
            return
         end if
      end if
      self%m = new%m
      self%rest_time = new%rest_time
      self%k = new%k
      self%head = new%head
      self%held = new%held
      self%lost = new%lost
      call move_alloc(new%u1, self%u1)
      call move_alloc(new%u2, self%u2)
      call move_alloc(new%deadline, self%deadline)
      call move_alloc(new%track, self%track)
      call move_alloc(new%shocks, self%shocks)
      call move_alloc(new%phases, self%phases)
      call move_alloc(new%ring, self%ring)
   end subroutine unpack_log

   !> Read a row stored as shock_row_values at values(p+1:), advance p.
   pure subroutine take_row(values, p, row, bad)
      real(wp), intent(in) :: values(:)
      integer, intent(inout) :: p
      type(shock_row), intent(out) :: row
      integer, intent(inout) :: bad
      call take_real(values, p, row%t_start)
      call take_real(values, p, row%t_end)
      call take_int(values, p, row%stop, bad)
      call take_int(values, p, row%side, bad)
      call take_real(values, p, row%velocity_in)
      call take_real(values, p, row%velocity_out)
      call take_real(values, p, row%impulse)
      call take_real(values, p, row%peak_reaction)
      call take_real(values, p, row%energy_taken)
      call take_int(values, p, row%rebounds, bad)
      call take_ik(values, p, row%contact_steps, bad)
      call take_real(values, p, row%contact_time)
      call take_logical(values, p, row%truncated, bad)
   end subroutine take_row

   !> A quiet NaN.
   function nan() result(x)
      real(wp) :: x
      x = ieee_value(x, ieee_quiet_nan)
   end function nan
end module beamstops_observe_shocks
