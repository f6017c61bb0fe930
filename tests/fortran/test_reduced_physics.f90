!> The physics of SPEC 8-9 in the reduced (modal) models (beamstops_reduced_scheme): Rayleigh
!> damping C_r = T^T C T = a M_r + b S_r and the Paoli-Schatzman restitution, against
!> mathematics: with all r = n - m modes the reduced run is the full damped (restitution) run in
!> another basis (the full engine's records to round-off through the impacts of the paper's scene,
!> tip-only and with stops along the span); the free decay of the reduced model's mode 1 has the
!> logarithmic decrement of its damping ratio to O(dt^2); without contact the balance
!> E - E0 = W - damped closes to round-off; with restitution the combination
!> (u^{n+1} + e u^{n-1})/(1 + e) satisfies the KKT conditions every step in reduced coordinates.
module test_reduced_physics
   use testing
   use test_support, only: int_text, run_recorded, band_eigenvalues, tube, balance_defect
   use beamstops_model, only: model_type, build_model
   use test_reduced, only: run_reduced_recorded, compare_full, free_reduced, tip_step_residual
   use physics_support, only: tip_decrement
   use beamstops, only: ik, scene_type, array_recorder, run_summary, law_none, law_signorini, law_compliance, validate_scene, &
      & steps_of, scene_from_text, record_count, stop_count, status_complete
   use beamstops_forcing, only: load_average
   use beamstops_lapack, only: dsygv
   use beamstops_reduced, only: reduced_model_type, prepare_reduced, reduced_matrices, build_reduced
   use beamstops_reduced_scheme, only: reduced_state_type, simulate_reduced, start_reduced, advance_reduced, run_reduced
   use beamstops_reduced_checkpoint, only: write_reduced_checkpoint, read_reduced_checkpoint
   use beamstops_files, only: remove_file
   use beamstops_recorder, only: col_t, col_u, col_energy, col_work, col_dissipated, col_damped, col_v, col_reaction
   implicit none
   private
   public :: collect_reduced_physics

contains

   !> Tests of the suite.
   subroutine collect_reduced_physics(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('all modes, damped (2 %), tip stops: the full engine to round-off up to 0.2 s', test_full_damped), &
         & new_unittest('all modes, damped tube (three stops): the full engine to round-off', test_full_damped_span), &
         & new_unittest('all modes, restitution e = 0.5, tip stops: the full engine up to 0.17 s', test_full_restitution), &
         & new_unittest('all modes, restitution e = 0.5, tube: the full engine to round-off', test_full_restitution_span), &
         & new_unittest('r = 3, damped: log decrement of mode 1 is 2 pi zeta/sqrt(1-zeta^2) to O(dt^2)', test_decrement), &
         & new_unittest('damped, no contact: E - E0 = W - damped to round-off (records and summary)', test_balance), &
         & new_unittest('r = 6, e = 0.5: KKT of the combination every step, in reduced coordinates', test_kkt_restitution), &
         & new_unittest('a reduced run (damped, restitution, three stops, statistics) resumed from a checkpoint: '// &
         & 'the same bits', test_resume), &
         & new_unittest('massless boundary, all modes: the full redistributed engine to round-off through the '// &
         & 'first contact period', test_full_massless), &
         & new_unittest('massless boundary, all modes, mass damping: the full redistributed engine', &
         & test_full_massless_damped), &
         & new_unittest('massless boundary, all modes, restitution e = 0.5 / compliance: the full redistributed '// &
         & 'engine', test_full_massless_laws), &
         & new_unittest('massless boundary: its frequencies are the full redistributed model''s lowest r for any r; '// &
         & 'its kappa (beta < 1/4) the full kappa_h', test_massless_frequencies), &
         & new_unittest('massless boundary, tube (three stops along the span): the condensed band, its frequencies '// &
         & 'the full redistributed model''s lowest r for any r; A_r z = e_p', test_massless_span_frequencies), &
         & new_unittest('massless boundary, tube (three stops along the span), all modes: the full redistributed '// &
         & 'engine to round-off, the same contact phases', test_full_massless_span), &
         & new_unittest('massless boundary, tube, no contact: E - E0 = W - damped to round-off', &
         & test_massless_span_balance), &
         & new_unittest('massless boundary, tube, r = 8: KKT of the box QP every step; the rows are the scheme''s', &
         & test_massless_span_kkt), &
         & new_unittest('massless boundary, no contact: E - E0 = W - damped to round-off', test_massless_balance), &
         & new_unittest('massless boundary, r = 8: KKT of the projection every step; the rows are the scheme''s', &
         & test_massless_kkt), &
         & new_unittest('massless boundary, r = 8: the stops'' energy -> 0 and the tip converges in dt through the '// &
         & 'first contact period', test_massless_convergence), &
         & new_unittest('a massless-boundary run (tip; tube) resumed from a checkpoint: the same bits', test_massless_resume), &
         & new_unittest('&mesh modes with damping, restitution and mass redistribution (tip, span) accepted', test_validate) &
         & ]
   end subroutine collect_reduced_physics

   !> The paper's scene with the tip stops, beta = 1/2, dt = 1e-5, 0.2 s.
   function paper_tip() result(scene)
      type(scene_type) :: scene
      scene%law = law_signorini
      scene%beta = 0.5_wp
      scene%dt = 1e-5_wp
      scene%t_end = 0.2_wp
   end function paper_tip

   subroutine test_full_damped(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = paper_tip()
      scene%damping_by_ratio = .true.
      scene%damping_ratio = [0.02_wp, 0.02_wp]
      call compare_full(scene, 0.085_wp, 1e-10_wp, 1e-6_wp, error)
   end subroutine test_full_damped

   subroutine test_full_damped_span(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = tube(0.2_wp)
      scene%damping_mass = 2.0_wp
      scene%damping_stiffness = 1.0e-5_wp
      call compare_full(scene, 0.05_wp, 1e-10_wp, 1e-6_wp, error)
   end subroutine test_full_damped_span

   subroutine test_full_restitution(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = paper_tip()
      ! Up to t = 0.17 s (impacts amplify round-off: measured 1e-9 of the tip's scale at 0.17 s,
      ! 4e-6 by 0.2 s).
      scene%t_end = 0.17_wp
      scene%restitution = 0.5_wp
      call compare_full(scene, 0.085_wp, 1e-10_wp, 1e-6_wp, error)
   end subroutine test_full_restitution

   subroutine test_full_restitution_span(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = tube(0.2_wp)
      scene%restitution = 0.5_wp
      call compare_full(scene, 0.05_wp, 1e-10_wp, 1e-6_wp, error)
   end subroutine test_full_restitution_span

   !> Free decay (no support motion, no stops, J = 8, r = 3, zeta_1 = zeta_2 = 0.02 on the full
   !> model's modes) from the reduced model's own mode 1 (lowest eigenvector of (S_r, M_r), tip
   !> 0.01 m): the decrement of the tip's peaks against 2 pi zeta_r/sqrt(1 - zeta_r^2),
   !> zeta_r = a/(2 omega_r) + b omega_r/2 at the reduced mode's frequency omega_r.
   subroutine decay(dt, decrement, expected, error)
      real(wp), intent(in) :: dt
      real(wp), intent(out) :: decrement, expected
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: pi = acos(-1.0_wp)
      type(scene_type) :: scene
      type(reduced_model_type) :: reduced
      type(array_recorder) :: rec
      type(run_summary) :: summary
      real(wp), allocatable :: mr(:, :), sr(:, :), w(:), work(:)
      real(wp) :: omega, zeta
      integer :: s, info
      decrement = 0
      expected = 0
      scene%elements = 8
      scene%dt = dt
      scene%t_end = 1.2_wp
      scene%beta = 0.25_wp
      scene%amplitude = 0
      scene%law = law_none
      scene%modes = 3
      scene%damping_by_ratio = .true.
      scene%damping_ratio = [0.02_wp, 0.02_wp]
      call validate_scene(scene, 'test scene', error)
      if (allocated(error)) return
      call prepare_reduced(scene, 'test scene', reduced, error)
      if (allocated(error)) return
      call reduced_matrices(reduced, mr, sr)
      s = reduced%size
      allocate (w(s), work(3*s))
      call dsygv(1, 'V', 'U', s, sr, s, mr, s, w, work, size(work), info)
      if (info /= 0) then
         call test_failed(error, 'dsygv info = '//int_text(info))
         return
      end if
      reduced%q0 = 0.01_wp*sr(:, 1)/dot_product(reduced%tip_row, sr(:, 1))
      reduced%v0 = 0
      omega = sqrt(w(1))
      zeta = reduced%damping_a/(2*omega) + reduced%damping_b*omega/2
      expected = 2*pi*zeta/sqrt(1 - zeta**2)
      call rec%reserve(steps_of(scene) + 1, 0_ik, scene%elements + 1)
      call simulate_reduced(scene, reduced, rec, summary, error)
      if (allocated(error)) return
      call tip_decrement(rec, decrement, error)
   end subroutine decay

   subroutine test_decrement(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: d1, d2, x1, x2, e1, e2
      call decay(2.0e-3_wp, d1, x1, error)
      if (allocated(error)) return
      call decay(1.0e-3_wp, d2, x2, error)
      if (allocated(error)) return
      e1 = abs(d1/x1 - 1)
      e2 = abs(d2/x2 - 1)
      call note('log decrement '//real_text(d2)//' (expected '//real_text(x2)//'); relative error '// &
         & real_text(e1)//' at dt = 2e-3, '//real_text(e2)//' at dt = 1e-3, order '//real_text(log(e1/e2)/log(2.0_wp)))
      call check(error, abs(x2/(2*acos(-1.0_wp)*0.02_wp) - 1) < 1e-3_wp, &
         & 'the reduced mode 1 has (nearly) the full model''s damping ratio')
      if (allocated(error)) return
      call check(error, e2 < 1.0e-3_wp, 'decrement within 1e-3 at dt = 1e-3')
      if (allocated(error)) return
      call check(error, log(e1/e2)/log(2.0_wp) > 1.7_wp, 'second order in dt')
   end subroutine test_decrement

   !> Law none, support moving, r = 5 and 30, beta = 1/4 and 1/2, damping a = 3, b = 2e-5 (about
   !> 1-5 % on the first modes), 1 s: max |(E_n - E_0) - (W_n - damped_n)| / max |E| in the records,
   !> the summary's residual likewise, and the damping's loss growing.
   subroutine test_balance(error)
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
            scene%damping_mass = 3.0_wp
            scene%damping_stiffness = 2.0e-5_wp
            call run_reduced_recorded(scene, rec, summary, error)
            if (allocated(error)) return
            escale = maxval(abs(rec%rows(col_energy, :rec%filled)))
            worst = balance_defect(rec)
            call note('beta = '//real_text(betas(k))//', r = '//int_text(rs(i))//': damped '// &
               & real_text(summary%damped)//' J, balance defect / max |E| '//real_text(worst)// &
               & ', summary residual / max |E| '//real_text(summary%energy_residual/escale))
            call check(error, rec%rows(col_dissipated, rec%filled), 0.0_wp, 'no energy taken by stops', thr=0.0_wp)
            if (allocated(error)) return
            call check(error, summary%damped > 0.01_wp*escale, 'the damping takes energy')
            if (allocated(error)) return
            call check(error, all(rec%rows(col_damped, 2:rec%filled) >= rec%rows(col_damped, 1:rec%filled - 1)), &
               & 'the damping loss never decreases')
            if (allocated(error)) return
            call check(error, summary%damped, rec%rows(col_damped, rec%filled), 'summary damped = last record', &
               & thr=0.0_wp)
            if (allocated(error)) return
            call check(error, worst, 0.0_wp, 'balance defect', thr=1e-12_wp)
            if (allocated(error)) return
            call check(error, summary%energy_residual/escale, 0.0_wp, 'summary residual', thr=1e-12_wp)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_balance

   !> Step by step (r = 6, paper's scene, beta = 1/2, e = 0.5, t <= 0.15 s): the residual
   !> rho = A_r (d^n - d^{n-1}) - dt^2 (G^n l_r - S_r q^n) vanishes in every row but the tip's,
   !> where rho/dt^2 is the reaction; the combination w = (q_tip^{n+1} + e q_tip^{n-1})/(1 + e)
   !> within the stops, the reaction zero unless w is on a stop, and pushing away from it.
   subroutine test_kkt_restitution(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: e = 0.5_wp
      type(scene_type) :: scene
      type(reduced_model_type) :: reduced
      type(reduced_state_type) :: state
      type(array_recorder) :: rec
      real(wp), allocatable :: mr(:, :), sr(:, :), ar(:, :), q_old(:), d_old(:), rho(:)
      real(wp) :: scale, worst_rows, w, reaction, tol_u
      integer(ik) :: step, done, steps, contacts
      integer :: pt
      scene%law = law_signorini
      scene%beta = 0.5_wp
      scene%dt = 1e-5_wp
      scene%t_end = 0.15_wp
      scene%modes = 6
      scene%restitution = e
      call validate_scene(scene, 'test scene', error)
      if (allocated(error)) return
      call prepare_reduced(scene, 'test scene', reduced, error)
      if (allocated(error)) return
      call reduced_matrices(reduced, mr, sr)
      ar = mr + scene%dt**2*scene%beta*sr
      pt = reduced%r + reduced%tip_stop
      steps = steps_of(scene)
      call rec%reserve(steps + 1, 0_ik, scene%elements + 1)
      call start_reduced(scene, reduced, state, rec, error)
      if (allocated(error)) return
      worst_rows = 0
      contacts = 0
      tol_u = 8*epsilon(1.0_wp)*scene%upper
      do step = 1, steps
         q_old = state%q
         d_old = state%d
         call advance_reduced(scene, reduced, state, rec, step, done)
         call tip_step_residual(scene, reduced, ar, sr, step, q_old, d_old, state, rho, scale)
         worst_rows = max(worst_rows, maxval(abs(rho(:pt - 1)))/scale)
         w = (state%q(pt) + e*(q_old(pt) - d_old(pt)))/(1 + e)
         reaction = rho(pt)/scene%dt**2
         call check(error, w >= scene%lower - tol_u .and. w <= scene%upper + tol_u, 'step '//int_text(step)// &
            & ': combination '//real_text(w)//' within the stops')
         if (allocated(error)) return
         if (abs(rho(pt)) > 1e-12_wp*scale) then
            contacts = contacts + 1
            call check(error, (reaction > 0 .and. abs(w - scene%lower) <= tol_u) .or. &
               & (reaction < 0 .and. abs(w - scene%upper) <= tol_u), 'step '//int_text(step)//': reaction '// &
               & real_text(reaction)//' only with the combination on a stop, pushing away from it (w = '// &
               & real_text(w)//')')
            if (allocated(error)) return
         end if
      end do
      call note('contact steps '//int_text(contacts)//', largest residual off the tip row / scale '// &
         & real_text(worst_rows)//', largest violation of u^{n+1} '//real_text(state%max_violation)//' m')
      call check(error, contacts > 10, 'the tip meets the stops'); if (allocated(error)) return
      call check(error, state%max_violation > 0, 'u^{n+1} itself passes the stop (reported, not hidden)')
      if (allocated(error)) return
      call check(error, worst_rows, 0.0_wp, 'residual of the rows off the tip', thr=1e-14_wp)
   end subroutine test_kkt_restitution

   !> The tube (r = 8, damping, e = 0.5, statistics) run to step 6000, checkpointed, read back into
   !> a new state; both continued to the end: every record after the checkpoint, q, d, the
   !> energies and the statistics' summary to the bit.
   subroutine test_resume(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = 'test_reduced_resume.checkpoint'
      type(scene_type) :: scene
      type(reduced_model_type) :: reduced
      type(reduced_state_type) :: straight, resumed
      type(array_recorder) :: a, b
      type(run_summary) :: sa, sb
      integer(ik) :: records, snapshots, first
      scene = tube(0.3_wp)
      scene%modes = 8
      scene%damping_mass = 2.0_wp
      scene%damping_stiffness = 1.0e-5_wp
      scene%restitution = 0.5_wp
      scene%statistics = .true.
      scene%transient = 0.05_wp
      scene%batches = 4
      call validate_scene(scene, 'test scene', error)
      if (allocated(error)) return
      call prepare_reduced(scene, 'test scene', reduced, error)
      if (allocated(error)) return
      call a%reserve(record_count(scene), 0_ik, scene%elements + 1, stop_count(scene))
      call b%reserve(record_count(scene), 0_ik, scene%elements + 1, stop_count(scene))
      call start_reduced(scene, reduced, straight, a, error)
      if (allocated(error)) return
      call run_reduced(scene, reduced, straight, a, sa, 6000_ik)
      call check(error, sa%status == 'running' .and. straight%step == 6001, 'stopped at step 6000')
      if (allocated(error)) return
      call write_reduced_checkpoint(path, scene, straight, a%filled, 0_ik, error)
      if (allocated(error)) return
      call read_reduced_checkpoint(path, scene, reduced, resumed, records, snapshots, error)
      call remove_file(path)
      if (allocated(error)) return
      call check(error, records == a%filled, 'the record count'); if (allocated(error)) return
      first = a%filled + 1
      b%filled = a%filled
      b%stops_filled = a%stops_filled
      call run_reduced(scene, reduced, straight, a, sa)
      call run_reduced(scene, reduced, resumed, b, sb)
      call check(error, sa%status == status_complete .and. sb%status == status_complete, 'both complete')
      if (allocated(error)) return
      call check(error, all(a%rows(:, first:a%filled) == b%rows(:, first:b%filled)) .and. a%filled == b%filled, &
         & 'the records after the checkpoint to the bit')
      if (allocated(error)) return
      call check(error, all(a%stops_u(:, first:a%filled) == b%stops_u(:, first:b%filled)), 'the stops'' records')
      if (allocated(error)) return
      call check(error, all(straight%q == resumed%q) .and. all(straight%d == resumed%d), 'q and d to the bit')
      if (allocated(error)) return
      call check(error, sa%damped == sb%damped .and. sa%damped > 0 .and. sa%dissipated == sb%dissipated .and. &
         & sa%energy_residual == sb%energy_residual, 'the energy ledger to the bit')
      if (allocated(error)) return
      call check(error, sa%impacts == sb%impacts .and. sa%impacts > 0, 'the shocks')
   end subroutine test_resume

   ! ---------------------------------------------------------------- the massless boundary (SPEC 10, 11)

   !> The paper's scene through the first contact period (t <= 0.125 s), beta = 1/4, mass
   !> redistributed, centred load, Taylor start, records every 1e-5 s.
   function massless_scene(dt, modes) result(scene)
      real(wp), intent(in) :: dt
      integer, intent(in) :: modes
      type(scene_type) :: scene
      scene%law = law_signorini
      scene%beta = 0.25_wp
      scene%dt = dt
      scene%t_end = 0.125_wp
      scene%record_every = nint(1.0e-5_wp/dt)
      scene%redistributed_mass = .true.
      scene%modes = modes
   end function massless_scene

   !> T = [Phi E_tip] with all r = n - 1 modes is a change of basis of the full redistributed model
   !> (the tip row the same equilibrium): every column to round-off before the first impact, the
   !> tip, energy and work within 1e-6 of their scale through the impacts of the first contact
   !> period, and the same contact phases.
   subroutine test_full_massless(error)
      type(error_type), allocatable, intent(out) :: error
      call compare_massless(massless_scene(6.25e-7_wp, 0), error)
   end subroutine test_full_massless

   !> The full redistributed run and the all-modes (r = n - 1) massless boundary: t, u, v,
   !> reaction, energy, work and damped within 1e-10 of their scale before the first impact
   !> (t <= 0.085 s); u, energy and work within 1e-6 of their scale through the contact period;
   !> the stops' energy (O(dt^2), ~0) within 1e-8 of the work's scale; the same contact phases.
   subroutine compare_massless(scene, error)
      type(scene_type), intent(in) :: scene
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: reduced_scene
      type(array_recorder) :: full, red
      type(run_summary) :: sf, sr
      integer, parameter :: clean_columns(7) = [col_t, col_u, col_v, col_reaction, col_energy, col_work, col_damped]
      real(wp) :: clean, whole, work_scale
      integer(ik) :: last
      integer :: k, col
      reduced_scene = scene
      reduced_scene%modes = 2*scene%elements - 1
      call run_recorded(scene, full, sf, error)
      if (allocated(error)) return
      call run_reduced_recorded(reduced_scene, red, sr, error)
      if (allocated(error)) return
      call check(error, red%filled == full%filled, 'as many records'); if (allocated(error)) return
      last = count(full%rows(col_t, :full%filled) <= 0.085_wp, kind=ik)
      do k = 1, size(clean_columns)
         col = clean_columns(k)
         clean = relative_difference(full, red, col, last)
         whole = relative_difference(full, red, col, full%filled)
         call note('column '//int_text(col)//': largest difference / scale up to 0.085 s '//real_text(clean)// &
            & ', up to t_end '//real_text(whole))
         call check(error, clean, 0.0_wp, 'column '//int_text(col)//' before the first impact', thr=1e-10_wp)
         if (allocated(error)) return
         if (any(col == [col_u, col_energy, col_work])) call check(error, whole, 0.0_wp, 'column '//int_text(col)// &
            & ' through the contact period', thr=1e-6_wp)
         if (allocated(error)) return
      end do
      work_scale = maxval(abs(full%rows(col_work, :full%filled)))
      whole = maxval(abs(full%rows(col_dissipated, :full%filled) - red%rows(col_dissipated, :red%filled)))/work_scale
      call note('stops'' energy: largest difference / work scale '//real_text(whole)//'; contact phases: full '// &
         & int_text(sf%impacts)//', reduced '//int_text(sr%impacts))
      call check(error, whole, 0.0_wp, 'the stops'' energy', thr=1e-8_wp)
      if (allocated(error)) return
      call check(error, sf%impacts > 0, 'the scene has impacts'); if (allocated(error)) return
      call check(error, int(sr%impacts), int(sf%impacts), 'the same contact phases')
   end subroutine compare_massless

   !> Largest difference of a column over rows 1..last, relative to the column's largest value.
   function relative_difference(a, b, c, last) result(diff)
      type(array_recorder), intent(in) :: a, b
      integer, intent(in) :: c
      integer(ik), intent(in) :: last
      real(wp) :: diff
      diff = maxval(abs(a%rows(c, :last) - b%rows(c, :last)))/max(maxval(abs(a%rows(c, :a%filled))), tiny(1.0_wp))
   end function relative_difference

   !> The same with mass-proportional damping (a = 3/s; the full model refuses b > 0 with
   !> redistribution) and beta = 1/2.
   subroutine test_full_massless_damped(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = massless_scene(1.25e-6_wp, 0)
      scene%beta = 0.5_wp
      scene%damping_mass = 3.0_wp
      call compare_massless(scene, error)
   end subroutine test_full_massless_damped

   !> The massless tip's static condensation is exact, so the finite spectrum of (S, M^rho) is that
   !> of the interior (S_ii - S_ib S_bi/S_bb, M^rho_ii), whose first r modes the basis takes: the
   !> reduced model's squared frequencies (M_r = diag(I, 0), S_r condensed: Lambda_c) are the full
   !> redistributed model's r lowest for every r (J = 19: r = 3, 8, 37), to 1e-10; with
   !> beta = 0.2 the reduced kappa of r = n - 1 is the full kappa_h and the reduced Newmark limit
   !> at r = 8 is larger than the full one (dt may grow).
   subroutine test_massless_frequencies(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: rs(3) = [3, 8, 37]
      type(scene_type) :: scene
      type(model_type) :: model
      type(reduced_model_type) :: reduced
      real(wp), allocatable :: mu(:), kappa_full(:)
      real(wp) :: worst, dt_full
      integer :: i, k, n
      scene = massless_scene(1e-5_wp, 1)
      scene%beta = 0.2_wp
      call build_model(scene, model, error)
      if (allocated(error)) return
      ! (M^rho, S): mu = 1/kappa, the massless mode at mu = 0 (the smallest).
      call band_eigenvalues(model%mass, model%stiffness, mu, error)
      if (allocated(error)) return
      n = size(mu)
      kappa_full = [(1/mu(n + 1 - k), k=1, n - 1)]
      do i = 1, size(rs)
         scene%modes = rs(i)
         call prepare_reduced(scene, 'test scene', reduced, error)
         if (allocated(error)) return
         worst = maxval(abs(reduced%lambda - kappa_full(:rs(i)))/kappa_full(:rs(i)))
         call note('r = '//int_text(rs(i))//': largest relative difference of omega^2 from the full model''s '// &
            & real_text(worst)//'; reduced kappa '//real_text(reduced%kappa)//', full kappa_h '// &
            & real_text(model%kappa_h)//' 1/s^2')
         call check(error, worst, 0.0_wp, 'the r lowest frequencies', thr=1e-10_wp)
         if (allocated(error)) return
         call check(error, reduced%kappa, kappa_full(rs(i)), 'kappa of the reduced model: its largest', rel=.true., &
            & thr=1e-10_wp)
         if (allocated(error)) return
      end do
      call check(error, reduced%kappa, model%kappa_h, 'r = n - 1: the full kappa_h', rel=.true., thr=1e-10_wp)
      if (allocated(error)) return
      scene%modes = 8
      call prepare_reduced(scene, 'test scene', reduced, error)
      if (allocated(error)) return
      dt_full = 2/sqrt((1 - 4*scene%beta)*model%kappa_h)
      call note('beta = 0.2: Newmark limit of the full model '//real_text(dt_full)//' s, of r = 8 '// &
         & real_text(reduced%dt_newmark)//' s')
      call check(error, reduced%dt_newmark > 10*dt_full, 'r = 8 takes a dt ten times the full model''s')
   end subroutine test_massless_frequencies

   !> The tube's three stops along the span, mass redistributed: each massless stop value couples
   !> to five consecutive interior unknowns, so the condensed interior stiffness has the
   !> half-bandwidth kd + 1 (a band of kd would drop the corner entries and shift the spectrum).
   !> Its finite spectrum is still the full redistributed model's: the reduced squared
   !> frequencies are the r lowest of (S, M^rho) for r = 4, 12 and n - 3 (the 12 lowest to 1e-10
   !> each, all to 1e-9 of the largest); the reduced
   !> kappa is the full kappa_h at r = n - m; the closed-form A_r solve (m = 3) gives
   !> A_r z_j = e_{r+j} to round-off against the dense A_r = M_r + dt^2 beta S_r.
   subroutine test_massless_span_frequencies(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(reduced_model_type) :: reduced
      real(wp), allocatable :: mu(:), kappa_full(:), mr(:, :), sr(:, :), residual(:)
      real(wp) :: worst
      integer :: i, j, k, n, m
      integer :: rs(3)
      scene = tube(0.01_wp)
      scene%redistributed_mass = .true.
      ! beta < 1/4: the models compute their kappa.
      scene%beta = 0.2_wp
      scene%allow_unstable = .true.
      call build_model(scene, model, error)
      if (allocated(error)) return
      m = size(scene%stop_nodes)
      call band_eigenvalues(model%mass, model%stiffness, mu, error)
      if (allocated(error)) return
      n = size(mu)
      ! mu = 1/kappa ascending: the m massless modes at mu = 0 first.
      kappa_full = [(1/mu(n + 1 - k), k=1, n - m)]
      rs = [4, 12, n - m]
      do i = 1, size(rs)
         scene%modes = rs(i)
         call build_reduced(scene, model, reduced, error)
         if (allocated(error)) return
         ! Relative to each omega^2 for the 12 lowest; all of them relative to the largest: the
         ! highest carry errors of eps times the spread (the reference 1/mu from (M^rho, S), the
         ! reduced quotient phi^T S phi - G S_bb^{-1} G^T phi a difference): 5e-10 at r = n - m.
         k = min(rs(i), 12)
         worst = maxval(abs(reduced%lambda(:k) - kappa_full(:k))/kappa_full(:k))
         call note('r = '//int_text(rs(i))//': largest relative difference of omega^2 from the full model''s '// &
            & '(12 lowest) '//real_text(worst)//', all / the largest '// &
            & real_text(maxval(abs(reduced%lambda - kappa_full(:rs(i))))/kappa_full(rs(i)))// &
            & '; reduced kappa '//real_text(reduced%kappa))
         call check(error, worst, 0.0_wp, 'the lowest frequencies', thr=1e-10_wp)
         if (allocated(error)) return
         call check(error, maxval(abs(reduced%lambda - kappa_full(:rs(i))))/kappa_full(rs(i)), 0.0_wp, &
            & 'the r lowest frequencies', thr=1e-9_wp)
         if (allocated(error)) return
         call check(error, reduced%kappa, kappa_full(rs(i)), 'kappa of the reduced model: its largest', rel=.true., &
            & thr=1e-10_wp)
         if (allocated(error)) return
      end do
      call check(error, reduced%kappa, model%kappa_h, 'r = n - m: the full kappa_h', rel=.true., thr=1e-10_wp)
      if (allocated(error)) return
      call reduced_matrices(reduced, mr, sr)
      mr = mr + reduced%dt2*reduced%beta*sr
      do j = 1, m
         residual = matmul(mr, reduced%z(:, j))
         residual(reduced%r + j) = residual(reduced%r + j) - 1
         worst = maxval(abs(residual))/maxval(abs(mr))/maxval(abs(reduced%z(:, j)))
         call note('stop '//int_text(j)//': |A_r z - e| / (|A_r| |z|) '//real_text(worst))
         call check(error, worst, 0.0_wp, 'A_r z_j = e_{r+j}', thr=1e-12_wp)
         if (allocated(error)) return
      end do
   end subroutine test_massless_span_frequencies

   !> The tube with mass redistributed (the values at its three stops massless) and all
   !> r = n - m modes is a change of basis of the full redistributed model: every column to 1e-10
   !> of its scale before the first impact (0.02 s), u, energy, work and the stop values within
   !> 1e-6 through the impacts up to 0.2 s (two contact phases), the same contact phases; also
   !> with mass damping (a = 3/s) and, up to 0.1 s, with restitution e = 0.5 (Euler start).
   subroutine test_full_massless_span(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = tube(0.2_wp)
      scene%redistributed_mass = .true.
      call compare_full(scene, 0.02_wp, 1e-10_wp, 1e-6_wp, error)
      if (allocated(error)) return
      ! Restitution amplifies the round-off at each impact: through the first phase (0.1 s).
      scene%t_end = 0.1_wp
      scene%restitution = 0.5_wp
      scene%taylor_start = .false.
      call compare_full(scene, 0.02_wp, 1e-10_wp, 1e-6_wp, error)
      if (allocated(error)) return
      scene = tube(0.2_wp)
      scene%redistributed_mass = .true.
      scene%damping_mass = 3.0_wp
      call compare_full(scene, 0.02_wp, 1e-10_wp, 1e-6_wp, error)
   end subroutine test_full_massless_span

   !> The tube without contact (law none, 0.5 s, dt = 1e-4), r = 8 and n - m, beta = 1/4, with
   !> and without mass damping: max |(E_n - E_0) - (W_n - damped_n)| / max |E| in the records and
   !> the summary's residual within 1e-10.
   subroutine test_massless_span_balance(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      real(wp), parameter :: dampings(2) = [0.0_wp, 3.0_wp]
      integer, parameter :: rs(2) = [8, 57]
      integer :: i, l
      real(wp) :: worst, escale
      do l = 1, 2
         do i = 1, 2
            scene = tube(0.5_wp)
            scene%law = law_none
            scene%dt = 1e-4_wp
            scene%modes = rs(i)
            scene%redistributed_mass = .true.
            scene%damping_mass = dampings(l)
            call run_reduced_recorded(scene, rec, summary, error)
            if (allocated(error)) return
            escale = maxval(abs(rec%rows(col_energy, :rec%filled)))
            worst = balance_defect(rec)
            call note('r = '//int_text(rs(i))//', a = '//real_text(dampings(l))//': balance defect / max |E| '// &
               & real_text(worst)//', summary residual / max |E| '// &
               & real_text(summary%energy_residual/escale)//', stops'' energy '// &
               & real_text(rec%rows(col_dissipated, rec%filled))//' J')
            call check(error, worst, 0.0_wp, 'balance defect', thr=1e-10_wp)
            if (allocated(error)) return
            call check(error, summary%energy_residual/escale, 0.0_wp, 'summary residual', thr=1e-10_wp)
            if (allocated(error)) return
            if (dampings(l) > 0) call check(error, summary%damped > 0.01_wp*escale, 'the damping takes energy')
            if (allocated(error)) return
         end do
      end do
   end subroutine test_massless_span_balance

   !> Step by step (tube, r = 8, 0.1 s): the residual rho = A_r (d^n - d^{n-1}) - rhs of the scheme
   !> vanishes in the modal rows, with each stop row's rhs its equilibrium at t_{n+1}; there
   !> lambda_j = rho_j/(dt^2 beta) is the stop's force (KKT of the box QP): every stop value within
   !> its bounds of t_{n+1}, the force zero unless the value is on a bound, pushing away from it.
   subroutine test_massless_span_kkt(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(reduced_model_type) :: reduced
      type(reduced_state_type) :: state
      type(array_recorder) :: rec
      real(wp), allocatable :: mr(:, :), sr(:, :), ar(:, :), q_old(:), d_old(:), rho(:), rhs(:), sd(:)
      real(wp) :: weight, sigma_next, scale, worst_rows, force, tol_u, phi, lo, hi, value
      integer(ik) :: step, done, steps, contacts
      integer :: r, j, p
      scene = tube(0.1_wp)
      scene%redistributed_mass = .true.
      scene%modes = 8
      call validate_scene(scene, 'test scene', error)
      if (allocated(error)) return
      call prepare_reduced(scene, 'test scene', reduced, error)
      if (allocated(error)) return
      r = reduced%r
      call reduced_matrices(reduced, mr, sr)
      call check(error, all(mr(:, r + 1:) == 0) .and. all(mr(r + 1:, :) == 0), &
         & 'M_r = diag(I, 0): the stop coordinates carry no mass')
      if (allocated(error)) return
      ar = mr + scene%dt**2*scene%beta*sr
      steps = steps_of(scene)
      call rec%reserve(record_count(scene), 0_ik, scene%elements + 1, stop_count(scene))
      call start_reduced(scene, reduced, state, rec, error)
      if (allocated(error)) return
      worst_rows = 0
      contacts = 0
      tol_u = 8*epsilon(1.0_wp)*maxval(scene%stop_upper)
      do step = 1, steps
         q_old = state%q
         d_old = state%d
         call advance_reduced(scene, reduced, state, rec, step, done)
         sigma_next = load_average(step + 1, scene%dt, scene%omega, scene%centered_load)
         weight = scene%beta*sigma_next + (1 - 2*scene%beta)*load_average(step, scene%dt, scene%omega, &
            & scene%centered_load) + scene%beta*load_average(step - 1, scene%dt, scene%omega, scene%centered_load)
         rhs = scene%dt**2*(weight*reduced%load - matmul(sr, q_old))
         sd = matmul(sr, d_old)
         do j = 1, reduced%m
            p = r + j
            rhs(p) = scene%dt**2*scene%beta*(sigma_next*reduced%load(p) - dot_product(sr(p, :), q_old) - sd(p))
         end do
         rho = matmul(ar, state%d - d_old) - rhs
         scale = maxval(matmul(abs(ar), abs(state%d) + abs(d_old)) + scene%dt**2*(matmul(abs(sr), &
            & abs(q_old) + abs(d_old)) + abs(reduced%load)))
         worst_rows = max(worst_rows, maxval(abs(rho(:r)))/scale)
         phi = scene%amplitude*sin(scene%omega*real(step + 1, wp)*scene%dt)
         do j = 1, reduced%m
            p = r + j
            lo = reduced%stops%lower(j) - reduced%stops%lift(j)*phi
            hi = reduced%stops%upper(j) - reduced%stops%lift(j)*phi
            value = state%q(p)
            force = rho(p)/(scene%dt**2*scene%beta)
            call check(error, value >= lo - tol_u .and. value <= hi + tol_u, 'step '//int_text(step)//': stop '// &
               & int_text(j)//' value '//real_text(value)//' within its bounds')
            if (allocated(error)) return
            if (abs(rho(p)) > 1e-12_wp*scale) then
               contacts = contacts + 1
               call check(error, (force > 0 .and. abs(value - lo) <= tol_u) .or. (force < 0 .and. &
                  & abs(value - hi) <= tol_u), 'step '//int_text(step)//': stop '//int_text(j)//' force '// &
                  & real_text(force)//' only on a bound, pushing away from it (value '//real_text(value)//')')
               if (allocated(error)) return
            end if
         end do
      end do
      call note('contact steps '//int_text(contacts)//', largest residual off the stop rows / scale '// &
         & real_text(worst_rows))
      call check(error, contacts > 10, 'the stops act'); if (allocated(error)) return
      call check(error, worst_rows, 0.0_wp, 'residual of the modal rows', thr=1e-14_wp)
   end subroutine test_massless_span_kkt

   !> The same with the other laws at the massless tip: restitution e = 0.5 (Euler start) and the
   !> compliance spring (k = 1e6 N/m per unit mass; the full model overwrites the spring's
   !> explicit part in the tip's row by its equilibrium, and so does the reduced loop).
   subroutine test_full_massless_laws(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = massless_scene(1.25e-6_wp, 0)
      scene%restitution = 0.5_wp
      scene%taylor_start = .false.
      call compare_massless(scene, error)
      if (allocated(error)) return
      scene = massless_scene(1.25e-6_wp, 0)
      scene%law = law_compliance
      scene%stiffness_per_mass = 1.0e6_wp
      call compare_massless(scene, error)
   end subroutine test_full_massless_laws

   !> No contact (law none, 1 s, dt = 1e-4), beta = 1/4 and 1/2, r = 5 and r = n - 1, with and
   !> without mass damping: max |(E_n - E_0) - (W_n - damped_n)| / max |E| in the records and the
   !> summary's residual within 1e-12, and no energy taken at the massless tip.
   subroutine test_massless_balance(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      real(wp), parameter :: betas(2) = [0.25_wp, 0.5_wp], dampings(2) = [0.0_wp, 3.0_wp]
      integer, parameter :: rs(2) = [5, 37]
      integer :: i, k, l
      real(wp) :: worst, escale
      do l = 1, 2
         do k = 1, 2
            do i = 1, 2
               scene = free_reduced(betas(k), rs(i))
               scene%redistributed_mass = .true.
               scene%damping_mass = dampings(l)
               call run_reduced_recorded(scene, rec, summary, error)
               if (allocated(error)) return
               escale = maxval(abs(rec%rows(col_energy, :rec%filled)))
               worst = balance_defect(rec)
               call note('beta = '//real_text(betas(k))//', r = '//int_text(rs(i))//', a = '// &
                  & real_text(dampings(l))//': balance defect / max |E| '//real_text(worst)// &
                  & ', summary residual / max |E| '//real_text(summary%energy_residual/escale)//', tip''s energy '// &
                  & real_text(rec%rows(col_dissipated, rec%filled))//' J')
               call check(error, worst, 0.0_wp, 'balance defect', thr=1e-10_wp)
               if (allocated(error)) return
               call check(error, summary%energy_residual/escale, 0.0_wp, 'summary residual', thr=1e-10_wp)
               if (allocated(error)) return
               if (dampings(l) > 0) call check(error, summary%damped > 0.01_wp*escale, 'the damping takes energy')
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_massless_balance

   !> Step by step (r = 8, first contact period, dt = 1.25e-6): the residual
   !> rho = A_r (d^n - d^{n-1}) - rhs of the scheme vanishes in the modal rows, with the tip's
   !> rhs its equilibrium at t_{n+1}; there rho/(dt^2 beta) = (S_r q^{n+1})_tip - sigma_{n+1} l_tip
   !> is the stops' force: the tip within the stops, the force zero unless the tip is on a stop,
   !> pushing away from it; and E - E0 = W - D through the contacts.
   subroutine test_massless_kkt(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(reduced_model_type) :: reduced
      type(reduced_state_type) :: state
      type(array_recorder) :: rec
      real(wp), allocatable :: mr(:, :), sr(:, :), ar(:, :), q_old(:), d_old(:), rho(:), rhs(:), sd(:)
      real(wp) :: weight, sigma_next, scale, worst_rows, force, tol_u, worst_balance
      integer(ik) :: step, done, steps, contacts, j
      integer :: pt
      scene = massless_scene(1.25e-6_wp, 8)
      call validate_scene(scene, 'test scene', error)
      if (allocated(error)) return
      call prepare_reduced(scene, 'test scene', reduced, error)
      if (allocated(error)) return
      call reduced_matrices(reduced, mr, sr)
      call check(error, all(mr(:, reduced%r + 1) == 0) .and. all(mr(reduced%r + 1, :) == 0), &
         & 'M_r = diag(I, 0): the tip coordinate carries no mass')
      if (allocated(error)) return
      ar = mr + scene%dt**2*scene%beta*sr
      pt = reduced%r + reduced%tip_stop
      steps = steps_of(scene)
      call rec%reserve(record_count(scene), 0_ik, scene%elements + 1)
      call start_reduced(scene, reduced, state, rec, error)
      if (allocated(error)) return
      worst_rows = 0
      contacts = 0
      tol_u = 8*epsilon(1.0_wp)*scene%upper
      do step = 1, steps
         q_old = state%q
         d_old = state%d
         call advance_reduced(scene, reduced, state, rec, step, done)
         sigma_next = load_average(step + 1, scene%dt, scene%omega, .true.)
         weight = scene%beta*sigma_next + (1 - 2*scene%beta)*load_average(step, scene%dt, scene%omega, .true.) &
            & + scene%beta*load_average(step - 1, scene%dt, scene%omega, .true.)
         rhs = scene%dt**2*(weight*reduced%load - matmul(sr, q_old))
         sd = matmul(sr, d_old)
         rhs(pt) = scene%dt**2*scene%beta*(sigma_next*reduced%load(pt) - dot_product(sr(pt, :), q_old) - sd(pt))
         rho = matmul(ar, state%d - d_old) - rhs
         scale = maxval(matmul(abs(ar), abs(state%d) + abs(d_old)) + scene%dt**2*(matmul(abs(sr), &
            & abs(q_old) + abs(d_old)) + abs(reduced%load)))
         worst_rows = max(worst_rows, maxval(abs(rho(:pt - 1)))/scale)
         force = rho(pt)/(scene%dt**2*scene%beta)
         call check(error, state%q(pt) >= scene%lower - tol_u .and. state%q(pt) <= scene%upper + tol_u, 'step '// &
            & int_text(step)//': tip '//real_text(state%q(pt))//' within the stops')
         if (allocated(error)) return
         if (abs(rho(pt)) > 1e-12_wp*scale) then
            contacts = contacts + 1
            call check(error, (force > 0 .and. abs(state%q(pt) - scene%lower) <= tol_u) .or. &
               & (force < 0 .and. abs(state%q(pt) - scene%upper) <= tol_u), 'step '//int_text(step)//': force '// &
               & real_text(force)//' only with the tip on a stop, pushing away from it (tip '// &
               & real_text(state%q(pt))//')')
            if (allocated(error)) return
         end if
      end do
      worst_balance = 0
      do j = 1, rec%filled
         worst_balance = max(worst_balance, abs(rec%rows(col_energy, j) - rec%rows(col_energy, 1) &
            & - rec%rows(col_work, j) + rec%rows(col_dissipated, j)))
      end do
      call note('contact steps '//int_text(contacts)//', largest residual off the tip row / scale '// &
         & real_text(worst_rows)//', balance defect '//real_text(worst_balance)//' J, max |E| '// &
         & real_text(maxval(abs(rec%rows(col_energy, :rec%filled))))//' J')
      call check(error, contacts > 10, 'the tip meets the stops'); if (allocated(error)) return
      call check(error, worst_rows, 0.0_wp, 'residual of the modal rows', thr=1e-14_wp)
      if (allocated(error)) return
      call check(error, worst_balance < 1e-12_wp*maxval(abs(rec%rows(col_energy, :rec%filled))), &
         & 'E - E0 = W - D through the contacts')
   end subroutine test_massless_kkt

   !> r = 8 (the first contact period): the stops' energy at t = 0.125 s -> 0 at order > 1.5
   !> between dt = 2.5e-6 and 1.25e-6, and the tip's largest error on [0.08, 0.125] s against
   !> dt = 7.8125e-8 falls at order > 1 from dt = 2.5e-6 to 6.25e-7, with the same contact
   !> phases in the two finest runs.
   subroutine test_massless_convergence(error)
      type(error_type), allocatable, intent(out) :: error
      type(array_recorder) :: ref, a, b, c
      type(run_summary) :: sref, sa, sb, sc
      real(wp) :: ea, ec, order, da, db, stop_order
      call run_reduced_recorded(massless_scene(7.8125e-8_wp, 8), ref, sref, error)
      if (allocated(error)) return
      call run_reduced_recorded(massless_scene(2.5e-6_wp, 8), a, sa, error)
      if (allocated(error)) return
      call run_reduced_recorded(massless_scene(1.25e-6_wp, 8), b, sb, error)
      if (allocated(error)) return
      call run_reduced_recorded(massless_scene(6.25e-7_wp, 8), c, sc, error)
      if (allocated(error)) return
      ea = late_distance(a, ref)
      ec = late_distance(c, ref)
      order = log(ea/ec)/log(4.0_wp)
      da = a%rows(col_dissipated, a%filled)
      db = b%rows(col_dissipated, b%filled)
      stop_order = log(abs(da/db))/log(2.0_wp)
      call note('r = 8: error on [0.08, 0.125] s against dt = 7.8125e-8: '//real_text(ea)//' (dt = 2.5e-6), '// &
         & real_text(late_distance(b, ref))//' (1.25e-6), '//real_text(ec)//' m (6.25e-7): order '// &
         & real_text(order)//'; stops'' energy '//real_text(da)//', '//real_text(db)//' J (order '// &
         & real_text(stop_order)//'), work '//real_text(b%rows(col_work, b%filled))//' J; contact phases '// &
         & int_text(sa%impacts)//', '//int_text(sb%impacts)//', '//int_text(sc%impacts)//', '//int_text(sref%impacts))
      call check(error, sref%impacts > 0, 'the tip meets the stops'); if (allocated(error)) return
      call check(error, order > 1.0_wp, 'the tip converges at order > 1'); if (allocated(error)) return
      call check(error, stop_order > 1.5_wp, 'the stops'' energy -> 0 at order > 1.5'); if (allocated(error)) return
      call check(error, abs(db) < 1.0e-4_wp*b%rows(col_work, b%filled), 'the stops'' energy below 1e-4 of the work')
      if (allocated(error)) return
      call check(error, int(sc%impacts), int(sref%impacts), 'the same contact phases as the reference')
   end subroutine test_massless_convergence

   !> max |u_tip - reference| on [0.08, 0.125] s at the common record times (every 1e-5 s).
   function late_distance(a, ref) result(e)
      type(array_recorder), intent(in) :: a, ref
      real(wp) :: e
      e = maxval(abs(a%rows(col_u, 1:a%filled) - ref%rows(col_u, 1:ref%filled)), &
         & mask=a%rows(col_t, 1:a%filled) >= 0.08_wp - 1.0e-12_wp)
   end function late_distance

   !> The massless boundary (r = 8, mass damping, statistics) to step 40000 (past the first
   !> impacts), and the tube's massless span stops to step 6000, checkpointed, read back; both
   !> continued to t = 0.2 s: the records, q, d and the energy ledger to the bit.
   subroutine test_massless_resume(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = massless_scene(2.5e-6_wp, 8)
      scene%t_end = 0.2_wp
      scene%damping_mass = 2.0_wp
      scene%statistics = .true.
      scene%transient = 0.05_wp
      scene%batches = 4
      call resume_bits(scene, 40000_ik, error)
      if (allocated(error)) return
      ! The tube's three massless stops along the span (r = 8), checkpointed at step 6000.
      scene = tube(0.2_wp)
      scene%redistributed_mass = .true.
      scene%modes = 8
      scene%damping_mass = 2.0_wp
      scene%statistics = .true.
      scene%transient = 0.05_wp
      scene%batches = 4
      call resume_bits(scene, 6000_ik, error)
   end subroutine test_massless_resume

   !> A reduced run checkpointed at step `at` (after impacts), read back, both continued to
   !> t_end: the records, q, d and the ledger to the bit.
   subroutine resume_bits(scene, at, error)
      type(scene_type), intent(inout) :: scene
      integer(ik), intent(in) :: at
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = 'test_reduced_massless.checkpoint'
      type(reduced_model_type) :: reduced
      type(reduced_state_type) :: straight, resumed
      type(array_recorder) :: a, b
      type(run_summary) :: sa, sb
      integer(ik) :: records, snapshots, first
      call validate_scene(scene, 'test scene', error)
      if (allocated(error)) return
      call prepare_reduced(scene, 'test scene', reduced, error)
      if (allocated(error)) return
      call a%reserve(record_count(scene), 0_ik, scene%elements + 1, stop_count(scene))
      call b%reserve(record_count(scene), 0_ik, scene%elements + 1, stop_count(scene))
      call start_reduced(scene, reduced, straight, a, error)
      if (allocated(error)) return
      call run_reduced(scene, reduced, straight, a, sa, at)
      call check(error, sa%status == 'running' .and. straight%step == at + 1 .and. straight%impacts > 0, &
         & 'stopped at step '//int_text(at)//', after impacts')
      if (allocated(error)) return
      call write_reduced_checkpoint(path, scene, straight, a%filled, 0_ik, error)
      if (allocated(error)) return
      call read_reduced_checkpoint(path, scene, reduced, resumed, records, snapshots, error)
      call remove_file(path)
      if (allocated(error)) return
      first = a%filled + 1
      b%filled = a%filled
      call run_reduced(scene, reduced, straight, a, sa)
      call run_reduced(scene, reduced, resumed, b, sb)
      call check(error, sa%status == status_complete .and. sb%status == status_complete, 'both complete')
      if (allocated(error)) return
      call check(error, all(a%rows(:, first:a%filled) == b%rows(:, first:b%filled)) .and. a%filled == b%filled, &
         & 'the records after the checkpoint to the bit')
      if (allocated(error)) return
      call check(error, all(straight%q == resumed%q) .and. all(straight%d == resumed%d), 'q and d to the bit')
      if (allocated(error)) return
      call check(error, sa%damped == sb%damped .and. sa%dissipated == sb%dissipated .and. &
         & sa%energy_residual == sb%energy_residual .and. sa%impacts == sb%impacts, 'the ledger and the shocks')
   end subroutine resume_bits

   !> Read by the one reader (scene_from_text): damping (ratios), restitution and mass
   !> redistribution (tip stops and stops along the span) are accepted with modes > 0.
   subroutine test_validate(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: nl = new_line('a'), &
         & base = '&mesh modes = 5 /'//nl//'&damping ratio = 0.02 /'//nl//'&stops restitution = 0.7'
      type(scene_type) :: scene
      type(error_type), allocatable :: failure
      call scene_from_text(base//' /', 'in.nml', scene, failure)
      if (allocated(failure)) then
         call test_failed(error, 'damping and restitution with modes > 0 refused: '//failure%message)
         return
      end if
      call check(error, scene%modes == 5 .and. scene%damping_by_ratio .and. scene%restitution == 0.7_wp, &
         & 'the scene read')
      if (allocated(error)) return
      call scene_from_text('&mesh modes = 5 /'//nl//"&stops mass = 'redistributed' /", 'in.nml', scene, failure)
      if (allocated(failure)) then
         call test_failed(error, 'mass redistribution (tip stops) with modes > 0 refused: '//failure%message)
         return
      end if
      call check(error, scene%modes == 5 .and. scene%redistributed_mass, 'the massless boundary read')
      if (allocated(error)) return
      call scene_from_text('&beam length = 1.5 /'//nl//'&mesh elements = 30, modes = 5 /'//nl// &
         & "&stops mass = 'redistributed', x = 0.5, 1.0, 1.5, lower = -0.002, upper = 0.1, 0.2, 0.3 /", 'in.nml', &
         & scene, failure)
      if (allocated(failure)) then
         call test_failed(error, 'mass redistribution with stops along the span and modes > 0 refused: '// &
            & failure%message)
         return
      end if
      call check(error, scene%modes == 5 .and. scene%redistributed_mass .and. stop_count(scene) == 3, &
         & 'the massless boundary with stops along the span read')
   end subroutine test_validate
end module test_reduced_physics
