!> validate_physics: every bad value of &damping and of the &stops keys restitution and
!> redistributed_mass refused with a message naming the source, group, key, value and the
!> allowed range; good scenes accepted.
module test_physics_checks
   use testing
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf, ieee_quiet_nan
   use beamstops, only: scene_type, law_none, law_compliance, model_type, build_model
   use beamstops_physics_checks, only: validate_physics
   implicit none
   private
   public :: collect_physics_checks

contains

   !> Tests of the suite.
   subroutine collect_physics_checks(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('good scenes pass', test_good), &
         & new_unittest('restitution out of [0, 1], or > 0 with law compliance or none', test_restitution), &
         & new_unittest('negative coefficients, ratio with coefficients, ratio out of [0, 1), bad modes', test_damping), &
         & new_unittest('infinite, NaN and huge Rayleigh coefficients refused, the bound shown below the true one', &
         &              test_damping_bounds), &
         & new_unittest('the coefficients &damping ratio gives (zeta < 1, any two modes) are within the bounds', &
         &              test_damping_bounds_hold_ratios), &
         & new_unittest('redistributed mass: beta = 0, law, stiffness damping, neighbouring stop nodes', &
         &              test_redistributed) &
         & ]
   end subroutine collect_physics_checks

   !> The scene must be refused with a message containing every needle.
   subroutine refused(scene, needles, error)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: needles(:)
      type(error_type), allocatable, intent(inout) :: error
      type(error_type), allocatable :: outcome
      integer :: i
      call validate_physics(scene, 'scene.nml', outcome)
      if (.not. allocated(outcome)) then
         call test_failed(error, 'accepted, expected a message with '''//trim(needles(1))//'''')
         return
      end if
      call note(outcome%message)
      do i = 1, size(needles)
         if (index(outcome%message, trim(needles(i))) == 0) then
            call test_failed(error, 'the message '''//outcome%message//''' lacks '''//trim(needles(i))//'''')
            return
         end if
      end do
   end subroutine refused

   subroutine test_good(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      call validate_physics(scene, 'scene.nml', error)
      if (allocated(error)) return
      scene%damping_by_ratio = .true.
      scene%damping_ratio = [0.02_wp, 0.0_wp]
      scene%restitution = 1
      call validate_physics(scene, 'scene.nml', error)
      if (allocated(error)) return
      scene = scene_type()
      scene%damping_mass = 0.5_wp
      scene%redistributed_mass = .true.
      call validate_physics(scene, 'scene.nml', error)
   end subroutine test_good

   subroutine test_restitution(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      character(len=64) :: needles(4)
      scene%restitution = 1.5_wp
      needles = [character(len=64) :: 'scene.nml: &stops restitution = 1.5 is out of range', &
         & 'allowed: 0 <= restitution <= 1', '', '']
      call refused(scene, needles(1:2), error)
      if (allocated(error)) return
      scene%restitution = -0.1_wp
      call refused(scene, [character(len=64) :: 'restitution = -0.1', 'allowed: 0 <= restitution <= 1'], error)
      if (allocated(error)) return
      scene%restitution = 0.5_wp
      scene%law = law_compliance
      scene%stiffness_per_mass = 1e8_wp
      call refused(scene, [character(len=64) :: '&stops restitution = 0.5', 'law = ''compliance''', &
         & 'allowed: restitution = 0 unless'], error)
      if (allocated(error)) return
      scene%law = law_none
      call refused(scene, [character(len=64) :: 'law = ''none'''], error)
   end subroutine test_restitution

   subroutine test_damping(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene%damping_mass = -1
      call refused(scene, [character(len=64) :: 'scene.nml: &damping mass_coefficient = -1', &
         & 'allowed: 0 <= mass_coefficient <= 1.69e+08 1/s'], error)
      if (allocated(error)) return
      scene = scene_type()
      scene%damping_stiffness = -1.0e-4_wp
      call refused(scene, [character(len=64) :: '&damping stiffness_coefficient = -0.0001', &
         & 'allowed: 0 <= stiffness_coefficient <= 7.62 s'], error)
      if (allocated(error)) return
      scene = scene_type()
      scene%damping_by_ratio = .true.
      scene%damping_ratio = 0.02_wp
      scene%damping_mass = 1
      call refused(scene, [character(len=64) :: '&damping ratio is given together with mass_coefficient', &
         & 'allowed: either the ratios or the coefficients'], error)
      if (allocated(error)) return
      scene%damping_mass = 0
      scene%damping_ratio = [0.02_wp, 1.0_wp]
      call refused(scene, [character(len=64) :: '&damping ratio = 1 is out of range', &
         & 'allowed: 0 <= ratio < 1'], error)
      if (allocated(error)) return
      scene%damping_ratio = [-0.01_wp, 0.0_wp]
      call refused(scene, [character(len=64) :: 'ratio = -0.01'], error)
      if (allocated(error)) return
      scene%damping_ratio = 0.02_wp
      scene%damping_modes = [2, 2]
      call refused(scene, [character(len=64) :: '&damping modes = 2, 2 is out of range', &
         & 'two distinct modes', '1 <= mode <= 2 elements = 38'], error)
      if (allocated(error)) return
      scene%damping_modes = [0, 1]
      call refused(scene, [character(len=64) :: 'modes = 0, 1'], error)
      if (allocated(error)) return
      scene%damping_modes = [1, 39]
      call refused(scene, [character(len=64) :: 'modes = 1, 39'], error)
   end subroutine test_damping

   !> mass_coefficient = Inf, 1e150 and stiffness_coefficient = 1e100 were accepted: the run
   !> diverged at t = 0 and its diverged output replaced an earlier complete one.
   subroutine test_damping_bounds(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(error_type), allocatable :: outcome
      real(wp) :: inf, bound
      inf = ieee_value(1.0_wp, ieee_positive_inf)
      scene%damping_mass = inf
      call refused(scene, [character(len=96) :: 'scene.nml: &damping mass_coefficient = Inf is out of range', &
         & 'allowed: 0 <= mass_coefficient <= 1.69e+08 1/s', 'sqrt(kappa_tilde) = 845083 rad/s'], error)
      if (allocated(error)) return
      scene%damping_mass = 1.0e150_wp
      call refused(scene, [character(len=64) :: 'mass_coefficient = 1e+150 is out of range'], error)
      if (allocated(error)) return
      scene%damping_mass = ieee_value(1.0_wp, ieee_quiet_nan)
      call refused(scene, [character(len=64) :: 'mass_coefficient = NaN is out of range'], error)
      if (allocated(error)) return
      scene = scene_type()
      scene%damping_stiffness = inf
      call refused(scene, [character(len=96) :: 'stiffness_coefficient = Inf is out of range', &
         & 'allowed: 0 <= stiffness_coefficient <= 7.62 s', 'omega_1 = 1.8751^2 sqrt(k2)/length^2 = 26.2 rad/s'], error)
      if (allocated(error)) return
      scene%damping_stiffness = 1.0e100_wp
      call refused(scene, [character(len=64) :: 'stiffness_coefficient = 1e+100 is out of range'], error)
      if (allocated(error)) return
      ! At the bound (to round-off), accepted; just beyond it, refused, beyond the bound as shown too.
      bound = 200/(1.8751040687119611_wp**2*sqrt(scene%k2)/scene%length**2)
      scene%damping_stiffness = bound*(1 - 4*epsilon(1.0_wp))
      call validate_physics(scene, 'scene.nml', error)
      if (allocated(error)) return
      scene%damping_stiffness = bound*(1 + 4*epsilon(1.0_wp))
      call validate_physics(scene, 'scene.nml', outcome)
      call check(error, allocated(outcome), 'just beyond the bound '//real_text(bound)//' refused')
      if (allocated(error)) return
      call check(error, index(outcome%message, '<= 7.62 s') > 0 .and. bound >= 7.62_wp, &
         & 'the bound is shown rounded down: '//outcome%message)
      if (allocated(error)) return
      scene = scene_type()
      bound = 200*sqrt(24.0_wp*420*19**2/37*scene%k2)*(scene%elements/scene%length)**2
      scene%damping_mass = bound*(1 - 4*epsilon(1.0_wp))
      call validate_physics(scene, 'scene.nml', error)
      if (allocated(error)) return
      scene%damping_mass = bound*(1 + 4*epsilon(1.0_wp))
      call refused(scene, [character(len=64) :: 'allowed: 0 <= mass_coefficient <= 1.69e+08 1/s'], error)
      if (allocated(error)) return
      ! The bounds follow the scene: a shorter, stiffer beam (higher frequencies) allows more a, less b.
      scene = scene_type()
      scene%length = 0.1_wp
      scene%damping_mass = 1.0e10_wp
      call validate_physics(scene, 'scene.nml', error)
      if (allocated(error)) return
      scene%damping_mass = 0
      scene%damping_stiffness = 1
      call refused(scene, [character(len=64) :: 'stiffness_coefficient = 1 is out of range'], error)
   end subroutine test_damping_bounds

   !> The ratio form gives a <= 2 zeta omega_i and b <= 2 zeta/omega_j at its two modes i < j
   !> (a, b >= 0): within the bounds for any ratios below 1 at any two modes, the highest
   !> included; the model's a and b, given as coefficients, are accepted.
   subroutine test_damping_bounds_hold_ratios(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: cases = 6
      integer, parameter :: elements(cases) = [19, 19, 19, 4, 60, 60]
      integer, parameter :: modes(2, cases) = reshape([37, 38, 1, 2, 36, 38, 1, 8, 119, 120, 1, 120], [2, cases])
      real(wp), parameter :: ratios(2, cases) = reshape([0.999_wp, 0.999_wp, 0.999_wp, 0.999_wp, 0.8_wp, 0.9_wp, &
         & 0.999_wp, 0.999_wp, 0.999_wp, 0.999_wp, 0.5_wp, 0.999_wp], [2, cases])
      type(scene_type) :: scene, coefficients
      type(model_type) :: model
      integer :: i
      do i = 1, cases
         scene = scene_type()
         scene%elements = elements(i)
         scene%damping_by_ratio = .true.
         scene%damping_ratio = ratios(:, i)
         scene%damping_modes = modes(:, i)
         call build_model(scene, model, error)
         if (allocated(error)) return
         call note('J = '//int_text(elements(i))//', modes '//int_text(modes(1, i))//', '//int_text(modes(2, i))// &
            & ': a = '//real_text(model%damping_a)//' 1/s, b = '//real_text(model%damping_b)//' s')
         coefficients = scene_type()
         coefficients%elements = elements(i)
         coefficients%damping_mass = model%damping_a
         coefficients%damping_stiffness = model%damping_b
         call validate_physics(coefficients, 'scene.nml', error)
         if (allocated(error)) return
      end do
   end subroutine test_damping_bounds_hold_ratios

   subroutine test_redistributed(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene%redistributed_mass = .true.
      scene%beta = 0
      call refused(scene, [character(len=64) :: 'scene.nml: &stops mass = ''redistributed'' needs beta > 0'], error)
      if (allocated(error)) return
      scene%beta = 0.25_wp
      scene%law = law_none
      call refused(scene, [character(len=64) :: 'mass = ''redistributed''', 'law = ''none''', 'allowed: law = ''signorini'''], &
         & error)
      if (allocated(error)) return
      scene = scene_type()
      scene%redistributed_mass = .true.
      scene%damping_stiffness = 1.0e-4_wp
      call refused(scene, [character(len=64) :: 'stiffness-proportional', 'allowed: mass_coefficient alone'], error)
      if (allocated(error)) return
      scene = scene_type()
      scene%redistributed_mass = .true.
      scene%stop_nodes = [18, 19]
      scene%stop_lower = [-0.1_wp, -0.1_wp]
      scene%stop_upper = [0.1_wp, 0.1_wp]
      call refused(scene, [character(len=64) :: 'neighbouring nodes 18 and 19'], error)
   end subroutine test_redistributed
end module test_physics_checks
