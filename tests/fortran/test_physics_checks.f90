!> validate_physics: every bad value of &damping and of the &stops keys restitution and
!> redistributed_mass refused with a message naming the source, group, key, value and the
!> allowed range; good scenes accepted.
module test_physics_checks
   use testing
   use beamstops, only: scene_type, law_none, law_compliance
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
      call refused(scene, [character(len=64) :: 'scene.nml: &damping mass_coefficient = -1', 'allowed: mass_coefficient >= 0'], &
         & error)
      if (allocated(error)) return
      scene = scene_type()
      scene%damping_stiffness = -1.0e-4_wp
      call refused(scene, [character(len=64) :: '&damping stiffness_coefficient = -0.0001', &
         & 'allowed: stiffness_coefficient >= 0'], error)
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
