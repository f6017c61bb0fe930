!> The HDF5 recorder's writer thread (beamstops_writer_thread): the records, energies and
!> snapshots a run hands to the writer thread, several buffers of them and checkpoints (flushes)
!> among them, reach the file exactly as the in-memory recorder keeps them; the same without a
!> thread (the orders carried out where they are posted).
module test_writer
   use hdf5, only: hid_t, h5fopen_f, h5fclose_f, H5F_ACC_RDONLY_F
   use testing
   use beamstops, only: ik, scene_type, model_type, array_recorder, &
      & hdf5_recorder, run_summary, record_count, snapshot_count, status_complete, state_type, start_state
   use beamstops_recorder, only: col_t, col_u, col_energy, col_work
   use test_support, only: validated_model
   use beamstops_recorder_hdf5_vector, only: read_vector
   use beamstops_run, only: continue_run
   use beamstops_files, only: remove_file, file_exists, replace_file
   use beamstops_writer_thread, only: writer_thread, start_writer, stop_writer, stream_row
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_signaling_nan, &
      & ieee_positive_inf, ieee_negative_inf
   implicit none
   private
   public :: collect_writer

contains

   !> Tests of the suite.
   subroutine collect_writer(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('records written by the writer thread, with checkpoints among them, are the in-memory '// &
         & 'recorder''s, bit for bit', test_thread), &
         & new_unittest('without a thread, the orders carried out where posted: the same bits', test_inline), &
         & new_unittest('a record streamed into a buffer is the same bits and is finite unless one value is a NaN or '// &
         & 'an infinity, at every position and buffer alignment', test_stream_row), &
         & new_unittest('a finished file replaces an earlier one, which is removed; a file that cannot be moved '// &
         & 'leaves the earlier one in place', test_replace_file), &
         & new_unittest('a file that cannot be created: told by open without a thread, by the run and finish '// &
         & 'with one (the writer creates it), the same message; nothing left', test_uncreatable) &
         & ]
   end subroutine collect_writer

   !> replace_file onto an earlier file: the new content in place, the earlier file removed (by a
   !> process of its own: looked for until it is gone), nothing else left beside it; from a source
   !> that does not exist: not done, and the earlier file where it was, unchanged.
   subroutine test_replace_file(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: target = 'test_replace_file.out', source = 'test_replace_file.new'
      character(len=*), parameter :: aside_prefix = '.test_replace_file.out.replaced-'
      logical :: ok
      integer :: tries
      call write_text(target, 'earlier')
      call write_text(source, 'new')
      call replace_file(source, target, ok)
      call check(error, ok, 'replaced')
      if (allocated(error)) return
      call check(error, read_text(target) == 'new' .and. .not. file_exists(source), 'the new file in place')
      if (allocated(error)) return
      do tries = 1, 1000
         if (.not. any_aside()) exit
         call execute_command_line('sleep 0.01')
      end do
      call check(error, .not. any_aside(), 'the earlier file removed')
      if (allocated(error)) return
      call replace_file('test_replace_file.missing', target, ok)
      call check(error, .not. ok, 'a missing source is not moved')
      if (allocated(error)) return
      call check(error, read_text(target) == 'new' .and. .not. any_aside(), 'the earlier file where it was')
      call remove_file(target)

   contains

      subroutine write_text(path, text)
         character(len=*), intent(in) :: path, text
         integer :: unit
         open (newunit=unit, file=path, status='replace', action='write')
         write (unit, '(a)') text
         close (unit)
      end subroutine write_text

      function read_text(path) result(text)
         character(len=*), intent(in) :: path
         character(len=32) :: text
         integer :: unit, stat
         text = ''
         open (newunit=unit, file=path, status='old', action='read', iostat=stat)
         if (stat /= 0) return
         read (unit, '(a)', iostat=stat) text
         close (unit)
      end function read_text

      !> Whether a file moved aside by replace_file is still there.
      logical function any_aside()
         character(len=32) :: pid
         write (pid, '(i0)') getpid()
         any_aside = file_exists(aside_prefix//trim(pid))
      end function any_aside
   end subroutine test_replace_file

   !> 40,000 steps, each recorded (several buffers of the recorder), a snapshot every 97 steps,
   !> a checkpoint every 15,000 steps.
   subroutine prepare(scene, model, error)
      type(scene_type), intent(out) :: scene
      type(model_type), intent(out) :: model
      type(error_type), allocatable, intent(out) :: error
      scene%dt = 5.0e-5_wp
      scene%t_end = 2.0_wp
      scene%record_every = 1
      scene%snapshot_every = 97
      scene%checkpoint_every = 15000
      call validated_model(scene, model, error)
   end subroutine prepare

   subroutine test_thread(error)
      type(error_type), allocatable, intent(out) :: error
      type(writer_thread) :: writer
      call start_writer(writer)
      call compare_with_memory(writer, 'test_writer_thread.h5', error)
      call stop_writer(writer)
   end subroutine test_thread

   subroutine test_inline(error)
      type(error_type), allocatable, intent(out) :: error
      type(writer_thread) :: none
      call compare_with_memory(none, 'test_writer_inline.h5', error)
   end subroutine test_inline

   !> A partial file in a folder that does not exist: without a writer thread, open fails with
   !> "cannot create"; with one, open returns, the run stops at its first full buffer and finish
   !> fails with the same message; no file either way.
   subroutine test_uncreatable(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = 'test_writer_no_such_folder/out.h5'
      type(writer_thread) :: none, thread
      type(scene_type) :: scene
      type(model_type), target :: model
      type(hdf5_recorder), target :: inline, threaded
      type(run_summary) :: summary
      type(state_type) :: state
      type(error_type), allocatable :: opened, failure, finished
      call prepare(scene, model, error)
      if (allocated(error)) return
      inline%writer = none
      call inline%open(path, scene, model, opened)
      call check(error, allocated(opened), 'without a thread, open fails')
      if (allocated(error)) return
      call check(error, index(opened%message, 'cannot create '//path//'.partial') > 0, opened%message)
      if (allocated(error)) return
      call start_writer(thread)
      threaded%writer = thread
      call threaded%open(path, scene, model, opened)
      call check(error, .not. allocated(opened), 'with a thread, open returns (the writer creates the file)')
      if (allocated(error)) return
      call start_state(scene, model, state, threaded, error)
      if (allocated(error)) return
      call continue_run(scene, model, state, threaded, summary, failure, path//'.checkpoint')
      call threaded%finish(summary, finished)
      call stop_writer(thread)
      call check(error, summary%status /= status_complete .and. state%step < 3*16384, &
         & 'the run stops early, at a buffer handed over')
      if (allocated(error)) return
      call check(error, allocated(finished), 'finish fails')
      if (allocated(error)) return
      call check(error, index(finished%message, 'cannot create '//path//'.partial') > 0, finished%message)
      if (allocated(error)) return
      call check(error, .not. file_exists(path) .and. .not. file_exists(path//'.partial'), 'no file')
   end subroutine test_uncreatable

   !> The scene run into `path` through `writer` (checkpoints into path.checkpoint), and into
   !> memory: the file's series equal the memory's, bit for bit.
   subroutine compare_with_memory(writer, path, error)
      type(writer_thread), intent(in) :: writer
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type), target :: model
      type(hdf5_recorder), target :: file_rec
      type(array_recorder) :: memory
      type(run_summary) :: summary, reference
      type(state_type) :: state
      type(error_type), allocatable :: failure
      call prepare(scene, model, error)
      if (allocated(error)) return
      call remove_file(path)
      file_rec%writer = writer
      call file_rec%open(path, scene, model, error)
      if (allocated(error)) return
      call start_state(scene, model, state, file_rec, error)
      if (allocated(error)) return
      call continue_run(scene, model, state, file_rec, summary, failure, path//'.checkpoint')
      call file_rec%finish(summary, error)
      call remove_file(path//'.checkpoint')
      if (allocated(error)) return
      call check(error, .not. allocated(failure), 'the run writes its file and its checkpoints')
      if (allocated(error)) return
      call check(error, summary%status == status_complete .and. file_exists(path), 'complete, and the file in place')
      if (allocated(error)) return
      ! in memory, with the same checkpoints: the loop's blocks end at the same steps (a block's
      ! last record takes its energy from dot products, not from the next forward pass)
      call memory%reserve(record_count(scene), snapshot_count(scene), scene%elements + 1)
      call start_state(scene, model, state, memory, error)
      if (allocated(error)) return
      call continue_run(scene, model, state, memory, reference, error, path//'.checkpoint')
      call remove_file(path//'.checkpoint')
      if (allocated(error)) return
      call check(error, int(memory%filled) > 2*16384, 'more records than two buffers of the recorder')
      if (allocated(error)) return
      call compare_file(path, memory, error)
      call remove_file(path)
   end subroutine compare_with_memory

   !> stream_row on records of ordinary, extreme (+-huge, +-tiny, a subnormal, -0) and non-finite
   !> (quiet and signalling NaN, +-infinity) values, each non-finite value at each of the eight
   !> positions, into a buffer at eight successive 8-byte offsets (each alignment the copy tells apart: 64-byte, 16-byte
   !> and none).
   subroutine test_stream_row(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: buffer(8 + 7), row(8), bad(4)
      real(wp), parameter :: extreme(8) = [huge(1.0_wp), -huge(1.0_wp), tiny(1.0_wp), -tiny(1.0_wp), &
         & tiny(1.0_wp)/8, -0.0_wp, 1.5_wp, -2.0e-300_wp]
      integer :: offset, k, j
      bad = [ieee_value(1.0_wp, ieee_quiet_nan), ieee_value(1.0_wp, ieee_signaling_nan), &
         & ieee_value(1.0_wp, ieee_positive_inf), ieee_value(1.0_wp, ieee_negative_inf)]
      do offset = 0, 7
         buffer = 0
         call check(error, stream_row(buffer(1 + offset:8 + offset), extreme) == 1, &
            & 'finite extreme values are finite (offset '//int_text(offset)//')')
         if (allocated(error)) return
         call check(error, all(transfer(buffer(1 + offset:8 + offset), 1_ik, 8) == transfer(extreme, 1_ik, 8)), &
            & 'the record is copied bit for bit (offset '//int_text(offset)//')')
         if (allocated(error)) return
         do k = 1, size(bad)
            do j = 1, 8
               row = extreme
               row(j) = bad(k)
               call check(error, stream_row(buffer(1 + offset:8 + offset), row) == 0, 'a non-finite value ('// &
                  & int_text(k)//' of NaN, signalling NaN, +inf, -inf) at position '//int_text(j)//' is seen')
               if (allocated(error)) return
               call check(error, all(transfer(buffer(1 + offset:8 + offset), 1_ik, 8) == transfer(row, 1_ik, 8)), &
                  & 'a non-finite record is copied too')
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_stream_row

   !> /tip/t, /tip/u, /energy/E, /energy/work and /snapshots/t of `path` against `memory`.
   subroutine compare_file(path, memory, error)
      character(len=*), intent(in) :: path
      type(array_recorder), intent(in) :: memory
      type(error_type), allocatable, intent(out) :: error
      integer(hid_t) :: file
      integer :: hdferr
      call h5fopen_f(path, H5F_ACC_RDONLY_F, file, hdferr)
      call check(error, hdferr == 0, 'the file opens')
      if (allocated(error)) return
      call same_series('/tip/t', memory%rows(col_t, :memory%filled))
      if (.not. allocated(error)) call same_series('/tip/u', memory%rows(col_u, :memory%filled))
      if (.not. allocated(error)) call same_series('/energy/E', memory%rows(col_energy, :memory%filled))
      if (.not. allocated(error)) call same_series('/energy/work', memory%rows(col_work, :memory%filled))
      if (.not. allocated(error)) call same_series('/snapshots/t', memory%snap_t(:memory%snaps))
      call h5fclose_f(file, hdferr)

   contains

      subroutine same_series(name, expected)
         character(len=*), intent(in) :: name
         real(wp), intent(in) :: expected(:)
         real(wp) :: values(size(expected))
         logical :: ok
         call read_vector(file, name, values, ok)
         call check(error, ok, name//' holds '//int_text(size(expected))//' values')
         if (allocated(error)) return
         call check(error, all(transfer(values, 1_ik, size(values)) == transfer(expected, 1_ik, size(expected))), &
            & name//' equals the in-memory series, bit for bit')
      end subroutine same_series
   end subroutine compare_file
end module test_writer
