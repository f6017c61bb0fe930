!> The lockstep loop with stops along the span (beamstops_lockstep_span: SPEC 13 with SPEC 7):
!> every member of a group on the tube of input/tube_supports.nml (supports at 1/3 and 2/3 of the
!> span, stops at the tip) equals the same scene run alone (simulate: advance_span) bit for bit,
!> every column of every record, the stops' records (u~ and reaction of each stop), every
!> snapshot, the summary (ledger, shocks, statistics). Members differ in omega, amplitude, the
!> stops' gaps, the record and snapshot cadences, and in restitution; groups of K = 3 and 5 (not
!> multiples of the vector width), with and without contact, damped, with massless stops; a run
!> of two blocks; a member whose recorder fails; an &ensemble. Members whose stops are not on
!> member 1's nodes are refused.
module test_lockstep_span
   use testing
   use beamstops, only: scene_type, model_type, run_summary, validate_scene, prepare_lockstep
   use test_lockstep, only: expect_refusal, compare_run_members, compare_members, check_failing_member
   use test_support, only: tube
   implicit none
   private
   public :: collect_lockstep_span

contains

   !> Tests of the suite.
   subroutine collect_lockstep_span(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('tube: K = 3, contact at the supports and the tip, two blocks', test_three_contact), &
         & new_unittest('tube: K = 5, contact, restitution e = 0 .. 1 per member', test_five_restitution), &
         & new_unittest('tube: K = 5, gaps too wide for contact', test_five_free), &
         & new_unittest('tube: K = 3, Rayleigh damping a and b, contact', test_three_damped), &
         & new_unittest('tube: K = 3, massless stops (mass redistribution), contact', test_three_massless), &
         & new_unittest('tube: K = 3, member 2''s recorder fails in its second block: it stops, the others go on '// &
         & 'bit for bit', test_failing_member), &
         & new_unittest('tube: &ensemble members = 6 in lockstep, the table of the members run one after the other', &
         & test_ensemble), &
         & new_unittest('members whose stops are not on member 1''s nodes are refused', test_refused_nodes) &
         & ]
   end subroutine collect_lockstep_span

   !> K members of the tube, member k varied by k: omega, amplitude, the gaps (times `gap`),
   !> the record and snapshot cadences.
   function tube_members(k_members, t_end, gap) result(scenes)
      integer, intent(in) :: k_members
      real(wp), intent(in) :: t_end, gap
      type(scene_type) :: scenes(k_members)
      integer :: k
      real(wp) :: s
      do k = 1, k_members
         scenes(k) = tube(t_end)
         s = real(k - 1, wp)/max(1, k_members - 1)
         scenes(k)%omega = 60.0_wp + 40.0_wp*s
         scenes(k)%amplitude = 0.004_wp - 0.001_wp*s
         scenes(k)%stop_lower = gap*[-0.0005_wp - 0.0002_wp*mod(k, 3), -0.0007_wp, -0.001_wp - 0.0005_wp*s]
         scenes(k)%stop_upper = gap*[0.0006_wp, 0.0005_wp + 0.0003_wp*s, 0.0012_wp]
         scenes(k)%record_every = 1 + mod(k - 1, 3)*2
         scenes(k)%snapshot_every = merge(0, 131*k, mod(k, 3) == 0)
      end do
   end function tube_members

   subroutine test_three_contact(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      ! 10000 steps: two blocks of the loop (block_steps = 8192)
      scenes = tube_members(3, 0.2_wp, 1.0_wp)
      call compare_span_group(scenes, error, contact=.true.)
   end subroutine test_three_contact

   subroutine test_five_restitution(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      integer :: k
      scenes = tube_members(5, 0.1_wp, 1.0_wp)
      do k = 1, size(scenes)
         scenes(k)%restitution = real(k - 1, wp)/4
      end do
      call compare_span_group(scenes, error, contact=.true.)
   end subroutine test_five_restitution

   subroutine test_five_free(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = tube_members(5, 0.1_wp, 1000.0_wp)
      call compare_span_group(scenes, error, contact=.false.)
   end subroutine test_five_free

   subroutine test_three_damped(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = tube_members(3, 0.1_wp, 1.0_wp)
      scenes%damping_mass = 2.0_wp
      scenes%damping_stiffness = 1.0e-5_wp
      call compare_span_group(scenes, error, contact=.true.)
   end subroutine test_three_damped

   subroutine test_three_massless(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = tube_members(3, 0.1_wp, 1.0_wp)
      scenes%redistributed_mass = .true.
      call compare_span_group(scenes, error, contact=.true.)
   end subroutine test_three_massless

   !> Member 2's recorder holds 3000 records (every 3rd step: full at step 9000, in the second
   !> block): member 2 stops 'failed' at the end of that block, its lanes go to rest, members 1
   !> and 3 still equal their runs alone.
   subroutine test_failing_member(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = tube_members(3, 0.4_wp, 1.0_wp)
      scenes(2)%record_every = 3
      call check_failing_member(scenes, error, stops=.true.)
   end subroutine test_failing_member

   !> An &ensemble of the tube (perturbed u0): run_members runs members 2..6 in the span loop;
   !> its table equals that of the members run one after the other (compare_run_members).
   subroutine test_ensemble(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(scene_type), allocatable :: scenes(:)
      type(model_type) :: model
      scenes = tube_members(1, 0.1_wp, 1.0_wp)
      scene = scenes(1)
      scene%members = 6
      scene%perturbation = 1.0e-4_wp
      scene%seed = 5
      call validate_scene(scene, 'tube ensemble', error)
      if (allocated(error)) return
      call prepare_lockstep([scene, scene], 'test group', model, error)
      if (allocated(error)) return
      call compare_run_members(scene, error)
   end subroutine test_ensemble

   !> Stops on other nodes, or fewer of them, or none: refused, naming the member and the key.
   subroutine test_refused_nodes(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      scenes = tube_members(3, 0.01_wp, 1.0_wp)
      scenes(3)%stop_nodes = [10, 21, 30]
      call expect_refusal(scenes, 'member 3: &stops nodes = 10, 21, 30 differs from member 1''s 10, 20, 30', error)
      if (allocated(error)) return
      scenes = tube_members(3, 0.01_wp, 1.0_wp)
      scenes(2)%stop_nodes = [10, 30]
      scenes(2)%stop_lower = [-0.001_wp, -0.001_wp]
      scenes(2)%stop_upper = [0.001_wp, 0.001_wp]
      call expect_refusal(scenes, 'member 2: &stops nodes (or x) gives 2 stops along the span, member 1''s 3', error)
      if (allocated(error)) return
      scenes = tube_members(3, 0.01_wp, 1.0_wp)
      deallocate (scenes(2)%stop_nodes, scenes(2)%stop_lower, scenes(2)%stop_upper)
      scenes(2)%lower = -0.004_wp
      scenes(2)%upper = 0.004_wp
      call expect_refusal(scenes, 'member 2: &stops nodes (or x) gives 0 stops along the span, member 1''s 3', error)
   end subroutine test_refused_nodes

   !> Run the members in lockstep and each alone (the stops' records kept); compare them to the
   !> bit. With `contact`, every member must have hit a stop; without, none.
   subroutine compare_span_group(scenes, error, contact)
      type(scene_type), intent(in) :: scenes(:)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: contact
      type(run_summary) :: summaries(size(scenes))
      call compare_members(scenes, summaries, error, stops=.true.)
      if (allocated(error)) return
      if (contact) then
         call check(error, all(summaries%impacts > 0), 'every member hit a stop (impacts: '// &
            & int_text(sum(summaries%impacts))//' in all)')
      else
         call check(error, sum(summaries%impacts) == 0 .and. all(summaries%max_violation == 0), &
            & 'no member reached a stop (impacts: '//int_text(sum(summaries%impacts))//')')
      end if
   end subroutine compare_span_group
end module test_lockstep_span
