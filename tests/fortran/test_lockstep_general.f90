!> The general lockstep loop (beamstops_lockstep_general: SPEC 13 with Rayleigh damping,
!> restitution and mass redistribution): every member of a group equals the same scene run alone
!> (simulate: advance_fused_general, or advance_fused for restitution alone) bit for bit, every
!> column of every record (the damped energy among them), every snapshot, the summary (the
!> ledger's damped energy, shocks, statistics). Groups of K = 3, 5, 13 (not multiples of the
!> vector width), with and without contact; members that cannot share C or M^rho are refused,
!> the message naming the member, the group and the key; an &ensemble with damping runs in
!> lockstep and gives the table of its members run one after the other.
module test_lockstep_general
   use testing
   use beamstops, only: scene_type, model_type, law_none, law_signorini, law_compliance, validate_scene, prepare_run, &
      & check_lockstep
   use beamstops_band_solve, only: band_diagonals, prepare_diagonals, diagonal_row
   use beamstops_band_solve_lockstep, only: lockstep_lanes
   use beamstops_band_solve_lockstep_general, only: lockstep_row
   use beamstops_model, only: build_model
   use test_support, only: base_scene
   use test_lockstep, only: members_of, compare_group, expect_refusal, compare_run_members, &
      & check_failing_member, same_bits
   implicit none
   private
   public :: collect_lockstep_general

contains

   !> Tests of the suite.
   subroutine collect_lockstep_general(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('lockstep_row: each lane equals diagonal_row to the bit, every row, J = 4..6, 19, 20', &
         & test_row_kernel), &
         & new_unittest('damping: K = 3, no stops, beta = 1/4, a and b, paper''s load and Euler start for some', &
         & test_damped_free), &
         & new_unittest('damping: K = 5, Signorini, beta = 1/2, different stops, omega, amplitude, cadences', &
         & test_damped_signorini), &
         & new_unittest('damping by ratio: K = 5, compliance 1e8, beta = 1/4', test_damped_compliance), &
         & new_unittest('damping: K = 13, J = 20, Signorini, beta = 1/4 (two chunks)', test_damped_thirteen), &
         & new_unittest('restitution: K = 5, e = 0 .. 1 per member, Signorini, undamped and damped', &
         & test_restitution), &
         & new_unittest('mass redistribution: K = 3 undamped, K = 5 damped (a only), Signorini', test_redistribution), &
         & new_unittest('&ensemble members = 6 with damping and restitution: in lockstep, the table of the members '// &
         & 'run one after the other', test_damped_ensemble), &
         & new_unittest('damped, with restitution: a member whose recorder fails stops; the others go on, still '// &
         & 'bit for bit', test_damped_failing_member), &
         & new_unittest('members that do not share C or the mass law are refused', test_refused_physics) &
         & ]
   end subroutine collect_lockstep_general

   !> lockstep_row against diagonal_row, lane by lane, every row of S, on random vectors.
   subroutine test_row_kernel(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: meshes(5) = [4, 5, 6, 19, 20]
      type(scene_type) :: scene
      type(model_type) :: model
      type(band_diagonals) :: s
      real(wp), allocatable :: x(:, :)
      real(wp) :: y(lockstep_lanes)
      integer :: a, row, k
      do a = 1, size(meshes)
         scene%elements = meshes(a)
         scene%dt = 1.0e-5_wp
         call build_model(scene, model, error)
         if (allocated(error)) return
         call prepare_diagonals(model%stiffness, s)
         if (allocated(x)) deallocate (x)
         allocate (x(lockstep_lanes, model%n))
         call random_number(x)
         x = x - 0.5_wp
         do row = 1, model%n
            call lockstep_row(s, x, row, y)
            do k = 1, lockstep_lanes
               if (.not. same_bits(y(k), diagonal_row(s, x(k, :), row))) then
                  call test_failed(error, 'J = '//int_text(meshes(a))//', row '//int_text(row)//', lane '// &
                     & int_text(k))
                  return
               end if
            end do
         end do
      end do
   end subroutine test_row_kernel

   !> Rayleigh damping C = a M + b S on every member of a list of scenes.
   subroutine damp(scenes, a, b)
      type(scene_type), intent(inout) :: scenes(:)
      real(wp), intent(in) :: a, b
      scenes%damping_mass = a
      scenes%damping_stiffness = b
   end subroutine damp

   subroutine test_damped_free(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.25_wp, law_none, 0.2_wp), 3, .true.)
      call damp(scenes, 2.0_wp, 1.0e-4_wp)
      call compare_group(scenes, error)
   end subroutine test_damped_free

   subroutine test_damped_signorini(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.25_wp), 5, .false.)
      call damp(scenes, 1.0_wp, 2.0e-4_wp)
      call compare_group(scenes, error, contact=.true.)
   end subroutine test_damped_signorini

   subroutine test_damped_compliance(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = members_of(base_scene(19, 4.0e-6_wp, 0.25_wp, law_compliance, 0.15_wp), 5, .true.)
      scenes%damping_by_ratio = .true.
      scenes%damping_ratio(1) = 0.02_wp
      scenes%damping_ratio(2) = 0.05_wp
      call compare_group(scenes, error, contact=.true.)
   end subroutine test_damped_compliance

   subroutine test_damped_thirteen(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = members_of(base_scene(20, 2.0e-5_wp, 0.25_wp, law_signorini, 0.3_wp), 13, .true.)
      call damp(scenes, 0.5_wp, 5.0e-5_wp)
      call compare_group(scenes, error, contact=.true.)
   end subroutine test_damped_thirteen

   !> Each member its own restitution coefficient, 0 (the paper's projection) to 1.
   subroutine test_restitution(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      integer :: k
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.25_wp), 5, .false.)
      do k = 1, size(scenes)
         scenes(k)%restitution = real(k - 1, wp)/4
      end do
      call compare_group(scenes, error, contact=.true.)
      if (allocated(error)) return
      call damp(scenes, 1.0_wp, 1.0e-4_wp)
      call compare_group(scenes, error, contact=.true.)
   end subroutine test_restitution

   !> The massless tip (SPEC 10), without damping and with mass-proportional damping (the only
   !> kind the massless tip takes).
   subroutine test_redistribution(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.25_wp, law_signorini, 0.2_wp), 3, .true.)
      scenes%redistributed_mass = .true.
      call compare_group(scenes, error, contact=.true.)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.2_wp), 5, .false.)
      scenes%redistributed_mass = .true.
      call damp(scenes, 3.0_wp, 0.0_wp)
      call compare_group(scenes, error, contact=.true.)
   end subroutine test_redistribution

   !> A damped group (restitution for some) with a member whose recorder fails after its second
   !> block: it stops 'failed', its lanes go to rest, the others still equal their runs alone.
   subroutine test_damped_failing_member(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.25_wp), 3, .false.)
      call damp(scenes, 1.0_wp, 1.0e-4_wp)
      scenes(2)%restitution = 0.6_wp
      scenes(3)%restitution = 0.3_wp
      call check_failing_member(scenes, error)
   end subroutine test_damped_failing_member

   !> An &ensemble of a damped scene with restitution: its members 2..K are accepted by
   !> check_lockstep (so run_members runs them in lockstep) and the ensemble table is that of the
   !> members run one after the other.
   subroutine test_damped_ensemble(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(scene_type), allocatable :: scenes(:)
      type(model_type) :: model
      scene = base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.3_wp)
      scene%members = 6
      scene%perturbation = 1.0e-4_wp
      scene%seed = 5
      scene%damping_by_ratio = .true.
      scene%damping_ratio = 0.01_wp
      scene%restitution = 0.5_wp
      call validate_scene(scene, 'test ensemble', error)
      if (allocated(error)) return
      call prepare_run(scene, 'test ensemble', model, error)
      if (allocated(error)) return
      allocate (scenes(5), source=scene)
      scenes%members = 1
      call check_lockstep(scenes, model, error)
      if (allocated(error)) then
         error%message = 'the damped ensemble is not run in lockstep: '//error%message
         return
      end if
      call compare_run_members(scene, error)
   end subroutine test_damped_ensemble

   !> Members whose damping or mass law differs from member 1's are refused, the message naming
   !> the member and the key; restitution may differ (accepted).
   subroutine test_refused_physics(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scenes(3)
      type(model_type) :: model
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(3)%damping_mass = 1.0_wp
      call expect_refusal(scenes, 'member 3: &damping mass_coefficient', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      call damp(scenes, 1.0_wp, 1.0e-4_wp)
      scenes(2)%damping_stiffness = 2.0e-4_wp
      call expect_refusal(scenes, 'member 2: &damping stiffness_coefficient', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes%damping_by_ratio = .true.
      scenes%damping_ratio(1) = 0.02_wp
      scenes%damping_ratio(2) = 0.02_wp
      scenes(3)%damping_ratio(2) = 0.03_wp
      call expect_refusal(scenes, 'member 3: &damping ratio', error)
      if (allocated(error)) return
      scenes(3)%damping_ratio(2) = 0.02_wp
      scenes(2)%damping_modes = [1, 3]
      call expect_refusal(scenes, 'member 2: &damping modes', error)
      if (allocated(error)) return
      scenes(2)%damping_modes = [1, 2]
      scenes(2)%damping_by_ratio = .false.
      call expect_refusal(scenes, 'member 2: &damping is given by mass_coefficient', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(2)%redistributed_mass = .true.
      call expect_refusal(scenes, 'member 2: &stops mass', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(2)%stop_nodes = [10, 19]
      scenes(2)%stop_lower = [-0.05_wp, -0.1_wp]
      scenes(2)%stop_upper = [0.05_wp, 0.1_wp]
      call expect_refusal(scenes, 'member 2: &stops nodes (or x) gives 2 stops along the span', error)
      if (allocated(error)) return
      ! restitution does not enter A: members with different e are accepted
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(2)%restitution = 0.7_wp
      call validate_scene(scenes(1), 'member 1', error)
      if (allocated(error)) return
      call build_model(scenes(1), model, error)
      if (allocated(error)) return
      call check_lockstep(scenes, model, error)
   end subroutine test_refused_physics
end module test_lockstep_general
