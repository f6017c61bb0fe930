!> The shock log (beamstops_observe_shocks) on synthetic reaction sequences, against hand
!> values and against an independent offline detector that sees the whole sequence at once.
module test_shocks
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_value, ieee_quiet_nan
   use testing
   use beamstops, only: ik
   use beamstops_scene, only: shock_row_bytes
   use beamstops_observe_shocks, only: shock_log, shock_row, new_shock_log, shock_row_values, n_shock_columns, &
      & shock_column_names, side_lower, side_upper
   implicit none
   private
   public :: collect_shocks, lecuyer, uniform, same_bits, expect_message

   !> Time step of the synthetic sequences (s).
   real(wp), parameter :: dt = 1.0e-3_wp

contains

   !> scene.f90's shock_row_bytes (the ensemble's memory check, which cannot see the type) is
   !> the size of a shock_row: the check said 11 kB a member of the paper's scene where a member
   !> took 0.4 MB, most of it its shock log.
   subroutine test_row_bytes(error)
      type(error_type), allocatable, intent(out) :: error
      type(shock_row) :: row
      call check(error, shock_row_bytes, int(storage_size(row)/8), 'bytes of a shock row')
   end subroutine test_row_bytes

   !> Tests of the suite.
   subroutine collect_shocks(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('one isolated contact: one shock, its times, impulse, velocities', test_isolated), &
         & new_unittest('the ensemble memory check counts a shock row at its size', test_row_bytes), &
         & new_unittest('chatter within rest_time: one shock with its rebounds', test_chatter_merged), &
         & new_unittest('phases further apart than rest_time: separate shocks', test_separate), &
         & new_unittest('rest_time = 0: every phase a shock', test_rest_zero), &
         & new_unittest('the other stop within rest_time: a new shock', test_side_switch), &
         & new_unittest('no contact: no shocks', test_no_contact), &
         & new_unittest('finish: the shock still in contact is closed, truncated', test_finish_in_contact), &
         & new_unittest('finish: a shock waiting for its rest is closed, truncated', test_finish_resting), &
         & new_unittest('random sequences, 2 stops: rows as the offline detector, sums', test_random_against_offline), &
         & new_unittest('a full ring drops rows and counts them', test_ring_overflow), &
         & new_unittest('bad inputs: stops, rest_time, u0, capacity', test_bad_inputs), &
         & new_unittest('row values: columns in the order of the names', test_row_values), &
         & new_unittest('pack at a random midpoint, unpack, continue: the same rows bit for bit', test_pack_resume), &
         & new_unittest('unpack of a truncated, padded, foreign or corrupted vector: an error', test_unpack_bad) &
         & ]
   end subroutine collect_shocks

   !> Feed one stop's sequence (t_k = k dt, k = 1..n; u_0 = u0) and collect every row.
   subroutine feed(r, u, e, rest_time, rows, log, error, no_finish)
      real(wp), intent(in) :: r(:), u(:), e(:), rest_time
      type(shock_row), allocatable, intent(out) :: rows(:)
      type(shock_log), intent(out) :: log
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: no_finish
      integer :: k
      type(shock_row) :: row
      allocate (rows(0))
      call new_shock_log(log, 1, rest_time, [0.0_wp], error)
      if (allocated(error)) return
      do k = 1, size(r)
         call log%step(k*dt, dt, u(k:k), r(k:k), e(k:k))
         do while (log%ready())
            call log%pop(row)
            rows = [rows, row]
         end do
      end do
      if (present(no_finish)) then
         if (no_finish) return
      end if
      call log%finish()
      do while (log%ready())
         call log%pop(row)
         rows = [rows, row]
      end do
   end subroutine feed

   !> A displacement that is a known smooth function of k (so velocities are checkable).
   pure function smooth_u(n) result(u)
      integer, intent(in) :: n
      real(wp) :: u(n)
      integer :: k
      do k = 1, n
         u(k) = 0.01_wp*sin(0.3_wp*k) + 1.0e-4_wp*k
      end do
   end function smooth_u

   subroutine test_isolated(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(30), u(30), e(30)
      type(shock_row), allocatable :: rows(:)
      type(shock_log) :: log
      r = 0
      r(5:7) = [5.0_wp, 7.0_wp, 3.0_wp]
      e = 0
      e(5:7) = [0.1_wp, 0.2_wp, 0.05_wp]
      u = smooth_u(30)
      call feed(r, u, e, 0.01_wp, rows, log, error)
      if (allocated(error)) return
      call check(error, size(rows), 1, 'shocks'); if (allocated(error)) return
      call check(error, rows(1)%t_start, 5*dt, 't_start', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, rows(1)%t_end, 8*dt, 't_end (first free sample)', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, rows(1)%impulse, 15*dt, 'impulse', rel=.true., thr=1.0e-14_wp); if (allocated(error)) return
      call check(error, rows(1)%peak_reaction, 7.0_wp, 'peak'); if (allocated(error)) return
      call check(error, rows(1)%energy_taken, 0.35_wp, 'energy', rel=.true., thr=1.0e-14_wp); if (allocated(error)) return
      call check(error, rows(1)%rebounds, 0, 'rebounds'); if (allocated(error)) return
      call check(error, int(rows(1)%contact_steps), 3, 'contact steps'); if (allocated(error)) return
      call check(error, rows(1)%contact_time, 3*dt, 'contact time', rel=.true., thr=1.0e-14_wp); if (allocated(error)) return
      call check(error, rows(1)%stop, 1, 'stop'); if (allocated(error)) return
      call check(error, rows(1)%side, side_lower, 'side'); if (allocated(error)) return
      call check(error, rows(1)%velocity_in, (u(5) - u(3))/(2*dt), 'velocity_in', rel=.true., thr=1.0e-14_wp)
      if (allocated(error)) return
      call check(error, rows(1)%velocity_out, (u(9) - u(7))/(2*dt), 'velocity_out', rel=.true., thr=1.0e-14_wp)
      if (allocated(error)) return
      call check(error, rows(1)%truncated, .false., 'truncated'); if (allocated(error)) return
      call check(error, int(log%shock_count()), 1, 'shock_count'); if (allocated(error)) return
      call check(error, int(log%phase_count()), 1, 'phase_count')
   end subroutine test_isolated

   subroutine test_chatter_merged(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(40), u(40), e(40)
      type(shock_row), allocatable :: rows(:)
      type(shock_log) :: log
      ! Phases 5-6, 9, 11-12 (gaps of 2 and 1 free samples), upper stop.
      r = 0
      r(5:6) = -2
      r(9) = -9
      r(11:12) = -1
      e = merge(0.5_wp, 0.0_wp, r /= 0)
      u = smooth_u(40)
      call feed(r, u, e, 2.5_wp*dt, rows, log, error)
      if (allocated(error)) return
      call check(error, size(rows), 1, 'shocks'); if (allocated(error)) return
      call check(error, rows(1)%rebounds, 2, 'rebounds'); if (allocated(error)) return
      call check(error, rows(1)%t_start, 5*dt, 't_start', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, rows(1)%t_end, 13*dt, 't_end', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, rows(1)%peak_reaction, -9.0_wp, 'peak, signed'); if (allocated(error)) return
      call check(error, rows(1)%impulse, -15*dt, 'impulse', rel=.true., thr=1.0e-14_wp); if (allocated(error)) return
      call check(error, rows(1)%side, side_upper, 'side'); if (allocated(error)) return
      call check(error, rows(1)%velocity_in, (u(5) - u(3))/(2*dt), 'velocity_in', rel=.true., thr=1.0e-14_wp)
      if (allocated(error)) return
      call check(error, rows(1)%velocity_out, (u(14) - u(12))/(2*dt), 'velocity_out after the last phase', &
         & rel=.true., thr=1.0e-14_wp); if (allocated(error)) return
      call check(error, int(rows(1)%contact_steps), 5, 'contact steps'); if (allocated(error)) return
      call check(error, rows(1)%energy_taken, 2.5_wp, 'energy', rel=.true., thr=1.0e-14_wp); if (allocated(error)) return
      call check(error, int(log%phase_count(1)), 3, 'phases'); if (allocated(error)) return
      call check(error, int(log%shock_count(1)), 1, 'shocks counted')
   end subroutine test_chatter_merged

   subroutine test_separate(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(40), u(40), e(40)
      type(shock_row), allocatable :: rows(:)
      type(shock_log) :: log
      r = 0
      r(5:6) = -2
      r(9) = -9
      r(11:12) = -1
      e = 0
      u = smooth_u(40)
      ! A gap of 2 free samples (2 dt) is not < 1.5 dt; one of 1 is.
      call feed(r, u, e, 1.5_wp*dt, rows, log, error)
      if (allocated(error)) return
      call check(error, size(rows), 2, 'shocks'); if (allocated(error)) return
      call check(error, rows(1)%t_start, 5*dt, 'first t_start', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, rows(1)%t_end, 7*dt, 'first t_end', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, rows(1)%rebounds, 0, 'first rebounds'); if (allocated(error)) return
      call check(error, rows(1)%velocity_out, (u(8) - u(6))/(2*dt), 'first velocity_out', rel=.true., thr=1.0e-14_wp)
      if (allocated(error)) return
      call check(error, rows(2)%t_start, 9*dt, 'second t_start', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, rows(2)%t_end, 13*dt, 'second t_end', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, rows(2)%rebounds, 1, 'second rebounds'); if (allocated(error)) return
      call check(error, rows(2)%velocity_in, (u(9) - u(7))/(2*dt), 'second velocity_in', rel=.true., thr=1.0e-14_wp)
      if (allocated(error)) return
      ! Exactly at the rest time: 2 free samples, rest_time = 2 dt: not merged (separated by not less).
      call feed(r, u, e, 2*dt, rows, log, error)
      if (allocated(error)) return
      call check(error, size(rows), 2, 'shocks with rest_time = 2 dt'); if (allocated(error)) return
      call check(error, rows(2)%rebounds, 1, 'second rebounds with rest_time = 2 dt')
   end subroutine test_separate

   subroutine test_rest_zero(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(40), u(40), e(40)
      type(shock_row), allocatable :: rows(:)
      type(shock_log) :: log
      r = 0
      r(5:6) = 2
      r(8) = 9
      r(10:12) = 1
      e = 0
      u = smooth_u(40)
      call feed(r, u, e, 0.0_wp, rows, log, error)
      if (allocated(error)) return
      call check(error, size(rows), 3, 'shocks'); if (allocated(error)) return
      ! The second shock (sample 8) starts right after the first's velocity_out sample.
      call check(error, rows(1)%velocity_out, (u(8) - u(6))/(2*dt), 'first velocity_out', rel=.true., thr=1.0e-14_wp)
      if (allocated(error)) return
      call check(error, rows(2)%velocity_in, (u(8) - u(6))/(2*dt), 'second velocity_in', rel=.true., thr=1.0e-14_wp)
      if (allocated(error)) return
      call check(error, rows(2)%t_end - rows(2)%t_start, dt, 'second duration', thr=1.0e-15_wp)
      if (allocated(error)) return
      call check(error, sum(rows%rebounds), 0, 'rebounds')
   end subroutine test_rest_zero

   subroutine test_side_switch(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(30), u(30), e(30)
      type(shock_row), allocatable :: rows(:)
      type(shock_log) :: log
      r = 0
      r(5:6) = 3
      r(8:9) = -4
      r(10) = 1
      e = 0
      u = smooth_u(30)
      call feed(r, u, e, 10*dt, rows, log, error)
      if (allocated(error)) return
      call check(error, size(rows), 3, 'shocks'); if (allocated(error)) return
      call check(error, rows(1)%side, side_lower, 'first side'); if (allocated(error)) return
      call check(error, rows(2)%side, side_upper, 'second side'); if (allocated(error)) return
      call check(error, rows(2)%t_end, 10*dt, 'second t_end at the switch', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, ieee_is_nan(rows(2)%velocity_out), .true., 'no velocity_out at a direct switch')
      if (allocated(error)) return
      call check(error, rows(3)%side, side_lower, 'third side'); if (allocated(error)) return
      call check(error, rows(3)%truncated, .false., 'third complete (its rest ends at sample 20 <= 30)')
   end subroutine test_side_switch

   subroutine test_no_contact(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(100), u(100), e(100)
      type(shock_row), allocatable :: rows(:)
      type(shock_log) :: log
      r = 0
      e = 0
      u = smooth_u(100)
      call feed(r, u, e, 5*dt, rows, log, error)
      if (allocated(error)) return
      call check(error, size(rows), 0, 'shocks'); if (allocated(error)) return
      call check(error, int(log%shock_count()), 0, 'shock_count'); if (allocated(error)) return
      call check(error, int(log%phase_count()), 0, 'phase_count')
   end subroutine test_no_contact

   subroutine test_finish_in_contact(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(20), u(20), e(20)
      type(shock_row), allocatable :: rows(:)
      type(shock_log) :: log
      r = 0
      r(17:20) = 2
      e = 0
      u = smooth_u(20)
      call feed(r, u, e, 3*dt, rows, log, error, no_finish=.true.)
      if (allocated(error)) return
      call check(error, size(rows), 0, 'no row before finish'); if (allocated(error)) return
      call feed(r, u, e, 3*dt, rows, log, error)
      if (allocated(error)) return
      call check(error, size(rows), 1, 'shocks'); if (allocated(error)) return
      call check(error, rows(1)%t_end, 21*dt, 't_end = last t + dt', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, ieee_is_nan(rows(1)%velocity_out), .true., 'velocity_out NaN'); if (allocated(error)) return
      call check(error, rows(1)%truncated, .true., 'truncated')
   end subroutine test_finish_in_contact

   subroutine test_finish_resting(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(20), u(20), e(20)
      type(shock_row), allocatable :: rows(:)
      type(shock_log) :: log
      r = 0
      r(10:12) = 2
      e = 0
      u = smooth_u(20)
      call feed(r, u, e, 10*dt, rows, log, error)
      if (allocated(error)) return
      call check(error, size(rows), 1, 'shocks'); if (allocated(error)) return
      call check(error, rows(1)%t_end, 13*dt, 't_end', thr=1.0e-15_wp); if (allocated(error)) return
      call check(error, rows(1)%velocity_out, (u(14) - u(12))/(2*dt), 'velocity_out', rel=.true., thr=1.0e-14_wp)
      if (allocated(error)) return
      call check(error, rows(1)%truncated, .true., 'truncated')
      if (allocated(error)) return
      ! With the rest over at the last sample (n - b = 8 >= R = 8) it is complete.
      call feed(r, u, e, 8*dt, rows, log, error, no_finish=.true.)
      if (allocated(error)) return
      call check(error, size(rows), 1, 'closed on its own at the last sample'); if (allocated(error)) return
      call check(error, rows(1)%truncated, .false., 'not truncated')
   end subroutine test_finish_resting

   !> Random contact sequences on 2 stops against the offline detector; impulses and energies
   !> of the shocks sum to those of the sequence.
   subroutine test_random_against_offline(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 20000, m = 2
      real(wp), allocatable :: r(:, :), u(:, :), e(:, :)
      real(wp) :: rest
      integer(ik) :: s1, s2
      integer :: k, i, trial, j
      type(shock_log) :: log
      type(shock_row) :: row
      type(shock_row), allocatable :: got(:), want(:)
      real(wp) :: a(n_shock_columns), b(n_shock_columns), sum_impulse, sum_energy
      real(wp), parameter :: rests(6) = [0.0_wp, 0.5_wp*dt, dt, 2*dt, 3.5_wp*dt, 12*dt]
      allocate (r(m, n), u(m, n), e(m, n))
      s1 = 12345
      s2 = 67890
      do trial = 1, 6
         rest = rests(trial)
         ! Contact bursts, sign switches rarely.
         call bursts(700, s1, s2, u, r, e)
         call new_shock_log(log, m, rest, [0.0_wp, 0.0_wp], error, capacity=64)
         if (allocated(error)) return
         allocate (got(0))
         do k = 1, n
            call log%step(k*dt, dt, u(:, k), r(:, k), e(:, k))
            if (mod(k, 50) == 0 .or. k == n) then
               do while (log%ready())
                  call log%pop(row)
                  got = [got, row]
               end do
            end if
         end do
         call log%finish()
         do while (log%ready())
            call log%pop(row)
            got = [got, row]
         end do
         call check(error, int(log%lost_count()), 0, 'rows lost'); if (allocated(error)) return
         do i = 1, m
            want = offline(r(i, :), u(i, :), e(i, :), rest, i)
            call check(error, count(got%stop == i), size(want), 'shocks at stop '//int_text(i)//', rest '// &
               & real_text(rest)); if (allocated(error)) return
            call check(error, int(log%shock_count(i)), size(want), 'shock_count'); if (allocated(error)) return
            call check(error, int(log%phase_count(i)), sum(want%rebounds) + size(want), 'phase_count')
            if (allocated(error)) return
            j = 0
            sum_impulse = 0
            sum_energy = 0
            do k = 1, size(got)
               if (got(k)%stop /= i) cycle
               j = j + 1
               a = shock_row_values(got(k))
               b = shock_row_values(want(j))
               call same_row(a, b, 'stop '//int_text(i)//' shock '//int_text(j)//', rest '//real_text(rest))
               if (allocated(error)) return
               sum_impulse = sum_impulse + got(k)%impulse
               sum_energy = sum_energy + got(k)%energy_taken
            end do
            call check(error, sum_impulse, sum(r(i, :))*dt, 'sum of impulses', rel=.true., thr=1.0e-9_wp)
            if (allocated(error)) return
            call check(error, sum_energy, sum(e(i, :)), 'sum of energies', rel=.true., thr=1.0e-11_wp)
            if (allocated(error)) return
         end do
         ! One stop through the scalar step_tip: the same rows as the offline detector.
         call new_shock_log(log, 1, rest, [0.0_wp], error)
         if (allocated(error)) return
         deallocate (got)
         allocate (got(0))
         do k = 1, n
            call log%step_tip(k*dt, dt, u(1, k), r(1, k), e(1, k))
            do while (log%ready())
               call log%pop(row)
               got = [got, row]
            end do
         end do
         call log%finish()
         do while (log%ready())
            call log%pop(row)
            got = [got, row]
         end do
         want = offline(r(1, :), u(1, :), e(1, :), rest, 1)
         call check(error, size(got), size(want), 'step_tip: shocks'); if (allocated(error)) return
         do j = 1, size(got)
            call same_row(shock_row_values(got(j)), shock_row_values(want(j)), 'step_tip: shock '//int_text(j))
            if (allocated(error)) return
         end do
         if (trial == 4) call note('rest 2 dt: '//int_text(size(got))//' shocks, '// &
            & int_text(int(log%phase_count()))//' phases')
         deallocate (got)
      end do
   contains
      subroutine same_row(a, b, what)
         real(wp), intent(in) :: a(:), b(:)
         character(len=*), intent(in) :: what
         integer :: c
         do c = 1, size(a)
            if (ieee_is_nan(a(c)) .and. ieee_is_nan(b(c))) cycle
            call check(error, a(c), b(c), what//' '//trim(shock_column_names(c)), rel=.true., thr=1.0e-12_wp)
            if (allocated(error)) return
         end do
      end subroutine same_row
   end subroutine test_random_against_offline

   !> The shocks of one stop from its whole sequence (t_k = k dt, u_0 = u_{-1} = 0): phases as
   !> runs of one sign, merged when same sign and (free samples between) dt < rest.
   function offline(r, u, e, rest, stop) result(rows)
      real(wp), intent(in) :: r(:), u(:), e(:), rest
      integer, intent(in) :: stop
      type(shock_row), allocatable :: rows(:)
      integer, allocatable :: pa(:), pb(:), ps(:)
      integer :: n, k, np, p, first, last, j
      type(shock_row) :: row
      real(wp) :: uu(-1:size(u))
      n = size(r)
      uu(-1:0) = 0
      uu(1:n) = u
      allocate (pa(0), pb(0), ps(0))
      k = 1
      do while (k <= n)
         if (r(k) == 0) then
            k = k + 1
            cycle
         end if
         first = k
         do while (k + 1 <= n)
            if (r(k + 1) == 0 .or. (r(k + 1) > 0 .neqv. r(first) > 0)) exit
            k = k + 1
         end do
         pa = [pa, first]
         pb = [pb, k]
         ps = [ps, merge(1, -1, r(first) > 0)]
         k = k + 1
      end do
      np = size(pa)
      allocate (rows(0))
      p = 1
      do while (p <= np)
         last = p
         do while (last + 1 <= np)
            if (ps(last + 1) /= ps(p)) exit
            if (.not. (real(pa(last + 1) - pb(last) - 1, wp)*dt < rest)) exit
            last = last + 1
         end do
         row = shock_row()
         row%stop = stop
         row%side = ps(p)
         row%t_start = pa(p)*dt
         row%rebounds = last - p
         row%velocity_in = (uu(pa(p)) - uu(pa(p) - 2))/(2*dt)
         row%impulse = 0
         row%energy_taken = 0
         row%peak_reaction = 0
         row%contact_steps = 0
         row%contact_time = 0
         do j = p, last
            do k = pa(j), pb(j)
               row%impulse = row%impulse + r(k)*dt
               row%energy_taken = row%energy_taken + e(k)
               if (abs(r(k)) > abs(row%peak_reaction)) row%peak_reaction = r(k)
               row%contact_steps = row%contact_steps + 1
               row%contact_time = row%contact_time + dt
            end do
         end do
         k = pb(last)
         row%t_end = (k + 1)*dt
         row%velocity_out = ieee_value(1.0_wp, ieee_quiet_nan)
         if (k + 2 <= n) then
            if (r(k + 1) == 0) row%velocity_out = (uu(k + 2) - uu(k))/(2*dt)
         end if
         ! Complete unless no later phase and the run ends before b + max(R, 2).
         row%truncated = .false.
         if (last == np) row%truncated = .not. (n - k >= 2 .and. real(n - k, wp)*dt >= rest)
         rows = [rows, row]
         p = last + 1
      end do
   end function offline

   subroutine test_ring_overflow(error)
      type(error_type), allocatable, intent(out) :: error
      type(shock_log) :: log
      type(shock_row) :: row
      integer :: k
      logical :: found
      call new_shock_log(log, 1, 0.0_wp, [0.0_wp], error, capacity=2)
      if (allocated(error)) return
      do k = 1, 50
         call log%step(k*dt, dt, [0.0_wp], [merge(1.0_wp, 0.0_wp, mod(k, 10) == 0)], [0.0_wp])
      end do
      call log%finish()
      call check(error, int(log%shock_count()), 5, 'shocks'); if (allocated(error)) return
      call check(error, int(log%lost_count()), 3, 'lost'); if (allocated(error)) return
      call log%pop(row, found)
      call check(error, row%t_start, 10*dt, 'oldest kept first', thr=1.0e-15_wp); if (allocated(error)) return
      call log%pop(row, found)
      call check(error, row%t_start, 20*dt, 'then the next', thr=1.0e-15_wp); if (allocated(error)) return
      call log%pop(row, found)
      call check(error, found, .false., 'then none')
   end subroutine test_ring_overflow

   subroutine test_bad_inputs(error)
      type(error_type), allocatable, intent(out) :: error
      type(shock_log) :: log
      call new_shock_log(log, 1, -1.0_wp, [0.0_wp], error)
      call expect_message(error, 'shock log: rest_time = -1 is out of range; allowed: rest_time >= 0 s')
      if (allocated(error)) return
      call new_shock_log(log, 0, 0.0_wp, [real(wp) ::], error)
      call expect_message(error, 'shock log: stops = 0 is out of range; allowed: stops >= 1'); if (allocated(error)) return
      call new_shock_log(log, 2, 0.0_wp, [0.0_wp], error)
      call expect_message(error, 'shock log: u0 has 1 values; allowed: one per stop (2)'); if (allocated(error)) return
      call new_shock_log(log, 1, 0.0_wp, [0.0_wp], error, capacity=0)
      call expect_message(error, 'shock log: capacity = 0 is out of range; allowed: capacity >= 1')
   end subroutine test_bad_inputs

   subroutine test_row_values(error)
      type(error_type), allocatable, intent(out) :: error
      type(shock_row) :: row
      real(wp) :: v(n_shock_columns)
      row%t_start = 1
      row%t_end = 2
      row%stop = 3
      row%side = -1
      row%velocity_in = 5
      row%velocity_out = 6
      row%impulse = 7
      row%peak_reaction = 8
      row%energy_taken = 9
      row%rebounds = 10
      row%contact_steps = 11
      row%contact_time = 12
      row%truncated = .true.
      v = shock_row_values(row)
      call check(error, v(4), -1.0_wp, 'side'); if (allocated(error)) return
      v(4) = 4
      call check(error, maxval(abs(v - [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 1])) == 0, 'values in column order')
      if (allocated(error)) return
      call check(error, trim(shock_column_names(7)) == 'impulse', 'column 7 is impulse')
   end subroutine test_row_values

   !> Whether a and b hold the same bits (any two NaNs count as the same).
   elemental logical function same_bits(a, b)
      real(wp), intent(in) :: a, b
      same_bits = transfer(a, 0_ik) == transfer(b, 0_ik) .or. (ieee_is_nan(a) .and. ieee_is_nan(b))
   end function same_bits

   !> A synthetic sequence of m stops: contact bursts (chatter) of either sign, energies.
   subroutine synthetic(m, n, seed, u, r, e)
      integer, intent(in) :: m, n
      integer(ik), intent(in) :: seed
      real(wp), allocatable, intent(out) :: u(:, :), r(:, :), e(:, :)
      integer(ik) :: s1, s2
      allocate (u(m, n), r(m, n), e(m, n))
      s1 = seed
      s2 = 2*seed + 1
      call bursts(300, s1, s2, u, r, e)
   end subroutine synthetic

   !> Fill u, r, e (stops x steps) with contact bursts (a two-state chain: free -> contact rarely,
   !> contact -> free often) whose sign switches every `period` steps, drawing from s1, s2.
   subroutine bursts(period, s1, s2, u, r, e)
      integer, intent(in) :: period
      integer(ik), intent(inout) :: s1, s2
      real(wp), intent(out) :: u(:, :), r(:, :), e(:, :)
      integer :: i, k
      logical :: contact
      do i = 1, size(u, 1)
         contact = .false.
         do k = 1, size(u, 2)
            if (contact) then
               contact = uniform(s1, s2) < 0.6_wp
            else
               contact = uniform(s1, s2) < 0.08_wp
            end if
            u(i, k) = 0.05_wp*sin(0.01_wp*k + i) + 1.0e-3_wp*uniform(s1, s2)
            if (contact) then
               r(i, k) = (0.5_wp + uniform(s1, s2))*merge(1, -1, mod(k/period + i, 2) == 0)
               e(i, k) = uniform(s1, s2)
            else
               r(i, k) = 0
               e(i, k) = 0
            end if
         end do
      end do
   end subroutine bursts

   !> pack at random midpoints, unpack into a fresh log, continue both with the same steps: the
   !> same rows, counts and packed state, bit for bit (rings of several sizes, some overflowing).
   subroutine test_pack_resume(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 3000, m = 3
      integer, parameter :: capacities(4) = [64, 3, 1, 4096]
      real(wp), parameter :: rests(4) = [3.5_wp*dt, 0.0_wp, 12*dt, dt]
      real(wp), allocatable :: u(:, :), r(:, :), e(:, :), va(:), vb(:)
      type(shock_log) :: a, b
      type(shock_row) :: ra, rb
      logical :: fa, fb
      integer(ik) :: s1, s2
      integer :: trial, k, mid, i, rows
      s1 = 777
      s2 = 4242
      do trial = 1, 8
         call synthetic(m, n, int(trial, ik), u, r, e)
         mid = 1 + int(uniform(s1, s2)*(n - 2))
         call new_shock_log(a, m, rests(mod(trial - 1, 4) + 1), [0.0_wp, 1.0e-3_wp, -2.0e-3_wp], error, &
            & capacity=capacities(mod(trial - 1, 4) + 1))
         if (allocated(error)) return
         do k = 1, mid
            call a%step(k*dt, dt, u(:, k), r(:, k), e(:, k))
            if (mod(k, 97) == 0) then
               do while (a%ready())
                  call a%pop(ra)
               end do
            end if
         end do
         call a%pack(va)
         call b%unpack(va, error)
         if (allocated(error)) return
         call b%pack(vb)
         call check(error, size(va) == size(vb), 'trial '//int_text(trial)//': repacked size'); if (allocated(error)) return
         call check(error, all(same_bits(va, vb)), 'trial '//int_text(trial)//': repacked values')
         if (allocated(error)) return
         rows = 0
         do k = mid + 1, n + 1
            if (k <= n) then
               call a%step(k*dt, dt, u(:, k), r(:, k), e(:, k))
               call b%step(k*dt, dt, u(:, k), r(:, k), e(:, k))
            else
               call a%finish()
               call b%finish()
            end if
            if (mod(k, 97) == 0 .or. k > n) then
               do
                  call a%pop(ra, fa)
                  call b%pop(rb, fb)
                  call check(error, fa .eqv. fb, 'trial '//int_text(trial)//': a row in both'); if (allocated(error)) return
                  if (.not. fa) exit
                  rows = rows + 1
                  call check(error, all(same_bits(shock_row_values(ra), shock_row_values(rb))), &
                     & 'trial '//int_text(trial)//': row '//int_text(rows)//' bit for bit'); if (allocated(error)) return
               end do
            end if
         end do
         call check(error, rows > 0, 'trial '//int_text(trial)//': rows after the midpoint'); if (allocated(error)) return
         do i = 1, m
            call check(error, int(a%shock_count(i)), int(b%shock_count(i)), 'shock_count'); if (allocated(error)) return
            call check(error, int(a%phase_count(i)), int(b%phase_count(i)), 'phase_count'); if (allocated(error)) return
         end do
         call check(error, int(a%lost_count()), int(b%lost_count()), 'lost_count'); if (allocated(error)) return
         call a%pack(va)
         call b%pack(vb)
         call check(error, size(va) == size(vb) .and. all(same_bits(va, vb)), 'trial '//int_text(trial)// &
            & ': final states'); if (allocated(error)) return
      end do
      ! The tip-only path and a log never constructed.
      call new_shock_log(a, 1, 2*dt, [0.0_wp], error)
      if (allocated(error)) return
      do k = 1, 500
         call a%step_tip(k*dt, dt, u(1, k), r(1, k), e(1, k))
      end do
      call a%pack(va)
      call b%unpack(va, error)
      if (allocated(error)) return
      do k = 501, 1000
         call a%step_tip(k*dt, dt, u(1, k), r(1, k), e(1, k))
         call b%step_tip(k*dt, dt, u(1, k), r(1, k), e(1, k))
      end do
      call a%finish()
      call b%finish()
      call a%pack(va)
      call b%pack(vb)
      call check(error, size(va) == size(vb) .and. all(same_bits(va, vb)), 'step_tip: final states')
      if (allocated(error)) return
      call check(error, a%ready() .and. size(va) > 10 + 24, 'step_tip: rows held at the end'); if (allocated(error)) return
      a = shock_log()
      call a%pack(va)
      call b%unpack(va, error)
      if (allocated(error)) return
      call check(error, b%stop_count(), 0, 'a log never constructed: restored as such')
   end subroutine test_pack_resume

   !> unpack of a truncated, padded, foreign or corrupted vector: an error, the log unchanged.
   subroutine test_unpack_bad(error)
      type(error_type), allocatable, intent(out) :: error
      type(shock_log) :: a, b
      real(wp), allocatable :: u(:, :), r(:, :), e(:, :), va(:), vb(:), vc(:)
      integer :: k, n
      call synthetic(2, 400, 5_ik, u, r, e)
      call new_shock_log(a, 2, 3*dt, [0.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      do k = 1, 400
         call a%step(k*dt, dt, u(:, k), r(:, k), e(:, k))
      end do
      call a%pack(va)
      n = size(va)
      call check(error, n, 10 + 24*2 + 13*int(a%shock_count()), 'length 10 + 24 m + 13 H'); if (allocated(error)) return
      call new_shock_log(b, 1, 0.0_wp, [0.5_wp], error)
      if (allocated(error)) return
      call b%pack(vb)
      call b%unpack(va(1:n - 1), error)
      call expect_message(error, 'shock log: unpack: '//int_text(n - 1)//' values, header length '//int_text(n)// &
         & '; the header (m = 2, held = '//int_text(int(a%shock_count()))//') needs '//int_text(n))
      if (allocated(error)) return
      call b%unpack(va(1:5), error)
      call expect_message(error, 'shock log: unpack: 5 values, too short for the header (6)'); if (allocated(error)) return
      call b%unpack([va, 0.0_wp], error)
      call expect_message(error, 'shock log: unpack: '//int_text(n + 1)//' values, header length '//int_text(n)// &
         & '; the header (m = 2, held = '//int_text(int(a%shock_count()))//') needs '//int_text(n))
      if (allocated(error)) return
      vc = va
      vc(1) = 7302
      call b%unpack(vc, error)
      call expect_message(error, 'shock log: unpack: tag 7302, version 1; expected tag 7301, version 1')
      if (allocated(error)) return
      vc = va
      vc(4) = 2.5_wp
      call b%unpack(vc, error)
      call expect_message(error, 'shock log: unpack: header value 4 = 2.5 is not an integer'); if (allocated(error)) return
      vc = va
      vc(10 + 5*2 + 1) = 0.5_wp
      call b%unpack(vc, error)
      if (.not. allocated(error)) then
         call test_failed(error, 'a logical 0.5: no error')
         return
      end if
      deallocate (error)
      vc = va
      vc(9) = 0
      call b%unpack(vc, error)
      if (.not. allocated(error)) then
         call test_failed(error, 'head 0: no error')
         return
      end if
      deallocate (error)
      call b%pack(vc)
      call check(error, size(vb) == size(vc) .and. all(same_bits(vb, vc)), 'unchanged after the errors')
   end subroutine test_unpack_bad

   !> Expect the error `message`: a failure in `error` when there is none or another, else
   !> `error` deallocated (the next call can go on).
   subroutine expect_message(error, message)
      !> The error of the call checked; on return, unallocated or the failure.
      type(error_type), allocatable, intent(inout) :: error
      !> The message expected.
      character(len=*), intent(in) :: message
      if (.not. allocated(error)) then
         call test_failed(error, 'no error; expected "'//message//'"')
      else if (error%message /= message) then
         call test_failed(error, 'message "'//error%message//'", expected "'//message//'"')
      else
         deallocate (error)
      end if
   end subroutine expect_message

   !> L'Ecuyer's combined generator (1988): deterministic, portable (int64, no overflow).
   function lecuyer(s1, s2) result(z)
      !> States (modified).
      integer(ik), intent(inout) :: s1, s2
      integer(ik) :: z
      s1 = mod(40014_ik*s1, 2147483563_ik)
      s2 = mod(40692_ik*s2, 2147483399_ik)
      z = s1 - s2
      if (z < 1) z = z + 2147483562_ik
   end function lecuyer

   !> A uniform number in (0, 1).
   function uniform(s1, s2) result(x)
      !> States (modified).
      integer(ik), intent(inout) :: s1, s2
      real(wp) :: x
      x = real(lecuyer(s1, s2), wp)*4.656613057391769e-10_wp
   end function uniform
end module test_shocks
