!> The HDF5 writer: chunked, extendable datasets written as the run goes,
!> the scene and the results as root attributes, and a `status` attribute that
!> says 'complete' only once the run has finished and every record is on disk.
!> The run writes OUT.partial beside the output OUT and renames it onto OUT when it has gone
!> to its end ('complete' or 'diverged') and the file is closed: a killed or failed run never
!> touches OUT. `check_output_path` refuses, before anything is written, an OUT that is the
!> input itself, an existing file that is not a beamstops output, a folder's name (OUT/), or one
!> whose partial file the system will not let the run create (with the system's reason).
!>
!>   /tip/t, /tip/u, /tip/v, /tip/reaction
!>   /energy/t, /energy/E, /energy/work, /energy/dissipated, /energy/damped
!>   /snapshots/t, /snapshots/x, /snapshots/u   (u: snapshots x (J+1))
!>   /stops/x, /stops/node, /stops/lower, /stops/upper, /stops/u, /stops/reaction
!>                                              (stops along the span; u, reaction: records x m)
module beamstops_recorder_hdf5
   use, intrinsic :: iso_c_binding, only: c_loc, c_ptr, c_f_pointer, c_associated
   use hdf5
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type, law_name, law_compliance, stop_count, steps_of, fmt_int
   use beamstops_model, only: model_type
   use beamstops_summary, only: run_summary, status_running, status_complete, status_diverged, status_failed
   use beamstops_files, only: same_file, replace_file, remove_file, creation_error, raise_hdf5_eoa, &
      & path_kind, kind_name, path_missing, path_regular, path_link, path_folder, lock_file, unlock_file, &
      & file_in_use, hdf5_locks, lock_busy, not_writable_here
   use beamstops_recorder_hdf5_vector, only: write_vector
   use beamstops_recorder, only: recorder_type, n_columns, col_t, all_finite
   use beamstops_attributes, only: attribute_list, kind_real, kind_int, kind_logical, kind_text
   use beamstops_output_attributes, only: run_attributes, summary_attributes
   use beamstops_recorder_hdf5_observations, only: write_observations
   use beamstops_recorder_hdf5_writes, only: write_order, hand_over, n_series
   use beamstops_recorder_disk_space, only: open_reservation, close_reservation
   use beamstops_writer_thread, only: writer_thread, wait_orders, stream_row
   implicit none
   private
   public :: hdf5_recorder, partial_path, check_output_path

   !> Rows buffered before a write (and rows of a chunk).
   integer, parameter :: buffer_rows = 16384
   character(len=*), parameter :: group_names(3) = [character(len=9) :: 'tip', 'energy', 'snapshots']
   character(len=*), parameter :: series_path(n_series) = [character(len=18) :: '/tip/t', '/tip/u', '/tip/v', &
      & '/tip/reaction', '/energy/t', '/energy/E', '/energy/work', '/energy/dissipated', '/energy/damped']
   character(len=*), parameter :: series_units(n_series) = [character(len=4) :: 's', 'm', 'm/s', 'N', 's', &
      & 'J', 'J', 'J', 'J']

   !> Recorder writing an HDF5 file.
   type, extends(recorder_type) :: hdf5_recorder
      !> The output file, replaced only when the run has gone to its end.
      character(len=:), allocatable :: path
      !> The file written as the run goes (partial_path(path)).
      character(len=:), allocatable :: partial
      !> The descriptor of the recorder's own lock on the partial file (lock_file; -1: none): held
      !> on an earlier run's partial file while it is removed or reopened, released before HDF5
      !> opens the file and takes its own lock (two locks of one process on one file would
      !> conflict); taken again on the created file, for the whole run, when HDF5 does not lock its
      !> files (HDF5_USE_FILE_LOCKING=FALSE).
      integer :: lock = -1
      integer(hid_t) :: file = -1
      integer(hsize_t) :: written = 0, snaps_written = 0
      integer :: fill = 0
      integer :: nodes = 0
      !> Buffered rows (n_columns, buffer_rows): a record is one contiguous row of 64 bytes (one
      !> store a step on the loop's thread; the writer thread picks the series out of it).
      real(wp), allocatable :: buffer(:, :)
      !> Scene of the run.
      type(scene_type) :: scene
      !> Buffered snapshots: times and shapes (nodes, snapshot_rows).
      real(wp), allocatable :: snap_t_buffer(:), snap_u_buffer(:, :)
      integer :: snap_fill = 0, snapshot_rows = 0
      !> Print a progress line on stderr.
      logical :: show_progress = .false.
      !> Whether the progress line is left without its end (finish ends it: a run that stops early).
      logical :: progress_open = .false.
      !> Stops along the span m, their two series (records x m) and buffers (m, stops_rows).
      integer :: stops = 0
      real(wp), allocatable :: stops_u_buffer(:, :), stops_r_buffer(:, :)
      integer :: stops_fill = 0, stops_rows = 0
      integer(hsize_t) :: stops_written = 0
      !> The writer thread the program gives (none: each write_buffer writes at once).
      type(writer_thread) :: writer
      !> The order the writer carries out while the loop fills the buffers above, with the file's
      !> datasets (a pointer: its address goes to the writer thread).
      type(write_order), pointer :: order => null()
   contains
      procedure :: open => open_file
      procedure :: reopen
      procedure :: record
      procedure :: record_stops
      procedure :: flush => flush_file
      procedure :: snapshot
      procedure :: progress
      procedure :: finish
   end type hdf5_recorder

contains

   !> Create the partial file beside `path`, its datasets and the scene's attributes; status
   !> 'running'. `path` itself is not touched before `finish`. The file is created by the writer
   !> thread (create_file) while the run starts: a Figure 4 run's creation took 1.6-2.9 ms, a
   !> nanosecond a step of its 2,000,000. A failure then fails the recorder at its first wait (the
   !> first full buffer, a checkpoint or the end), with the same message; without a writer thread
   !> the file is created here and a failure is told at once.
   subroutine open_file(self, path, scene, model, error)
      !> Recorder (its address goes to the writer thread until the file is created).
      class(hdf5_recorder), intent(inout), target :: self
      !> Output file (replaced by finish when the run has gone to its end).
      character(len=*), intent(in) :: path
      !> Scene of the run.
      type(scene_type), intent(in) :: scene
      !> Its model (its address goes to the writer thread until the file is created).
      type(model_type), intent(in), target :: model
      !> Set when the file cannot be created (with no writer thread; else the first wait tells).
      type(error_type), allocatable, intent(out) :: error
      call prepare(self, path, scene, model)
      ! A partial file of an earlier run (check_output_path found it one, or empty) is removed
      ! under the recorder's lock, and HDF5 creates the file anew, exclusively: never truncated. A
      ! file truncated and then written makes ext4 write it back when it is closed (its
      ! auto_da_alloc), 50 ms of the Figure 4 run's end; and two runs started at once cannot both
      ! create it.
      call hold_partial(self, error)
      if (allocated(error)) return
      if (path_kind(self%partial, follow=.false.) /= path_missing) call remove_file(self%partial)
      call release_partial(self)
      call allocate_stops_buffer(self)
      select type (self)
      type is (hdf5_recorder)
         self%order%creating = c_loc(self)
         self%order%model = c_loc(model)
         call hand_over(self%writer, self%order)
         if (c_associated(self%writer%handle)) return
      class default
         call create_file_of(self, model)
      end select
      if (self%failed) call fatal_error(error, self%message)
   end subroutine open_file

   !> The writer thread's creation of the file (an order of open_file; create_file_of).
   subroutine create_file(recorder, model_address) bind(c, name='beamstops_create_file')
      !> The recorder (c_loc of an hdf5_recorder).
      type(c_ptr), value :: recorder
      !> The run's model (c_loc of a model_type).
      type(c_ptr), value :: model_address
      type(hdf5_recorder), pointer :: self
      type(model_type), pointer :: model
      call c_f_pointer(recorder, self)
      call c_f_pointer(model_address, model)
      call create_file_of(self, model)
   end subroutine create_file

   !> The partial file, its groups and datasets, the scene's attributes, flushed. A failure fails
   !> the recorder (and its order, so that nothing more is written).
   subroutine create_file_of(self, model)
      class(hdf5_recorder), intent(inout) :: self
      type(model_type), intent(in) :: model
      integer :: hdferr, i
      integer(hid_t) :: group
      logical :: ok
      associate (scene => self%scene)
         call h5fcreate_f(self%partial, H5F_ACC_EXCL_F, self%file, hdferr)
         if (hdferr /= 0) then
            self%file = -1
            if (path_kind(self%partial, follow=.false.) /= path_missing) then
               call fail(self, busy_partial(self%partial))
            else
               call fail(self, 'cannot create '//self%partial//': '//creation_failure(self%partial))
            end if
            self%order%failed = .true.
            return
         end if
         ! HDF5 holds a lock on the file it has open; without it (HDF5_USE_FILE_LOCKING=FALSE),
         ! the recorder's own, for the whole run
         if (.not. hdf5_locks()) call hold_partial_quietly(self)
         call open_reservation(self%order%space, self%partial)
         do i = 1, 3
            call h5gcreate_f(self%file, trim(group_names(i)), group, hdferr)
            call h5gclose_f(group, hdferr)
         end do
         do i = 1, n_series
            call create_series(self, trim(series_path(i)), trim(series_units(i)), 1, self%order%series(i), &
               & rows=rows_of(scene, scene%record_every))
         end do
         if (scene%snapshot_every > 0) then
            call create_series(self, '/snapshots/t', 's', 1, self%order%snap_t, rows=rows_of(scene, scene%snapshot_every))
            call create_series(self, '/snapshots/u', 'm', self%nodes, self%order%snap_u)
         end if
         call write_fixed(self%file, '/snapshots/x', model%x, 'm', ok)
         if (.not. ok) call fail(self, 'cannot write dataset /snapshots/x')
         if (stop_count(scene) > 0) call create_stops(self, scene, model)
         call attribute_text(self, 'status', status_running)
         call write_attributes(self, run_attributes(scene, model))
         if (.not. self%failed) then
            call h5fflush_f(self%file, H5F_SCOPE_GLOBAL_F, hdferr)
            if (hdferr /= 0) call fail(self, write_failure(self))
         end if
         if (self%failed) self%order%failed = .true.
      end associate
   end subroutine create_file_of

   !> Buffer one row; write the buffer when full. The row goes into the buffer's next place
   !> first, and counts only when its values are finite (all_finite, tested by stream_row).
   subroutine record(self, row)
      class(hdf5_recorder), intent(inout) :: self
      real(wp), intent(in) :: row(n_columns)
      if (.not. self%blew_up) then
         if (stream_row(self%buffer(:, self%fill + 1), row) /= 0) then
            self%fill = self%fill + 1
            if (self%fill == buffer_rows) call write_buffer(self)
            return
         end if
      end if
      call self%stop_keeping(row(col_t))
      ! the stops' values of this row came just before it: the stops keep as many rows as the
      ! series (once, not one fewer at each record after it: the steps to the block's end, up to
      ! 8,191 records, had emptied /stops/u and /stops/reaction of a run that diverged)
      if (self%stops > 0) self%stops_fill = int(max(0_hsize_t, min(int(self%stops_fill, hsize_t), &
         & self%written + int(self%fill, hsize_t) - self%stops_written)))
   end subroutine record

   !> Buffer the stops' values of the row that follows; write the buffers when full.
   subroutine record_stops(self, u, reaction)
      class(hdf5_recorder), intent(inout) :: self
      real(wp), intent(in) :: u(:)
      real(wp), intent(in) :: reaction(:)
      if (self%stops == 0 .or. self%blew_up) return
      self%stops_fill = self%stops_fill + 1
      self%stops_u_buffer(:, self%stops_fill) = u
      self%stops_r_buffer(:, self%stops_fill) = reaction
      if (self%stops_fill == self%stops_rows) call write_buffer(self)
   end subroutine record_stops

   !> The group /stops: positions and bounds of the stops along the span, and their two series.
   subroutine create_stops(self, scene, model)
      class(hdf5_recorder), intent(inout) :: self
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      integer(hid_t) :: group
      integer :: hdferr
      logical :: ok(4)
      call h5gcreate_f(self%file, 'stops', group, hdferr)
      call h5gclose_f(group, hdferr)
      call write_fixed(self%file, '/stops/x', model%stops%x, 'm', ok(1))
      call write_fixed(self%file, '/stops/node', real(scene%stop_nodes, wp), '1', ok(2))
      call write_fixed(self%file, '/stops/lower', scene%stop_lower, 'm', ok(3))
      call write_fixed(self%file, '/stops/upper', scene%stop_upper, 'm', ok(4))
      if (.not. all(ok)) call fail(self, 'cannot write the datasets of /stops')
      call create_series(self, '/stops/u', 'm', stop_count(scene), self%order%stops_u, matrix=.true.)
      call create_series(self, '/stops/reaction', 'N', stop_count(scene), self%order%stops_reaction, matrix=.true.)
   end subroutine create_stops

   !> Buffers of the stops' series (when the scene has stops along the span).
   subroutine allocate_stops_buffer(self)
      class(hdf5_recorder), intent(inout) :: self
      self%stops = stop_count(self%scene)
      self%order%stops = self%stops
      if (self%stops == 0) return
      self%stops_rows = max(1, min(buffer_rows, 2**19/self%stops))
      allocate (self%stops_u_buffer(self%stops, self%stops_rows), self%stops_r_buffer(self%stops, self%stops_rows))
   end subroutine allocate_stops_buffer

   !> Buffer one snapshot; write the buffer when full.
   subroutine snapshot(self, t, u)
      class(hdf5_recorder), intent(inout) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: u(:)
      if (self%blew_up .or. .not. all_finite(size(u), u)) then
         call self%stop_keeping(t)
         return
      end if
      self%snap_fill = self%snap_fill + 1
      self%snap_t_buffer(self%snap_fill) = t
      self%snap_u_buffer(:, self%snap_fill) = u
      if (self%snap_fill == self%snapshot_rows) call write_buffer(self)
   end subroutine snapshot

   !> A progress line on stderr (only when asked, i.e. attached to a terminal).
   subroutine progress(self, step, steps)
      class(hdf5_recorder), intent(inout) :: self
      integer(ik), intent(in) :: step
      integer(ik), intent(in) :: steps
      character(len=*), parameter :: cr = achar(13)
      if (.not. self%show_progress) return
      write (0, '(a,a,f6.2,a,i0,a,i0,a)', advance='no') cr, 'beamstops: ', 100.0_wp*step/steps, '% (', step, &
         & ' of ', steps, ' steps)'
      self%progress_open = step /= steps
      if (step == steps) write (0, '(a)') ''
      flush (0)
   end subroutine progress

   !> Write what is buffered, the results as attributes and the final status; close the file
   !> and, when the run went to its end ('complete' or 'diverged'), rename it onto the output.
   !> When a write failed, the partial file is marked 'failed' if it still takes it, and stays.
   subroutine finish(self, summary, error)
      !> Recorder.
      class(hdf5_recorder), intent(inout) :: self
      !> Outcome of the run.
      type(run_summary), intent(in) :: summary
      !> Set when the file could not be completed (or moved into place).
      type(error_type), allocatable, intent(out) :: error
      integer :: hdferr
      logical :: ok
      ! the file's creation, when the writer thread carries it out, is waited for here at the latest
      call wait_orders(self%writer)
      if (self%file < 0) then
         call release_partial(self)
         if (self%failed) call fatal_error(error, self%message)
         return
      end if
      if (self%progress_open) write (0, '(a)') ''
      self%progress_open = .false.
      call store(self)
      if (allocated(summary%shocks) .and. .not. self%failed) then
         call write_observations(self%file, summary%shocks, summary%statistics, self%scene%transient, &
            & self%scene%batches, self%scene%bins, self%scene%rest_time, ok, summary%ensemble, &
            & summary%ensemble_members)
         if (.not. ok) call fail(self, 'cannot write /impacts or /statistics')
      end if
      call write_attributes(self, summary_attributes(summary))
      if (.not. self%failed) then
         call h5fflush_f(self%file, H5F_SCOPE_GLOBAL_F, hdferr)
         if (hdferr /= 0) call fail(self, write_failure(self))
      end if
      if (self%failed) then
         ! best effort: a full disk may take nothing more, and the file then says 'running'
         call text_attribute_on(self%file, 'status', status_failed, ok)
         call text_attribute_on(self%file, 'message', self%message, ok)
      else
         call attribute_text(self, 'status', summary%status)
      end if
      call close_file(self)
      if (self%failed) then
         call release_partial(self)
         call fatal_error(error, self%message)
         return
      end if
      if (summary%status == status_complete .or. summary%status == status_diverged) then
         call replace_file(self%partial, self%path, ok)
         if (.not. ok) call fatal_error(error, self%path//': cannot move '//self%partial//' onto it')
      end if
      call release_partial(self)
   end subroutine finish

   !> Take the recorder's own lock on its partial file, when there is one, before anything is
   !> done to it: a partial file another process holds a lock on (another run writing it) is
   !> refused, untouched. A file system without locks takes none.
   subroutine hold_partial(self, error)
      class(hdf5_recorder), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      self%lock = lock_file(self%partial)
      if (self%lock == lock_busy) then
         call fail(self, busy_partial(self%partial))
         call fatal_error(error, self%message)
      end if
   end subroutine hold_partial

   !> Take the recorder's own lock on its partial file, just created by this run (nothing to
   !> refuse: another run that created it would have made the creation fail).
   subroutine hold_partial_quietly(self)
      class(hdf5_recorder), intent(inout) :: self
      self%lock = lock_file(self%partial)
   end subroutine hold_partial_quietly

   !> Release the recorder's own lock on its partial file, if it holds one.
   subroutine release_partial(self)
      class(hdf5_recorder), intent(inout) :: self
      call unlock_file(self%lock)
      self%lock = -1
   end subroutine release_partial

   !> What a partial file another process holds a lock on says.
   pure function busy_partial(partial) result(what)
      character(len=*), intent(in) :: partial
      character(len=:), allocatable :: what
      what = partial//' is being written by another run (a process holds a lock on it: another beamstops run, '// &
         & 'or a program reading it); allowed: wait for it to end, or choose another output (-o OUT.h5, or '// &
         & '&output file)'
   end function busy_partial

   !> Close the datasets and the file (so that closing writes everything and says so), once the
   !> writer is done with them.
   subroutine close_file(self)
      class(hdf5_recorder), intent(inout) :: self
      integer :: hdferr, i
      logical :: ok
      call wait_writes(self)
      ok = .true.
      do i = 1, n_series
         call close_dataset(self%order%series(i))
      end do
      call close_dataset(self%order%snap_t)
      call close_dataset(self%order%snap_u)
      call close_dataset(self%order%stops_u)
      call close_dataset(self%order%stops_reaction)
      call h5fclose_f(self%file, hdferr)
      call close_reservation(self%order%space)
      self%file = -1
      if (hdferr /= 0 .or. .not. ok) call fail(self, write_failure(self))
      deallocate (self%order)

   contains

      subroutine close_dataset(dset)
         integer(hid_t), intent(inout) :: dset
         if (dset < 0) return
         call h5dclose_f(dset, hdferr)
         ok = ok .and. hdferr == 0
         dset = -1
      end subroutine close_dataset
   end subroutine close_file

   !> Open the partial file of an interrupted run to continue it: its series are cut back to
   !> the `records` and `snapshots` of the checkpoint, its status is 'running' again.
   subroutine reopen(self, path, scene, model, records, snapshots, error)
      !> Recorder.
      class(hdf5_recorder), intent(inout) :: self
      !> Output file of the interrupted run (its partial file is reopened).
      character(len=*), intent(in) :: path
      !> Scene of the run.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> Records and snapshots written before the checkpoint.
      integer(ik), intent(in) :: records, snapshots
      !> Set when the file cannot be opened or lacks a series.
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: end_groups(3) = [character(len=10) :: 'impacts', 'statistics', 'ensemble']
      integer :: hdferr, i
      logical :: stale, raised
      call prepare(self, path, scene, model)
      call hold_partial(self, error)
      if (allocated(error)) return
      ! a run killed while HDF5 flushed may have left indexes past the allocation the file records
      raised = raise_hdf5_eoa(self%partial)
      if (hdf5_locks()) call release_partial(self)
      call h5fopen_f(self%partial, H5F_ACC_RDWR_F, self%file, hdferr)
      if (hdferr /= 0) then
         call fail(self, 'cannot reopen '//self%partial//', the output of the interrupted run (a run killed while '// &
            & 'HDF5 wrote it may leave it unreadable); run without --restart to start over')
         call release_partial(self)
         call fatal_error(error, self%message)
         return
      end if
      call open_reservation(self%order%space, self%partial)
      do i = 1, n_series
         call reopen_series(trim(series_path(i)), self%order%series(i), [records])
      end do
      if (scene%snapshot_every > 0) then
         call reopen_series('/snapshots/t', self%order%snap_t, [snapshots])
         call reopen_series('/snapshots/u', self%order%snap_u, [int(self%nodes, ik), snapshots])
      end if
      call allocate_stops_buffer(self)
      if (self%stops > 0) then
         call reopen_series('/stops/u', self%order%stops_u, [int(self%stops, ik), records])
         call reopen_series('/stops/reaction', self%order%stops_reaction, [int(self%stops, ik), records])
      end if
      self%written = records
      self%snaps_written = snapshots
      self%stops_written = records
      call attribute_text(self, 'status', status_running)
      ! An attempt that failed after the checkpoint left its message in the file: the file is
      ! running again, and its end writes the message it has (none for a complete run).
      call h5aexists_f(self%file, 'message', stale, hdferr)
      if (hdferr == 0 .and. stale) call h5adelete_f(self%file, 'message', hdferr)
      if (hdferr /= 0) call fail(self, 'cannot clear the message of the failed attempt in '//self%partial)
      ! An attempt killed in its end may have written its observations already: they are the
      ! run's end, written again by this one.
      do i = 1, size(end_groups)
         call h5lexists_f(self%file, trim(end_groups(i)), stale, hdferr)
         if (hdferr == 0 .and. stale) call h5ldelete_f(self%file, trim(end_groups(i)), hdferr)
         if (hdferr /= 0) call fail(self, 'cannot clear /'//trim(end_groups(i))//' of the killed attempt in '// &
            & self%partial)
      end do
      if (self%failed) call release_partial(self)
      if (self%failed) call fatal_error(error, self%message)

   contains

      subroutine reopen_series(name, dset, dims)
         character(len=*), intent(in) :: name
         integer(hid_t), intent(out) :: dset
         integer(ik), intent(in) :: dims(:)
         integer(hid_t) :: access, space
         integer(hsize_t) :: held(2), most(2)
         integer :: ignored, rank
         access = direct_access()
         call h5dopen_f(self%file, name, dset, hdferr, access)
         call h5pclose_f(access, ignored)
         if (hdferr /= 0) then
            call fail(self, self%partial//', the output of the interrupted run, has no series '//name)
            return
         end if
         ! the file must hold at least the rows its checkpoint counts (a partial file older than
         ! the checkpoint, restored or copied, would be extended with zeros and called complete)
         held = 0
         call h5dget_space_f(dset, space, hdferr)
         if (hdferr == 0) call h5sget_simple_extent_ndims_f(space, rank, hdferr)
         if (hdferr == 0 .and. rank == size(dims)) call h5sget_simple_extent_dims_f(space, held(:rank), most(:rank), hdferr)
         call h5sclose_f(space, ignored)
         if (hdferr < 0 .or. rank /= size(dims)) then
            call fail(self, self%partial//', the output of the interrupted run, has no series '//name)
            return
         end if
         if (held(rank) < int(dims(size(dims)), hsize_t)) then
            call fail(self, self%partial//', the output of the interrupted run, holds '// &
               & fmt_int(int(held(rank), ik))//' rows of '//name//', fewer than the '//fmt_int(dims(size(dims)))// &
               & ' its checkpoint counts (the file is older than the checkpoint: restored or copied?); run '// &
               & 'without --restart to start over')
            hdferr = -1
            return
         end if
         call h5dset_extent_f(dset, int(dims, hsize_t), hdferr)
         if (hdferr /= 0) call fail(self, self%partial//', the output of the interrupted run, has no series '//name)
      end subroutine reopen_series
   end subroutine reopen

   !> Write what is buffered and flush the file; the records and snapshots now in it.
   subroutine flush_file(self, records, snapshots)
      !> Recorder.
      class(hdf5_recorder), intent(inout) :: self
      !> Records in the file.
      integer(ik), intent(out) :: records
      !> Snapshots in the file.
      integer(ik), intent(out) :: snapshots
      integer :: hdferr
      call store(self)
      if (.not. self%failed) then
         call h5fflush_f(self%file, H5F_SCOPE_GLOBAL_F, hdferr)
         if (hdferr /= 0) call fail(self, write_failure(self))
      end if
      records = int(self%written, ik)
      snapshots = int(self%snaps_written, ik)
   end subroutine flush_file

   !> The file a run writes as it goes, renamed onto `output` when the run has gone to its end.
   pure function partial_path(output) result(path)
      !> Output file.
      character(len=*), intent(in) :: output
      character(len=:), allocatable :: path
      path = output//'.partial'
   end function partial_path

   !> Refuse, before anything is written, an output the run cannot write or that would destroy
   !> data: a name ending in '/' (a folder's, not a file's); the input file itself (under any
   !> name: same device and inode); an existing file at the output path that is not a regular
   !> file (a FIFO, a socket, a device: refused without being opened) or not a beamstops output
   !> (an HDF5 file with the root attributes `version`, `status` and `scene` and the dataset
   !> /tip/t; a symbolic link there is replaced as a name, what it leads to is tested); at the
   !> partial path, the input file, a symbolic link, anything but a regular file, a file another
   !> process holds a lock on (another run writing it: HDF5 locks the files it has open), and a
   !> file that is neither empty, nor an HDF5 file that cannot be opened, nor a beamstops output
   !> (an empty or unreadable HDF5 file there is taken for the partial output of an earlier run,
   !> which a kill may have left empty and a failed write unreadable); a partial file the system
   !> will not let the run create (the message gives its reason: name too long, no such folder,
   !> permission denied, read-only file system, ...). The message names the output and where its
   !> name came from (`origin`), and says why.
   subroutine check_output_path(output, input, origin, error)
      !> Output file.
      character(len=*), intent(in) :: output
      !> Input file of the run.
      character(len=*), intent(in) :: input
      !> Where the output's name came from, e.g. '-o' or '&output file of in.nml'.
      character(len=*), intent(in) :: origin
      !> Set when the output must not be written.
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: why, named, example, partial
      integer :: kind
      if (len(output) == 0) then
         call fatal_error(error, input//': a namelist read from a pipe, a device or an open descriptor (/dev/stdin, '// &
            & '/dev/fd/N, <(...)) gives no output name; allowed: name the output, -o OUT.h5 or &output file = ''OUT.h5''')
         return
      end if
      named = output//' ('//origin//'): '
      if (output(len(output):) == '/') then
         example = output(:verify(output, '/', back=.true.))
         if (len(example) == 0) example = 'out.h5'
         call fatal_error(error, named//'ends with /, the name of a folder, not of a file; allowed: the name of '// &
            & 'the HDF5 file to write, e.g. '//example)
         return
      end if
      if (same_file(output, input)) then
         call fatal_error(error, named//'is the input file '//input//'; writing the output there would '// &
            & 'destroy it (name another output: -o OUT.h5, or &output file)')
         return
      end if
      kind = path_kind(output, follow=.true.)
      if (kind /= path_missing .and. kind /= path_regular .and. kind /= path_folder) then
         why = 'is '//kind_name(kind)
         if (path_kind(output, follow=.false.) == path_link) why = 'is a symbolic link to '//kind_name(kind)
         call fatal_error(error, named//why//', not a regular file; refusing to write it (name another output: '// &
            & '-o OUT.h5, or &output file)')
         return
      end if
      why = not_an_output(output, strict=.true.)
      if (len(why) > 0) then
         call fatal_error(error, named//'exists and is not a beamstops output ('//why//'); refusing to '// &
            & 'overwrite it (name another output: -o OUT.h5, or &output file)')
         return
      end if
      partial = partial_path(output)
      why = not_writable_here(partial, input)
      if (len(why) > 0) then
         call fatal_error(error, named//partial//', where the run writes until it is done, '//why// &
            & '; refusing to write it (move it away)')
         return
      end if
      if (file_in_use(partial)) then
         call fatal_error(error, named//busy_partial(partial))
         return
      end if
      why = not_an_output(partial, strict=.false.)
      if (len(why) > 0) then
         call fatal_error(error, named//partial//', where the run writes until it is done, exists '// &
            & 'and is not the partial output of a beamstops run ('//why//'); refusing to overwrite it (move it away)')
         return
      end if
      why = creation_error(partial)
      if (len(why) > 0) call fatal_error(error, named//'cannot create '//partial//', where the run '// &
         & 'writes until it is done: '//why)
   end subroutine check_output_path

   !> Why an existing `path` is not a beamstops output ('' when it is one, or does not exist): a
   !> beamstops output is an HDF5 file with the root attributes `version`, `status` and `scene`
   !> and the dataset /tip/t, which every output and partial file of the program has from its
   !> first flush. Not `strict`: an empty file passes too, and an HDF5 file that cannot be opened
   !> (what a kill or a failed write may leave). Anything but a regular file is named, not opened.
   function not_an_output(path, strict) result(why)
      character(len=*), intent(in) :: path
      logical, intent(in) :: strict
      character(len=:), allocatable :: why
      integer(hid_t) :: file
      integer :: hdferr, closing, kind
      integer(ik) :: bytes
      logical :: hdf5_file
      why = ''
      kind = path_kind(path, follow=.true.)
      if (kind == path_missing) return
      if (kind == path_folder) then
         why = 'a folder'
         return
      end if
      if (kind /= path_regular) then
         why = kind_name(kind)
         return
      end if
      inquire (file=path, size=bytes)
      if (.not. strict .and. bytes == 0) return
      call h5open_f(hdferr)
      call h5eset_auto_f(0, hdferr)
      ! one opening of the file when it opens (h5fis_hdf5_f opens it too; each opening builds a
      ! metadata cache of ~1 MB), the test only to name what is wrong when it does not
      call h5fopen_f(path, H5F_ACC_RDONLY_F, file, hdferr)
      if (hdferr == 0) then
         if (.not. has_signature(file)) why = 'an HDF5 file without the root attributes version, status and '// &
            & 'scene and the dataset /tip/t that beamstops writes'
         call h5fclose_f(file, closing)
         return
      end if
      call h5fis_hdf5_f(path, hdf5_file, hdferr)
      if (hdferr /= 0) then
         why = 'unreadable'
         return
      end if
      if (.not. hdf5_file) then
         why = 'not an HDF5 file'
         return
      end if
      if (strict) why = 'an HDF5 file that cannot be opened'

   contains

      !> Whether the open file has what every beamstops output has.
      logical function has_signature(file)
         integer(hid_t), intent(in) :: file
         character(len=*), parameter :: names(3) = [character(len=7) :: 'version', 'status', 'scene']
         logical :: found
         integer :: i
         has_signature = .false.
         do i = 1, size(names)
            call h5aexists_f(file, trim(names(i)), found, hdferr)
            if (hdferr /= 0 .or. .not. found) return
         end do
         call h5lexists_f(file, 'tip', found, hdferr)
         if (hdferr /= 0 .or. .not. found) return
         call h5lexists_f(file, 'tip/t', found, hdferr)
         has_signature = hdferr == 0 .and. found
      end function has_signature
   end function not_an_output

   !> What opening and reopening share: the run's names and sizes, the buffers, the HDF5
   !> library (its own error printing off: failures become messages).
   subroutine prepare(self, path, scene, model)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      integer :: hdferr
      self%path = path
      self%partial = partial_path(path)
      self%scene = scene
      self%nodes = size(model%x)
      allocate (self%buffer(n_columns, buffer_rows))
      if (.not. associated(self%order)) allocate (self%order)
      self%order%nodes = self%nodes
      if (scene%snapshot_every > 0) then
         self%snapshot_rows = max(1, min(buffer_rows, 2**20/self%nodes))
         allocate (self%snap_t_buffer(self%snapshot_rows), self%snap_u_buffer(self%nodes, self%snapshot_rows))
      end if
      call h5open_f(hdferr)
      call h5eset_auto_f(0, hdferr)
   end subroutine prepare

   !> Hand the buffered records, stops and snapshots to the writer thread as one order and start
   !> filling the other buffers; the loop goes on while the writer stores them. The previous
   !> order is waited for first: one order at a time, and HDF5 called by one thread at a time.
   subroutine write_buffer(self)
      class(hdf5_recorder), intent(inout) :: self
      call wait_writes(self)
      associate (o => self%order)
         call swap(self%buffer, o%rows)
         call pass_rows(self%fill, self%written, o%fill, o%written)
         if (self%stops > 0) then
            call swap(self%stops_u_buffer, o%stops_u_rows)
            call swap(self%stops_r_buffer, o%stops_r_rows)
         end if
         call pass_rows(self%stops_fill, self%stops_written, o%stops_fill, o%stops_written)
         if (self%snapshot_rows > 0) then
            call swap(self%snap_u_buffer, o%snap_u_rows)
            call swap_vector(self%snap_t_buffer, o%snap_t_rows)
         end if
         call pass_rows(self%snap_fill, self%snaps_written, o%snap_fill, o%snaps_written)
      end associate
      call hand_over(self%writer, self%order)
   end subroutine write_buffer

   !> The `fill` rows buffered go into the order at row `written` of their dataset; the buffer
   !> starts empty and the dataset's next rows come after them.
   pure subroutine pass_rows(fill, written, order_fill, order_written)
      integer, intent(inout) :: fill
      integer(hsize_t), intent(inout) :: written
      integer, intent(out) :: order_fill
      integer(hsize_t), intent(out) :: order_written
      order_fill = fill
      order_written = written
      written = written + fill
      fill = 0
   end subroutine pass_rows

   !> Everything buffered written, and the writer done with it.
   subroutine store(self)
      class(hdf5_recorder), intent(inout) :: self
      call write_buffer(self)
      call wait_writes(self)
   end subroutine store

   !> Wait for the writer's order in progress; a write of it that failed fails the recorder.
   subroutine wait_writes(self)
      class(hdf5_recorder), intent(inout) :: self
      call wait_orders(self%writer)
      if (.not. associated(self%order)) return
      if (self%order%failed) call fail(self, write_failure(self))
   end subroutine wait_writes

   !> Exchange a buffer with its twin in the order (allocated like it the first time).
   subroutine swap(a, b)
      real(wp), allocatable, intent(inout) :: a(:, :), b(:, :)
      real(wp), allocatable :: t(:, :)
      if (.not. allocated(b)) allocate (b, mold=a)
      call move_alloc(a, t)
      call move_alloc(b, a)
      call move_alloc(t, b)
   end subroutine swap

   !> swap for the snapshot times.
   subroutine swap_vector(a, b)
      real(wp), allocatable, intent(inout) :: a(:), b(:)
      real(wp), allocatable :: t(:)
      if (.not. allocated(b)) allocate (b, mold=a)
      call move_alloc(a, t)
      call move_alloc(b, a)
      call move_alloc(t, b)
   end subroutine swap_vector

   !> The rows a series of the scene gets when one is kept every `every` steps (the first and
   !> the last step included), at least 1.
   pure integer(ik) function rows_of(scene, every) result(rows)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: every
      rows = steps_of(scene)/max(1, every) + 2
   end function rows_of

   !> An extendable, chunked dataset of rows of `width` doubles (1-D for width 1 unless `matrix`).
   !> A 1-D series' chunks hold buffer_rows values, or `rows` when the run has fewer: a short
   !> run's file is not padded to a whole chunk per series (a 100-step run wrote 1.2 MB).
   subroutine create_series(self, path, units, width, dset, matrix, rows)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: path, units
      integer, intent(in) :: width
      integer(hid_t), intent(out) :: dset
      logical, intent(in), optional :: matrix
      integer(ik), intent(in), optional :: rows
      integer(hid_t) :: space, plist, access
      integer(hsize_t) :: dims(2), maxdims(2), chunk(2)
      integer :: hdferr, rank
      rank = merge(1, 2, width == 1)
      if (present(matrix)) rank = merge(2, rank, matrix)
      if (rank == 1) then
         dims(1) = 0; maxdims(1) = H5S_UNLIMITED_F; chunk(1) = buffer_rows
         if (present(rows)) chunk(1) = int(max(1_ik, min(int(buffer_rows, ik), rows)), hsize_t)
      else
         dims = [int(width, hsize_t), 0_hsize_t]; maxdims = [int(width, hsize_t), H5S_UNLIMITED_F]
         chunk = [int(width, hsize_t), int(max(1, min(256, 65536/width)), hsize_t)]
      end if
      call h5screate_simple_f(rank, dims(:rank), space, hdferr, maxdims(:rank))
      call h5pcreate_f(H5P_DATASET_CREATE_F, plist, hdferr)
      call h5pset_chunk_f(plist, rank, chunk(:rank), hdferr)
      ! every value of the extent is written before it is read: no chunk is filled first
      call h5pset_fill_time_f(plist, H5D_FILL_TIME_NEVER_F, hdferr)
      access = direct_access()
      call h5dcreate_f(self%file, path, H5T_NATIVE_DOUBLE, space, dset, hdferr, plist, dapl_id=access)
      if (hdferr /= 0) call fail(self, 'cannot create dataset '//path)
      call h5pclose_f(access, hdferr)
      call h5pclose_f(plist, hdferr)
      call h5sclose_f(space, hdferr)
      call dataset_units(dset, units)
   end subroutine create_series

   !> The access properties of a series: no chunk cache. The writer hands HDF5 whole chunks (a
   !> buffer of rows), which then go to the file at once with no copy into a cache, and the
   !> file's flushes and close have no chunks left to write (with HDF5's cache of 1 MB per
   !> dataset, closing a long run's file wrote 9 MB after the time loop).
   function direct_access() result(access)
      integer(hid_t) :: access
      integer :: hdferr
      call h5pcreate_f(H5P_DATASET_ACCESS_F, access, hdferr)
      call h5pset_chunk_cache_f(access, 0_size_t, 0_size_t, 1.0, hdferr)
   end function direct_access

   !> A whole 1-D dataset of doubles written once (write_vector) with its `units` attribute.
   subroutine write_fixed(file, path, values, units, ok)
      integer(hid_t), intent(in) :: file
      character(len=*), intent(in) :: path, units
      real(wp), intent(in) :: values(:)
      logical, intent(out) :: ok
      integer(hid_t) :: dset
      integer :: hdferr
      call write_vector(file, path, values, ok)
      if (.not. ok) return
      call h5dopen_f(file, path, dset, hdferr)
      ok = hdferr == 0
      if (.not. ok) return
      call text_attribute_on(dset, 'units', units, ok)
      call h5dclose_f(dset, hdferr)
   end subroutine write_fixed

   subroutine dataset_units(dset, units)
      integer(hid_t), intent(in) :: dset
      character(len=*), intent(in) :: units
      logical :: ok
      call text_attribute_on(dset, 'units', units, ok)
   end subroutine dataset_units

   !> Write the root attributes of a list (lists are datasets, not attributes: skipped).
   subroutine write_attributes(self, list)
      class(hdf5_recorder), intent(inout) :: self
      type(attribute_list), intent(in) :: list
      integer :: i
      do i = 1, list%count
         associate (item => list%items(i))
            if (.not. item%attribute .or. item%list) cycle
            select case (item%kind)
            case (kind_real)
               call attribute_real(self, item%name, item%reals(1))
            case (kind_int, kind_logical)
               call attribute_int(self, item%name, item%ints(1))
            case (kind_text)
               call attribute_text(self, item%name, item%text)
            end select
         end associate
      end do
   end subroutine write_attributes

   subroutine attribute_text(self, name, value)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: name, value
      logical :: ok
      if (self%failed) return
      call text_attribute_on(self%file, name, value, ok)
      if (.not. ok) call fail(self, 'cannot write attribute '//name//' to '//self%partial)
   end subroutine attribute_text

   !> Create or replace a scalar string attribute; ok is false on any HDF5 failure.
   subroutine text_attribute_on(object, name, value, ok)
      integer(hid_t), intent(in) :: object
      character(len=*), intent(in) :: name, value
      logical, intent(out) :: ok
      integer(hid_t) :: space, atype, attr
      integer(hsize_t) :: dims(1) = 1
      integer :: hdferr
      logical :: exists
      call h5aexists_f(object, name, exists, hdferr)
      if (exists) call h5adelete_f(object, name, hdferr)
      call h5screate_f(H5S_SCALAR_F, space, hdferr)
      call h5tcopy_f(H5T_C_S1, atype, hdferr)
      call h5tset_size_f(atype, int(max(1, len(value)), size_t), hdferr)
      call h5acreate_f(object, name, atype, space, attr, hdferr)
      ok = hdferr == 0
      if (ok) then
         call h5awrite_f(attr, atype, value, dims, hdferr)
         ok = hdferr == 0
      end if
      call h5aclose_f(attr, hdferr)
      call h5tclose_f(atype, hdferr)
      call h5sclose_f(space, hdferr)
   end subroutine text_attribute_on

   subroutine attribute_real(self, name, value)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: value
      real(wp), target :: buffer
      buffer = value
      call attribute_scalar(self, name, H5T_NATIVE_DOUBLE, h5kind_to_type(wp, H5_REAL_KIND), c_loc(buffer))
   end subroutine attribute_real

   subroutine attribute_int(self, name, value)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(ik), intent(in) :: value
      integer(ik), target :: buffer
      buffer = value
      call attribute_scalar(self, name, H5T_STD_I64LE, h5kind_to_type(ik, H5_INTEGER_KIND), c_loc(buffer))
   end subroutine attribute_int

   !> Create or replace a scalar numeric root attribute of file type `file_type` from memory at `value`.
   subroutine attribute_scalar(self, name, file_type, memory_type, value)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: name
      integer(hid_t), intent(in) :: file_type, memory_type
      type(c_ptr), intent(in) :: value
      integer(hid_t) :: space, attr
      integer :: hdferr
      logical :: exists
      if (self%failed) return
      call h5aexists_f(self%file, name, exists, hdferr)
      if (exists) call h5adelete_f(self%file, name, hdferr)
      call h5screate_f(H5S_SCALAR_F, space, hdferr)
      call h5acreate_f(self%file, name, file_type, space, attr, hdferr)
      call h5awrite_f(attr, memory_type, value, hdferr)
      if (hdferr /= 0) call fail(self, 'cannot write attribute '//name//' to '//self%partial)
      call h5aclose_f(attr, hdferr)
      call h5sclose_f(space, hdferr)
   end subroutine attribute_scalar

   !> Note the first failure: `what` went wrong with the output.
   subroutine fail(self, what)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: what
      if (.not. self%failed) self%message = self%path//': '//what
      self%failed = .true.
   end subroutine fail

   !> Why a file could not be created: the system's reason, or HDF5's when the system has none.
   function creation_failure(path) result(why)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: why
      why = creation_error(path)
      if (len(why) == 0) why = 'HDF5 could not create it'
   end function creation_failure

   !> What a failed write says.
   function write_failure(self) result(what)
      class(hdf5_recorder), intent(in) :: self
      character(len=:), allocatable :: what
      what = 'cannot write to '//self%partial//' (disk full, or beyond the file-size limit?)'
   end function write_failure
end module beamstops_recorder_hdf5
