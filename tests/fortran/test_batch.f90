!> Several scenes in one process (beamstops_batch): the partition into lockstep groups is the
!> lockstep path's own rule (every group is accepted by check_lockstep, and a scene that starts
!> a group is refused by every earlier group), scenes that checkpoint stay alone, and every
!> member of a group run by simulate_group equals its scene run alone (simulate) to the bit:
!> every record column and the summary, an &ensemble scene's table across its members included.
module test_batch
   use, intrinsic :: iso_fortran_env, only: int64
   use testing
   use beamstops, only: ik, scene_type, model_type, array_recorder, run_summary, prepare_run, simulate, &
      & record_count, law_signorini, status_complete, check_lockstep
   use beamstops_observe_statistics, only: statistics_table
   use beamstops_batch, only: lockstep_groups, simulate_group
   implicit none
   private
   public :: collect_batch

contains

   !> Tests of the suite.
   subroutine collect_batch(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('groups: each accepted by check_lockstep, each new one refused by the earlier ones; '// &
         & 'checkpointing scenes alone', test_groups), &
         & new_unittest('simulate_group: each member (an &ensemble one too) equals its scene run alone, to the bit', &
         & test_group_equals_alone) &
         & ]
   end subroutine collect_batch

   !> The paper's scene, J = 10, beta = 1/2, Signorini tip stops, a short run; omega and the
   !> stops varied by k.
   function scene_of(k, dt) result(scene)
      integer, intent(in) :: k
      real(wp), intent(in) :: dt
      type(scene_type) :: scene
      scene%elements = 10
      scene%dt = dt
      scene%beta = 0.5_wp
      scene%law = law_signorini
      scene%t_end = 0.2_wp
      scene%omega = 8.0_wp + 3.0_wp*k
      scene%lower = -0.05_wp - 0.01_wp*mod(k, 3)
      scene%record_every = 1 + mod(k, 3)
   end function scene_of

   subroutine test_groups(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scenes(7)
      type(model_type) :: models(7)
      type(error_type), allocatable :: refusal
      integer, allocatable :: group(:)
      integer :: i, g, first
      scenes(1) = scene_of(1, 1.0e-4_wp)
      scenes(2) = scene_of(2, 2.0e-4_wp)
      scenes(3) = scene_of(3, 1.0e-4_wp)
      scenes(4) = scene_of(4, 1.0e-4_wp)
      scenes(4)%checkpoint_every = 100
      scenes(5) = scene_of(5, 2.0e-4_wp)
      scenes(6) = scene_of(6, 1.0e-4_wp)
      scenes(6)%modes = 4
      scenes(7) = scene_of(7, 1.0e-4_wp)
      do i = 1, size(scenes)
         call prepare_run(scenes(i), 'test scene', models(i), error)
         if (allocated(error)) return
      end do
      call lockstep_groups(scenes, models, group)
      call check(error, group(1) == group(3) .and. group(1) == group(7), 'scenes 1, 3, 7 (one dt) share a group')
      if (allocated(error)) return
      call check(error, group(2) == group(5) .and. group(2) /= group(1), 'scenes 2, 5 (another dt) share another')
      if (allocated(error)) return
      call check(error, count(group == group(4)) == 1, 'the checkpointing scene 4 runs alone')
      if (allocated(error)) return
      do g = 1, maxval(group)
         first = findloc(group, g, dim=1)
         call check(error, first > 0, 'groups numbered 1, 2, ... without gaps')
         if (allocated(error)) return
         if (count(group == g) > 1) then
            call check_lockstep(pack(scenes, group == g), models(first), refusal)
            call check(error, .not. allocated(refusal), 'group '//int_text(g)//' is accepted by check_lockstep')
            if (allocated(error)) return
         end if
         if (scenes(first)%checkpoint_every > 0) cycle
         do i = 1, g - 1
            ! a scene that starts a group could join no earlier group (the earlier group's scenes before it)
            call check_lockstep([pack(scenes(:first - 1), group(:first - 1) == i), scenes(first)], &
               & models(findloc(group, i, dim=1)), refusal)
            if (scenes(findloc(group, i, dim=1))%checkpoint_every > 0) cycle
            call check(error, allocated(refusal), 'scene '//int_text(first)//' starts group '//int_text(g)// &
               & ' but check_lockstep accepts it into group '//int_text(i))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_groups

   subroutine test_group_equals_alone(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: k = 4
      type(scene_type) :: scenes(k)
      type(model_type) :: models(k)
      type(array_recorder) :: recorders(k)
      type(run_summary) :: summaries(k), reference
      type(error_type) :: failures(k)
      integer :: i
      do i = 1, k
         scenes(i) = scene_of(i, 5.0e-5_wp)
      end do
      scenes(3)%members = 3
      scenes(3)%perturbation = 1.0e-5_wp
      do i = 1, k
         call prepare_run(scenes(i), 'test scene', models(i), error)
         if (allocated(error)) return
         call recorders(i)%reserve(record_count(scenes(i)), 0_ik, scenes(i)%elements + 1)
      end do
      call simulate_group(scenes, models, recorders, summaries, failures, error)
      if (allocated(error)) return
      do i = 1, k
         call check(error, .not. allocated(failures(i)%message), 'member '//int_text(i)//' closes without error')
         if (allocated(error)) return
         block
         type(array_recorder) :: alone
         call alone%reserve(record_count(scenes(i)), 0_ik, scenes(i)%elements + 1)
         call simulate(scenes(i), models(i), alone, reference, error)
         if (allocated(error)) return
         call check(error, summaries(i)%status == status_complete .and. reference%status == status_complete, &
            & 'member '//int_text(i)//' completes')
         if (allocated(error)) return
         call check(error, recorders(i)%filled == alone%filled .and. &
            & same_bits(recorders(i)%rows(:, :alone%filled), alone%rows(:, :alone%filled)), &
            & 'member '//int_text(i)//': every record column as alone')
         if (allocated(error)) return
         call check(error, summaries(i)%impacts == reference%impacts .and. summaries(i)%steps == reference%steps &
            & .and. same_bits([summaries(i)%work, summaries(i)%dissipated, summaries(i)%energy_residual, &
            & summaries(i)%max_violation], [reference%work, reference%dissipated, reference%energy_residual, &
            & reference%max_violation]), 'member '//int_text(i)//': the summary as alone')
         if (allocated(error)) return
         call check(error, same_table(summaries(i)%statistics, reference%statistics), &
            & 'member '//int_text(i)//': the statistics as alone')
         if (allocated(error)) return
         call check(error, summaries(i)%ensemble_members == reference%ensemble_members .and. &
            & same_table(summaries(i)%ensemble, reference%ensemble), 'member '//int_text(i)//': the ensemble as alone')
         end block
         if (allocated(error)) return
      end do
      call check(error, summaries(3)%ensemble_members == 3, 'the &ensemble scene ran its 3 members: '// &
         & int_text(summaries(3)%ensemble_members))
   end subroutine test_group_equals_alone

   !> Whether two arrays hold the same bits.
   logical function same_bits(a, b)
      real(wp), intent(in) :: a(..), b(..)
      select rank (a)
      rank (1)
         select rank (b)
         rank (1)
            same_bits = size(a) == size(b)
            if (same_bits) same_bits = all(transfer(a, 1_int64, size(a)) == transfer(b, 1_int64, size(b)))
         rank default
            same_bits = .false.
         end select
      rank (2)
         select rank (b)
         rank (2)
            same_bits = size(a) == size(b)
            if (same_bits) same_bits = all(transfer(a, 1_int64, size(a)) == transfer(b, 1_int64, size(b)))
         rank default
            same_bits = .false.
         end select
      rank default
         same_bits = .false.
      end select
   end function same_bits

   !> Whether two statistics tables hold the same quantities and bits.
   logical function same_table(a, b)
      type(statistics_table), intent(in) :: a, b
      integer :: q
      same_table = allocated(a%quantity) .eqv. allocated(b%quantity)
      if (.not. same_table .or. .not. allocated(a%quantity)) return
      same_table = size(a%quantity) == size(b%quantity)
      if (.not. same_table) return
      do q = 1, size(a%quantity)
         same_table = same_table .and. a%quantity(q)%name == b%quantity(q)%name .and. &
            & same_bits(a%quantity(q)%value, b%quantity(q)%value) .and. &
            & same_bits(a%quantity(q)%half_width, b%quantity(q)%half_width)
      end do
   end function same_table
end module test_batch
