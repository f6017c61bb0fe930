!> Running statistics with batch-means intervals (beamstops_observe_statistics): Student's t
!> quantiles, input checks, window values against a direct computation, interval coverage on
!> i.i.d. sequences, agreement of disjoint halves of a stationary series, ensembles, and the cost
!> of the per-step updates (printed, never asserted).
module test_statistics
   use, intrinsic :: iso_fortran_env, only: int64
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_value, ieee_quiet_nan, ieee_positive_inf, ieee_next_after
   use testing
   use beamstops, only: ik
   use beamstops_observe_shocks, only: shock_log, shock_row, new_shock_log, shock_row_values
   use beamstops_observe_statistics, only: statistics_type, new_statistics, validate_statistics, validate_ensemble, &
      & statistics_table, quantity_type, ensemble_table, student_t_quantile, student_t_cdf
   use beamstops_observe_observer, only: observer_type, new_observer
   use beamstops_observe_quiet, only: quiet_observer, take_quiet, give_quiet, observe_quiet
   use test_shocks, only: uniform, same_bits, expect_message
   implicit none
   private
   public :: collect_statistics

   !> Time step of the synthetic sequences (s).
   real(wp), parameter :: dt = 1.0e-3_wp

contains

   !> Tests of the suite.
   subroutine collect_statistics(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('Student t quantiles: known values, inverse of the cdf, symmetry', test_t_quantiles), &
         & new_unittest('bad inputs: messages naming group, key and allowed range', test_bad_inputs), &
         & new_unittest('window values and half-widths against a direct computation', test_direct), &
         & new_unittest('i.i.d. sequences: the 95 % intervals cover the true means at about 95 %', test_coverage), &
         & new_unittest('disjoint halves of a stationary series agree within their intervals', test_halves), &
         & new_unittest('no contact: no shocks, zero power, zero forces', test_no_contact), &
         & new_unittest('histogram: a sample is in bin i exactly when edge i <= u < edge i+1 (stored edges)', &
         & test_histogram_edges), &
         & new_unittest('samples and shocks before the transient are left out', test_transient), &
         & new_unittest('step_tip and step give the same table', test_step_tip), &
         & new_unittest('ensemble: mean and t s/sqrt(K) across members; bad members', test_ensemble), &
         & new_unittest('pack at a random midpoint, unpack, continue: the same tables bit for bit', test_pack_resume), &
         & new_unittest('unpack of a truncated, padded, foreign or corrupted vector: an error', test_unpack_bad), &
         & new_unittest('quiet samples in the loop''s variables: the observer of tip, bit for bit', test_quiet), &
         & new_unittest('per-step cost of the shock log and the statistics (printed)', test_cost) &
         & ]
   end subroutine collect_statistics

   subroutine test_t_quantiles(error)
      type(error_type), allocatable, intent(out) :: error
      ! scipy.stats.t.ppf(0.975, dof)
      real(wp), parameter :: dof(11) = [1, 2, 3, 4, 5, 9, 19, 29, 99, 1000, 100000]
      real(wp), parameter :: want(11) = [12.706204736174694_wp, 4.302652729749462_wp, 3.1824463052837078_wp, &
         & 2.7764451051977934_wp, 2.5705818356363146_wp, 2.262157162798205_wp, 2.0930240544083087_wp, &
         & 2.045229642132703_wp, 1.9842169515864174_wp, 1.9623390808264083_wp, 1.9599877075346095_wp]
      real(wp) :: p(4), t
      integer :: i, j
      do i = 1, size(dof)
         call check(error, student_t_quantile(0.975_wp, dof(i)), want(i), 't(0.975, '//real_text(dof(i))//')', &
            & rel=.true., thr=1.0e-12_wp); if (allocated(error)) return
      end do
      call check(error, student_t_quantile(0.95_wp, 10.0_wp), 1.8124611228116756_wp, 't(0.95, 10)', rel=.true., &
         & thr=1.0e-12_wp); if (allocated(error)) return
      call check(error, student_t_quantile(0.995_wp, 7.0_wp), 3.4994832973504924_wp, 't(0.995, 7)', rel=.true., &
         & thr=1.0e-12_wp); if (allocated(error)) return
      call check(error, student_t_quantile(0.6_wp, 3.0_wp), 0.2766706623326898_wp, 't(0.6, 3)', rel=.true., &
         & thr=1.0e-12_wp); if (allocated(error)) return
      call check(error, student_t_quantile(0.025_wp, 19.0_wp), -2.09302405440831_wp, 't(0.025, 19)', rel=.true., &
         & thr=1.0e-12_wp); if (allocated(error)) return
      call check(error, student_t_quantile(0.9999_wp, 2.5_wp), 34.867969321116306_wp, 't(0.9999, 2.5)', rel=.true., &
         & thr=1.0e-12_wp); if (allocated(error)) return
      ! Either side of the switch to the Cornish-Fisher expansion (dof > 1000).
      call check(error, student_t_quantile(0.9999_wp, 1000.0_wp), 3.7328516045753966_wp, 't(0.9999, 1000)', &
         & rel=.true., thr=1.0e-12_wp); if (allocated(error)) return
      call check(error, student_t_quantile(0.9999_wp, 1001.0_wp), 3.732837737396866_wp, 't(0.9999, 1001)', &
         & rel=.true., thr=1.0e-12_wp); if (allocated(error)) return
      call check(error, student_t_quantile(0.6_wp, 5000.0_wp), 0.25336058396923183_wp, 't(0.6, 5000)', &
         & rel=.true., thr=1.0e-12_wp); if (allocated(error)) return
      p = [0.01_wp, 0.3_wp, 0.8_wp, 0.999_wp]
      do i = 1, 4
         do j = 3, 60, 7
            t = student_t_quantile(p(i), real(j, wp))
            call check(error, student_t_cdf(t, real(j, wp)), p(i), 'cdf(quantile) dof '//int_text(j), thr=1.0e-14_wp)
            if (allocated(error)) return
            call check(error, student_t_quantile(1 - p(i), real(j, wp)), -t, 'symmetry dof '//int_text(j), &
               & rel=.true., thr=1.0e-12_wp); if (allocated(error)) return
         end do
      end do
      call check(error, ieee_is_nan(student_t_quantile(1.0_wp, 3.0_wp)), .true., 'p = 1 gives NaN')
      if (allocated(error)) return
      call check(error, ieee_is_nan(student_t_quantile(0.9_wp, 0.0_wp)), .true., 'dof = 0 gives NaN')
   end subroutine test_t_quantiles

   subroutine test_bad_inputs(error)
      type(error_type), allocatable, intent(out) :: error
      type(statistics_type) :: stats
      call validate_statistics(1.0_wp, 10.0_wp, 1, 10, 0.0_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics batches = 1 is out of range; allowed: 2 <= batches <= 1000')
      if (allocated(error)) return
      call validate_statistics(10.0_wp, 10.0_wp, 20, 10, 0.0_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics transient = 10 is out of range; allowed: 0 <= transient < 10 s,'// &
         & ' the time the run reaches (t_end in whole steps of dt)')
      if (allocated(error)) return
      call validate_statistics(-1.0_wp, 10.0_wp, 20, 10, 0.0_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics transient = -1 is out of range; allowed: 0 <= transient < 10 s,'// &
         & ' the time the run reaches (t_end in whole steps of dt)')
      if (allocated(error)) return
      call validate_statistics(1.0_wp, 10.0_wp, 20, 10, -2.0e-3_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics rest_time = -0.002 is out of range; allowed: 0 <= rest_time <= '// &
         & '1e+09 s')
      if (allocated(error)) return
      ! Infinite or huge values were accepted: a rest time, the histogram's range (infinite bins).
      call validate_statistics(1.0_wp, 10.0_wp, 20, 10, huge(1.0_wp), -0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics rest_time = 1.7976931348623157e+308 is out of range; allowed: '// &
         & '0 <= rest_time <= 1e+09 s')
      if (allocated(error)) return
      call validate_statistics(1.0_wp, 10.0_wp, 20, 10, 0.0_wp, -huge(1.0_wp), 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics histogram_lower = -1.7976931348623157e+308 is out of range; '// &
         & 'allowed: -1e+09 <= histogram_lower < 1e+09 m')
      if (allocated(error)) return
      call validate_statistics(1.0_wp, 10.0_wp, 20, 10, 0.0_wp, -0.1_wp, ieee_value(1.0_wp, ieee_positive_inf), &
         & 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics histogram_upper = Inf is out of range; allowed: '// &
         & 'histogram_lower = -0.1 < histogram_upper <= 1e+09 m')
      if (allocated(error)) return
      call validate_statistics(1.0_wp, 10.0_wp, 20, 0, 0.0_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics bins = 0 is out of range; allowed: 1 <= bins <= 1000000')
      if (allocated(error)) return
      call validate_statistics(1.0_wp, 10.0_wp, 20, 10, 0.0_wp, 0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics histogram_upper = 0.1 is out of range; allowed: histogram_lower = '// &
         & '0.1 < histogram_upper <= 1e+09 m')
      if (allocated(error)) return
      call validate_ensemble(0, 'in.nml', error)
      call expect_message(error, 'in.nml: &ensemble members = 0 is out of range; allowed: 1 <= members <= 10000')
      if (allocated(error)) return
      ! Beyond these the tables did not fit in memory: the program ended with a backtrace.
      call validate_statistics(1.0_wp, 10.0_wp, 100000000, 10, 0.0_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics batches = 100000000 is out of range; allowed: 2 <= batches <= 1000')
      if (allocated(error)) return
      call validate_statistics(1.0_wp, 10.0_wp, 20, 2000000000, 0.0_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics bins = 2000000000 is out of range; allowed: 1 <= bins <= 1000000')
      if (allocated(error)) return
      call validate_statistics(1.0_wp, 10.0_wp, 11, 1000000, 0.0_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call expect_message(error, 'in.nml: &statistics bins = 1000000 is out of range; allowed: bins*batches <= '// &
         & '10000000 (every batch keeps its histogram; batches = 11)')
      if (allocated(error)) return
      call validate_ensemble(2000000000, 'in.nml', error)
      call expect_message(error, 'in.nml: &ensemble members = 2000000000 is out of range; allowed: 1 <= members <= 10000')
      if (allocated(error)) return
      call validate_statistics(1.0_wp, 10.0_wp, 1000, 10000, 0.0_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call check(error, .not. allocated(error), 'batches = 1000, bins = 10000 accepted'); if (allocated(error)) return
      call validate_ensemble(10000, 'in.nml', error)
      call check(error, .not. allocated(error), 'members = 10000 accepted'); if (allocated(error)) return
      call validate_statistics(1.0_wp, 10.0_wp, 2, 1, 0.0_wp, -0.1_wp, 0.1_wp, 'in.nml', error)
      call check(error, .not. allocated(error), 'batches = 2, bins = 1 accepted'); if (allocated(error)) return
      call validate_ensemble(1, 'in.nml', error)
      call check(error, .not. allocated(error), 'members = 1 accepted'); if (allocated(error)) return
      call new_statistics(stats, 1, 0.0_wp, 1.0_wp, 1, 4, -1.0_wp, 1.0_wp, error)
      call expect_message(error, 'statistics: &statistics batches = 1 is out of range; allowed: 2 <= batches <= 1000')
   end subroutine test_bad_inputs

   !> Feed a one-stop sequence (t_k = k dt) to a shock log and to statistics, shocks drained every
   !> 64 steps; returns the table and the shock rows.
   subroutine run_both(u, r, e, rest, transient, t_end, batches, bins, lower, upper, table, rows, error)
      real(wp), intent(in) :: u(:), r(:), e(:), rest, transient, t_end, lower, upper
      integer, intent(in) :: batches, bins
      type(statistics_table), intent(out) :: table
      type(shock_row), allocatable, intent(out) :: rows(:)
      type(error_type), allocatable, intent(out) :: error
      type(shock_log) :: log
      type(statistics_type) :: stats
      type(shock_row) :: row
      integer :: k
      call new_shock_log(log, 1, rest, [0.0_wp], error)
      if (allocated(error)) return
      call new_statistics(stats, 1, transient, t_end, batches, bins, lower, upper, error)
      if (allocated(error)) return
      allocate (rows(0))
      do k = 1, size(u)
         call log%step(k*dt, dt, u(k:k), r(k:k), e(k:k))
         call stats%step(k*dt, dt, u(k), r(k:k), e(k:k))
         if (mod(k, 64) == 0) call drain()
      end do
      call log%finish()
      call drain()
      call stats%finish()
      table = stats%results()
   contains
      subroutine drain()
         do while (log%ready())
            call log%pop(row)
            call stats%add_shock(row)
            rows = [rows, row]
         end do
      end subroutine drain
   end subroutine run_both

   !> Value and half-width of a quantity (entry 1 unless given).
   subroutine get(table, name, v, h, entry)
      type(statistics_table), intent(in) :: table
      character(len=*), intent(in) :: name
      real(wp), intent(out) :: v, h
      integer, intent(in), optional :: entry
      integer :: q, i
      i = 1
      if (present(entry)) i = entry
      q = table%find(name)
      if (q == 0) then
         v = ieee_value(v, ieee_quiet_nan)
         h = v
         return
      end if
      v = table%quantity(q)%value(i)
      h = table%quantity(q)%half_width(i)
   end subroutine get

   !> The value of quantity `name` (its first entry) in a table; NaN when it is not there.
   function value_of(table, name) result(v)
      type(statistics_table), intent(in) :: table
      character(len=*), intent(in) :: name
      real(wp) :: v, h
      call get(table, name, v, h)
   end function value_of

   !> Half-width t(0.975, 4) s/sqrt(5) of five batch values.
   pure function hw5(x) result(h)
      real(wp), intent(in) :: x(5)
      real(wp) :: h
      h = 2.7764451051977934_wp*sqrt(sum((x - sum(x)/5)**2)/4)/sqrt(5.0_wp)
   end function hw5

   subroutine test_direct(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 1200, nb = 5, bins = 8
      real(wp), parameter :: transient = 0.2005_wp, t_end = 1.2005_wp, lower = -0.1_wp, upper = 0.1_wp
      real(wp) :: u(n), r(n), e(n), t, w
      integer :: batch(n), k, j, s, b
      integer(ik) :: s1, s2
      type(statistics_table) :: table
      type(shock_row), allocatable :: rows(:)
      real(wp) :: cnt(nb), su(nb), suu(nb), sr(nb), srr(nb), nc(nb), se(nb), ns(nb), nreb(nb), dur(nb), imp(nb)
      real(wp) :: hist(bins, nb), x(nb)
      logical :: in_window(n)
      s1 = 2024
      s2 = 77
      ! A tip swinging between the stops, touching them in bursts.
      do k = 1, n
         u(k) = 0.09_wp*sin(0.05_wp*k) + 0.02_wp*(uniform(s1, s2) - 0.5_wp)
         r(k) = 0
         e(k) = 0
         if (abs(u(k)) > 0.085_wp .and. uniform(s1, s2) < 0.7_wp) then
            r(k) = -sign(1.0_wp + 10*uniform(s1, s2), u(k))
            e(k) = 1.0e-3_wp*uniform(s1, s2)
         end if
      end do
      call run_both(u, r, e, 3*dt, transient, t_end, nb, bins, lower, upper, table, rows, error)
      if (allocated(error)) return
      ! Batches by the formula floor((t - transient)/w) + 1 (no sample near an edge here).
      w = (t_end - transient)/nb
      do k = 1, n
         t = k*dt
         batch(k) = 0
         if (t >= transient) batch(k) = min(nb, floor((t - transient)/w) + 1)
      end do
      in_window = batch > 0
      do j = 1, nb
         cnt(j) = count(batch == j)
         su(j) = sum(u, mask=batch == j)
         suu(j) = sum(u**2, mask=batch == j)
         sr(j) = sum(abs(r), mask=batch == j)
         srr(j) = sum(r**2, mask=batch == j)
         nc(j) = count(batch == j .and. r /= 0)
         se(j) = sum(e, mask=batch == j)
         do b = 1, bins
            hist(b, j) = count(batch == j .and. bin_of(u) == b)
         end do
      end do
      ns = 0
      nreb = 0
      dur = 0
      imp = 0
      do s = 1, size(rows)
         t = rows(s)%t_start
         if (t < transient) cycle
         j = min(nb, floor((t - transient)/w) + 1)
         ns(j) = ns(j) + 1
         nreb(j) = nreb(j) + rows(s)%rebounds
         dur(j) = dur(j) + (rows(s)%t_end - rows(s)%t_start)
         imp(j) = imp(j) + abs(rows(s)%impulse)
      end do
      call note(int_text(size(rows))//' shocks, '//int_text(int(sum(nc)))//' contact samples in the window')
      call check(error, all(ns > 0) .and. all(nc > 0), 'every batch has shocks'); if (allocated(error)) return
      call same('window', sum(cnt)*dt, ieee_value(1.0_wp, ieee_quiet_nan)); if (allocated(error)) return
      call same('tip_mean', sum(su)/sum(cnt), hw5(su/cnt)); if (allocated(error)) return
      call same('tip_rms', sqrt(sum(suu)/sum(cnt)), hw5(sqrt(suu/cnt))); if (allocated(error)) return
      call same('tip_min', minval(u, mask=in_window), ieee_value(1.0_wp, ieee_quiet_nan)); if (allocated(error)) return
      call same('tip_max', maxval(u, mask=in_window), ieee_value(1.0_wp, ieee_quiet_nan)); if (allocated(error)) return
      call same('force_mean', sum(sr)/sum(cnt), hw5(sr/cnt)); if (allocated(error)) return
      call same('force_rms', sqrt(sum(srr)/sum(cnt)), hw5(sqrt(srr/cnt))); if (allocated(error)) return
      call same('force_max', maxval(abs(r), mask=in_window), ieee_value(1.0_wp, ieee_quiet_nan))
      if (allocated(error)) return
      call same('force_mean_contact', sum(sr)/sum(nc), hw5(sr/nc)); if (allocated(error)) return
      call same('force_rms_contact', sqrt(sum(srr)/sum(nc)), hw5(sqrt(srr/nc))); if (allocated(error)) return
      call same('contact_fraction', sum(nc)/sum(cnt), hw5(nc/cnt)); if (allocated(error)) return
      call same('power', sum(se)/(sum(cnt)*dt), hw5(se/(cnt*dt))); if (allocated(error)) return
      call same('shocks', sum(ns), ieee_value(1.0_wp, ieee_quiet_nan)); if (allocated(error)) return
      call same('contact_phases', sum(ns) + sum(nreb), ieee_value(1.0_wp, ieee_quiet_nan)); if (allocated(error)) return
      call same('shocks_per_second', sum(ns)/(sum(cnt)*dt), hw5(ns/(cnt*dt))); if (allocated(error)) return
      call same('rebounds_per_shock', sum(nreb)/sum(ns), hw5(nreb/ns)); if (allocated(error)) return
      call same('shock_duration_mean', sum(dur)/sum(ns), hw5(dur/ns)); if (allocated(error)) return
      call same('impulse_rate', sum(imp)/(sum(cnt)*dt), hw5(imp/(cnt*dt))); if (allocated(error)) return
      x(1) = huge(1.0_wp)
      x(2) = -huge(1.0_wp)
      do s = 1, size(rows)
         if (rows(s)%t_start < transient) cycle
         x(1) = min(x(1), rows(s)%t_end - rows(s)%t_start)
         x(2) = max(x(2), rows(s)%t_end - rows(s)%t_start)
      end do
      call same('shock_duration_min', x(1), ieee_value(1.0_wp, ieee_quiet_nan)); if (allocated(error)) return
      call same('shock_duration_max', x(2), ieee_value(1.0_wp, ieee_quiet_nan)); if (allocated(error)) return
      do b = 1, bins
         call same('tip_histogram', sum(hist(b, :))/sum(cnt), hw5(hist(b, :)/cnt), b); if (allocated(error)) return
      end do
      call same('tip_histogram_edges', lower, 0.0_wp, 1); if (allocated(error)) return
      call same('tip_histogram_edges', lower + 3*(upper - lower)/bins, 0.0_wp, 4); if (allocated(error)) return
      call same('tip_histogram_edges', upper, 0.0_wp, bins + 1); if (allocated(error)) return
   contains
      elemental integer function bin_of(x)
         real(wp), intent(in) :: x
         bin_of = 1 + min(max(floor((x - lower)*(bins/(upper - lower))), 0), bins - 1)
      end function bin_of
      subroutine same(name, v, h, entry)
         character(len=*), intent(in) :: name
         real(wp), intent(in) :: v, h
         integer, intent(in), optional :: entry
         real(wp) :: gv, gh
         call get(table, name, gv, gh, entry)
         call check(error, gv, v, name//' value', rel=.true., thr=1.0e-12_wp)
         if (allocated(error)) return
         if (ieee_is_nan(h)) then
            call check(error, ieee_is_nan(gh), name//' has no interval (got '//real_text(gh)//')')
         else
            call check(error, gh, h, name//' half-width', rel=.true., thr=1.0e-10_wp)
         end if
      end subroutine same
   end subroutine test_direct

   subroutine test_coverage(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: seeds = 400, n = 2000, nb = 20
      type(statistics_type) :: stats
      type(statistics_table) :: table
      integer(ik) :: s1, s2
      integer :: seed, k, covered(4)
      real(wp) :: u, r, e, v, h, fraction(4)
      character(len=*), parameter :: names(4) = [character(len=16) :: 'tip_mean', 'contact_fraction', 'power', &
         & 'tip_histogram']
      real(wp), parameter :: truth(4) = [0.5_wp, 0.1_wp, 0.1_wp*0.5_wp/dt, 0.25_wp]
      covered = 0
      do seed = 1, seeds
         s1 = 1000 + 7919*seed
         s2 = 31 + 104729*seed
         call new_statistics(stats, 1, 0.0_wp, n*dt, nb, 4, 0.0_wp, 1.0_wp, error)
         if (allocated(error)) return
         do k = 1, n
            u = uniform(s1, s2)
            r = 0
            e = 0
            if (uniform(s1, s2) < 0.1_wp) then
               r = 1 + uniform(s1, s2)
               e = uniform(s1, s2)
            end if
            call stats%step(k*dt, dt, u, [r], [e])
         end do
         table = stats%results()
         do k = 1, 4
            call get(table, trim(names(k)), v, h)
            if (abs(v - truth(k)) <= h) covered(k) = covered(k) + 1
         end do
      end do
      fraction = real(covered, wp)/seeds
      call note('coverage over '//int_text(seeds)//' seeds: tip_mean '//real_text(fraction(1))//', contact_fraction '// &
         & real_text(fraction(2))//', power '//real_text(fraction(3))//', tip_histogram(1) '//real_text(fraction(4)))
      do k = 1, 4
         call check(error, fraction(k) >= 0.92_wp .and. fraction(k) <= 0.98_wp, trim(names(k))// &
            & ' coverage '//real_text(fraction(k))//' in [0.92, 0.98]')
         if (allocated(error)) return
      end do
   end subroutine test_coverage

   subroutine test_halves(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 400000, nb = 20
      real(wp), parameter :: phi = 0.95_wp, gap = 0.1_wp, stiffness = 1.0e4_wp
      type(shock_log) :: shocks
      type(statistics_type) :: first, second
      type(statistics_table) :: t1, t2
      type(shock_row) :: row
      integer(ik) :: s1, s2
      integer :: k, q
      real(wp) :: u, x, r, e, v1, h1, v2, h2, half, a, b
      character(len=*), parameter :: names(10) = [character(len=20) :: 'tip_mean', 'tip_rms', 'contact_fraction', &
         & 'power', 'shocks_per_second', 'force_mean', 'impulse_rate', 'rebounds_per_shock', 'shock_duration_mean', &
         & 'force_mean_contact']
      s1 = 5
      s2 = 9
      half = (n/2)*dt
      call new_statistics(first, 1, 0.0_wp, half, nb, 10, -gap, gap, error)
      if (allocated(error)) return
      call new_statistics(second, 1, half, n*dt, nb, 10, -gap, gap, error)
      if (allocated(error)) return
      call new_shock_log(shocks, 1, 4*dt, [0.0_wp], error)
      if (allocated(error)) return
      x = 0
      do k = 1, n
         ! AR(1) with unit-variance innovations scaled to a standard deviation of 0.05 m; a
         ! penalty-like reaction beyond +-gap.
         a = uniform(s1, s2)
         b = uniform(s1, s2)
         x = phi*x + sqrt(1 - phi**2)*0.05_wp*sqrt(-2*log(a))*cos(2*acos(-1.0_wp)*b)
         u = x
         r = 0
         if (u > gap) r = -stiffness*(u - gap)
         if (u < -gap) r = stiffness*(-gap - u)
         e = 1.0e-3_wp*abs(r)
         if (k <= n/2) call first%step(k*dt, dt, u, [r], [e])
         if (k > n/2) call second%step(k*dt, dt, u, [r], [e])
         call shocks%step(k*dt, dt, [u], [r], [e])
         if (mod(k, 1024) == 0 .or. k == n) then
            if (k == n) call shocks%finish()
            do while (shocks%ready())
               call shocks%pop(row)
               if (row%t_start < half) then
                  call first%add_shock(row)
               else
                  call second%add_shock(row)
               end if
            end do
         end if
      end do
      t1 = first%results()
      t2 = second%results()
      do q = 1, size(names)
         call get(t1, trim(names(q)), v1, h1)
         call get(t2, trim(names(q)), v2, h2)
         call note(trim(names(q))//': '//real_text(v1)//' +- '//real_text(h1)//' and '//real_text(v2)//' +- '// &
            & real_text(h2))
         call check(error, abs(v1 - v2) <= h1 + h2, trim(names(q))//' halves '//real_text(v1)//' +- '//real_text(h1)// &
            & ' and '//real_text(v2)//' +- '//real_text(h2)//' agree')
         if (allocated(error)) return
         call check(error, h1 > 0 .and. h2 > 0, trim(names(q))//' intervals positive'); if (allocated(error)) return
      end do
   end subroutine test_halves

   subroutine test_no_contact(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 3000
      real(wp) :: u(n), r(n), e(n), v, h
      type(statistics_table) :: table
      type(shock_row), allocatable :: rows(:)
      integer :: k
      do k = 1, n
         u(k) = 0.05_wp*sin(0.01_wp*k)
      end do
      r = 0
      e = 0
      call run_both(u, r, e, 0.0_wp, 0.5005_wp, n*dt, 10, 5, -0.1_wp, 0.1_wp, table, rows, error)
      if (allocated(error)) return
      call check(error, size(rows), 0, 'shock rows'); if (allocated(error)) return
      call check(error, value_of(table, 'shocks'), 0.0_wp, 'shocks'); if (allocated(error)) return
      call get(table, 'power', v, h)
      call check(error, v, 0.0_wp, 'power'); if (allocated(error)) return
      call check(error, h, 0.0_wp, 'power half-width'); if (allocated(error)) return
      call check(error, value_of(table, 'shocks_per_second'), 0.0_wp, 'shocks per second'); if (allocated(error)) return
      call check(error, value_of(table, 'force_max'), 0.0_wp, 'force_max'); if (allocated(error)) return
      call check(error, value_of(table, 'contact_fraction'), 0.0_wp, 'contact fraction'); if (allocated(error)) return
      call check(error, ieee_is_nan(value_of(table, 'rebounds_per_shock')), &
         & 'rebounds per shock undefined (NaN) without shocks')
      if (allocated(error)) return
      call check(error, ieee_is_nan(value_of(table, 'force_mean_contact')), 'force over contact time undefined (NaN)')
      if (allocated(error)) return
      call check(error, ieee_is_nan(value_of(table, 'shock_duration_max')), 'shock duration max undefined (NaN)')
      if (allocated(error)) return
      call check(error, value_of(table, 'window'), (n - 500)*dt, 'window', rel=.true., thr=1.0e-12_wp)
   end subroutine test_no_contact

   !> A tip resting on the stop at 0.1 was counted in the bin [0.1, 0.2) of a histogram over
   !> [-0.2, 0.2] whose stored lower edge was 0.10000000000000003: the edges did not give the bins.
   !> For ranges and bin counts where the nominal edges round both ways, samples at each stored
   !> edge, one ulp below it and at the nominal edge are binned by the engine as by the edges.
   subroutine test_histogram_edges(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: cases = 6
      real(wp), parameter :: lowers(cases) = [-0.2_wp, -0.1_wp, 0.1_wp, -1.0e9_wp, -3.0e-3_wp, -0.7_wp]
      real(wp), parameter :: uppers(cases) = [0.2_wp, 0.1_wp, 0.7_wp, 1.0e9_wp, 7.0e-2_wp, 0.3_wp]
      integer, parameter :: bin_counts(cases) = [4, 10, 7, 3, 13, 1000]
      real(wp), allocatable :: u(:), r(:), e(:), edges(:), by_edges(:)
      type(statistics_table) :: table
      type(shock_row), allocatable :: rows(:)
      real(wp) :: nominal, h
      integer :: c, bins, i, k, q
      do c = 1, cases
         bins = bin_counts(c)
         ! three samples a bin edge: the nominal edge, and (once the edges are known) the stored one
         ! and the double below it
         allocate (u(3*(bins - 1)))
         do i = 1, bins - 1
            nominal = lowers(c) + i*((uppers(c) - lowers(c))/bins)
            u(3*i - 2:3*i) = nominal
         end do
         allocate (r(size(u)), e(size(u)))
         r = 0
         e = 0
         call run_both(u, r, e, 0.0_wp, 0.0_wp, size(u)*dt, 2, bins, lowers(c), uppers(c), table, rows, error)
         if (allocated(error)) return
         q = table%find('tip_histogram_edges')
         edges = table%quantity(q)%value
         call check(error, size(edges), bins + 1, 'edges'); if (allocated(error)) return
         call check(error, edges(1) == lowers(c) .and. edges(bins + 1) == uppers(c), 'first and last edges')
         if (allocated(error)) return
         do i = 1, bins - 1
            call check(error, abs(edges(i + 1) - u(3*i)) <= 4*spacing(max(abs(lowers(c)), abs(uppers(c)))), &
               & 'edge '//int_text(i)//' beside its nominal value')
            if (allocated(error)) return
            u(3*i - 1) = edges(i + 1)
            u(3*i) = ieee_next_after(edges(i + 1), -huge(1.0_wp))
         end do
         call run_both(u, r, e, 0.0_wp, 0.0_wp, size(u)*dt, 2, bins, lowers(c), uppers(c), table, rows, error)
         if (allocated(error)) return
         allocate (by_edges(bins))
         by_edges = 0
         do k = 1, size(u)
            ! edge i <= u < edge i+1 (u within [lower, upper) here)
            i = count(edges(2:bins) <= u(k)) + 1
            by_edges(i) = by_edges(i) + 1
         end do
         do i = 1, bins
            call get(table, 'tip_histogram', nominal, h, i)
            call check(error, nint(nominal*size(u)), nint(by_edges(i)), 'samples in bin '//int_text(i)//' of '// &
               & int_text(bins)//' over ['//real_text(lowers(c))//', '//real_text(uppers(c))//']')
            if (allocated(error)) return
         end do
         call note(int_text(bins)//' bins over ['//real_text(lowers(c))//', '//real_text(uppers(c))//']: '// &
            & int_text(count(edges(2:bins) /= [(lowers(c) + i*((uppers(c) - lowers(c))/bins), i = 1, bins - 1)]))// &
            & ' stored edges differ from their nominal value')
         deallocate (u, r, e, by_edges)
      end do
   end subroutine test_histogram_edges

   subroutine test_transient(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 1000
      real(wp) :: u(n), r(n), e(n)
      type(statistics_table) :: table
      type(shock_row), allocatable :: rows(:)
      ! A big excursion and shock in the transient, one shock after.
      u = 0.01_wp
      u(100) = 5
      r = 0
      e = 0
      r(100:103) = -7
      e(100:103) = 1
      r(600:601) = 2
      e(600:601) = 0.25_wp
      call run_both(u, r, e, 5*dt, 0.3005_wp, n*dt, 4, 2, -0.1_wp, 0.1_wp, table, rows, error)
      if (allocated(error)) return
      call check(error, size(rows), 2, 'rows'); if (allocated(error)) return
      call check(error, value_of(table, 'shocks'), 1.0_wp, 'shocks after the transient'); if (allocated(error)) return
      call check(error, value_of(table, 'tip_max'), 0.01_wp, 'tip_max'); if (allocated(error)) return
      call check(error, value_of(table, 'force_max'), 2.0_wp, 'force_max'); if (allocated(error)) return
      call check(error, value_of(table, 'power'), 0.5_wp/((n - 300)*dt), 'power', rel=.true., thr=1.0e-12_wp)
      if (allocated(error)) return
      call check(error, value_of(table, 'impulse_rate'), 4*dt/((n - 300)*dt), 'impulse rate', rel=.true., thr=1.0e-12_wp)
   end subroutine test_transient

   subroutine test_step_tip(error)
      type(error_type), allocatable, intent(out) :: error
      type(statistics_type) :: a, b
      type(statistics_table) :: ta, tb
      integer(ik) :: s1, s2
      integer :: k, q, i
      real(wp) :: u, r, e
      call new_statistics(a, 1, 0.1_wp, 1.0_wp, 4, 7, -0.1_wp, 0.1_wp, error)
      if (allocated(error)) return
      call new_statistics(b, 1, 0.1_wp, 1.0_wp, 4, 7, -0.1_wp, 0.1_wp, error)
      if (allocated(error)) return
      s1 = 3
      s2 = 4
      do k = 1, 1000
         u = 0.12_wp*sin(0.01_wp*k) + 0.01_wp*uniform(s1, s2)
         r = merge(uniform(s1, s2), 0.0_wp, abs(u) > 0.1_wp)
         e = 0.1_wp*r
         call a%step_tip(k*dt, dt, u, r, e)
         call b%step(k*dt, dt, u, [r], [e])
      end do
      ta = a%results()
      tb = b%results()
      do q = 1, size(ta%quantity)
         do i = 1, size(ta%quantity(q)%value)
            call check(error, ta%quantity(q)%value(i) == tb%quantity(q)%value(i) .or. &
               & (ieee_is_nan(ta%quantity(q)%value(i)) .and. ieee_is_nan(tb%quantity(q)%value(i))), &
               & ta%quantity(q)%name//' value '//int_text(i))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_step_tip

   !> Whether two tables hold the same quantities with the same bits (any two NaNs the same).
   logical function same_tables(ta, tb)
      type(statistics_table), intent(in) :: ta, tb
      integer :: q
      same_tables = size(ta%quantity) == size(tb%quantity)
      if (.not. same_tables) return
      do q = 1, size(ta%quantity)
         same_tables = ta%quantity(q)%name == tb%quantity(q)%name .and. &
            & size(ta%quantity(q)%value) == size(tb%quantity(q)%value)
         if (.not. same_tables) return
         same_tables = all(same_bits(ta%quantity(q)%value, tb%quantity(q)%value)) .and. &
            & all(same_bits(ta%quantity(q)%half_width, tb%quantity(q)%half_width))
         if (.not. same_tables) return
      end do
   end function same_tables

   !> The one-scene loop's observer (beamstops_observe_quiet) against observer_type's tip on the
   !> same samples: quiet stretches, contact bursts with energy taken, the tip across the
   !> histogram's bins and beyond its range, batch edges, the window's end, a NaN; the quiet values
   !> handed back and taken again at random steps (the loop's calls). The packed observers and
   !> the final tables agree bit for bit; before a hand-back they differ (the quiet path was
   !> taken).
   subroutine test_quiet(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 6000
      type(observer_type) :: a, b
      type(quiet_observer) :: q
      type(statistics_table) :: ta, tb
      real(wp), allocatable :: va(:), vb(:), shocks_a(:, :), shocks_b(:, :)
      real(wp) :: u, r, dissipated, t
      integer(ik) :: s1, s2
      integer :: trial, k
      logical :: kept_apart
      s1 = 7
      s2 = 4242
      do trial = 1, 4
         kept_apart = .false.
         call new_observer(a, 1, [0.0_wp], 2.0_wp, dt, 3*dt, 0.3_wp, n*dt, 6, 11, -0.1_wp, 0.1_wp, 0.0_wp, &
            & int(n - 200*trial, ik), error)
         if (allocated(error)) return
         b = a
         call take_quiet(q, b)
         dissipated = 0
         do k = 1, n
            t = k*dt
            u = 0.13_wp*sin(0.011_wp*k + trial) + 0.002_wp*uniform(s1, s2)
            r = 0
            if (abs(u) > 0.1_wp .and. uniform(s1, s2) < 0.6_wp) r = -sign(0.5_wp + uniform(s1, s2), u)
            if (r /= 0 .and. uniform(s1, s2) < 0.5_wp) dissipated = dissipated + 0.01_wp*abs(r)
            if (trial == 4 .and. k == n - 10) u = ieee_value(u, ieee_quiet_nan)
            if (a%takes(t)) call a%tip(t, u, r, dissipated)
            call observe_quiet(q, b, t, u, r, dissipated)
            if (uniform(s1, s2) < 1.0e-3_wp) then
               call give_quiet(q, b)
               call take_quiet(q, b)
            end if
            if (mod(k, 250) == 0) then
               call a%pack(va)
               call b%pack(vb)
               kept_apart = kept_apart .or. size(va) /= size(vb) .or. .not. all(same_bits(va, vb))
            end if
         end do
         call check(error, kept_apart, 'trial '//int_text(trial)//': the quiet samples were kept in the loop''s '// &
            & 'variables'); if (allocated(error)) return
         call a%pack(va)
         call give_quiet(q, b)
         call b%pack(vb)
         call check(error, size(va) == size(vb), 'trial '//int_text(trial)//': packed sizes'); if (allocated(error)) return
         call check(error, all(same_bits(va, vb)), 'trial '//int_text(trial)//': packed observers bit for bit')
         if (allocated(error)) return
         call a%finish(shocks_a, ta)
         call b%finish(shocks_b, tb)
         call check(error, size(shocks_a) == size(shocks_b) .and. size(shocks_a, 2) > 0, 'trial '//int_text(trial)// &
            & ': shocks'); if (allocated(error)) return
         call check(error, all(same_bits(shocks_a, shocks_b)), 'trial '//int_text(trial)//': shock rows')
         if (allocated(error)) return
         call check(error, same_tables(ta, tb), 'trial '//int_text(trial)//': tables'); if (allocated(error)) return
      end do
   end subroutine test_quiet

   !> A shock log and statistics of 2 stops packed at a random midpoint (in the transient, in a
   !> batch, with rows waiting), unpacked into fresh objects, then both pairs continued with the
   !> same steps: the same rows and results tables, bit for bit (NaN-aware), during and after.
   subroutine test_pack_resume(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 4000, m = 2
      real(wp), allocatable :: u(:, :), r(:, :), e(:, :), vl(:), vs(:), wl(:), ws(:)
      type(shock_log) :: la, lb
      type(statistics_type) :: sa, sb
      type(shock_row) :: ra, rb
      type(statistics_table) :: table
      logical :: fa, fb
      integer(ik) :: s1, s2
      integer :: trial, k, mid, c
      s1 = 99
      s2 = 1234
      allocate (u(m, n), r(m, n), e(m, n))
      do trial = 1, 6
         ! Contact bursts (chatter) at both stops, the tip swinging across the histogram range.
         do c = 1, m
            do k = 1, n
               u(c, k) = 0.12_wp*sin(0.013_wp*k + c) + 0.01_wp*uniform(s1, s2)
               r(c, k) = 0
               if (merge(u(c, k) > 0.1_wp, u(c, k) < -0.1_wp, c == 1) .and. uniform(s1, s2) < 0.7_wp) &
                  & r(c, k) = merge(-1, 1, c == 1)*(0.5_wp + uniform(s1, s2))
               e(c, k) = 0.1_wp*abs(r(c, k))
            end do
         end do
         mid = 1 + int(uniform(s1, s2)*(n - 2))
         if (trial == 1) mid = 150
         call new_shock_log(la, m, 3*dt, [0.0_wp, 0.0_wp], error, capacity=16)
         if (allocated(error)) return
         call new_statistics(sa, m, 0.5_wp, n*dt, 5, 9, -0.1_wp, 0.1_wp, error)
         if (allocated(error)) return
         do k = 1, mid
            call advance(la, sa, k)
         end do
         call la%pack(vl)
         call sa%pack(vs)
         call lb%unpack(vl, error)
         if (allocated(error)) return
         call sb%unpack(vs, error)
         if (allocated(error)) return
         call lb%pack(wl)
         call check(error, size(vl) == size(wl) .and. all(same_bits(vl, wl)), 'trial '//int_text(trial)// &
            & ': repacked log'); if (allocated(error)) return
         call sb%pack(ws)
         call check(error, size(vs) == size(ws), 'trial '//int_text(trial)//': repacked size'); if (allocated(error)) return
         call check(error, all(same_bits(vs, ws)), 'trial '//int_text(trial)//': repacked values')
         if (allocated(error)) return
         call check(error, same_tables(sa%results(), sb%results()), 'trial '//int_text(trial)//': tables at the midpoint')
         if (allocated(error)) return
         do k = mid + 1, n
            call advance(la, sa, k)
            call advance(lb, sb, k)
            if (allocated(error)) return
            if (mod(k, 1000) == 0) then
               call check(error, same_tables(sa%results(), sb%results()), 'trial '//int_text(trial)//': tables at '// &
                  & int_text(k)); if (allocated(error)) return
            end if
         end do
         call la%finish()
         call lb%finish()
         call drain(la, sa, lb, sb)
         if (allocated(error)) return
         call sa%finish()
         call sb%finish()
         call check(error, same_tables(sa%results(), sb%results()), 'trial '//int_text(trial)//': final tables')
         if (allocated(error)) return
         table = sa%results()
         call check(error, sum(table%quantity(table%find('shocks'))%value) > 0, 'trial '//int_text(trial)// &
            & ': shocks counted')
         if (allocated(error)) return
         call sa%pack(vs)
         call sb%pack(ws)
         call check(error, size(vs) == size(ws) .and. all(same_bits(vs, ws)), 'trial '//int_text(trial)//': final states')
         if (allocated(error)) return
      end do
      ! Statistics never constructed.
      sa = statistics_type()
      call sa%pack(vs)
      call sb%unpack(vs, error)
      if (allocated(error)) return
      call sb%pack(ws)
      call check(error, size(ws), 6, 'statistics never constructed: the header alone')
   contains
      !> Step k of a log and its statistics, rows drained every 50 steps.
      subroutine advance(log, stats, k)
         type(shock_log), intent(inout) :: log
         type(statistics_type), intent(inout) :: stats
         integer, intent(in) :: k
         type(shock_row) :: row
         call log%step(k*dt, dt, u(:, k), r(:, k), e(:, k))
         call stats%step(k*dt, dt, u(1, k), r(:, k), e(:, k))
         if (mod(k, 50) == 0) then
            do while (log%ready())
               call log%pop(row)
               call stats%add_shock(row)
            end do
         end if
      end subroutine advance
      !> Drain both logs into their statistics, comparing the rows.
      subroutine drain(log_a, stats_a, log_b, stats_b)
         type(shock_log), intent(inout) :: log_a, log_b
         type(statistics_type), intent(inout) :: stats_a, stats_b
         do
            call log_a%pop(ra, fa)
            call log_b%pop(rb, fb)
            call check(error, fa .eqv. fb, 'a row in both'); if (allocated(error)) return
            if (.not. fa) exit
            call check(error, all(same_bits(shock_row_values(ra), shock_row_values(rb))), 'rows bit for bit')
            if (allocated(error)) return
            call stats_a%add_shock(ra)
            call stats_b%add_shock(rb)
         end do
      end subroutine drain
   end subroutine test_pack_resume

   !> unpack of a truncated, padded, foreign or corrupted vector: an error, the statistics unchanged.
   subroutine test_unpack_bad(error)
      type(error_type), allocatable, intent(out) :: error
      type(statistics_type) :: a, b
      type(shock_log) :: log
      real(wp), allocatable :: va(:), vb(:), vc(:)
      integer :: k, n
      call new_statistics(a, 2, 0.1_wp, 1.0_wp, 4, 7, -0.1_wp, 0.1_wp, error)
      if (allocated(error)) return
      do k = 1, 600
         call a%step(k*dt, dt, 0.1_wp*sin(0.02_wp*k), [merge(1.0_wp, 0.0_wp, mod(k, 9) == 0), 0.0_wp], [0.0_wp, 0.0_wp])
      end do
      call a%pack(va)
      n = size(va)
      call check(error, n, 21 + 6*4 + 7 + 5*2 + 7*4 + 11*2*4, 'length 21 + 6 B + K + 5 m + K B + 11 m B')
      if (allocated(error)) return
      call new_statistics(b, 1, 0.0_wp, 1.0_wp, 2, 1, 0.0_wp, 1.0_wp, error)
      if (allocated(error)) return
      call b%pack(vb)
      call b%unpack(va(1:n - 1), error)
      call expect_message(error, 'statistics: unpack: '//int_text(n - 1)//' values, header length '//int_text(n)// &
         & '; the header (m = 2, batches = 4, bins = 7) needs '//int_text(n))
      if (allocated(error)) return
      call b%unpack(va(1:3), error)
      call expect_message(error, 'statistics: unpack: 3 values, too short for the header (6)'); if (allocated(error)) return
      call b%unpack([va, 1.0_wp], error)
      call expect_message(error, 'statistics: unpack: '//int_text(n + 1)//' values, header length '//int_text(n)// &
         & '; the header (m = 2, batches = 4, bins = 7) needs '//int_text(n))
      if (allocated(error)) return
      call new_shock_log(log, 1, 0.0_wp, [0.0_wp], error)
      if (allocated(error)) return
      call log%pack(vc)
      call b%unpack(vc, error)
      call expect_message(error, 'statistics: unpack: tag 7301, version 1; expected tag 7302, version 1')
      if (allocated(error)) return
      vc = va
      vc(5) = 1
      call b%unpack(vc, error)
      call expect_message(error, 'statistics: unpack: header m = 2, batches = 1, bins = 7 is inconsistent')
      if (allocated(error)) return
      vc = va
      vc(6 + 7) = 5
      call b%unpack(vc, error)
      call expect_message(error, 'statistics: unpack: value 13 = 5 is out of range (expected an integer, or a batch or'// &
         & ' bin index '// &
         & 'in range)'); if (allocated(error)) return
      vc = va
      vc(6 + 9) = 0.5_wp
      call b%unpack(vc, error)
      call expect_message(error, 'statistics: unpack: value 15 = 0.5 is out of range (expected an integer, or a batch or'// &
         & ' bin index '// &
         & 'in range)'); if (allocated(error)) return
      call b%pack(vc)
      call check(error, size(vb) == size(vc) .and. all(same_bits(vb, vc)), 'unchanged after the errors')
   end subroutine test_unpack_bad

   subroutine test_ensemble(error)
      type(error_type), allocatable, intent(out) :: error
      type(statistics_table) :: members(3), ensemble
      type(statistics_table), allocatable :: none(:)
      real(wp) :: nan
      integer :: k
      nan = ieee_value(nan, ieee_quiet_nan)
      do k = 1, 3
         allocate (members(k)%quantity(2))
         members(k)%quantity(1) = quantity_type('power', 'W', 'stop', [real(k, wp), 10.0_wp*k], [0.1_wp, 0.1_wp])
         members(k)%quantity(2) = quantity_type('tip_max', 'm', 'tip', [merge(nan, real(k, wp), k == 2)], [nan])
      end do
      call ensemble_table(members, ensemble, error)
      if (allocated(error)) return
      call check(error, ensemble%quantity(1)%value(1), 2.0_wp, 'mean'); if (allocated(error)) return
      call check(error, ensemble%quantity(1)%half_width(1), 4.302652729749462_wp/sqrt(3.0_wp), 'half-width', &
         & rel=.true., thr=1.0e-12_wp); if (allocated(error)) return
      call check(error, ensemble%quantity(1)%value(2), 20.0_wp, 'mean, entry 2', rel=.true., thr=1.0e-15_wp)
      if (allocated(error)) return
      call check(error, ensemble%quantity(1)%half_width(2), 10*4.302652729749462_wp/sqrt(3.0_wp), 'half-width 2', &
         & rel=.true., thr=1.0e-12_wp); if (allocated(error)) return
      ! A member without a value is left out: K' = 2, values 1 and 3.
      call check(error, ensemble%quantity(2)%value(1), 2.0_wp, 'mean without the NaN member'); if (allocated(error)) return
      call check(error, ensemble%quantity(2)%half_width(1), 12.706204736174694_wp*sqrt(2.0_wp)/sqrt(2.0_wp), &
         & 'half-width with K'' = 2', rel=.true., thr=1.0e-12_wp); if (allocated(error)) return
      call check(error, ensemble%quantity(1)%name == 'power' .and. ensemble%quantity(1)%unit == 'W', 'name and unit kept')
      if (allocated(error)) return
      allocate (none(0))
      call ensemble_table(none, ensemble, error)
      if (.not. allocated(error)) then
         call test_failed(error, 'no members accepted')
         return
      end if
      if (error%message /= 'ensemble: &ensemble members = 0 is out of range; allowed: 1 <= members <= 10000') then
         call test_failed(error, 'message: '//error%message)
         return
      end if
      deallocate (error)
      members(3)%quantity(2)%name = 'tip_min'
      call ensemble_table(members, ensemble, error)
      if (.not. allocated(error)) then
         call test_failed(error, 'mismatched tables accepted')
         return
      end if
      call note(error%message)
      if (index(error%message, 'member 3') == 0) then
         call test_failed(error, 'message should name member 3: '//error%message)
         return
      end if
      deallocate (error)
   end subroutine test_ensemble

   !> ns per step of the shock log, of the statistics and of both (m = 1; array and scalar
   !> interfaces), without contact and with contact in 5 % of the steps (bursts of 20 steps), net
   !> of the bare loop; the least of 7 interleaved repeats of 2e6 steps. Printed as TAP notes,
   !> never asserted.
   subroutine test_cost(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 2000000, period = 4096, repeats = 7, kinds = 6
      character(len=*), parameter :: label(kinds) = [character(len=22) :: 'loop alone', 'shock log (step_tip)', &
         & 'statistics (step_tip)', 'both (step_tip)', 'both (step, arrays)', 'dependent FMA']
      real(wp) :: u(0:period - 1), r(0:period - 1), e(0:period - 1), sink, best(kinds)
      integer :: k, variant, rep, what
      integer(ik) :: shocks
      do k = 0, period - 1
         u(k) = 0.09_wp*sin(2*acos(-1.0_wp)*k/period)
      end do
      do variant = 1, 2
         r = 0
         if (variant == 2) then
            do k = 0, period - 1
               if (mod(k, 400) < 20) r(k) = -1
            end do
         end if
         e = merge(1.0e-6_wp, 0.0_wp, r /= 0)
         best = huge(1.0_wp)
         sink = 0
         do rep = 1, repeats
            do what = 1, kinds
               best(what) = min(best(what), timed(what))
               if (allocated(error)) return
            end do
         end do
         do what = 2, kinds - 1
            call note(trim(merge('no contact:     ', '5 % in contact: ', variant == 1))//' '//trim(label(what))//' '// &
               & fixed(best(what) - best(1))//' ns per step')
         end do
         call note(trim(merge('no contact:     ', '5 % in contact: ', variant == 1))//' (loop alone '// &
            & fixed(best(1))//' ns per step; '//int_text(shocks)//' shocks; machine speed: a dependent '// &
            & 'multiply-add takes '//fixed(best(kinds))//' ns)')
      end do
      if (sink == 12345) call note('sink')
   contains
      !> ns per step of one kind of loop.
      function timed(what) result(ns)
         integer, intent(in) :: what
         real(wp) :: ns
         type(shock_log) :: log
         type(statistics_type) :: stats
         type(shock_row) :: row
         integer(int64) :: c0, c1, rate
         integer :: k, j
         real(wp) :: step
         step = 1.0e-6_wp
         call new_shock_log(log, 1, 5*step, [0.0_wp], error)
         if (allocated(error)) return
         call new_statistics(stats, 1, 0.0_wp, n*step, 20, 50, -0.1_wp, 0.1_wp, error)
         if (allocated(error)) return
         call system_clock(c0, rate)
         select case (what)
         case (1)
            do k = 1, n
               j = iand(k, period - 1)
               sink = sink + (u(j)*r(j) + e(j))*(k*step)
            end do
         case (2)
            do k = 1, n
               j = iand(k, period - 1)
               call log%step_tip(k*step, step, u(j), r(j), e(j))
               if (iand(k, 8191) == 0) then
                  do while (log%ready())
                     call log%pop(row)
                  end do
               end if
            end do
         case (3)
            do k = 1, n
               j = iand(k, period - 1)
               call stats%step_tip(k*step, step, u(j), r(j), e(j))
            end do
         case (4)
            do k = 1, n
               j = iand(k, period - 1)
               call log%step_tip(k*step, step, u(j), r(j), e(j))
               call stats%step_tip(k*step, step, u(j), r(j), e(j))
               if (iand(k, 8191) == 0) then
                  do while (log%ready())
                     call log%pop(row)
                     call stats%add_shock(row)
                  end do
               end if
            end do
         case (6)
            ns = 1
            do k = 1, n
               ns = ns*0.999999_wp + 1.0e-9_wp
            end do
            sink = sink + ns
         case (5)
            do k = 1, n
               j = iand(k, period - 1)
               call log%step(k*step, step, u(j:j), r(j:j), e(j:j))
               call stats%step(k*step, step, u(j), r(j:j), e(j:j))
               if (iand(k, 8191) == 0) then
                  do while (log%ready())
                     call log%pop(row)
                     call stats%add_shock(row)
                  end do
               end if
            end do
         end select
         call system_clock(c1)
         ns = real(c1 - c0, wp)/rate*1.0e9_wp/n
         if (what == 4) shocks = log%shock_count()
      end function timed
      function fixed(x) result(s)
         real(wp), intent(in) :: x
         character(len=:), allocatable :: s
         character(len=16) :: buf
         write (buf, '(f8.2)') x
         s = trim(adjustl(buf))
      end function fixed
   end subroutine test_cost
end module test_statistics
