!> Running statistics of impacts and of the tip (SPEC 12) with batch-means confidence intervals,
!> and their ensemble across members.
!>
!> The window [transient, t_end] is cut into B equal batches, edges e_j = transient + j w,
!> w = (t_end - transient)/B, j = 1..B-1: a sample at time t belongs to batch 0 (the transient,
!> ignored) when t < transient, else to the batch j = 1 + #{i in 1..B-1 : t >= e_i} (the last
!> batch takes every later sample). Samples are those of beamstops_observe_shocks: t_k, the tip
!> displacement u_k, the reaction r_k (N) and energy e_k (J) of each stop in the step that
!> brought u there. Each shock row (from the shock log) counts in the batch holding its t_start.
!>
!> Per batch j with n_j > 0 samples (T_j = n_j dt; dt the step, constant) and per stop, the
!> batch values, and over the window (sums over the batches 1..B, N = sum n_j, T = N dt) the
!> values reported:
!> - shocks_per_second = S / T (S shocks), rebounds_per_shock = sum rebounds / S,
!> - force_mean = sum |r_k| / N, force_rms = sqrt(sum r_k^2 / N), force_max = max |r_k|,
!> - force_mean_contact = sum |r_k| / C, force_rms_contact = sqrt(sum r_k^2 / C) (C contact
!>   samples, r_k /= 0), contact_fraction = C / N,
!> - shock_duration_mean = sum (t_end - t_start) / S, shock_duration_min, shock_duration_max,
!> - impulse_rate = sum over shocks |impulse| / T (N), power = sum e_k / T (W),
!> - shocks and contact_phases: counts over the window;
!> and for the tip: tip_mean = sum u_k / N, tip_rms = sqrt(sum u_k^2 / N), tip_min, tip_max,
!> tip_histogram = fraction of the samples in each of `bins` equal bins over [lower, upper]:
!> u_k counts in bin 1 + min(max(floor((u_k - lower) * (bins/(upper - lower))), 0), bins - 1)
!> (u below lower in the first bin, u >= upper in the last), and tip_histogram_edges, the
!> bins + 1 edges of those bins: lower, for i = 1..bins-1 the least double u with
!> (u - lower) (bins/(upper - lower)) >= i as rounded (lower + i ((upper - lower)/bins) or an ulp
!> or so beside it), and upper: u in [lower, upper] is in bin i exactly when edge i <= u < edge i+1;
!> window = T (s), the time the samples after the transient cover.
!> The value of a quantity is its window estimate; its half-width is the batch-means interval
!> t_{0.975, B'-1} s / sqrt(B'), s the sample standard deviation (divisor B'-1) of the B'
!> finite batch values (a batch without samples, or a ratio with a zero denominator, has none);
!> NaN when B' < 2, and for counts and extremes (min, max), which batch means do not estimate.
!> An undefined value (a ratio over nothing) is NaN. Shock rows whose stop is not in 1..m are
!> ignored; truncated rows (closed by the log's finish) count like the others.
!>
!> Use: new_statistics, then every step `step` (arrays over the m stops) or `step_tip` (m = 1,
!> scalars: about half the cost), add_shock for each row drained from the shock log, finish at
!> the end, results for the table. The step allocates nothing and writes nothing.
module beamstops_observe_statistics
   use, intrinsic :: iso_fortran_env, only: int64
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite, ieee_is_nan
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: fmt_real, fmt_int, max_members
   use beamstops_observe_pack, only: put, take_header, take_real, take_reals, take_int, take_ik, take_iks
   use beamstops_observe_shocks, only: shock_row
   implicit none
   private
   public :: statistics_type, new_statistics, validate_statistics, validate_ensemble
   public :: quantity_type, statistics_table, ensemble_table
   public :: student_t_quantile, student_t_cdf, incomplete_beta, batch_interval
   public :: quiet_tip_stats

   !> One quantity of a table: name, unit, what its entries run over, and value and
   !> half-width of its 95 % interval per entry.
   type :: quantity_type
      !> Name (a dataset name under /statistics).
      character(len=:), allocatable :: name
      !> SI unit ('1': a pure number).
      character(len=:), allocatable :: unit
      !> What the entries run over: 'stop' (m), 'tip' or 'run' (1), 'bin' (bins), 'edge' (bins + 1).
      character(len=:), allocatable :: axis
      !> Value of each entry.
      real(wp), allocatable :: value(:)
      !> Half-width of the 95 % interval of each entry (NaN: none).
      real(wp), allocatable :: half_width(:)
   end type quantity_type

   !> A table of quantities (the statistics of a run, or of an ensemble).
   type :: statistics_table
      !> The quantities, in a fixed order.
      type(quantity_type), allocatable :: quantity(:)
   contains
      !> Index of a quantity by name (0: none).
      procedure :: find
   end type statistics_table

   !> What a quiet tip sample reads and changes of the statistics: one in the current batch
   !> (t < next_edge) and histogram bin (run_bin), without contact or energy taken, so that it only
   !> adds to the tip's sums and extremes and counts (beamstops_observe_lanes keeps these across
   !> lockstep lanes; quiet_tip and set_quiet_tip move them).
   type :: quiet_tip_stats
      !> End of the current batch (s); histogram's lower end (m), bins per metre, bins - 1/2.
      real(wp) :: next_edge = 0, lower = 0, scale = 0, top = 0
      !> The current batch's tip sum, sum of squares and extremes (m, m^2).
      real(wp) :: su = 0, suu = 0, umin = 0, umax = 0
      !> Bin of the current run of samples.
      integer :: run_bin = 0
      !> Samples of the current batch.
      integer(ik) :: n = 0
   end type quiet_tip_stats

   !> Running statistics of m stops and the tip.
   type :: statistics_type
      private
      !> Stops, batches, bins.
      integer :: m = 0, batches = 0, bins = 0
      !> Start of the window, end of the run (s).
      real(wp) :: transient = 0, t_end = 0
      !> Histogram range (m) and bins per metre.
      real(wp) :: lower = 0, upper = 0, scale = 0
      !> Time step (given at each change of batch, s).
      real(wp) :: dt = 0
      !> Upper edges of the batches (edge(B) = huge) (B).
      real(wp), allocatable :: edge(:)
      !> Current batch (0: the transient) and the time at which it ends.
      integer :: batch = 0
      real(wp) :: next_edge = 0
      ! The current batch's sums: samples, tip sum, sum of squares, extremes, histogram; the
      ! samples since n = run_start all fell in bin run_bin and are not in hist yet.
      integer(ik) :: n = 0, run_start = 0
      integer :: run_bin = 0
      real(wp) :: su = 0, suu = 0, umin = huge(1.0_wp), umax = -huge(1.0_wp)
      integer(ik), allocatable :: hist(:)
      ! Per stop: contact samples, sum |r|, sum r^2, max |r|, sum e.
      integer(ik), allocatable :: contact(:)
      real(wp), allocatable :: sr(:), srr(:), rmax(:), se(:)
      ! The same per batch (index j = 1..B last).
      integer(ik), allocatable :: bn(:)
      real(wp), allocatable :: bsu(:), bsuu(:), bumin(:), bumax(:)
      integer(ik), allocatable :: bhist(:, :), bcontact(:, :)
      real(wp), allocatable :: bsr(:, :), bsrr(:, :), brmax(:, :), bse(:, :)
      ! Shocks per stop and batch: count, rebounds, sum / min / max of durations, sum |impulse|.
      integer(ik), allocatable :: bshocks(:, :), brebounds(:, :)
      real(wp), allocatable :: bdur(:, :), bdurmin(:, :), bdurmax(:, :), bimp(:, :)
   contains
      !> Take one sample (every step).
      procedure :: step
      !> Take one sample of statistics of one stop, from scalars (every step; the tip-only scene).
      procedure :: step_tip
      !> Take one completed shock.
      procedure :: add_shock
      !> What a quiet tip sample reads and changes.
      procedure :: quiet_tip
      !> The sums, extremes and count after quiet tip samples taken elsewhere.
      procedure :: set_quiet_tip
      !> Close the current batch at the end of a run.
      procedure :: finish
      !> The table of quantities.
      procedure :: results
      !> The complete state as a vector of reals (checkpoints).
      procedure :: pack => pack_statistics
      !> Restore the state from a vector of pack.
      procedure :: unpack => unpack_statistics
      ! The rare paths, bound so that calls go through the type's table and stay out of line:
      ! the common path of step is then a leaf without register saves.
      procedure, private :: contact_sample
      procedure, private :: turn
      procedure, private :: new_run
   end type statistics_type

   !> Largest numbers of batches, of histogram bins and of both together (every batch keeps its
   !> histogram; the members of an ensemble: beamstops_scene's max_members): beyond them the
   !> tables did not fit in memory (a failed allocation ended the program with a backtrace).
   integer, parameter :: max_batches = 1000, max_bins = 1000000
   integer(ik), parameter :: max_batch_bins = 10000000_ik
   !> Longest rest time (s): the longest run (t_end <= 1e9 s); beyond it every contact phase of
   !> a stop is one shock anyway.
   real(wp), parameter :: max_rest_time = 1.0e9_wp
   !> Largest magnitude of the histogram's range (m): a thousand times the stops' (|lower|,
   !> upper <= 1e6 m), finite so that its bins are.
   real(wp), parameter :: max_histogram = 1.0e9_wp

   !> First two values of packed statistics: their tag and the version of the layout.
   real(wp), parameter :: pack_tag = 7302, pack_version = 1
   !> Values of the header and of the scalars of packed statistics.
   integer, parameter :: pack_header = 6, pack_scalars = 15

contains

   !> Check the values of the &statistics group (keys transient, batches, bins, rest_time,
   !> histogram_lower, histogram_upper; t_end is &time's); `source` (a file name) starts the
   !> message, in the form of validate_scene's: "SOURCE: &statistics KEY = VALUE is out of range;
   !> allowed: RANGE".
   subroutine validate_statistics(transient, t_last, batches, bins, rest_time, lower, upper, source, error)
      !> Start of the window (s), and the time the run reaches (s): its last step's, t_end
      !> rounded to a whole number of steps.
      real(wp), intent(in) :: transient, t_last
      !> Number of batches (>= 2) and of histogram bins (>= 1).
      integer, intent(in) :: batches, bins
      !> Rest time of the shock log (s, >= 0).
      real(wp), intent(in) :: rest_time
      !> Histogram range (m), lower < upper (keys histogram_lower, histogram_upper).
      real(wp), intent(in) :: lower, upper
      !> Where the values came from, for messages.
      character(len=*), intent(in) :: source
      !> Set on the first value out of range.
      type(error_type), allocatable, intent(out) :: error
      if (batches < 2 .or. batches > max_batches) then
         call say('batches', fmt_int(int(batches, ik)), '2 <= batches <= '//fmt_int(int(max_batches, ik))); return
      end if
      if (bins < 1 .or. bins > max_bins) then
         call say('bins', fmt_int(int(bins, ik)), '1 <= bins <= '//fmt_int(int(max_bins, ik))); return
      end if
      ! Each batch keeps its own histogram: bins x batches values.
      if (int(bins, ik)*batches > max_batch_bins) then
         call say('bins', fmt_int(int(bins, ik)), 'bins*batches <= '//fmt_int(max_batch_bins)//' (every batch keeps '// &
            & 'its histogram; batches = '//fmt_int(int(batches, ik))//')'); return
      end if
      if (.not. (rest_time >= 0 .and. rest_time <= max_rest_time)) then
         call say('rest_time', fmt_real(rest_time), '0 <= rest_time <= '//fmt_real(max_rest_time)//' s'); return
      end if
      if (.not. (ieee_is_finite(transient) .and. transient >= 0 .and. transient < t_last)) then
         call say('transient', fmt_real(transient), '0 <= transient < '//fmt_real(t_last)// &
            & ' s, the time the run reaches (t_end in whole steps of dt)'); return
      end if
      if (.not. (lower >= -max_histogram .and. lower < max_histogram)) then
         call say('histogram_lower', fmt_real(lower), fmt_real(-max_histogram)//' <= histogram_lower < '// &
            & fmt_real(max_histogram)//' m'); return
      end if
      if (.not. (upper > lower .and. upper <= max_histogram)) then
         call say('histogram_upper', fmt_real(upper), 'histogram_lower = '//fmt_real(lower)//' < histogram_upper <= '// &
            & fmt_real(max_histogram)//' m')
         return
      end if
   contains
      subroutine say(key, value, allowed)
         character(len=*), intent(in) :: key, value, allowed
         call fatal_error(error, source//': &statistics '//key//' = '//value//' is out of range; allowed: '//allowed)
      end subroutine say
   end subroutine validate_statistics

   !> Check the number of members of an ensemble.
   subroutine validate_ensemble(members, source, error)
      !> Number of members K (>= 1).
      integer, intent(in) :: members
      !> Where the value came from, for messages.
      character(len=*), intent(in) :: source
      !> Set when out of range.
      type(error_type), allocatable, intent(out) :: error
      if (members < 1 .or. members > max_members) call fatal_error(error, source//': &ensemble members = '// &
         & fmt_int(int(members, ik))//' is out of range; allowed: 1 <= members <= '//fmt_int(int(max_members, ik)))
   end subroutine validate_ensemble

   !> Statistics of `stops` stops over [transient, t_end] in `batches` batches, with a tip
   !> histogram of `bins` bins over [lower, upper] (the stop range, or any range).
   subroutine new_statistics(stats, stops, transient, t_end, batches, bins, lower, upper, error, source)
      !> The statistics, empty.
      type(statistics_type), intent(out) :: stats
      !> Number of stops m (>= 1).
      integer, intent(in) :: stops
      !> Start of the window and end of the run (s).
      real(wp), intent(in) :: transient, t_end
      !> Number of batches (>= 2) and of histogram bins (>= 1).
      integer, intent(in) :: batches, bins
      !> Histogram range (m).
      real(wp), intent(in) :: lower, upper
      !> Set when a value is out of range.
      type(error_type), allocatable, intent(out) :: error
      !> Where the values came from, for messages (default 'statistics').
      character(len=*), intent(in), optional :: source
      integer :: j, b, m, status
      if (present(source)) then
         call validate_statistics(transient, t_end, batches, bins, 0.0_wp, lower, upper, source, error)
      else
         call validate_statistics(transient, t_end, batches, bins, 0.0_wp, lower, upper, 'statistics', error)
      end if
      if (allocated(error)) return
      if (stops < 1) then
         call fatal_error(error, 'statistics: stops = '//fmt_int(int(stops, ik))//' is out of range; allowed: stops >= 1')
         return
      end if
      m = stops
      b = batches
      stats%m = m
      stats%batches = b
      stats%bins = bins
      stats%transient = transient
      stats%t_end = t_end
      stats%lower = lower
      stats%upper = upper
      stats%scale = bins/(upper - lower)
      allocate (stats%edge(b))
      do j = 1, b - 1
         stats%edge(j) = rounded_sum(transient, j, (t_end - transient)/b)
      end do
      stats%edge(b) = huge(1.0_wp)
      stats%batch = 0
      stats%next_edge = transient
      allocate (stats%hist(0:bins - 1), stats%contact(m), stats%sr(m), stats%srr(m), stats%rmax(m), stats%se(m))
      call reset(stats)
      allocate (stats%bn(b), stats%bsu(b), stats%bsuu(b), stats%bumin(b), stats%bumax(b), stats%bhist(bins, b), &
         & stat=status)
      if (status /= 0) then
         ! the histograms of the batches are the statistics' largest table (an ensemble keeps one a member)
         call fatal_error(error, 'not enough memory for the histograms of the statistics: bins x batches = '// &
            & fmt_int(int(bins, ik)*b)//' values, '//fmt_real(8*real(bins, wp)*b/1.0e9_wp, 4)// &
            & ' GB (&statistics bins, batches; &ensemble members keep one each); allowed: fewer bins, batches or members')
         return
      end if
      allocate (stats%bcontact(m, b), stats%bsr(m, b), stats%bsrr(m, b), stats%brmax(m, b), stats%bse(m, b))
      allocate (stats%bshocks(m, b), stats%brebounds(m, b), stats%bdur(m, b), stats%bdurmin(m, b), &
         & stats%bdurmax(m, b), stats%bimp(m, b))
      stats%bn = 0
      stats%bsu = 0
      stats%bsuu = 0
      stats%bumin = huge(1.0_wp)
      stats%bumax = -huge(1.0_wp)
      stats%bhist = 0
      stats%bcontact = 0
      stats%bsr = 0
      stats%bsrr = 0
      stats%brmax = 0
      stats%bse = 0
      stats%bshocks = 0
      stats%brebounds = 0
      stats%bdur = 0
      stats%bdurmin = huge(1.0_wp)
      stats%bdurmax = -huge(1.0_wp)
      stats%bimp = 0
   end subroutine new_statistics

   !> Empty the current batch's sums.
   pure subroutine reset(stats)
      type(statistics_type), intent(inout) :: stats
      stats%n = 0
      stats%run_start = 0
      stats%su = 0
      stats%suu = 0
      stats%umin = huge(1.0_wp)
      stats%umax = -huge(1.0_wp)
      stats%hist = 0
      stats%contact = 0
      stats%sr = 0
      stats%srr = 0
      stats%rmax = 0
      stats%se = 0
   end subroutine reset

   !> Take the sample of one step: no allocation, no I/O; the batch changes on a test of t.
   subroutine step(self, t, dt, u_tip, reaction, energy_taken)
      !> Statistics.
      class(statistics_type), intent(inout) :: self
      !> Time of the sample (s).
      real(wp), intent(in) :: t
      !> Time step (s).
      real(wp), intent(in) :: dt
      !> Tip displacement at t (m).
      real(wp), intent(in) :: u_tip
      !> Reaction of each stop in the step that brought the tip there (N) (m).
      real(wp), intent(in), contiguous :: reaction(:)
      !> Energy each stop took in that step (J) (m).
      real(wp), intent(in), contiguous :: energy_taken(:)
      integer :: i
      call tip_sample(self, t, dt, u_tip)
      do i = 1, self%m
         self%se(i) = self%se(i) + energy_taken(i)
         if (reaction(i) /= 0) call self%contact_sample(i, reaction(i))
      end do
   end subroutine step

   !> step for statistics of one stop (m = 1), from scalars: the same update without arrays.
   subroutine step_tip(self, t, dt, u_tip, reaction, energy_taken)
      !> Statistics of one stop.
      class(statistics_type), intent(inout) :: self
      !> Time of the sample (s).
      real(wp), intent(in) :: t
      !> Time step (s).
      real(wp), intent(in) :: dt
      !> Tip displacement at t (m).
      real(wp), intent(in) :: u_tip
      !> Reaction of the stop in the step that brought the tip there (N).
      real(wp), intent(in) :: reaction
      !> Energy the stop took in that step (J).
      real(wp), intent(in) :: energy_taken
      call tip_sample(self, t, dt, u_tip)
      self%se(1) = self%se(1) + energy_taken
      if (reaction /= 0) call self%contact_sample(1, reaction)
   end subroutine step_tip

   !> start + j width with the product rounded before the sum, never as one multiply-add: the
   !> form docs/statistics.md gives the batch and histogram edges in, so that they can be
   !> reproduced outside the engine (a sample on an edge is in the same batch for both).
   function rounded_sum(start, j, width) result(edge)
      real(wp), intent(in) :: start, width
      integer, intent(in) :: j
      real(wp) :: edge
      real(wp), volatile :: product
      product = j*width
      edge = start + product
   end function rounded_sum

   !> The lower edge of histogram bin k (from 0) as the samples are binned (tip_sample: bin k when
   !> (u - lower) scale, rounded, is at least k and below k + 1): the least double u with
   !> (u - lower) scale >= k, so that a sample is in bin k exactly when edge(k) <= u < edge(k + 1)
   !> (numpy's histogram or searchsorted on the stored edges reproduces the bins). The nominal edge
   !> lower + k ((upper - lower)/bins) can be an ulp off it: a tip resting on a stop at 0.1 was
   !> counted in the bin whose nominal edge was 0.10000000000000003. Found by bisection over the
   !> doubles in their order (at most 64 halvings), from the nominal edge.
   pure function bin_edge(lower, scale, k, nominal) result(edge)
      real(wp), intent(in) :: lower, scale, nominal
      integer, intent(in) :: k
      real(wp) :: edge
      integer(int64) :: below, above, middle
      ! below: a key whose double is under the edge; above: one at or over it
      below = order_key(lower)
      above = order_key(lower + (k + 1)/scale)
      if (in_bin_or_above(nominal)) then
         above = order_key(nominal)
      else
         below = order_key(nominal)
      end if
      do
         ! floor((below + above)/2) without forming the sum (past huge when both are large):
         ! below when they are neighbours, else strictly between them
         middle = iand(below, above) + shifta(ieor(below, above), 1)
         if (middle == below) exit
         if (in_bin_or_above(key_value(middle))) then
            above = middle
         else
            below = middle
         end if
      end do
      edge = key_value(above)
   contains
      pure logical function in_bin_or_above(u)
         real(wp), intent(in) :: u
         in_bin_or_above = (u - lower)*scale >= k
      end function in_bin_or_above
   end function bin_edge

   !> A finite double as an integer in the doubles' order (-0 and +0 both 0).
   pure integer(int64) function order_key(x) result(key)
      real(wp), intent(in) :: x
      key = transfer(x, key)
      if (key < 0) key = -iand(key, huge(key))
   end function order_key

   !> The double of an order_key.
   pure real(wp) function key_value(key) result(x)
      integer(int64), intent(in) :: key
      if (key >= 0) then
         x = transfer(key, x)
      else
         x = transfer(ior(-key, ishft(1_int64, 63)), x)
      end if
   end function key_value

   !> What a quiet tip sample reads and changes (quiet_tip_stats).
   pure function quiet_tip(self) result(q)
      !> Statistics of the tip.
      class(statistics_type), intent(in) :: self
      !> Their values.
      type(quiet_tip_stats) :: q
      q%next_edge = self%next_edge
      q%lower = self%lower
      q%scale = self%scale
      q%top = self%bins - 0.5_wp
      q%su = self%su
      q%suu = self%suu
      q%umin = self%umin
      q%umax = self%umax
      q%run_bin = self%run_bin
      q%n = self%n
   end function quiet_tip

   !> The tip's sums, extremes and count after quiet samples taken elsewhere (from quiet_tip, each
   !> sample as tip_sample takes it: the same bits).
   pure subroutine set_quiet_tip(self, q)
      !> Statistics of the tip.
      class(statistics_type), intent(inout) :: self
      !> Their values after the quiet samples.
      type(quiet_tip_stats), intent(in) :: q
      self%su = q%su
      self%suu = q%suu
      self%umin = q%umin
      self%umax = q%umax
      self%n = q%n
   end subroutine set_quiet_tip

   !> The batch, the count and the tip's sums, extremes and histogram of a sample.
   pure subroutine tip_sample(self, t, dt, u_tip)
      class(statistics_type), intent(inout) :: self
      real(wp), intent(in) :: t, dt, u_tip
      real(wp) :: x
      integer :: bin
      if (t >= self%next_edge) call self%turn(t, dt)
      self%su = self%su + u_tip
      self%suu = self%suu + u_tip*u_tip
      self%umin = min(self%umin, u_tip)
      self%umax = max(self%umax, u_tip)
      ! The bin, safe for any u (NaN and infinities included). Counted by runs: the tip stays in
      ! a bin for many steps, and an increment of hist(bin) at every step would chain each step's
      ! load and store through the late-known address.
      x = min(max((u_tip - self%lower)*self%scale, 0.0_wp), self%bins - 0.5_wp)
      bin = min(max(int(x), 0), self%bins - 1)
      if (bin /= self%run_bin) call self%new_run(bin)
      self%n = self%n + 1
   end subroutine tip_sample

   !> A contact sample of stop i.
   pure subroutine contact_sample(self, i, r)
      class(statistics_type), intent(inout) :: self
      integer, intent(in) :: i
      real(wp), intent(in) :: r
      self%contact(i) = self%contact(i) + 1
      self%sr(i) = self%sr(i) + abs(r)
      self%srr(i) = self%srr(i) + r*r
      self%rmax(i) = max(self%rmax(i), abs(r))
   end subroutine contact_sample

   !> The tip enters another bin: count the run that ends and start one.
   pure subroutine new_run(self, bin)
      class(statistics_type), intent(inout) :: self
      integer, intent(in) :: bin
      self%hist(self%run_bin) = self%hist(self%run_bin) + (self%n - self%run_start)
      self%run_bin = bin
      self%run_start = self%n
   end subroutine new_run

   !> The sample at t starts a later batch: keep the current batch's sums and move on (and take
   !> the time step, constant in a run: every run turns at the first sample after the transient).
   pure subroutine turn(self, t, dt)
      class(statistics_type), intent(inout) :: self
      real(wp), intent(in) :: t, dt
      self%dt = dt
      call keep(self)
      do while (t >= self%next_edge)
         self%batch = self%batch + 1
         self%next_edge = self%edge(self%batch)
      end do
   end subroutine turn

   !> Add the current sums to their batch (nothing for the transient) and empty them.
   pure subroutine keep(self)
      type(statistics_type), intent(inout) :: self
      integer :: j
      j = self%batch
      self%hist(self%run_bin) = self%hist(self%run_bin) + (self%n - self%run_start)
      if (j >= 1) then
         self%bn(j) = self%bn(j) + self%n
         self%bsu(j) = self%bsu(j) + self%su
         self%bsuu(j) = self%bsuu(j) + self%suu
         self%bumin(j) = min(self%bumin(j), self%umin)
         self%bumax(j) = max(self%bumax(j), self%umax)
         self%bhist(:, j) = self%bhist(:, j) + self%hist
         self%bcontact(:, j) = self%bcontact(:, j) + self%contact
         self%bsr(:, j) = self%bsr(:, j) + self%sr
         self%bsrr(:, j) = self%bsrr(:, j) + self%srr
         self%brmax(:, j) = max(self%brmax(:, j), self%rmax)
         self%bse(:, j) = self%bse(:, j) + self%se
      end if
      call reset(self)
   end subroutine keep

   !> The batch of a time (0: the transient), by the comparisons the steps make.
   pure integer function batch_of(self, t) result(j)
      type(statistics_type), intent(in) :: self
      real(wp), intent(in) :: t
      j = 0
      if (t < self%transient) return
      j = 1
      do while (t >= self%edge(j))
         j = j + 1
      end do
   end function batch_of

   !> Take a completed shock (from the shock log): it counts in the batch of its t_start.
   pure subroutine add_shock(self, row)
      !> Statistics.
      class(statistics_type), intent(inout) :: self
      !> The shock.
      type(shock_row), intent(in) :: row
      integer :: j, i
      real(wp) :: d
      j = batch_of(self, row%t_start)
      i = row%stop
      if (j < 1 .or. i < 1 .or. i > self%m) return
      d = row%t_end - row%t_start
      self%bshocks(i, j) = self%bshocks(i, j) + 1
      self%brebounds(i, j) = self%brebounds(i, j) + row%rebounds
      self%bdur(i, j) = self%bdur(i, j) + d
      self%bdurmin(i, j) = min(self%bdurmin(i, j), d)
      self%bdurmax(i, j) = max(self%bdurmax(i, j), d)
      self%bimp(i, j) = self%bimp(i, j) + abs(row%impulse)
   end subroutine add_shock

   !> Keep the current batch's sums at the end of a run (results does it on a copy anyway).
   pure subroutine finish(self)
      !> Statistics.
      class(statistics_type), intent(inout) :: self
      call keep(self)
   end subroutine finish

   !> The table of quantities (see the module's definitions), in this order: window, shocks,
   !> contact_phases, shocks_per_second, rebounds_per_shock, force_mean, force_rms, force_max,
   !> force_mean_contact, force_rms_contact, shock_duration_mean, shock_duration_min,
   !> shock_duration_max, contact_fraction, impulse_rate, power, tip_mean, tip_rms, tip_min,
   !> tip_max, tip_histogram, tip_histogram_edges.
   function results(self) result(table)
      !> Statistics (the current batch is counted too).
      class(statistics_type), intent(in) :: self
      type(statistics_table) :: table
      type(statistics_type) :: s
      real(wp), allocatable :: tb(:), nb(:), v(:), h(:)
      real(wp) :: nn, tt, nan, t_all
      integer :: i, b, k, q
      s = self
      call keep(s)
      b = s%batches
      t_all = interval_factor(b)
      nan = ieee_value(nan, ieee_quiet_nan)
      nb = real(s%bn, wp)
      tb = nb*s%dt
      nn = sum(nb)
      tt = nn*s%dt
      allocate (table%quantity(22))
      allocate (v(s%m), h(s%m))
      q = 0
      call put('window', 's', 'run', [tt], [nan])
      do i = 1, s%m
         v(i) = real(sum(s%bshocks(i, :)), wp)
      end do
      call put('shocks', '1', 'stop', v, spread(nan, 1, s%m))
      do i = 1, s%m
         v(i) = real(sum(s%bshocks(i, :)) + sum(s%brebounds(i, :)), wp)
      end do
      call put('contact_phases', '1', 'stop', v, spread(nan, 1, s%m))
      do i = 1, s%m
         v(i) = ratio(real(sum(s%bshocks(i, :)), wp), tt)
         h(i) = batch_interval(ratios(real(s%bshocks(i, :), wp), tb), t_all)
      end do
      call put('shocks_per_second', '1/s', 'stop', v, h)
      do i = 1, s%m
         v(i) = ratio(real(sum(s%brebounds(i, :)), wp), real(sum(s%bshocks(i, :)), wp))
         h(i) = batch_interval(ratios(real(s%brebounds(i, :), wp), real(s%bshocks(i, :), wp)), t_all)
      end do
      call put('rebounds_per_shock', '1', 'stop', v, h)
      do i = 1, s%m
         v(i) = ratio(sum(s%bsr(i, :)), nn)
         h(i) = batch_interval(ratios(s%bsr(i, :), nb), t_all)
      end do
      call put('force_mean', 'N', 'stop', v, h)
      do i = 1, s%m
         v(i) = sqrt(ratio(sum(s%bsrr(i, :)), nn))
         h(i) = batch_interval(sqrt(ratios(s%bsrr(i, :), nb)), t_all)
      end do
      call put('force_rms', 'N', 'stop', v, h)
      do i = 1, s%m
         v(i) = maxval(s%brmax(i, :))
         if (nn == 0) v(i) = nan
      end do
      call put('force_max', 'N', 'stop', v, spread(nan, 1, s%m))
      do i = 1, s%m
         v(i) = ratio(sum(s%bsr(i, :)), real(sum(s%bcontact(i, :)), wp))
         h(i) = batch_interval(ratios(s%bsr(i, :), real(s%bcontact(i, :), wp)), t_all)
      end do
      call put('force_mean_contact', 'N', 'stop', v, h)
      do i = 1, s%m
         v(i) = sqrt(ratio(sum(s%bsrr(i, :)), real(sum(s%bcontact(i, :)), wp)))
         h(i) = batch_interval(sqrt(ratios(s%bsrr(i, :), real(s%bcontact(i, :), wp))), t_all)
      end do
      call put('force_rms_contact', 'N', 'stop', v, h)
      do i = 1, s%m
         v(i) = ratio(sum(s%bdur(i, :)), real(sum(s%bshocks(i, :)), wp))
         h(i) = batch_interval(ratios(s%bdur(i, :), real(s%bshocks(i, :), wp)), t_all)
      end do
      call put('shock_duration_mean', 's', 'stop', v, h)
      do i = 1, s%m
         v(i) = nan
         if (sum(s%bshocks(i, :)) > 0) v(i) = minval(s%bdurmin(i, :))
      end do
      call put('shock_duration_min', 's', 'stop', v, spread(nan, 1, s%m))
      do i = 1, s%m
         v(i) = nan
         if (sum(s%bshocks(i, :)) > 0) v(i) = maxval(s%bdurmax(i, :))
      end do
      call put('shock_duration_max', 's', 'stop', v, spread(nan, 1, s%m))
      do i = 1, s%m
         v(i) = ratio(real(sum(s%bcontact(i, :)), wp), nn)
         h(i) = batch_interval(ratios(real(s%bcontact(i, :), wp), nb), t_all)
      end do
      call put('contact_fraction', '1', 'stop', v, h)
      do i = 1, s%m
         v(i) = ratio(sum(s%bimp(i, :)), tt)
         h(i) = batch_interval(ratios(s%bimp(i, :), tb), t_all)
      end do
      call put('impulse_rate', 'N', 'stop', v, h)
      do i = 1, s%m
         v(i) = ratio(sum(s%bse(i, :)), tt)
         h(i) = batch_interval(ratios(s%bse(i, :), tb), t_all)
      end do
      call put('power', 'W', 'stop', v, h)
      call put('tip_mean', 'm', 'tip', [ratio(sum(s%bsu), nn)], [batch_interval(ratios(s%bsu, nb), t_all)])
      call put('tip_rms', 'm', 'tip', [sqrt(ratio(sum(s%bsuu), nn))], [batch_interval(sqrt(ratios(s%bsuu, nb)), t_all)])
      if (nn > 0) then
         call put('tip_min', 'm', 'tip', [minval(s%bumin)], [nan])
         call put('tip_max', 'm', 'tip', [maxval(s%bumax)], [nan])
      else
         call put('tip_min', 'm', 'tip', [nan], [nan])
         call put('tip_max', 'm', 'tip', [nan], [nan])
      end if
      deallocate (v, h)
      allocate (v(s%bins), h(s%bins))
      do k = 1, s%bins
         v(k) = ratio(real(sum(s%bhist(k, :)), wp), nn)
         h(k) = batch_interval(ratios(real(s%bhist(k, :), wp), nb), t_all)
      end do
      call put('tip_histogram', '1', 'bin', v, h)
      deallocate (v)
      allocate (v(s%bins + 1))
      v(1) = s%lower
      do k = 1, s%bins - 1
         v(k + 1) = bin_edge(s%lower, s%scale, k, rounded_sum(s%lower, k, (s%upper - s%lower)/s%bins))
      end do
      v(s%bins + 1) = s%upper
      call put('tip_histogram_edges', 'm', 'edge', v, spread(0.0_wp, 1, s%bins + 1))
   contains
      subroutine put(name, unit, axis, value, half_width)
         character(len=*), intent(in) :: name, unit, axis
         real(wp), intent(in) :: value(:), half_width(:)
         q = q + 1
         table%quantity(q)%name = name
         table%quantity(q)%unit = unit
         table%quantity(q)%axis = axis
         table%quantity(q)%value = value
         table%quantity(q)%half_width = half_width
      end subroutine put
   end function results

   !> The complete state of the statistics as reals, for a checkpoint (unpack restores it;
   !> statistics never constructed pack as their header alone, with m = 0). Integers are stored
   !> exactly as reals (counts stay far below 2**53), reals bit for bit. Layout, version 1
   !> (m stops, B batches, K bins; arrays of two indices column-major, the first index fastest):
   !> - header (6): 7302 (tag), 1 (version), total length, m, B, K;
   !> - scalars (15): transient, t_end, lower, upper, scale, dt, batch, next_edge, n, run_start,
   !>   run_bin, su, suu, umin, umax;
   !> - edge (B), hist (K, bins 0..K-1);
   !> - the current batch per stop (m each): contact, sr, srr, rmax, se;
   !> - per batch (B each): bn, bsu, bsuu, bumin, bumax; bhist (K x B);
   !> - per stop and batch (m x B each): bcontact, bsr, bsrr, brmax, bse, bshocks, brebounds,
   !>   bdur, bdurmin, bdurmax, bimp.
   !> Total: 21 + 6 B + K + 5 m + K B + 11 m B (6 when m = 0).
   subroutine pack_statistics(self, values)
      !> Statistics.
      class(statistics_type), intent(in) :: self
      !> The state, in the layout above.
      real(wp), allocatable, intent(out) :: values(:)
      integer :: p, n, m, b, k
      if (self%m == 0) then
         values = [pack_tag, pack_version, real(pack_header, wp), 0.0_wp, 0.0_wp, 0.0_wp]
         return
      end if
      m = self%m
      b = self%batches
      k = self%bins
      n = pack_header + pack_scalars + 6*b + k + 5*m + k*b + 11*m*b
      allocate (values(n))
      p = 0
      call put(values, p, [pack_tag, pack_version, real(n, wp), real(m, wp), real(b, wp), real(k, wp)])
      call put(values, p, [self%transient, self%t_end, self%lower, self%upper, self%scale, self%dt, &
         & real(self%batch, wp), self%next_edge, real(self%n, wp), real(self%run_start, wp), real(self%run_bin, wp), &
         & self%su, self%suu, self%umin, self%umax])
      call put(values, p, self%edge)
      call put(values, p, real(self%hist, wp))
      call put(values, p, real(self%contact, wp))
      call put(values, p, self%sr)
      call put(values, p, self%srr)
      call put(values, p, self%rmax)
      call put(values, p, self%se)
      call put(values, p, real(self%bn, wp))
      call put(values, p, self%bsu)
      call put(values, p, self%bsuu)
      call put(values, p, self%bumin)
      call put(values, p, self%bumax)
      call put(values, p, reshape(real(self%bhist, wp), [k*b]))
      call put(values, p, reshape(real(self%bcontact, wp), [m*b]))
      call put(values, p, reshape(self%bsr, [m*b]))
      call put(values, p, reshape(self%bsrr, [m*b]))
      call put(values, p, reshape(self%brmax, [m*b]))
      call put(values, p, reshape(self%bse, [m*b]))
      call put(values, p, reshape(real(self%bshocks, wp), [m*b]))
      call put(values, p, reshape(real(self%brebounds, wp), [m*b]))
      call put(values, p, reshape(self%bdur, [m*b]))
      call put(values, p, reshape(self%bdurmin, [m*b]))
      call put(values, p, reshape(self%bdurmax, [m*b]))
      call put(values, p, reshape(self%bimp, [m*b]))
   end subroutine pack_statistics

   !> Restore the statistics from a vector of pack (the layout of pack_statistics): afterwards
   !> they take the same samples and shocks and give the same results, bit for bit, as the
   !> statistics that were packed. On an error (a vector too short or too long for its header,
   !> another tag or version, a value that is not an integer where one is due, a batch or bin
   !> index out of range) the statistics are left unchanged.
   subroutine unpack_statistics(self, values, error)
      !> Statistics (any state: they are replaced).
      class(statistics_type), intent(inout) :: self
      !> The state, from pack.
      real(wp), intent(in) :: values(:)
      !> Set when the vector is not packed statistics.
      type(error_type), allocatable, intent(out) :: error
      type(statistics_type) :: s
      integer :: p, n, m, b, k, bad, header(pack_header - 2)
      real(wp) :: want
      call take_header(values, 'statistics', pack_tag, pack_version, header, error)
      if (allocated(error)) return
      n = header(1)
      m = header(2)
      b = header(3)
      k = header(4)
      bad = 0
      if (.not. ((m >= 1 .and. b >= 2 .and. k >= 1) .or. (m == 0 .and. b == 0 .and. k == 0))) then
         call fatal_error(error, 'statistics: unpack: header m = '//fmt_int(int(m, ik))//', batches = '// &
            & fmt_int(int(b, ik))//', bins = '//fmt_int(int(k, ik))//' is inconsistent')
         return
      end if
      ! In reals: exact for any length that can match the vector's, no overflow otherwise.
      want = pack_header
      if (m > 0) want = pack_header + pack_scalars + 6*real(b, wp) + k + 5*real(m, wp) + real(k, wp)*b + &
         & 11*real(m, wp)*b
      if (n /= want .or. size(values) /= want) then
         call fatal_error(error, 'statistics: unpack: '//fmt_int(int(size(values), ik))//' values, header length '// &
            & fmt_int(int(n, ik))//'; the header (m = '//fmt_int(int(m, ik))//', batches = '//fmt_int(int(b, ik))// &
            & ', bins = '//fmt_int(int(k, ik))//') needs '//fmt_real(want))
         return
      end if
      if (m > 0) then
         s%m = m
         s%batches = b
         s%bins = k
         allocate (s%edge(b), s%hist(0:k - 1), s%contact(m), s%sr(m), s%srr(m), s%rmax(m), s%se(m))
         allocate (s%bn(b), s%bsu(b), s%bsuu(b), s%bumin(b), s%bumax(b), s%bhist(k, b))
         allocate (s%bcontact(m, b), s%bsr(m, b), s%bsrr(m, b), s%brmax(m, b), s%bse(m, b))
         allocate (s%bshocks(m, b), s%brebounds(m, b), s%bdur(m, b), s%bdurmin(m, b), s%bdurmax(m, b), s%bimp(m, b))
         p = pack_header
         call take_real(values, p, s%transient)
         call take_real(values, p, s%t_end)
         call take_real(values, p, s%lower)
         call take_real(values, p, s%upper)
         call take_real(values, p, s%scale)
         call take_real(values, p, s%dt)
         call take_int(values, p, s%batch, bad)
         if (bad == 0 .and. (s%batch < 0 .or. s%batch > b)) bad = p
         call take_real(values, p, s%next_edge)
         call take_ik(values, p, s%n, bad, finite=.true.)
         call take_ik(values, p, s%run_start, bad, finite=.true.)
         call take_int(values, p, s%run_bin, bad)
         if (bad == 0 .and. (s%run_bin < 0 .or. s%run_bin > k - 1)) bad = p
         call take_real(values, p, s%su)
         call take_real(values, p, s%suu)
         call take_real(values, p, s%umin)
         call take_real(values, p, s%umax)
         call take_reals(values, p, size(s%edge), s%edge)
         call take_iks(values, p, size(s%hist), s%hist, bad, finite=.true.)
         call take_iks(values, p, size(s%contact), s%contact, bad, finite=.true.)
         call take_reals(values, p, size(s%sr), s%sr)
         call take_reals(values, p, size(s%srr), s%srr)
         call take_reals(values, p, size(s%rmax), s%rmax)
         call take_reals(values, p, size(s%se), s%se)
         call take_iks(values, p, size(s%bn), s%bn, bad, finite=.true.)
         call take_reals(values, p, size(s%bsu), s%bsu)
         call take_reals(values, p, size(s%bsuu), s%bsuu)
         call take_reals(values, p, size(s%bumin), s%bumin)
         call take_reals(values, p, size(s%bumax), s%bumax)
         call take_iks(values, p, size(s%bhist), s%bhist, bad, finite=.true.)
         call take_iks(values, p, size(s%bcontact), s%bcontact, bad, finite=.true.)
         call take_reals(values, p, size(s%bsr), s%bsr)
         call take_reals(values, p, size(s%bsrr), s%bsrr)
         call take_reals(values, p, size(s%brmax), s%brmax)
         call take_reals(values, p, size(s%bse), s%bse)
         call take_iks(values, p, size(s%bshocks), s%bshocks, bad, finite=.true.)
         call take_iks(values, p, size(s%brebounds), s%brebounds, bad, finite=.true.)
         call take_reals(values, p, size(s%bdur), s%bdur)
         call take_reals(values, p, size(s%bdurmin), s%bdurmin)
         call take_reals(values, p, size(s%bdurmax), s%bdurmax)
         call take_reals(values, p, size(s%bimp), s%bimp)
         if (bad /= 0) then
            call fatal_error(error, 'statistics: unpack: value '//fmt_int(int(bad, ik))//' = '// &
               & fmt_real(values(bad))//' is out of range (expected an integer, or a batch or bin index in range)')
            return
         end if
      end if
      self%m = s%m
      self%batches = s%batches
      self%bins = s%bins
      self%transient = s%transient
      self%t_end = s%t_end
      self%lower = s%lower
      self%upper = s%upper
      self%scale = s%scale
      self%dt = s%dt
      self%batch = s%batch
      self%next_edge = s%next_edge
      self%n = s%n
      self%run_start = s%run_start
      self%run_bin = s%run_bin
      self%su = s%su
      self%suu = s%suu
      self%umin = s%umin
      self%umax = s%umax
      call move_alloc(s%edge, self%edge)
      call move_alloc(s%hist, self%hist)
      call move_alloc(s%contact, self%contact)
      call move_alloc(s%sr, self%sr)
      call move_alloc(s%srr, self%srr)
      call move_alloc(s%rmax, self%rmax)
      call move_alloc(s%se, self%se)
      call move_alloc(s%bn, self%bn)
      call move_alloc(s%bsu, self%bsu)
      call move_alloc(s%bsuu, self%bsuu)
      call move_alloc(s%bumin, self%bumin)
      call move_alloc(s%bumax, self%bumax)
      call move_alloc(s%bhist, self%bhist)
      call move_alloc(s%bcontact, self%bcontact)
      call move_alloc(s%bsr, self%bsr)
      call move_alloc(s%bsrr, self%bsrr)
      call move_alloc(s%brmax, self%brmax)
      call move_alloc(s%bse, self%bse)
      call move_alloc(s%bshocks, self%bshocks)
      call move_alloc(s%brebounds, self%brebounds)
      call move_alloc(s%bdur, self%bdur)
      call move_alloc(s%bdurmin, self%bdurmin)
      call move_alloc(s%bdurmax, self%bdurmax)
      call move_alloc(s%bimp, self%bimp)
   end subroutine unpack_statistics

   !> a / b, NaN when b = 0.
   elemental function ratio(a, b) result(r)
      real(wp), intent(in) :: a, b
      real(wp) :: r
      if (b == 0) then
         r = ieee_value(r, ieee_quiet_nan)
      else
         r = a/b
      end if
   end function ratio

   !> Batch values a_j / b_j (NaN where b_j = 0).
   pure function ratios(a, b) result(r)
      real(wp), intent(in) :: a(:), b(:)
      real(wp) :: r(size(a))
      r = ratio(a, b)
   end function ratios

   !> Half-width of the 95 % interval of the mean of the finite values x_j:
   !> t_{0.975, B'-1} s / sqrt(B'), s^2 = sum (x_j - mean)^2 / (B' - 1); NaN when B' < 2.
   pure function batch_interval(x, t_all) result(h)
      !> Batch (or member) values; NaN entries are left out.
      real(wp), intent(in) :: x(:)
      !> interval_factor(size(x)), the factor of the common case, all values finite: computed once
      !> for a whole table by the caller instead of by a bisection at every call (a table of 40
      !> histogram bins made its finish cost about 1 ms).
      real(wp), intent(in) :: t_all
      real(wp) :: h
      real(wp) :: shift, mean, s2
      integer :: nb
      logical :: use(size(x))
      use = ieee_is_finite(x)
      nb = count(use)
      if (nb < 2) then
         h = ieee_value(h, ieee_quiet_nan)
         return
      end if
      ! about the first value: equal values give exactly 0 (sum(x)/nb need not be x)
      shift = x(findloc(use, .true., dim=1))
      mean = sum(x - shift, mask=use)/nb
      s2 = sum((x - shift - mean)**2, mask=use)/(nb - 1)
      if (nb == size(x)) then
         h = t_all*sqrt(s2/nb)
      else
         h = interval_factor(nb)*sqrt(s2/nb)
      end if
   end function batch_interval

   !> The factor t_{0.975, n-1} of batch_interval for n finite values (NaN when n < 2:
   !> student_t_quantile's for dof <= 0).
   pure function interval_factor(n) result(t)
      !> Number of finite values.
      integer, intent(in) :: n
      real(wp) :: t
      t = student_t_quantile(0.975_wp, real(n - 1, wp))
   end function interval_factor

   !> Index of the quantity `name` in a table (0: none).
   pure integer function find(self, name)
      !> Table.
      class(statistics_table), intent(in) :: self
      !> Name of the quantity.
      character(len=*), intent(in) :: name
      integer :: q
      find = 0
      if (.not. allocated(self%quantity)) return
      do q = 1, size(self%quantity)
         if (self%quantity(q)%name == name) then
            find = q
            return
         end if
      end do
   end function find

   !> The statistics of an ensemble of K members (tables of the same quantities and sizes):
   !> per entry, over the K' members whose value is not NaN, value = mean, half-width =
   !> t_{0.975, K'-1} s / sqrt(K') (s the sample standard deviation; NaN when K' < 2). The members
   !> are independent runs, so every quantity, counts and extremes included, gets an interval
   !> (of its expectation over a window of that length). Edges are copied from the first member.
   subroutine ensemble_table(members, ensemble, error)
      !> Tables of the K members.
      type(statistics_table), intent(in) :: members(:)
      !> Their ensemble statistics.
      type(statistics_table), intent(out) :: ensemble
      !> Set when there are no members or the tables do not match.
      type(error_type), allocatable, intent(out) :: error
      integer :: k, q, e, nk
      real(wp), allocatable :: x(:)
      logical, allocatable :: kept(:)
      real(wp) :: t_all, shift
      call validate_ensemble(size(members), 'ensemble', error)
      if (allocated(error)) return
      nk = size(members)
      do k = 2, nk
         if (size(members(k)%quantity) /= size(members(1)%quantity)) then
            call fatal_error(error, 'ensemble: member '//fmt_int(int(k, ik))//' has '// &
               & fmt_int(int(size(members(k)%quantity), ik))//' quantities, member 1 has '// &
               & fmt_int(int(size(members(1)%quantity), ik)))
            return
         end if
         do q = 1, size(members(1)%quantity)
            if (members(k)%quantity(q)%name /= members(1)%quantity(q)%name .or. &
               & size(members(k)%quantity(q)%value) /= size(members(1)%quantity(q)%value)) then
               call fatal_error(error, 'ensemble: member '//fmt_int(int(k, ik))//' quantity '// &
                  & fmt_int(int(q, ik))//' is '//members(k)%quantity(q)%name//' of size '// &
                  & fmt_int(int(size(members(k)%quantity(q)%value), ik))//', member 1 has '// &
                  & members(1)%quantity(q)%name//' of size '//fmt_int(int(size(members(1)%quantity(q)%value), ik)))
               return
            end if
         end do
      end do
      ensemble%quantity = members(1)%quantity
      allocate (x(nk), kept(nk))
      t_all = interval_factor(nk)
      do q = 1, size(ensemble%quantity)
         if (ensemble%quantity(q)%axis == 'edge') cycle
         do e = 1, size(ensemble%quantity(q)%value)
            do k = 1, nk
               x(k) = members(k)%quantity(q)%value(e)
            end do
            kept = .not. ieee_is_nan(x)
            if (any(kept)) then
               ! about the first value: K equal members give it exactly
               shift = x(findloc(kept, .true., dim=1))
               ensemble%quantity(q)%value(e) = shift + sum(x - shift, mask=kept)/count(kept)
            else
               ensemble%quantity(q)%value(e) = ieee_value(x(1), ieee_quiet_nan)
            end if
            ensemble%quantity(q)%half_width(e) = batch_interval(x, t_all)
         end do
      end do
   end subroutine ensemble_table

   !> Quantile of Student's t distribution with `dof` degrees of freedom: the t with
   !> P(T <= t) = p. Exact forms for dof = 1 and 2; up to dof = 1000 bisection on t of the upper
   !> tail (student_tail) down to adjacent doubles (relative accuracy about 1e-14 in t); beyond,
   !> the Cornish-Fisher expansion in 1/dof to the fourth order around the normal quantile
   !> (relative accuracy 1e-13 at p = 0.9999, 1e-15 at 0.975). NaN outside 0 < p < 1 or dof <= 0.
   elemental function student_t_quantile(p, dof) result(t)
      !> Probability.
      real(wp), intent(in) :: p
      !> Degrees of freedom (> 0, need not be an integer).
      real(wp), intent(in) :: dof
      real(wp) :: t
      real(wp) :: q, lo, hi, mid
      real(wp), parameter :: pi = acos(-1.0_wp)
      integer :: it
      if (.not. (p > 0 .and. p < 1 .and. dof > 0)) then
         t = ieee_value(t, ieee_quiet_nan)
         return
      end if
      if (p == 0.5_wp) then
         t = 0
         return
      end if
      if (dof == 1) then
         t = tan(pi*(p - 0.5_wp))
         return
      end if
      if (dof == 2) then
         t = (2*p - 1)/sqrt(2*p*(1 - p))
         return
      end if
      if (dof > 1000) then
         t = cornish_fisher(p, dof)
         return
      end if
      ! The upper tail P(T > t) decreases from 1/2 at t = 0; find where it equals q.
      q = min(p, 1 - p)
      lo = 0
      hi = 1
      do it = 1, 2000
         if (student_tail(hi, dof) <= q) exit
         lo = hi
         hi = 2*hi
      end do
      do it = 1, 2000
         mid = 0.5_wp*(lo + hi)
         if (mid <= lo .or. mid >= hi) exit
         if (student_tail(mid, dof) > q) then
            lo = mid
         else
            hi = mid
         end if
      end do
      t = 0.5_wp*(lo + hi)
      if (p < 0.5_wp) t = -t
   end function student_t_quantile

   !> Student's t quantile for a large dof: z + g1/dof + g2/dof^2 + g3/dof^3 + g4/dof^4 with
   !> z the normal quantile (Abramowitz & Stegun 26.7.5).
   elemental function cornish_fisher(p, dof) result(t)
      real(wp), intent(in) :: p, dof
      real(wp) :: t, z, z2, g1, g2, g3, g4
      z = normal_quantile(p)
      z2 = z*z
      g1 = z*(z2 + 1)/4
      g2 = z*((5*z2 + 16)*z2 + 3)/96
      g3 = z*(((3*z2 + 19)*z2 + 17)*z2 - 15)/384
      g4 = z*((((79*z2 + 776)*z2 + 1482)*z2 - 1920)*z2 - 945)/92160
      t = z + (g1 + (g2 + (g3 + g4/dof)/dof)/dof)/dof
   end function cornish_fisher

   !> Quantile of the standard normal distribution: Acklam's rational approximation (relative
   !> error 1.2e-9) and one Halley step on erfc, to full precision.
   elemental function normal_quantile(p) result(x)
      !> Probability, 0 < p < 1.
      real(wp), intent(in) :: p
      real(wp) :: x
      real(wp), parameter :: a(6) = [-3.969683028665376e+01_wp, 2.209460984245205e+02_wp, &
         & -2.759285104469687e+02_wp, 1.383577518672690e+02_wp, -3.066479806614716e+01_wp, 2.506628277459239e+00_wp]
      real(wp), parameter :: b(5) = [-5.447609879822406e+01_wp, 1.615858368580409e+02_wp, &
         & -1.556989798598866e+02_wp, 6.680131188771972e+01_wp, -1.328068155288572e+01_wp]
      real(wp), parameter :: c(6) = [-7.784894002430293e-03_wp, -3.223964580411365e-01_wp, &
         & -2.400758277161838e+00_wp, -2.549732539343734e+00_wp, 4.374664141464968e+00_wp, 2.938163982698783e+00_wp]
      real(wp), parameter :: d(4) = [7.784695709041462e-03_wp, 3.224671290700398e-01_wp, 2.445134137142996e+00_wp, &
         & 3.754408661907416e+00_wp]
      real(wp), parameter :: p_low = 0.02425_wp, pi = acos(-1.0_wp)
      real(wp) :: q, r, e, u
      if (p < p_low) then
         q = sqrt(-2*log(p))
         x = (((((c(1)*q + c(2))*q + c(3))*q + c(4))*q + c(5))*q + c(6))/((((d(1)*q + d(2))*q + d(3))*q + d(4))*q + 1)
      else if (p <= 1 - p_low) then
         q = p - 0.5_wp
         r = q*q
         x = (((((a(1)*r + a(2))*r + a(3))*r + a(4))*r + a(5))*r + a(6))*q/ &
            & (((((b(1)*r + b(2))*r + b(3))*r + b(4))*r + b(5))*r + 1)
      else
         q = sqrt(-2*log(1 - p))
         x = -(((((c(1)*q + c(2))*q + c(3))*q + c(4))*q + c(5))*q + c(6))/((((d(1)*q + d(2))*q + d(3))*q + d(4))*q + 1)
      end if
      e = 0.5_wp*erfc(-x/sqrt(2.0_wp)) - p
      u = e*sqrt(2*pi)*exp(0.5_wp*x*x)
      x = x - u/(1 + 0.5_wp*x*u)
   end function normal_quantile

   !> Distribution function of Student's t: P(T <= t).
   elemental function student_t_cdf(t, dof) result(p)
      !> Argument.
      real(wp), intent(in) :: t
      !> Degrees of freedom (> 0).
      real(wp), intent(in) :: dof
      real(wp) :: p
      if (t >= 0) then
         p = 1 - student_tail(t, dof)
      else
         p = student_tail(-t, dof)
      end if
   end function student_t_cdf

   !> Upper tail P(T > t) = I_x(a, 1/2)/2 of Student's t for t >= 0, a = dof/2, x = dof/(dof + t^2),
   !> with x and 1 - x = t^2/(dof + t^2) formed separately, log x = -log1p(t^2/dof), and
   !> log Gamma(a + 1/2) - log Gamma(a) by Stirling's series for a >= 20 (no cancellation).
   elemental function student_tail(t, dof) result(tail)
      real(wp), intent(in) :: t, dof
      real(wp) :: tail
      real(wp) :: a, x, y, front, lx, ly
      real(wp), parameter :: half_log_pi = 0.5_wp*log(acos(-1.0_wp))
      if (t <= 0) then
         tail = 0.5_wp
         return
      end if
      a = 0.5_wp*dof
      x = dof/(dof + t*t)
      y = (t*t)/(dof + t*t)
      if (y <= 0) then
         tail = 0.5_wp
         return
      end if
      lx = -log1p(t*t/dof)
      ly = 2*log(t) - log(dof + t*t)
      front = exp(log_gamma_ratio(a) - half_log_pi + a*lx + 0.5_wp*ly)
      if (x < (a + 1)/(a + 2.5_wp)) then
         tail = 0.5_wp*front*beta_fraction(a, 0.5_wp, x)/a
      else
         tail = 0.5_wp*(1 - 2*front*beta_fraction(0.5_wp, a, y))
      end if
   end function student_tail

   !> log Gamma(a + 1/2) - log Gamma(a).
   elemental function log_gamma_ratio(a) result(d)
      real(wp), intent(in) :: a
      real(wp) :: d
      if (a < 20) then
         d = log_gamma(a + 0.5_wp) - log_gamma(a)
      else
         ! (a) log(a + 1/2) - (a - 1/2) log a - 1/2 + c(a + 1/2) - c(a), Stirling's c(z).
         d = 0.5_wp*log(a) + (a*log1p(0.5_wp/a) - 0.5_wp) + (stirling(a + 0.5_wp) - stirling(a))
      end if
   end function log_gamma_ratio

   !> Stirling's correction log Gamma(z) - ((z - 1/2) log z - z + log(2 pi)/2), z >= 20.
   elemental function stirling(z) result(c)
      real(wp), intent(in) :: z
      real(wp) :: c, w
      w = 1/(z*z)
      c = (1.0_wp/12 - w*(1.0_wp/360 - w*(1.0_wp/1260 - w*(1.0_wp/1680 - w/1188))))/z
   end function stirling

   !> log(1 + z) accurate for small z (z > -1).
   elemental function log1p(z) result(l)
      real(wp), intent(in) :: z
      real(wp) :: l, w
      w = 1 + z
      if (w == 1) then
         l = z
      else
         l = log(w)*(z/(w - 1))
      end if
   end function log1p

   !> Regularized incomplete beta function I_x(a, b) by its continued fraction (modified
   !> Lentz), on the side of x where it converges fast.
   elemental function incomplete_beta(a, b, x) result(y)
      !> Parameters (> 0).
      real(wp), intent(in) :: a, b
      !> Argument in [0, 1].
      real(wp), intent(in) :: x
      real(wp) :: y
      real(wp) :: front
      if (x <= 0) then
         y = 0
         return
      end if
      if (x >= 1) then
         y = 1
         return
      end if
      front = exp(log_gamma(a + b) - log_gamma(a) - log_gamma(b) + a*log(x) + b*log(1 - x))
      if (x < (a + 1)/(a + b + 2)) then
         y = front*beta_fraction(a, b, x)/a
      else
         y = 1 - front*beta_fraction(b, a, 1 - x)/b
      end if
   end function incomplete_beta

   !> The continued fraction of I_x(a, b) (Numerical Recipes' betacf, modified Lentz).
   elemental function beta_fraction(a, b, x) result(h)
      real(wp), intent(in) :: a, b, x
      real(wp) :: h
      real(wp), parameter :: tiny_value = 1.0e-300_wp
      real(wp) :: c, d, aa, del, qab, qap, qam
      integer :: m, m2
      qab = a + b
      qap = a + 1
      qam = a - 1
      c = 1
      d = 1 - qab*x/qap
      if (abs(d) < tiny_value) d = tiny_value
      d = 1/d
      h = d
      do m = 1, 1000
         m2 = 2*m
         aa = m*(b - m)*x/((qam + m2)*(a + m2))
         d = 1 + aa*d
         if (abs(d) < tiny_value) d = tiny_value
         c = 1 + aa/c
         if (abs(c) < tiny_value) c = tiny_value
         d = 1/d
         h = h*d*c
         aa = -(a + m)*(qab + m)*x/((a + m2)*(qap + m2))
         d = 1 + aa*d
         if (abs(d) < tiny_value) d = tiny_value
         c = 1 + aa/c
         if (abs(c) < tiny_value) c = tiny_value
         d = 1/d
         del = d*c
         h = h*del
         if (abs(del - 1) < 1.0e-16_wp) exit
      end do
   end function beta_fraction
end module beamstops_observe_statistics
