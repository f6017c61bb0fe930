!> Stops along the span (SPEC 7, contact/span_stops.f90) in whole runs: the KKT conditions
!> at every step, one stop at the tip against the tip-only path (bit for bit), the energy the
!> stops take never negative and the balance closed, a stop never reached changing nothing,
!> many stops active at once (the columns and the solve of the correction), a dense written-out
!> scheme with its QP solved by enumeration, and the &stops lists of the namelist.
module test_stops
   use testing
   use test_support, only: run_recorded, int_text, exact_element, dense_assembly, lift, lift_prime, solve_spd, &
      & simpson_load
   use beamstops, only: ik, scene_type, array_recorder, run_summary, law_none, law_signorini, read_scene, &
      & stop_count, steps_of
   use beamstops_recorder, only: col_t, col_u, col_v, col_reaction, col_energy, col_work, col_dissipated, n_columns
   implicit none
   private
   public :: collect_stops

contains

   !> Tests of the suite.
   subroutine collect_stops(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('two supports and the tip: KKT at every step', test_kkt), &
         & new_unittest('one stop at the tip: the tip-only path, bit for bit', test_single_tip), &
         & new_unittest('energy taken by the stops never negative, balance closed', test_energy), &
         & new_unittest('a mid-span stop never reached: the free scene, bit for bit', test_unreached_free), &
         & new_unittest('a mid-span stop never reached: the tip-only scene, bit for bit', test_unreached_tip), &
         & new_unittest('sixteen stops, many active at once: KKT, balance', test_many_active), &
         & new_unittest('J = 3, two stops: the written-out scheme with its QP by enumeration', test_dense), &
         & new_unittest('namelist: nodes, x, one bound for all, the tip-only form unchanged', test_namelist_valid), &
         & new_unittest('namelist: refused lists, with messages', test_namelist_refused) &
         & ]
   end subroutine collect_stops

   ! ---------------------------------------------------------------- helpers

   !> The paper's beam with stops at `nodes` (gaps `lower`, `upper`), beta = 1/4.
   function span_scene(nodes, lower, upper, elements, dt, t_end) result(scene)
      integer, intent(in) :: nodes(:)
      real(wp), intent(in) :: lower(:), upper(:)
      integer, intent(in) :: elements
      real(wp), intent(in) :: dt, t_end
      type(scene_type) :: scene
      scene%law = law_signorini
      scene%beta = 0.25_wp
      scene%elements = elements
      scene%dt = dt
      scene%t_end = t_end
      allocate (scene%stop_nodes, source=nodes)
      allocate (scene%stop_lower, source=lower)
      allocate (scene%stop_upper, source=upper)
   end function span_scene

   !> Run with every record, the stops' values reserved too.
   subroutine run_span(scene, rec, summary, error)
      type(scene_type), intent(in) :: scene
      type(array_recorder), intent(out) :: rec
      type(run_summary), intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      call run_recorded(scene, rec, summary, error)
      if (allocated(error)) return
      call check(error, size(rec%stops_u, 1) == stop_count(scene) .and. rec%stops_filled == rec%filled, &
         & 'the recorder holds the values of the '//int_text(int(stop_count(scene), ik))//' stops at every record')
   end subroutine run_span

   !> Support position phi(t) = a sin(omega t).
   pure real(wp) function phi(scene, t)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: t
      phi = scene%amplitude*sin(scene%omega*t)
   end function phi

   !> KKT conditions of every step in the records: u~ of every stop within its stops (to the
   !> round-off of u~ = u + h phi), a reaction only on a stop, pushing away from it. A row holds
   !> u~^n and the reaction of the step that put it there.
   subroutine check_kkt(scene, rec, error, contacts)
      type(scene_type), intent(in) :: scene
      type(array_recorder), intent(in) :: rec
      type(error_type), allocatable, intent(inout) :: error
      integer(ik), intent(out) :: contacts
      integer(ik) :: j
      integer :: i, m
      real(wp) :: u, r, tol
      character(len=:), allocatable :: where
      m = stop_count(scene)
      contacts = 0
      tol = 4*epsilon(1.0_wp)*(abs(scene%amplitude) + maxval(abs(scene%stop_upper)) + maxval(abs(scene%stop_lower)))
      do j = 1, rec%filled
         do i = 1, m
            u = rec%stops_u(i, j)
            where = ' (stop '//int_text(int(i, ik))//', t = '//real_text(rec%rows(col_t, j))//')'
            call check(error, u >= scene%stop_lower(i) - tol .and. u <= scene%stop_upper(i) + tol, &
               & 'u~ = '//real_text(u)//' within ['//real_text(scene%stop_lower(i))//', '// &
               & real_text(scene%stop_upper(i))//']'//where)
            if (allocated(error)) return
            r = rec%stops_reaction(i, j)
            if (r < 0) then
               call check(error, abs(u - scene%stop_upper(i)) <= tol, 'reaction '//real_text(r)// &
                  & ' < 0 needs u~^{n+1} = '//real_text(u)//' at the upper stop'//where)
            else if (r > 0) then
               call check(error, abs(u - scene%stop_lower(i)) <= tol, 'reaction '//real_text(r)// &
                  & ' > 0 needs u~^{n+1} = '//real_text(u)//' at the lower stop'//where)
            end if
            if (allocated(error)) return
            if (r /= 0) contacts = contacts + 1
         end do
      end do
   end subroutine check_kkt

   !> max |(E_n - E_0) - (W_n - D_n)| / max |E| <= thr, and D nondecreasing to round-off.
   subroutine check_energy(rec, thr, error)
      type(array_recorder), intent(in) :: rec
      real(wp), intent(in) :: thr
      type(error_type), allocatable, intent(inout) :: error
      real(wp) :: scale, worst, step_min
      integer(ik) :: j
      scale = maxval(abs(rec%rows(col_energy, :rec%filled)))
      worst = 0
      step_min = 0
      do j = 1, rec%filled
         worst = max(worst, abs((rec%rows(col_energy, j) - rec%rows(col_energy, 1)) &
            & - (rec%rows(col_work, j) - rec%rows(col_dissipated, j))))
         if (j > 1) step_min = min(step_min, rec%rows(col_dissipated, j) - rec%rows(col_dissipated, j - 1))
      end do
      call note('energy taken by the stops '//real_text(rec%rows(col_dissipated, rec%filled))// &
         & ' J; smallest step '//real_text(step_min)//' J; balance defect '//real_text(worst/scale)//' of max |E|')
      call check(error, rec%rows(col_dissipated, rec%filled) > 0, 'the stops took energy')
      if (allocated(error)) return
      call check(error, step_min >= -1e-13_wp*scale, 'the energy taken by the stops never decreases (smallest step '// &
         & real_text(step_min)//' J)')
      if (allocated(error)) return
      call check(error, worst/scale, 0.0_wp, 'balance defect / max |E|', thr=thr)
   end subroutine check_energy

   !> Every record of two runs equal bit for bit (all columns), and the same impacts.
   subroutine check_same(a, b, sa, sb, what, error)
      type(array_recorder), intent(in) :: a, b
      type(run_summary), intent(in) :: sa, sb
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(inout) :: error
      integer(ik) :: j
      integer :: c
      character(len=*), parameter :: names(n_columns) = [character(len=10) :: 't', 'u', 'v', 'reaction', 'energy', &
         & 'work', 'dissipated', 'damped']
      call check(error, a%filled == b%filled, what//': as many records'); if (allocated(error)) return
      do j = 1, a%filled
         do c = 1, n_columns
            if (a%rows(c, j) /= b%rows(c, j)) then
               call test_failed(error, what//': '//trim(names(c))//' differs at t = '//real_text(a%rows(col_t, j))// &
                  & ': '//real_text(a%rows(c, j))//' against '//real_text(b%rows(c, j)))
               return
            end if
         end do
      end do
      call check(error, sa%impacts == sb%impacts, what//': impacts '//int_text(sa%impacts)//' and '// &
         & int_text(sb%impacts)); if (allocated(error)) return
      call check(error, sa%max_violation == sb%max_violation, what//': max_violation')
   end subroutine check_same

   ! ---------------------------------------------------------------- runs

   !> Two loose supports and the tip stops of a vibrating tube, as input/tube_supports.nml.
   function supports_scene() result(scene)
      type(scene_type) :: scene
      scene = span_scene([10, 20, 30], [-0.002_wp, -0.002_wp, -0.004_wp], [0.002_wp, 0.002_wp, 0.004_wp], &
         & 30, 2e-5_wp, 1.0_wp)
      scene%length = 1.5_wp
      scene%amplitude = 0.002_wp
      scene%omega = 40.0_wp
   end function supports_scene

   subroutine test_kkt(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      integer(ik) :: contacts
      scene = supports_scene()
      call run_span(scene, rec, summary, error)
      if (allocated(error)) return
      call check_kkt(scene, rec, error, contacts)
      if (allocated(error)) return
      call note('impacts '//int_text(summary%impacts)//', stop-steps with a reaction '//int_text(contacts)// &
         & ', max_violation '//real_text(summary%max_violation))
      call check(error, contacts > 100, 'the supports act (got '//int_text(contacts)//' stop-steps)')
      if (allocated(error)) return
      call check(error, summary%max_violation, 0.0_wp, 'max_violation', thr=0.0_wp)
   end subroutine test_kkt

   subroutine test_single_tip(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: tip, span
      type(array_recorder) :: a, b
      type(run_summary) :: sa, sb
      integer :: k
      real(wp), parameter :: betas(2) = [0.25_wp, 0.5_wp]
      do k = 1, 2
         tip%law = law_signorini
         tip%beta = betas(k)
         tip%dt = 5e-5_wp
         tip%t_end = 1.0_wp
         span = tip
         span%stop_nodes = [span%elements]
         span%stop_lower = [span%lower]
         span%stop_upper = [span%upper]
         call run_recorded(tip, a, sa, error)
         if (allocated(error)) return
         call run_span(span, b, sb, error)
         if (allocated(error)) return
         call check(error, sa%impacts > 0, 'the tip reaches the stops'); if (allocated(error)) return
         call check_same(a, b, sa, sb, 'beta = '//real_text(betas(k)), error)
         if (allocated(error)) return
         call check(error, all(b%stops_u(1, :b%filled) == b%rows(col_u, :b%filled)), '/stops/u = /tip/u')
         if (allocated(error)) return
         call check(error, all(b%stops_reaction(1, :b%filled) == b%rows(col_reaction, :b%filled)), &
            & '/stops/reaction = /tip/reaction')
         if (allocated(error)) return
      end do
   end subroutine test_single_tip

   subroutine test_energy(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      scene = supports_scene()
      call run_span(scene, rec, summary, error)
      if (allocated(error)) return
      ! J = 30: the round-off of E grows like J^3 (test_energy.f90); 1e-10 at J = 19 there.
      call check_energy(rec, 1e-9_wp, error)
   end subroutine test_energy

   subroutine test_unreached_free(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: free, span
      type(array_recorder) :: a, b
      type(run_summary) :: sa, sb
      free%law = law_none
      free%beta = 0.25_wp
      free%t_end = 1.0_wp
      span = free
      span%law = law_signorini
      span%stop_nodes = [10]
      span%stop_lower = [-10.0_wp]
      span%stop_upper = [10.0_wp]
      call run_recorded(free, a, sa, error)
      if (allocated(error)) return
      call run_span(span, b, sb, error)
      if (allocated(error)) return
      call check(error, maxval(abs(b%stops_u(1, :b%filled))) > 0.1_wp, 'the mid-span node moves')
      if (allocated(error)) return
      call check_same(a, b, sa, sb, 'free against an unreached stop at node 10', error)
   end subroutine test_unreached_free

   subroutine test_unreached_tip(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: tip, span
      type(array_recorder) :: a, b
      type(run_summary) :: sa, sb
      tip%law = law_signorini
      tip%beta = 0.25_wp
      tip%t_end = 1.0_wp
      span = tip
      span%stop_nodes = [10, tip%elements]
      span%stop_lower = [-10.0_wp, tip%lower]
      span%stop_upper = [10.0_wp, tip%upper]
      call run_recorded(tip, a, sa, error)
      if (allocated(error)) return
      call run_span(span, b, sb, error)
      if (allocated(error)) return
      call check(error, sa%impacts > 0, 'the tip reaches the stops'); if (allocated(error)) return
      call check_same(a, b, sa, sb, 'tip-only against the tip and an unreached stop at node 10', error)
   end subroutine test_unreached_tip

   subroutine test_many_active(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      integer(ik) :: contacts, j, most
      integer :: i
      scene = span_scene([(i, i=1, 19)], [(-1e-3_wp, i=1, 19)], [(1e-3_wp, i=1, 19)], 19, 5e-5_wp, 0.5_wp)
      call run_span(scene, rec, summary, error)
      if (allocated(error)) return
      call check_kkt(scene, rec, error, contacts)
      if (allocated(error)) return
      most = 0
      do j = 1, rec%filled
         most = max(most, int(count(rec%stops_reaction(:, j) /= 0), ik))
      end do
      call note('stop-steps with a reaction '//int_text(contacts)//', most stops acting at once '//int_text(most))
      call check(error, most > 8, 'more than 8 stops act at once (the solve of the correction), got '//int_text(most))
      if (allocated(error)) return
      call check_energy(rec, 1e-10_wp, error)
   end subroutine test_many_active

   !> J = 3, stops at nodes 1 and 2 (fixed in space), the support moving: the scheme written
   !> out with dense matrices (SPEC 4, increment form), its QP solved by trying the 9 splits
   !> of the two stops into free, on the lower and on the upper stop.
   subroutine test_dense(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      real(wp), allocatable :: mm(:, :), ss(:, :), aa(:, :), g(:), bh(:), b1(:), z(:, :), u(:), d(:), v0(:), f(:), e(:)
      real(wp) :: me(4, 4), se(4, 4), h, dt, beta, weight, c(2, 2), hs(2), lam(2), x, du_max, dr_max, u_scale, r_scale
      integer :: n, i, k(2), s
      integer(ik) :: step, contacts
      scene = span_scene([1, 2], [-0.02_wp, -0.05_wp], [0.03_wp, 0.05_wp], 3, 5e-5_wp, 0.5_wp)
      call run_span(scene, rec, summary, error)
      if (allocated(error)) return
      n = 2*scene%elements
      h = scene%length/scene%elements
      dt = scene%dt
      beta = scene%beta
      call exact_element(h, scene%k2, me, se)
      mm = dense_assembly(scene%elements, me)
      ss = dense_assembly(scene%elements, se)
      aa = mm + dt**2*beta*ss
      call simpson_load(scene%elements, scene%length, bh, b1)
      g = scene%amplitude*(scene%omega**2*bh + 8*scene%k2/scene%length**4*b1)
      k = 2*scene%stop_nodes - 1
      hs = lift(scene%stop_nodes*h, scene%length)
      allocate (z(n, 2), e(n), v0(n))
      do s = 1, 2
         e = 0
         e(k(s)) = 1
         z(:, s) = solve_spd(aa, e)
      end do
      c = z(k, :)
      do i = 1, scene%elements
         x = i*h
         v0(2*i - 1) = -scene%amplitude*scene%omega*lift(x, scene%length)
         v0(2*i) = -scene%amplitude*scene%omega*lift_prime(x, scene%length)
      end do
      ! u^0 = 0, u^1 = dt v0 (+ dt^2/2 a0, a0 = M^-1 (G(0) - S u^0) = 0), projected at t_1
      u = dt*v0
      lam = qp(u(k), 1_ik)
      u = u + matmul(z, lam)
      d = u
      lam = 0
      du_max = 0
      dr_max = 0
      contacts = 0
      u_scale = maxval(abs(rec%stops_u(:, :rec%filled)))
      r_scale = max(maxval(abs(rec%stops_reaction(:, :rec%filled))), tiny(1.0_wp))
      do step = 1, steps_of(scene)
         ! the engine's row of step n: u~^n at the stops and the reaction of step n-1 (it put them there)
         du_max = max(du_max, maxval(abs(rec%stops_u(:, step + 1) - (u(k) + hs*phi(scene, step*dt)))))
         dr_max = max(dr_max, maxval(abs(rec%stops_reaction(:, step + 1) - scene%mass_per_length*lam/dt**2)))
         weight = beta*average(step + 1) + (1 - 2*beta)*average(step) + beta*average(step - 1)
         f = dt**2*(weight*g - matmul(ss, u))
         d = d + solve_spd(aa, f)
         lam = qp(u(k) + d(k), step + 1)
         d = d + matmul(z, lam)
         u = u + d
         if (any(lam /= 0)) contacts = contacts + 1
      end do
      call note('steps with contact '//int_text(contacts)//' of '//int_text(steps_of(scene))// &
         & '; max |u~ engine - written out| '//real_text(du_max)//' m, reaction '//real_text(dr_max/r_scale)//' of max')
      call check(error, contacts > 0, 'the written-out scheme reaches the stops'); if (allocated(error)) return
      call check(error, du_max, 0.0_wp, 'max |u~ at the stops, engine - written out| (m)', thr=1e-11_wp*u_scale)
      if (allocated(error)) return
      call check(error, dr_max/r_scale, 0.0_wp, 'max |reaction, engine - written out| / max', thr=1e-6_wp)

   contains

      !> Exact time average of sin(omega t) over step j's interval (centred rule).
      real(wp) function average(j)
         integer(ik), intent(in) :: j
         real(wp) :: a
         a = real(j, wp)*dt - dt/2
         average = (cos(scene%omega*a) - cos(scene%omega*(a + dt)))/(scene%omega*dt)
      end function average

      !> Multipliers of the stops for trial values at t_j: of the 9 splits (free, on lo, on hi),
      !> the one that satisfies the KKT conditions (the least violation).
      function qp(trial, j) result(best)
         real(wp), intent(in) :: trial(2)
         integer(ik), intent(in) :: j
         real(wp) :: best(2), l(2), yy(2), lo(2), hi(2), worst, score
         integer :: split(2), code, t
         lo = scene%stop_lower - hs*phi(scene, j*dt)
         hi = scene%stop_upper - hs*phi(scene, j*dt)
         worst = huge(1.0_wp)
         best = 0
         do code = 0, 8
            split = [mod(code, 3), code/3]
            l = 0
            if (all(split /= 0)) then
               l = solve_spd(c, merge(lo, hi, split == 1) - trial)
            else
               do t = 1, 2
                  if (split(t) /= 0) l(t) = (merge(lo(t), hi(t), split(t) == 1) - trial(t))/c(t, t)
               end do
            end if
            yy = trial + matmul(c, l)
            score = 0
            do t = 1, 2
               score = max(score, lo(t) - yy(t), yy(t) - hi(t))
               if (split(t) == 1) score = max(score, -l(t)*c(t, t))
               if (split(t) == 2) score = max(score, l(t)*c(t, t))
            end do
            if (score < worst) then
               worst = score
               best = l
            end if
         end do
      end function qp
   end subroutine test_dense

   ! ---------------------------------------------------------------- namelist

   !> A file in $TMPDIR (or /tmp) with these lines; its path.
   function write_file(name, lines) result(path)
      character(len=*), intent(in) :: name
      character(len=*), intent(in) :: lines(:)
      character(len=:), allocatable :: path
      character(len=4096) :: base
      character(len=16) :: pid
      integer :: unit, i, length, stat
      call get_environment_variable('TMPDIR', base, length, stat)
      if (stat /= 0 .or. length == 0) base = '/tmp'
      write (pid, '(i0)') getpid()
      path = trim(base)//'/beamstops-stops-'//trim(pid)//'-'//name
      open (newunit=unit, file=path, status='replace', action='write')
      do i = 1, size(lines)
         write (unit, '(a)') trim(lines(i))
      end do
      close (unit)
   end function write_file

   subroutine delete(path)
      character(len=*), intent(in) :: path
      integer :: unit, stat
      open (newunit=unit, file=path, status='old', iostat=stat)
      if (stat == 0) close (unit, status='delete')
   end subroutine delete

   subroutine test_namelist_valid(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      character(len=:), allocatable :: path
      path = write_file('nodes.nml', [character(len=100) :: '&mesh elements = 30 /', &
         & '&stops nodes = 10, 20, 30, lower = -0.002, -0.003, -0.015, upper = 0.002, 0.003, 0.015 /'])
      call read_scene(path, scene, error)
      call delete(path)
      if (allocated(error)) return
      call check(error, stop_count(scene), 3, 'stops'); if (allocated(error)) return
      call check(error, all(scene%stop_nodes == [10, 20, 30]), 'nodes'); if (allocated(error)) return
      call check(error, all(scene%stop_lower == [-0.002_wp, -0.003_wp, -0.015_wp]), 'lower'); if (allocated(error)) return
      call check(error, all(scene%stop_upper == [0.002_wp, 0.003_wp, 0.015_wp]), 'upper'); if (allocated(error)) return
      ! x at nodes (to 1e-9 L), one bound for all
      path = write_file('x.nml', [character(len=100) :: '&beam length = 1.5 /', '&mesh elements = 30 /', &
         & '&stops x = 0.5, 1.0000000001, 1.5, lower = -0.002, upper = 0.004 /'])
      call read_scene(path, scene, error)
      call delete(path)
      if (allocated(error)) return
      call check(error, all(scene%stop_nodes == [10, 20, 30]), 'nodes from x'); if (allocated(error)) return
      call check(error, all(scene%stop_lower == -0.002_wp) .and. all(scene%stop_upper == 0.004_wp), &
         & 'one bound for all'); if (allocated(error)) return
      ! the tip-only form
      path = write_file('tip.nml', [character(len=100) :: '&stops lower = -0.05, upper = 0.07 /'])
      call read_scene(path, scene, error)
      call delete(path)
      if (allocated(error)) return
      call check(error, stop_count(scene), 0, 'no stops along the span'); if (allocated(error)) return
      call check(error, scene%lower, -0.05_wp, 'tip lower'); if (allocated(error)) return
      call check(error, scene%upper, 0.07_wp, 'tip upper')
   end subroutine test_namelist_valid

   subroutine test_namelist_refused(error)
      type(error_type), allocatable, intent(out) :: error
      call refused('off.nml', '&beam length = 1.5 / &mesh elements = 30 / &stops x = 0.5, 0.52 /', &
         & [character(len=40) :: 'x(2) = 0.52', 'nearest nodes are 10 (x = 0.5)', '11 (x = 0.55)'], error)
      if (allocated(error)) return
      call refused('both.nml', '&stops nodes = 3, x = 0.5 /', ['nodes', 'x    '], error)
      if (allocated(error)) return
      call refused('count.nml', '&stops nodes = 3, 5, lower = -0.1, -0.1, -0.1 /', ['lower', '3    ', '2    '], error)
      if (allocated(error)) return
      call refused('tiplist.nml', '&stops lower = -0.1, -0.2 /', ['lower', 'nodes'], error)
      if (allocated(error)) return
      call refused('twice.nml', '&stops nodes = 3, 5, 3 /', ['nodes(3) = 3', 'twice       '], error)
      if (allocated(error)) return
      call refused('range.nml', '&stops nodes = 0, 5 /', ['nodes(1) = 0', 'clamped     '], error)
      if (allocated(error)) return
      call refused('gap.nml', '&stops nodes = 3, 5, lower = -0.1, 0.1 /', ['lower(2) = 0.1'], error)
      if (allocated(error)) return
      call refused('law.nml', '&stops nodes = 3, law = ''compliance'', stiffness = 1e7 /', ['compliance', 'nodes     '], &
         & error)

   contains

      subroutine refused(name, text, needles, error)
         character(len=*), intent(in) :: name, text
         character(len=*), intent(in) :: needles(:)
         type(error_type), allocatable, intent(out) :: error
         type(scene_type) :: scene
         type(error_type), allocatable :: read_error
         character(len=:), allocatable :: path
         character(len=200) :: lines(1)
         integer :: i
         lines(1) = text
         path = write_file(name, lines)
         call read_scene(path, scene, read_error)
         call delete(path)
         if (.not. allocated(read_error)) then
            call test_failed(error, 'read_scene accepted '//text)
            return
         end if
         call note(read_error%message)
         do i = 1, size(needles)
            call check(error, index(read_error%message, trim(needles(i))) > 0, 'the message names '''// &
               & trim(needles(i))//''': '//read_error%message)
            if (allocated(error)) return
         end do
      end subroutine refused
   end subroutine test_namelist_refused
end module test_stops
