!> The run in blocks (beamstops_run's continue_run): between two blocks the recorder is
!> flushed, then the loop's state is saved with the records the recorder says it stored; a run
!> resumed from that checkpoint gives the uninterrupted run's records bit for bit; a checkpoint
!> or a recorder that cannot write stops the run with status 'failed' and a message.
module test_run
   use testing
   use beamstops, only: ik, scene_type, model_type, simulate, array_recorder, &
      & run_summary, record_count, status_complete, status_failed, state_type, start_state
   use beamstops_run, only: continue_run
   use test_support, only: validated_model
   use beamstops_checkpoint, only: read_checkpoint
   use beamstops_files, only: remove_file, file_exists
   implicit none
   private
   public :: collect_run

   !> An array recorder that says what it stored at each flush.
   type, extends(array_recorder) :: flushing_recorder
      !> Flushes so far.
      integer :: flushes = 0
      !> Records stored at the last flush.
      integer(ik) :: flushed = -1
   contains
      procedure :: flush => flush_rows
   end type flushing_recorder

   character(len=*), parameter :: checkpoint = 'test_run.checkpoint'

contains

   !> Tests of the suite.
   subroutine collect_run(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('checkpoints between blocks: flush, then the state', test_blocks), &
         & new_unittest('a run resumed from a checkpoint gives the same bits', test_resume), &
         & new_unittest('without a checkpoint file, no flush and simulate''s bits', test_no_checkpoint), &
         & new_unittest('a checkpoint that cannot be written stops the run', test_checkpoint_fails), &
         & new_unittest('a recorder that cannot write stops the run', test_recorder_fails) &
         & ]
   end subroutine collect_run

   subroutine flush_rows(self, records, snapshots)
      class(flushing_recorder), intent(inout) :: self
      integer(ik), intent(out) :: records
      integer(ik), intent(out) :: snapshots
      self%flushes = self%flushes + 1
      self%flushed = self%filled
      records = self%filled
      snapshots = self%snaps
   end subroutine flush_rows

   !> 1000 steps, a record every 7, a checkpoint every 300 steps.
   subroutine prepare(scene, model, error)
      type(scene_type), intent(out) :: scene
      type(model_type), intent(out) :: model
      type(error_type), allocatable, intent(out) :: error
      scene%dt = 5.0e-5_wp
      scene%t_end = 0.05_wp
      scene%record_every = 7
      scene%checkpoint_every = 300
      call validated_model(scene, model, error)
   end subroutine prepare

   !> Run from t = 0 with checkpoints into `rec`.
   subroutine run_with_checkpoints(scene, model, rec, summary, error)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(flushing_recorder), intent(inout) :: rec
      type(run_summary), intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      type(state_type) :: state
      call rec%reserve(record_count(scene), 0_ik, scene%elements + 1)
      call remove_file(checkpoint)
      call start_state(scene, model, state, rec, error)
      if (allocated(error)) return
      call continue_run(scene, model, state, rec, summary, error, checkpoint)
   end subroutine run_with_checkpoints

   subroutine test_blocks(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(flushing_recorder) :: rec
      type(run_summary) :: summary
      type(state_type) :: state
      integer(ik) :: records, snapshots
      call prepare(scene, model, error)
      if (allocated(error)) return
      call run_with_checkpoints(scene, model, rec, summary, error)
      if (allocated(error)) return
      call check(error, summary%status == status_complete, 'the run completes: '//summary%status)
      if (allocated(error)) return
      ! checkpoints at steps 300, 600, 900; none at the end
      call check(error, rec%flushes, 3, 'flushes')
      if (allocated(error)) return
      call read_checkpoint(checkpoint, scene, model, state, records, snapshots, error)
      if (allocated(error)) return
      call check(error, int(state%step - 1), 900, 'steps done at the last checkpoint')
      if (allocated(error)) return
      call check(error, int(records), int(rec%flushed), 'records of the checkpoint = records flushed')
      if (allocated(error)) return
      ! the rows of steps 0, 7, ..., 896 (and no more) were stored at step 900: 129
      call check(error, int(records), 129, 'records at step 900 (steps 0, 7, ..., 896)')
      call remove_file(checkpoint)
   end subroutine test_blocks

   subroutine test_resume(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(flushing_recorder) :: whole
      type(array_recorder) :: rest
      type(run_summary) :: summary, resumed
      type(state_type) :: state
      integer(ik) :: records, snapshots, n
      call prepare(scene, model, error)
      if (allocated(error)) return
      call run_with_checkpoints(scene, model, whole, summary, error)
      if (allocated(error)) return
      call read_checkpoint(checkpoint, scene, model, state, records, snapshots, error)
      if (allocated(error)) return
      call rest%reserve(record_count(scene) - records, 0_ik, scene%elements + 1)
      call continue_run(scene, model, state, rest, resumed, error)
      call remove_file(checkpoint)
      if (allocated(error)) return
      call check(error, resumed%status == status_complete, 'the resumed run completes: '//resumed%status)
      if (allocated(error)) return
      n = whole%filled - records
      call check(error, int(rest%filled), int(n), 'rows after the checkpoint')
      if (allocated(error)) return
      call check(error, all(transfer(rest%rows(:, :n), 1_ik, size(rest%rows(:, :n))) == &
         & transfer(whole%rows(:, records + 1:whole%filled), 1_ik, size(rest%rows(:, :n)))), &
         & 'the resumed rows are the uninterrupted run''s, bit for bit')
      if (allocated(error)) return
      call check(error, int(resumed%impacts), int(summary%impacts), 'impacts')
   end subroutine test_resume

   subroutine test_no_checkpoint(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(flushing_recorder) :: blocks
      type(array_recorder) :: plain
      type(run_summary) :: a, b
      type(state_type) :: state
      call prepare(scene, model, error)
      if (allocated(error)) return
      call blocks%reserve(record_count(scene), 0_ik, scene%elements + 1)
      call start_state(scene, model, state, blocks, error)
      if (allocated(error)) return
      call continue_run(scene, model, state, blocks, a, error)
      if (allocated(error)) return
      call check(error, blocks%flushes, 0, 'flushes without a checkpoint file')
      if (allocated(error)) return
      call plain%reserve(record_count(scene), 0_ik, scene%elements + 1)
      call simulate(scene, model, plain, b, error)
      if (allocated(error)) return
      call check(error, all(transfer(blocks%rows, 1_ik, size(blocks%rows)) == transfer(plain%rows, 1_ik, &
         & size(plain%rows))), 'the same rows as simulate, bit for bit')
   end subroutine test_no_checkpoint

   subroutine test_checkpoint_fails(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(flushing_recorder) :: rec
      type(run_summary) :: summary
      type(state_type) :: state
      type(error_type), allocatable :: failure
      call prepare(scene, model, error)
      if (allocated(error)) return
      call rec%reserve(record_count(scene), 0_ik, scene%elements + 1)
      call start_state(scene, model, state, rec, error)
      if (allocated(error)) return
      call continue_run(scene, model, state, rec, summary, failure, 'no/such/folder/x.checkpoint')
      call check(error, allocated(failure), 'an error when the checkpoint cannot be written')
      if (allocated(error)) return
      call check(error, index(failure%message, 'no/such/folder/x.checkpoint') > 0, &
         & 'the message names the checkpoint: '//failure%message)
      if (allocated(error)) return
      call check(error, summary%status == status_failed, 'status failed: '//summary%status)
      if (allocated(error)) return
      call check(error, int(state%step - 1), 300, 'the run stopped at the first checkpoint')
      if (allocated(error)) return
      call check(error, .not. file_exists('no/such/folder/x.checkpoint.tmp'), 'no temporary file left')
   end subroutine test_checkpoint_fails

   subroutine test_recorder_fails(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(array_recorder) :: rec
      type(run_summary) :: summary
      type(state_type) :: state
      type(error_type), allocatable :: failure
      call prepare(scene, model, error)
      if (allocated(error)) return
      call rec%reserve(10_ik, 0_ik, scene%elements + 1)  ! room for 10 of the 143 records
      call start_state(scene, model, state, rec, error)
      if (allocated(error)) return
      call continue_run(scene, model, state, rec, summary, failure)
      call check(error, allocated(failure), 'an error when the recorder cannot write')
      if (allocated(error)) return
      call check(error, summary%status == status_failed .and. summary%message == failure%message, &
         & 'status failed with the same message: '//summary%status)
   end subroutine test_recorder_fails
end module test_run
