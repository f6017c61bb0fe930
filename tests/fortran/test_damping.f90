!> Rayleigh damping (SPEC 8): the free decay of one mode, the ratio form, the energy balance
!> with the damping's column, and zero damping equal to the undamped engine.
module test_damping
   use testing
   use test_support, only: run_recorded, same_columns, band_eigenvalues, balance_defect
   use physics_support, only: tube_scene, open_run, modes, tip_decrement
   use beamstops, only: ik, scene_type, model_type, build_model, state_type, array_recorder, run_summary, &
      & law_none, law_signorini, steps_of
   use beamstops_scheme, only: advance
   use beamstops_checkpoint, only: write_checkpoint, read_checkpoint
   use beamstops_files, only: remove_file
   use beamstops_namelist, only: scene_from_text
   use beamstops_recorder, only: col_t, col_u, col_energy, col_work, col_dissipated, col_damped
   implicit none
   private
   public :: collect_damping

contains

   !> Tests of the suite.
   subroutine collect_damping(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('free decay of mode 1: log decrement 2 pi zeta/sqrt(1-zeta^2) to O(dt^2)', test_decrement), &
         & new_unittest('ratio form: zeta at both chosen modes; one ratio: both equal', test_ratio_form), &
         & new_unittest('ratio form on a fine mesh (J = 1000): the modes are the cantilever''s', test_ratio_fine_mesh), &
         & new_unittest('balance E - E0 = W - D - damped to round-off (fused and reference paths)', test_balance), &
         & new_unittest('zero damping: the undamped engine to the bit', test_zero_damping), &
         & new_unittest('stops along the span (tube), damped: balance E - E0 = W - D - damped', test_span_balance), &
         & new_unittest('a damped run resumed from a checkpoint continues with the same bits', test_resume) &
         & ]
   end subroutine collect_damping

   !> The paper's beam without support motion and stops, J elements, beta = 1/4.
   function quiet_scene(elements, dt, t_end) result(scene)
      integer, intent(in) :: elements
      real(wp), intent(in) :: dt, t_end
      type(scene_type) :: scene
      scene%elements = elements
      scene%dt = dt
      scene%t_end = t_end
      scene%beta = 0.25_wp
      scene%amplitude = 0
      scene%law = law_none
   end function quiet_scene

   !> Log decrement of the tip displacement of a free decay from mode 1 (zeta_1 = zeta_2 = 0.02).
   subroutine decay(dt, decrement, error)
      real(wp), intent(in) :: dt
      real(wp), intent(out) :: decrement
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(state_type) :: state
      type(array_recorder) :: rec
      real(wp), allocatable :: kappa(:), v(:, :)
      decrement = 0
      scene = quiet_scene(8, dt, 1.2_wp)
      scene%damping_by_ratio = .true.
      scene%damping_ratio = [0.02_wp, 0.02_wp]
      call build_model(scene, model, error)
      if (allocated(error)) return
      call modes(model, kappa, v, error)
      if (allocated(error)) return
      call open_run(scene, model, state, rec, error, u0=0.01_wp*v(:, 1)/v(model%tip, 1), v0=0*v(:, 1))
      if (allocated(error)) return
      call advance(scene, model, state, rec, steps_of(scene))
      call tip_decrement(rec, decrement, error)
   end subroutine decay

   subroutine test_decrement(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: zeta = 0.02_wp, pi = acos(-1.0_wp)
      real(wp) :: expected, d1, d2, e1, e2
      expected = 2*pi*zeta/sqrt(1 - zeta**2)
      call decay(2.0e-3_wp, d1, error)
      if (allocated(error)) return
      call decay(1.0e-3_wp, d2, error)
      if (allocated(error)) return
      e1 = abs(d1/expected - 1)
      e2 = abs(d2/expected - 1)
      call note('log decrement '//real_text(d2)//' (expected '//real_text(expected)//'); relative error '// &
         & real_text(e1)//' at dt = 2e-3, '//real_text(e2)//' at dt = 1e-3, order '//real_text(log(e1/e2)/log(2.0_wp)))
      call check(error, e2 < 1.0e-3_wp, 'decrement within 1e-3 at dt = 1e-3')
      if (allocated(error)) return
      call check(error, log(e1/e2)/log(2.0_wp) > 1.7_wp, 'second order in dt')
   end subroutine test_decrement

   subroutine test_ratio_form(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: failure
      type(scene_type) :: scene
      type(model_type) :: model
      real(wp), allocatable :: w(:)
      integer :: i
      scene = quiet_scene(19, 1.0e-5_wp, 0.01_wp)
      scene%damping_by_ratio = .true.
      scene%damping_ratio = [0.01_wp, 0.03_wp]
      scene%damping_modes = [1, 3]
      call build_model(scene, model, error)
      if (allocated(error)) return
      call band_eigenvalues(model%stiffness, model%mass, w, error)
      if (allocated(error)) return
      do i = 1, 2
         ! w: dsbgv's S v = kappa M v, accurate to eps kappa_max (1e-10 of kappa_1 at J = 19)
         call check(error, model%damping_omega(i), sqrt(w(scene%damping_modes(i))), 'frequency of mode '// &
            & int_text(scene%damping_modes(i)), thr=1.0e-9_wp, rel=.true.)
         if (allocated(error)) return
         call check(error, model%damping_a/(2*model%damping_omega(i)) + model%damping_b*model%damping_omega(i)/2, &
            & scene%damping_ratio(i), 'zeta at mode '//int_text(scene%damping_modes(i)), thr=1.0e-13_wp, rel=.true.)
         if (allocated(error)) return
      end do
      call check(error, model%damped, 'the model is damped')
      if (allocated(error)) return
      ! one ratio read: both modes get it
      call scene_from_text('&mesh elements = 19 / &time dt = 1e-5, t_end = 0.01 / &damping ratio = 0.05 /', &
         & 'one.nml', scene, error)
      if (allocated(error)) return
      call build_model(scene, model, error)
      if (allocated(error)) return
      do i = 1, 2
         call check(error, model%damping_a/(2*model%damping_omega(i)) + model%damping_b*model%damping_omega(i)/2, &
            & 0.05_wp, 'one ratio, zeta at mode '//int_text(i), thr=1.0e-13_wp, rel=.true.)
         if (allocated(error)) return
      end do
      ! two ratios read, the second 0: that pair (b < 0 here), not one ratio for both
      call scene_from_text('&mesh elements = 19 / &time dt = 1e-5, t_end = 0.01 / &damping ratio = 0.05, 0 /', &
         & 'two.nml', scene, error)
      if (allocated(error)) return
      call build_model(scene, model, failure)
      call check(error, allocated(failure), 'ratio = 0.05, 0 is refused (b < 0)')
      if (allocated(error)) return
      call check(error, index(failure%message, 'ratio = 0.05, 0 ') > 0, 'the message gives the ratios: '// &
         & failure%message)
   end subroutine test_ratio_form

   !> The frequencies the ratio form uses are accurate at the low end on fine meshes, where dsbgv's
   !> eigenvalues of S v = kappa M v are accurate only to eps kappa_max (kappa_1 off by 6 % at
   !> J = 1000): they are the clamped-free cantilever's, beta_i^2 sqrt(k2)/L^2, to 1e-5 (the
   !> elements' O(h^4) is 1e-13 there; the rounding of S and M itself leaves about 1e-6).
   subroutine test_ratio_fine_mesh(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      ! beta_i L of the clamped-free beam: cos(x) cosh(x) = -1
      real(wp), parameter :: beta_l(2) = [1.8751040687119611_wp, 4.6940911329741746_wp]
      real(wp) :: analytic
      integer :: i
      call scene_from_text('&mesh elements = 1000 / &time dt = 1e-6, t_end = 1e-5 / &damping ratio = 0.02 /', &
         & 'fine.nml', scene, error)
      if (allocated(error)) return
      call build_model(scene, model, error)
      if (allocated(error)) return
      do i = 1, 2
         analytic = beta_l(i)**2*sqrt(scene%k2)/scene%length**2
         call check(error, model%damping_omega(i), analytic, 'frequency of mode '//int_text(i), thr=1.0e-5_wp, &
            & rel=.true.)
         if (allocated(error)) return
         call check(error, model%damping_a/(2*model%damping_omega(i)) + model%damping_b*model%damping_omega(i)/2, &
            & 0.02_wp, 'zeta at mode '//int_text(i), thr=1.0e-13_wp, rel=.true.)
         if (allocated(error)) return
      end do
   end subroutine test_ratio_fine_mesh

   subroutine test_balance(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(state_type) :: state
      type(array_recorder) :: fused, reference
      type(run_summary) :: summary
      integer(ik) :: j
      real(wp) :: gap
      scene = quiet_scene(8, 5.0e-5_wp, 0.5_wp)
      scene%amplitude = 0.2_wp   ! the paper's support motion: work is done
      scene%damping_mass = 1.0_wp
      scene%damping_stiffness = 1.0e-4_wp
      call run_recorded(scene, fused, summary, error)
      if (allocated(error)) return
      call note('fused: defect '//real_text(balance_defect(fused))//', damped '// &
         & real_text(fused%rows(col_damped, fused%filled))//' J, work '//real_text(fused%rows(col_work, fused%filled))//' J')
      call check(error, balance_defect(fused) < 1.0e-12_wp, 'fused path: balance within 1e-12 of max |E|')
      if (allocated(error)) return
      call check(error, fused%rows(col_damped, fused%filled) > 0, 'the damping takes energy')
      if (allocated(error)) return
      do j = 2, fused%filled
         if (fused%rows(col_damped, j) < fused%rows(col_damped, j - 1)) then
            call test_failed(error, 'the damped column decreases at record '//int_text(j))
            return
         end if
      end do
      call check(error, maxval(abs(fused%rows(col_dissipated, 1:fused%filled))), 0.0_wp, 'no stops, nothing dissipated')
      if (allocated(error)) return
      call open_run(scene, model, state, reference, error)
      if (allocated(error)) return
      state%lapack_solve = .true.
      call advance(scene, model, state, reference, steps_of(scene))
      call check(error, balance_defect(reference) < 1.0e-12_wp, 'reference path: balance within 1e-12 of max |E|')
      if (allocated(error)) return
      gap = maxval(abs(fused%rows(col_u, 1:fused%filled) - reference%rows(col_u, 1:reference%filled)))
      call note('fused vs reference, tip: '//real_text(gap)//' m')
      call check(error, gap < 1.0e-12_wp, 'fused and reference paths agree to round-off')
   end subroutine test_balance

   subroutine test_zero_damping(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: plain, zero
      type(array_recorder) :: a, b
      type(run_summary) :: summary
      plain%elements = 8
      plain%dt = 5.0e-5_wp
      plain%t_end = 0.5_wp
      plain%beta = 0.25_wp
      zero = plain
      zero%damping_mass = 0
      zero%damping_stiffness = 0
      zero%damping_by_ratio = .true.
      zero%damping_ratio = 0
      call run_recorded(plain, a, summary, error)
      if (allocated(error)) return
      call run_recorded(zero, b, summary, error)
      if (allocated(error)) return
      call same_columns(error, a, b)
      if (allocated(error)) return
      call check(error, maxval(abs(b%rows(col_damped, 1:b%filled))), 0.0_wp, 'nothing damped')
   end subroutine test_zero_damping

   subroutine test_span_balance(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      scene = tube_scene(2.0e-5_wp, 1.0_wp)
      scene%damping_by_ratio = .true.
      scene%damping_ratio = [0.02_wp, 0.02_wp]
      call run_recorded(scene, rec, summary, error)
      if (allocated(error)) return
      call note('tube, zeta = 0.02: defect '//real_text(balance_defect(rec))//', damped '// &
         & real_text(rec%rows(col_damped, rec%filled))//' J, stops '//real_text(rec%rows(col_dissipated, rec%filled))// &
         & ' J, '//int_text(summary%impacts)//' contact phases')
      call check(error, summary%impacts > 0, 'the stops act')
      if (allocated(error)) return
      call check(error, balance_defect(rec) < 1.0e-10_wp, 'balance within 1e-10 of max |E|')
   end subroutine test_span_balance

   subroutine test_resume(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = 'test_damping_resume.checkpoint'
      type(scene_type) :: scene
      type(model_type) :: model
      type(state_type) :: straight, resumed
      type(array_recorder) :: a, b
      integer(ik) :: records, snapshots
      scene = quiet_scene(8, 5.0e-5_wp, 0.2_wp)
      scene%amplitude = 0.2_wp
      scene%law = law_signorini
      scene%lower = -0.02_wp
      scene%upper = 0.02_wp
      scene%damping_mass = 2.0_wp
      scene%damping_stiffness = 2.0e-4_wp
      call open_run(scene, model, straight, a, error)
      if (allocated(error)) return
      call advance(scene, model, straight, a, 1000_ik)
      call write_checkpoint(path, scene, straight, a%filled, 0_ik, error)
      if (allocated(error)) return
      call read_checkpoint(path, scene, model, resumed, records, snapshots, error)
      call remove_file(path)
      if (allocated(error)) return
      call b%reserve(a%filled + 4000, 0_ik, scene%elements + 1)
      call advance(scene, model, straight, a, 4000_ik)
      call advance(scene, model, resumed, b, 4000_ik)
      call check(error, all(straight%u == resumed%u) .and. all(straight%d == resumed%d), 'u and d to the bit')
      if (allocated(error)) return
      call check(error, straight%damped == resumed%damped .and. straight%damped > 0, 'the damped energy to the bit')
   end subroutine test_resume
end module test_damping
