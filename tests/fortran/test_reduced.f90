!> Reduced (modal) models (SPEC 11, beamstops_reduced and beamstops_reduced_scheme) against
!> mathematics: with all r = n - m fixed-interface modes the basis T is square and the reduced
!> scheme is the full one in another basis (the full engine's records to round-off, through the
!> impacts of the first contact period, tip-only and with stops along the span); Rayleigh-Ritz
!> (the reduced frequencies bound the full ones from above and decrease as r grows); the
!> constraint modes make the static response to a load at the stops exact for any r; the
!> projection's KKT conditions at every step in reduced coordinates; the energy balance closed
!> to round-off without contact; and the checks of &mesh modes.
module test_reduced
   use testing
   use test_support, only: run_recorded, band_eigenvalues, dense_eigenvalues, solve_spd, int_text, tube, balance_defect
   use beamstops, only: ik, scene_type, array_recorder, run_summary, law_none, law_signorini, law_compliance, &
      & validate_scene, record_count, stop_count, status_complete, model_type, build_model, prepare_run, simulate, &
      & run_limit_type, run_limit
   use beamstops_band, only: cholesky_factor, cholesky_solve, band_to_dense
   use beamstops_forcing, only: load_average
   use beamstops_reduced, only: reduced_model_type, prepare_reduced, build_reduced, validate_reduced, &
      & reduced_matrices, expand, stop_unknowns
   use beamstops_reduced_scheme, only: reduced_state_type, simulate_reduced, start_reduced, advance_reduced
   use beamstops_recorder, only: col_t, col_u, col_v, col_reaction, col_energy, col_work, col_dissipated, col_damped, &
      & n_columns
   implicit none
   private
   public :: collect_reduced
   ! (for the suite reduced_physics)
   public :: run_reduced_recorded, compare_full, free_reduced, tip_step_residual

contains

   !> Tests of the suite.
   subroutine collect_reduced(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('all modes, tip stops, beta = 1/2: the full engine to round-off up to 0.2 s', test_full_tip), &
         & new_unittest('all modes, compliance, beta = 1/4: the full engine to round-off before the first contact', test_full_compliance), &
         & new_unittest('all modes, tube supports (three stops): the full engine to round-off', test_full_span), &
         & new_unittest('all modes, two supports, the tip free (a modal coordinate): the full engine', test_full_supports), &
         & new_unittest('all modes, no stops, beta = 0.3, paper''s load, Euler start: the full engine', test_full_free), &
         & new_unittest('frequencies of (S_r, M_r) decrease to the full ones as r grows', test_frequencies), &
         & new_unittest('static response to loads at the stops exact for any r', test_static), &
         & new_unittest('reduced basis: T^T M T and T^T S T are the stored blocks', test_blocks), &
         & new_unittest('KKT of the tip projection at every step, in reduced coordinates', test_kkt_steps), &
         & new_unittest('three stops, r = 8: KKT in the records, balance closed', test_span_kkt), &
         & new_unittest('no contact: the energy balance closes to round-off', test_energy_free), &
         & new_unittest('modes by inverse iteration (the default) and by dsbgvx: the same reduced runs', test_inverse_iteration), &
         & new_unittest('snapshots: u = T q at the nodes, the full run''s with all modes', test_snapshots), &
         & new_unittest('&mesh modes: range checks with messages', test_validate), &
         & new_unittest('prepare_run: beta < 1/4 against the limit of the reduced model the run steps', test_run_limit), &
         & new_unittest('one element, its one interior unknown as the mode: the full engine', test_one_element) &
         & ]
   end subroutine collect_reduced

   ! ---------------------------------------------------------------- helpers

   !> The paper's beam without stops (law none), dt = 1e-4, 1 s, with beta and r modes.
   function free_reduced(beta, modes) result(scene)
      real(wp), intent(in) :: beta
      integer, intent(in) :: modes
      type(scene_type) :: scene
      scene%law = law_none
      scene%beta = beta
      scene%dt = 1e-4_wp
      scene%t_end = 1.0_wp
      scene%modes = modes
   end function free_reduced

   !> Validate, prepare and run a reduced scene (scene%modes > 0), every record kept.
   subroutine run_reduced_recorded(scene, rec, summary, error)
      type(scene_type), intent(in) :: scene
      type(array_recorder), intent(out) :: rec
      type(run_summary), intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(reduced_model_type) :: reduced
      call validate_scene(scene, 'test scene', error)
      if (allocated(error)) return
      call validate_reduced(scene, 2*scene%elements, stop_unknowns(scene), 'test scene', error)
      if (allocated(error)) return
      call prepare_reduced(scene, 'test scene', reduced, error)
      if (allocated(error)) return
      call rec%reserve(record_count(scene), 0_ik, scene%elements + 1, stop_count(scene))
      call simulate_reduced(scene, reduced, rec, summary, error)
      if (allocated(error)) return
      if (summary%status /= status_complete) then
         call test_failed(error, 'the reduced run ended with status '//summary%status)
         return
      end if
      if (rec%filled /= record_count(scene)) call test_failed(error, 'the reduced run recorded '//int_text(rec%filled)// &
         & ' rows, record_count gives '//int_text(record_count(scene)))
   end subroutine run_reduced_recorded

   !> Largest difference of a column of two records over rows 1..last, relative to the column's
   !> largest value over the whole run.
   function column_difference(a, b, c, last) result(diff)
      type(array_recorder), intent(in) :: a, b
      integer, intent(in) :: c
      integer(ik), intent(in) :: last
      real(wp) :: diff
      diff = maxval(abs(a%rows(c, :last) - b%rows(c, :last)))/max(maxval(abs(a%rows(c, :a%filled))), tiny(1.0_wp))
   end function column_difference

   !> The full and the all-modes reduced run of a scene. Up to t_clean (before the first impact),
   !> every column within thr_clean of the full run's (relative to the column's scale): the
   !> round-off of a change of basis. Over the whole run (thr_all > 0), every column within thr_all
   !> and the same impacts: impacts amplify round-off (the full engine's own two solvers, LAPACK's
   !> and the fused one, differ by 1e-14 of the tip's scale before the first impact of the paper's
   !> scene and by 2e-9 at t = 0.2 s; with the compliance spring 1e8, by 1e-2: there only the part
   !> before the first contact is compared).
   subroutine compare_full(scene, t_clean, thr_clean, thr_all, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: t_clean, thr_clean, thr_all
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: reduced_scene
      type(array_recorder) :: full, red
      type(run_summary) :: sf, sr
      character(len=*), parameter :: names(n_columns) = [character(len=10) :: 't', 'u', 'v', 'reaction', 'energy', &
         & 'work', 'dissipated', 'damped']
      real(wp) :: diff, clean
      integer(ik) :: last
      integer :: c
      reduced_scene = scene
      reduced_scene%modes = 2*scene%elements - stop_unknowns(scene)
      call run_recorded(scene, full, sf, error)
      if (allocated(error)) return
      call run_reduced_recorded(reduced_scene, red, sr, error)
      if (allocated(error)) return
      call check(error, red%filled == full%filled, 'as many records'); if (allocated(error)) return
      call divergence_report(full, red)
      last = count(full%rows(col_t, :full%filled) <= t_clean, kind=ik)
      do c = 1, n_columns
         clean = column_difference(full, red, c, last)
         diff = column_difference(full, red, c, full%filled)
         call note(trim(names(c))//': largest difference / scale up to t = '//real_text(t_clean)//' s '// &
            & real_text(clean)//', up to t_end '//real_text(diff))
         call check(error, clean, 0.0_wp, trim(names(c))//' of the full and the reduced run up to t = '// &
            & real_text(t_clean), thr=thr_clean)
         if (allocated(error)) return
         ! Velocities, reactions and the stops' energy jump at impacts: compared before them only.
         if (thr_all > 0 .and. any(c == [col_u, col_energy, col_work, col_damped])) call check(error, diff, 0.0_wp, &
            & trim(names(c))//' of the full and the reduced run', thr=thr_all)
         if (allocated(error)) return
      end do
      if (stop_count(scene) > 0) then
         diff = maxval(abs(full%stops_u(:, :full%filled) - red%stops_u(:, :red%filled)))/ &
            & maxval(abs(full%stops_u(:, :full%filled)))
         call note('stops u: largest difference / scale '//real_text(diff))
         if (thr_all > 0) call check(error, diff, 0.0_wp, 'values at the stops', thr=thr_all)
         if (allocated(error)) return
      end if
      call note('impacts: full '//int_text(sf%impacts)//', reduced '//int_text(sr%impacts)// &
         & '; max_violation: full '//real_text(sf%max_violation)//', reduced '//real_text(sr%max_violation))
      if (scene%law /= law_none) call check(error, sf%impacts > 0, 'the scene has impacts')
      if (allocated(error)) return
      if (thr_all > 0) call check(error, int(sr%impacts), int(sf%impacts), 'impacts of the reduced run')
   end subroutine compare_full

   !> Diagnostic: the difference of the tip series as time goes.
   subroutine divergence_report(a, b)
      type(array_recorder), intent(in) :: a, b
      integer(ik) :: j, every
      real(wp) :: scale, worst
      character(len=:), allocatable :: line
      scale = maxval(abs(a%rows(col_u, :a%filled)))
      every = max(1_ik, a%filled/20)
      worst = 0
      line = ''
      do j = 1, a%filled
         worst = max(worst, abs(a%rows(col_u, j) - b%rows(col_u, j))/scale)
         if (mod(j, every) == 0) line = line//' t='//trim(real_text(a%rows(col_t, j)))//':'//trim(real_text(worst))
      end do
      call note('largest tip difference / scale up to t:'//line)
   end subroutine divergence_report

   ! ---------------------------------------------------------------- tests

   subroutine test_full_tip(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene%law = law_signorini
      scene%beta = 0.5_wp
      scene%dt = 1e-5_wp
      scene%t_end = 0.2_wp
      call compare_full(scene, 0.085_wp, 1e-10_wp, 1e-6_wp, error)
   end subroutine test_full_tip

   subroutine test_full_compliance(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene%law = law_compliance
      scene%stiffness_per_mass = 1e8_wp
      scene%beta = 0.25_wp
      scene%dt = 5e-6_wp
      scene%t_end = 0.2_wp
      call compare_full(scene, 0.085_wp, 1e-10_wp, 0.0_wp, error)
   end subroutine test_full_compliance

   !> The tube's two supports alone: the tip is not a stop coordinate, its records come from the
   !> row of T at the tip.
   subroutine test_full_supports(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = tube(0.2_wp)
      scene%stop_nodes = [10, 20]
      scene%stop_lower = [-0.002_wp, -0.002_wp]
      scene%stop_upper = [0.002_wp, 0.002_wp]
      call compare_full(scene, 0.02_wp, 1e-10_wp, 1e-6_wp, error)
   end subroutine test_full_supports

   subroutine test_full_free(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene%law = law_none
      scene%beta = 0.3_wp
      scene%centered_load = .false.
      scene%taylor_start = .false.
      scene%dt = 1e-5_wp
      scene%t_end = 0.5_wp
      call compare_full(scene, 0.5_wp, 1e-10_wp, 0.0_wp, error)
   end subroutine test_full_free

   subroutine test_full_span(error)
      type(error_type), allocatable, intent(out) :: error
      call compare_full(tube(0.2_wp), 0.05_wp, 1e-10_wp, 1e-6_wp, error)
   end subroutine test_full_span

   !> Rayleigh-Ritz: the k-th eigenvalue of (S_r, M_r) is at least the full one, does not grow
   !> with r (nested spaces) and equals it for r = n - m; tip-only and with three stops. A
   !> generalized eigenvalue solver is accurate to eps times the largest eigenvalue in absolute
   !> terms: the lowest five are computed from the inverted pencils (M, S) and (M_r, S_r) (S is
   !> positive definite), accurate relative to themselves, and checked to 1e-10 (the structured
   !> blocks of the reduced model may move them by eps lambda_max/lambda_1 = 8e-9 at most, 1e-11
   !> measured); all of them from
   !> (S, M) and (S_r, M_r), to 64 n eps lambda_max.
   subroutine test_frequencies(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scenes(2)
      type(model_type) :: model
      type(reduced_model_type) :: reduced
      real(wp), allocatable :: full(:), full_low(:), w(:), low(:), previous(:), mr(:, :), sr(:, :)
      integer :: s, r, k, nm, nlow
      real(wp) :: tol
      real(wp), parameter :: rel = 1e-10_wp
      character(len=:), allocatable :: line
      scenes(1)%dt = 1e-5_wp
      scenes(2) = tube(0.1_wp)
      do s = 1, 2
         call build_model(scenes(s), model, error)
         if (allocated(error)) return
         call band_eigenvalues(model%stiffness, model%mass, full, error)
         if (allocated(error)) return
         call band_eigenvalues(model%mass, model%stiffness, full_low, error)
         if (allocated(error)) return
         full_low = 1/full_low(size(full_low):1:-1)
         nm = model%n - stop_unknowns(scenes(s))
         tol = 64*model%n*epsilon(1.0_wp)*full(model%n)
         line = ''
         do r = 1, nm
            scenes(s)%modes = r
            call build_reduced(scenes(s), model, reduced, error)
            if (allocated(error)) return
            call reduced_matrices(reduced, mr, sr)
            call dense_eigenvalues(sr, mr, w, error)
            if (allocated(error)) return
            call dense_eigenvalues(mr, sr, low, error)
            if (allocated(error)) return
            low = 1/low(size(low):1:-1)
            nlow = min(5, size(low))
            do k = 1, r + reduced%m
               call check(error, w(k) >= full(k) - tol, 'r = '//int_text(r)//': eigenvalue '//int_text(k)// &
                  & ' of the reduced model '//real_text(w(k))//' >= the full '//real_text(full(k)))
               if (allocated(error)) return
               if (k <= nlow) call check(error, low(k) >= full_low(k)*(1 - rel), 'r = '//int_text(r)//': eigenvalue '// &
                  & int_text(k)//' of the reduced model '//real_text(low(k))//' >= the full '//real_text(full_low(k)))
               if (allocated(error)) return
               if (r > 1 .and. k <= r - 1 + reduced%m) then
                  call check(error, w(k) <= previous(k) + tol, 'r = '//int_text(r)//': eigenvalue '// &
                     & int_text(k)//' '//real_text(w(k))//' <= its value with r - 1, '//real_text(previous(k)))
                  if (allocated(error)) return
               end if
            end do
            if (r <= 4 .or. r == nm) line = line//' r='//int_text(r)//': '//real_text(sqrt(low(1)))//' '// &
               & real_text(sqrt(low(2)))
            previous = w
         end do
         call note('scene '//int_text(s)//', omega_1, omega_2 (rad/s) as r grows:'//line)
         do k = 1, model%n
            call check(error, w(k), full(k), 'all modes: eigenvalue '//int_text(k), thr=tol)
            if (allocated(error)) return
         end do
         do k = 1, 5
            call check(error, low(k), full_low(k), 'all modes: eigenvalue '//int_text(k), thr=rel, rel=.true.)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_frequencies

   !> S u = f with f at the stop unknowns: u = S^{-1} f (band Cholesky) against T S_r^{-1} T^T f for
   !> r = 1, 2, 5, 20 (the constraint modes span S^{-1} P exactly).
   subroutine test_static(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scenes(2)
      type(model_type) :: model
      type(reduced_model_type) :: reduced
      real(wp), allocatable :: sfac(:, :), f(:), u(:), ur(:), q(:), mr(:, :), sr(:, :)
      integer, parameter :: rs(4) = [1, 2, 5, 20]
      integer :: s, i, j
      real(wp) :: diff, worst
      worst = 0
      scenes(1)%dt = 1e-5_wp
      scenes(2) = tube(0.1_wp)
      do s = 1, 2
         call build_model(scenes(s), model, error)
         if (allocated(error)) return
         sfac = model%stiffness
         call cholesky_factor(sfac, 'S', error)
         if (allocated(error)) return
         allocate (f(model%n), ur(model%n))
         do i = 1, size(rs)
            scenes(s)%modes = rs(i)
            call build_reduced(scenes(s), model, reduced, error)
            if (allocated(error)) return
            call reduced_matrices(reduced, mr, sr)
            do j = 1, reduced%m
               f = 0
               f(reduced%b(j)) = 1
               u = f
               call cholesky_solve(sfac, u)
               q = solve_spd(sr, matmul(f, reduced%basis))
               call expand(reduced, q, ur)
               diff = maxval(abs(ur - u))/maxval(abs(u))
               call check(error, diff, 0.0_wp, 'scene '//int_text(s)//', r = '//int_text(rs(i))//', load at stop '// &
                  & int_text(j)//': |T S_r^-1 T^T f - S^-1 f| / |S^-1 f|', thr=1e-9_wp)
               worst = max(worst, diff)
               if (allocated(error)) return
            end do
         end do
         deallocate (f, ur)
      end do
      call note('largest relative difference of the static responses '//real_text(worst))
   end subroutine test_static

   !> The stored blocks are the T^T M T, T^T S T of the stored T (dense products), the rows b of T
   !> unit rows, and l_r = T^T l.
   subroutine test_blocks(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(reduced_model_type) :: reduced
      real(wp), allocatable :: mm(:, :), ss(:, :), mr(:, :), sr(:, :), tmt(:, :), tst(:, :)
      integer :: j
      scene = tube(0.1_wp)
      scene%modes = 12
      call build_model(scene, model, error)
      if (allocated(error)) return
      call build_reduced(scene, model, reduced, error)
      if (allocated(error)) return
      mm = band_to_dense(model%mass)
      ss = band_to_dense(model%stiffness)
      call reduced_matrices(reduced, mr, sr)
      tmt = matmul(transpose(reduced%basis), matmul(mm, reduced%basis))
      tst = matmul(transpose(reduced%basis), matmul(ss, reduced%basis))
      call check(error, maxval(abs(tmt - mr))/maxval(abs(mr)), 0.0_wp, 'T^T M T - M_r', thr=1e-12_wp)
      if (allocated(error)) return
      call check(error, maxval(abs(tst - sr))/maxval(abs(sr)), 0.0_wp, 'T^T S T - S_r', thr=1e-12_wp)
      if (allocated(error)) return
      do j = 1, reduced%m
         call check(error, all(reduced%basis(reduced%b(j), :reduced%r) == 0) .and. &
            & reduced%basis(reduced%b(j), reduced%r + j) == 1 .and. &
            & count(reduced%basis(reduced%b(j), reduced%r + 1:) /= 0) == 1, 'row b('//int_text(j)//') of T is a unit row')
         if (allocated(error)) return
      end do
      call check(error, maxval(abs(matmul(model%load, reduced%basis) - reduced%load))/maxval(abs(reduced%load)), &
         & 0.0_wp, 'l_r - T^T l', thr=1e-14_wp)
   end subroutine test_blocks

   !> Step by step (r = 6, paper's scene, beta = 1/2, t <= 0.15 s): the residual
   !> rho = A_r (d^n - d^{n-1}) - dt^2 (G^n l_r - S_r q^n) vanishes in every row but the tip's, where
   !> rho/dt^2 is the reaction: zero between the stops, >= 0 on the lower one, <= 0 on the upper
   !> one; the tip value within the stops.
   subroutine test_kkt_steps(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(reduced_model_type) :: reduced
      type(reduced_state_type) :: state
      type(array_recorder) :: rec
      real(wp), allocatable :: mr(:, :), sr(:, :), ar(:, :), q_old(:), d_old(:), rho(:)
      real(wp) :: scale, worst_rows, tip, reaction, tol_u
      integer(ik) :: step, done, steps, contacts
      integer :: pt, r
      scene%law = law_signorini
      scene%beta = 0.5_wp
      scene%dt = 1e-5_wp
      scene%t_end = 0.15_wp
      scene%modes = 6
      call prepare_reduced(scene, 'test scene', reduced, error)
      if (allocated(error)) return
      call reduced_matrices(reduced, mr, sr)
      ar = mr + scene%dt**2*scene%beta*sr
      r = reduced%r
      pt = r + reduced%tip_stop
      steps = nint(scene%t_end/scene%dt, ik)
      call rec%reserve(steps + 1, 0_ik, scene%elements + 1)
      call start_reduced(scene, reduced, state, rec, error)
      if (allocated(error)) return
      worst_rows = 0
      contacts = 0
      tol_u = 4*epsilon(1.0_wp)*scene%upper
      do step = 1, steps
         q_old = state%q
         d_old = state%d
         call advance_reduced(scene, reduced, state, rec, step, done)
         call tip_step_residual(scene, reduced, ar, sr, step, q_old, d_old, state, rho, scale)
         worst_rows = max(worst_rows, maxval(abs(rho(:pt - 1)))/scale)
         tip = state%q(pt)
         reaction = rho(pt)/scene%dt**2
         call check(error, tip >= scene%lower - tol_u .and. tip <= scene%upper + tol_u, 'step '//int_text(step)// &
            & ': tip '//real_text(tip)//' within the stops')
         if (allocated(error)) return
         if (abs(rho(pt)) > 1e-12_wp*scale) then
            contacts = contacts + 1
            call check(error, (reaction > 0 .and. abs(tip - scene%lower) <= tol_u) .or. &
               & (reaction < 0 .and. abs(tip - scene%upper) <= tol_u), 'step '//int_text(step)//': reaction '// &
               & real_text(reaction)//' only on a stop, pushing away from it (tip '//real_text(tip)//')')
            if (allocated(error)) return
         end if
      end do
      call note('contact steps '//int_text(contacts)//', largest residual off the tip row / scale '// &
         & real_text(worst_rows))
      call check(error, contacts > 10, 'the tip meets the stops'); if (allocated(error)) return
      call check(error, worst_rows, 0.0_wp, 'residual of the rows off the tip', thr=1e-14_wp)
   end subroutine test_kkt_steps

   !> The residual rho = A_r (d^n - d^{n-1}) - dt^2 (G^n l_r - S_r q^n) of the step `step` of a
   !> reduced run with stops at the tip (from q_old, d_old to the state's q, d), and the size of the
   !> terms whose round-off it carries (q: the tip set exactly onto a stop changes d there by the
   !> round-off of q).
   subroutine tip_step_residual(scene, reduced, ar, sr, step, q_old, d_old, state, rho, scale)
      type(scene_type), intent(in) :: scene
      type(reduced_model_type), intent(in) :: reduced
      !> A_r = M_r + dt^2 beta S_r, and S_r.
      real(wp), intent(in) :: ar(:, :), sr(:, :)
      integer(ik), intent(in) :: step
      !> q^n and d^{n-1} before the step.
      real(wp), intent(in) :: q_old(:), d_old(:)
      !> The state after the step.
      type(reduced_state_type), intent(in) :: state
      real(wp), allocatable, intent(out) :: rho(:)
      real(wp), intent(out) :: scale
      real(wp) :: weight
      weight = scene%beta*load_average(step + 1, scene%dt, scene%omega, .true.) &
         & + (1 - 2*scene%beta)*load_average(step, scene%dt, scene%omega, .true.) &
         & + scene%beta*load_average(step - 1, scene%dt, scene%omega, .true.)
      rho = matmul(ar, state%d - d_old) - scene%dt**2*(weight*reduced%load - matmul(sr, q_old))
      scale = maxval(matmul(abs(ar), abs(state%d) + abs(d_old) + abs(state%q)) + scene%dt**2*(matmul(abs(sr), abs(q_old)) &
         & + abs(weight*reduced%load)))
   end subroutine tip_step_residual

   !> The tube with r = 8: in the records, each stop within its bounds and a reaction only on a
   !> bound; the energy the stops take grows, the balance E - E0 = W - D closes.
   subroutine test_span_kkt(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      integer(ik) :: j, contacts
      integer :: i
      real(wp) :: u, react, tol, worst, escale
      scene = tube(0.3_wp)
      scene%modes = 8
      call run_reduced_recorded(scene, rec, summary, error)
      if (allocated(error)) return
      tol = 4*epsilon(1.0_wp)*(abs(scene%amplitude) + 0.004_wp)
      contacts = 0
      do j = 1, rec%filled
         do i = 1, 3
            u = rec%stops_u(i, j)
            react = rec%stops_reaction(i, j)
            call check(error, u >= scene%stop_lower(i) - tol .and. u <= scene%stop_upper(i) + tol, 'stop '// &
               & int_text(i)//' at t = '//real_text(rec%rows(col_t, j))//': '//real_text(u)//' within its bounds')
            if (allocated(error)) return
            if (react /= 0) then
               contacts = contacts + 1
               call check(error, (react > 0 .and. abs(u - scene%stop_lower(i)) <= tol) .or. &
                  & (react < 0 .and. abs(u - scene%stop_upper(i)) <= tol), 'stop '//int_text(i)//' at t = '// &
                  & real_text(rec%rows(col_t, j))//': reaction '//real_text(react)//' on the bound it pushes from')
               if (allocated(error)) return
            end if
         end do
      end do
      escale = maxval(abs(rec%rows(col_energy, :rec%filled)))
      worst = balance_defect(rec)
      call note('stop-steps with a reaction '//int_text(contacts)//', impacts '//int_text(summary%impacts)// &
         & ', energy taken '//real_text(rec%rows(col_dissipated, rec%filled))//' J, balance defect / max |E| '// &
         & real_text(worst))
      call check(error, contacts > 50, 'the stops act'); if (allocated(error)) return
      call check(error, summary%max_violation, 0.0_wp, 'max_violation', thr=0.0_wp); if (allocated(error)) return
      call check(error, rec%rows(col_dissipated, rec%filled) > 0, 'the stops took energy'); if (allocated(error)) return
      call check(error, worst, 0.0_wp, 'balance defect', thr=1e-10_wp)
   end subroutine test_span_kkt

   !> Law none, r = 5 and r = 30, beta = 1/4 and 1/2, 1 s: max |(E_n - E_0) - W_n| / max |E|.
   subroutine test_energy_free(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      real(wp), parameter :: betas(2) = [0.25_wp, 0.5_wp]
      integer, parameter :: rs(2) = [5, 30]
      integer :: i, k
      real(wp) :: worst, escale
      do k = 1, 2
         do i = 1, 2
            scene = free_reduced(betas(k), rs(i))
            call run_reduced_recorded(scene, rec, summary, error)
            if (allocated(error)) return
            escale = maxval(abs(rec%rows(col_energy, :rec%filled)))
            worst = balance_defect(rec)
            call note('beta = '//real_text(betas(k))//', r = '//int_text(rs(i))//': balance defect / max |E| '// &
               & real_text(worst))
            call check(error, rec%rows(col_dissipated, rec%filled), 0.0_wp, 'no energy taken', thr=0.0_wp)
            if (allocated(error)) return
            call check(error, worst, 0.0_wp, 'balance defect', thr=1e-12_wp)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_energy_free

   !> The tube (three stops) and the paper's beam, r = 20: the modes by inverse iteration against dsbgvx's: the same
   !> frequencies, M-orthonormal, small residuals, and the same reduced run over 0.1 s.
   subroutine test_inverse_iteration(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scenes(2)
      type(model_type) :: model
      type(reduced_model_type) :: a, b
      type(array_recorder) :: ra, rb
      type(run_summary) :: summary
      real(wp), allocatable :: mm(:, :), ss(:, :), phi(:, :), gram(:, :), res(:, :)
      real(wp) :: worst_lambda, worst_gram, worst_res, diff
      integer :: s, k, r
      scenes(1) = tube(0.1_wp)
      scenes(2)%dt = 1e-5_wp
      scenes(2)%t_end = 0.1_wp
      do s = 1, 2
         scenes(s)%modes = 20
         call build_model(scenes(s), model, error)
         if (allocated(error)) return
         call build_reduced(scenes(s), model, a, error, inverse_iteration=.false.)
         if (allocated(error)) return
         call build_reduced(scenes(s), model, b, error, inverse_iteration=.true.)
         if (allocated(error)) return
         r = b%r
         worst_lambda = maxval(abs(a%lambda - b%lambda)/a%lambda)
         mm = band_to_dense(model%mass)
         ss = band_to_dense(model%stiffness)
         phi = b%basis(:, :r)
         gram = matmul(transpose(phi), matmul(mm, phi))
         do k = 1, r
            gram(k, k) = gram(k, k) - 1
         end do
         worst_gram = maxval(abs(gram))
         ! (S Phi - M Phi Lambda) vanishes off the stop rows b (where the held stops react).
         res = matmul(ss, phi) - matmul(mm, phi)*spread(b%lambda, 1, model%n)
         res(b%b, :) = 0
         worst_res = 0
         do k = 1, r
            worst_res = max(worst_res, maxval(abs(res(:, k)))/(b%lambda(k)*maxval(abs(matmul(mm, phi(:, k))))))
         end do
         call note('scene '//int_text(s)//': frequencies '//real_text(worst_lambda)//', |Phi^T M Phi - I| '// &
            & real_text(worst_gram)//', residual '//real_text(worst_res)//'; smallest relative gap of two frequencies '// &
            & real_text(minval(b%lambda(2:)/b%lambda(:r - 1) - 1)))
         call check(error, worst_lambda, 0.0_wp, 'frequencies', thr=1e-12_wp); if (allocated(error)) return
         call check(error, worst_gram, 0.0_wp, 'M-orthonormal', thr=1e-12_wp); if (allocated(error)) return
         call check(error, worst_res, 0.0_wp, 'residual of the modes', thr=1e-9_wp); if (allocated(error)) return
         call ra%reserve(record_count(scenes(s)), 0_ik, scenes(s)%elements + 1, stop_count(scenes(s)))
         call rb%reserve(record_count(scenes(s)), 0_ik, scenes(s)%elements + 1, stop_count(scenes(s)))
         call simulate_reduced(scenes(s), a, ra, summary, error)
         if (allocated(error)) return
         call simulate_reduced(scenes(s), b, rb, summary, error)
         if (allocated(error)) return
         diff = column_difference(ra, rb, col_u, ra%filled)
         call note('scene '//int_text(s)//': tip of the two reduced runs, largest difference / scale '//real_text(diff))
         call check(error, diff, 0.0_wp, 'tip of the two reduced runs', thr=1e-9_wp); if (allocated(error)) return
         deallocate (ra%rows, ra%snap_t, ra%snap_u, ra%stops_u, ra%stops_reaction)
         deallocate (rb%rows, rb%snap_t, rb%snap_u, rb%stops_u, rb%stops_reaction)
      end do
      ! J = 300: the S-coupling of the modes, which the reduced model takes as zero.
      scenes(2)%elements = 300
      scenes(2)%modes = 10
      call build_model(scenes(2), model, error)
      if (allocated(error)) return
      call build_reduced(scenes(2), model, a, error, inverse_iteration=.false.)
      if (allocated(error)) return
      call build_reduced(scenes(2), model, b, error)
      if (allocated(error)) return
      call note('J = 300: largest |phi_i^T S phi_j|/sqrt(lambda_i lambda_j), i /= j: dsbgvx '// &
         & real_text(coupling(a, model))//', inverse iteration '//real_text(coupling(b, model)))
      call check(error, coupling(b, model), 0.0_wp, 'S-coupling of the modes by inverse iteration', thr=1e-7_wp)
      if (allocated(error)) return
      call check(error, coupling(b, model) < coupling(a, model), 'inverse iteration couples less than dsbgvx')
   contains
      function coupling(red, model) result(worst)
         type(reduced_model_type), intent(in) :: red
         type(model_type), intent(in) :: model
         real(wp) :: worst
         real(wp), allocatable :: ss(:, :), g(:, :)
         integer :: i, j
         ss = band_to_dense(model%stiffness)
         g = matmul(transpose(red%basis(:, :red%r)), matmul(ss, red%basis(:, :red%r)))
         worst = 0
         do j = 1, red%r
            do i = 1, red%r
               if (i /= j) worst = max(worst, abs(g(i, j))/sqrt(red%lambda(i)*red%lambda(j)))
            end do
         end do
      end function coupling
   end subroutine test_inverse_iteration

   !> Snapshots every 500 steps (the tube with its three stops, t <= 0.1 s): the reduced run's
   !> physical shape at the nodes against the full run's, all modes; with r = 10, the stops'
   !> nodes of the snapshots are the recorded values at the stops.
   subroutine test_snapshots(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(reduced_model_type) :: reduced
      type(array_recorder) :: full, red
      type(run_summary) :: summary
      integer(ik) :: j, k
      integer :: i, pass
      real(wp) :: diff
      scene = tube(0.1_wp)
      scene%snapshot_every = 500
      call validate_scene(scene, 'test scene', error)
      if (allocated(error)) return
      call full%reserve(record_count(scene), 11_ik, scene%elements + 1, 3)
      call prepare_run_full(scene, model, full, summary, error)
      if (allocated(error)) return
      do pass = 1, 2
         scene%modes = merge(2*scene%elements - 3, 10, pass == 1)
         call build_reduced(scene, model, reduced, error)
         if (allocated(error)) return
         if (allocated(red%rows)) deallocate (red%rows, red%snap_t, red%snap_u, red%stops_u, red%stops_reaction)
         call red%reserve(record_count(scene), 11_ik, scene%elements + 1, 3)
         call simulate_reduced(scene, reduced, red, summary, error)
         if (allocated(error)) return
         call check(error, int(red%snaps), 11, 'snapshots taken'); if (allocated(error)) return
         call check(error, all(red%snap_t(:11) == full%snap_t(:11)), 'snapshot times'); if (allocated(error)) return
         if (pass == 1) then
            diff = maxval(abs(red%snap_u(:, :11) - full%snap_u(:, :11)))/maxval(abs(full%snap_u(:, :11)))
            call note('all modes: largest snapshot difference / scale '//real_text(diff))
            call check(error, diff, 0.0_wp, 'snapshots of the full and the reduced run', thr=1e-9_wp)
            if (allocated(error)) return
         else
            do k = 1, 11
               j = nint(red%snap_t(k)/scene%dt, ik)/scene%record_every + 1
               do i = 1, 3
                  call check(error, red%snap_u(scene%stop_nodes(i) + 1, k), red%stops_u(i, j), 'r = 10: snapshot '// &
                     & int_text(k)//' at stop '//int_text(i), thr=1e-15_wp)
                  if (allocated(error)) return
               end do
            end do
         end if
      end do
   end subroutine test_snapshots

   !> The full model of a scene and its run into `rec` (reserved by the caller).
   subroutine prepare_run_full(scene, model, rec, summary, error)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(out) :: model
      type(array_recorder), intent(inout) :: rec
      type(run_summary), intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      call prepare_run(scene, 'test scene', model, error)
      if (allocated(error)) return
      call simulate(scene, model, rec, summary, error)
   end subroutine prepare_run_full

   subroutine test_validate(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      character(len=*), parameter :: expected = 'in.nml: &mesh modes = 50 is out of range; allowed: 0 <= modes '// &
         & '<= n - m = 37 (2*elements minus the stop unknowns; 0: the full model)'
      call validate_reduced(scene, 38, 1, 'in.nml', error)
      call check(error, .not. allocated(error), 'modes = 0 accepted'); if (allocated(error)) return
      scene%modes = 37
      call validate_reduced(scene, 38, 1, 'in.nml', error)
      call check(error, .not. allocated(error), 'modes = n - m accepted'); if (allocated(error)) return
      scene%modes = 50
      call validate_reduced(scene, 38, 1, 'in.nml', error)
      if (.not. allocated(error)) then
         call test_failed(error, 'modes = 50 refused')
         return
      end if
      if (error%message /= expected) then
         error%message = 'message: got "'//error%message//'", expected "'//expected//'"'
         return
      end if
      deallocate (error)
      scene%modes = -1
      call validate_reduced(scene, 38, 1, 'in.nml', error)
      if (.not. allocated(error)) then
         call test_failed(error, 'modes = -1 refused')
         return
      end if
      deallocate (error)
      scene%modes = 20000
      call validate_reduced(scene, 40000, 1, 'in.nml', error)
      if (.not. allocated(error)) then
         call test_failed(error, 'a basis of 40000 x 20001 refused')
         return
      end if
      call note(error%message)
      deallocate (error)
      scene%modes = 3
      call validate_reduced(scene, 100000, 1, 'in.nml', error)
      if (.not. allocated(error)) then
         call test_failed(error, 'a reduced model of 100000 unknowns refused')
         return
      end if
      call note(error%message)
      deallocate (error)
   end subroutine test_validate

   !> prepare_run (the preparation of `beamstops run`, `info` and the Python engine) applies the
   !> linear stability limit of the model the run steps: with &mesh modes = 4 and beta = 0 the
   !> reduced model's (1.3e-3 s for the paper's beam), not the full model's (1.24e-5 s), and
   !> run_limit reports that limit and names that model.
   subroutine test_run_limit(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(reduced_model_type) :: reduced
      type(run_limit_type) :: limit
      character(len=:), allocatable :: message
      character(len=*), parameter :: expected = 'in.nml: &time dt = 0.01 is out of range; allowed: dt < 0.00129667 s'
      scene%beta = 0
      scene%t_end = 0.05_wp
      scene%modes = 4
      scene%dt = 1e-3_wp
      call validate_scene(scene, 'in.nml', error)
      if (allocated(error)) return
      call prepare_run(scene, 'in.nml', model, error, reduced)
      call check(error, .not. allocated(error), 'dt = 1e-3 beyond the full limit, within the reduced: accepted')
      if (allocated(error)) return
      limit = run_limit(scene, model, reduced)
      call check(error, limit%dt_newmark, 2/sqrt(reduced%kappa), 'the limit of the reduced model', rel=.true., &
         & thr=1e-15_wp)
      if (allocated(error)) return
      call check(error, limit%dt_newmark > 1e-3_wp .and. model%dt_newmark < 2e-5_wp, 'the reduced limit '// &
         & real_text(limit%dt_newmark)//' s above dt, the full '//real_text(model%dt_newmark)//' s below')
      if (allocated(error)) return
      call check(error, limit%model == 'reduced model of 4 modes', 'the model named: '//limit%model)
      if (allocated(error)) return
      scene%dt = 1e-2_wp
      message = refusal(scene)
      call check(error, index(message, expected) == 1 .and. index(message, 'reduced model with modes = 4') > 0, &
         & 'dt = 1e-2, beyond the reduced limit: refused with "'//expected//' ... reduced model with modes = 4 ...", '// &
         & 'got "'//message//'"')
      if (allocated(error)) return
      scene%modes = 0
      scene%dt = 1e-3_wp
      call check(error, len(refusal(scene)) > 0, 'the full model at dt = 1e-3 refused')
      if (allocated(error)) return
      call build_model(scene, model, error)
      if (allocated(error)) return
      limit = run_limit(scene, model, reduced)
      call check(error, limit%dt_newmark, model%dt_newmark, 'the full model''s limit')
      if (allocated(error)) return
      call check(error, limit%model == 'full model', 'the model named: '//limit%model)
   end subroutine test_run_limit

   !> prepare_run's message for a scene ('' when it accepts it).
   function refusal(scene) result(message)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: message
      type(model_type) :: model
      type(error_type), allocatable :: error
      message = ''
      call prepare_run(scene, 'in.nml', model, error)
      if (allocated(error)) message = error%message
   end function refusal

   !> One element with tip stops leaves one interior unknown (the tip's slope), fewer than the
   !> band's half-bandwidth: the fixed-interface mode is still found (LAPACK's band eigensolver
   !> read past the last column, a heap corruption in the program) and with r = n - m = 1 the
   !> reduced run is the full one to round-off; consistent and redistributed mass.
   subroutine test_one_element(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene, reduced_scene
      type(array_recorder) :: full, red
      type(run_summary) :: sf, sr
      integer :: variant
      real(wp) :: diff
      do variant = 1, 2
         scene = scene_type()
         scene%elements = 1
         scene%law = law_signorini
         scene%redistributed_mass = variant == 2
         scene%dt = 1e-4_wp
         scene%t_end = 0.05_wp
         reduced_scene = scene
         reduced_scene%modes = 1
         call run_recorded(scene, full, sf, error)
         if (allocated(error)) return
         call run_reduced_recorded(reduced_scene, red, sr, error)
         if (allocated(error)) return
         call check(error, red%filled == full%filled, 'as many records'); if (allocated(error)) return
         diff = column_difference(full, red, col_u, full%filled)
         call note('variant '//int_text(variant)//': tip difference / scale '//real_text(diff))
         call check(error, diff, 0.0_wp, 'tip of the full and the one-mode reduced run', thr=1e-10_wp)
         if (allocated(error)) return
      end do
   end subroutine test_one_element
end module test_reduced
