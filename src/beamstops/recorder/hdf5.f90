!> The HDF5 writer: chunked, extendable datasets written as the run goes,
!> the scene and the results as root attributes, and a `status` attribute that
!> says 'complete' only once the run has finished and every record is on disk.
!>
!>   /tip/t, /tip/u, /tip/v, /tip/reaction
!>   /energy/t, /energy/E, /energy/work, /energy/dissipated, /energy/damped
!>   /snapshots/t, /snapshots/x, /snapshots/u   (u: snapshots x (J+1))
!>   /stops/x, /stops/node, /stops/lower, /stops/upper, /stops/u, /stops/reaction
!>                                              (stops along the span; u, reaction: records x m)
module beamstops_recorder_hdf5
   use, intrinsic :: iso_c_binding, only: c_loc, c_ptr
   use hdf5
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type, law_name, law_compliance, stop_count
   use beamstops_model, only: model_type
   use beamstops_summary, only: run_summary, status_running, status_complete
   use beamstops_state, only: state_type
   use beamstops_checkpoint, only: write_checkpoint, checkpoint_path, remove_file
   use beamstops_recorder_hdf5_vector, only: write_vector
   use beamstops_recorder, only: recorder_type, n_columns, col_t, col_u, col_v, col_reaction, col_energy, &
      & col_work, col_dissipated, col_damped
   use beamstops_version, only: version
   implicit none
   private
   public :: hdf5_recorder

   !> Rows buffered before a write (and rows of a chunk).
   integer, parameter :: buffer_rows = 16384
   integer, parameter :: n_series = 9
   character(len=*), parameter :: group_names(3) = [character(len=9) :: 'tip', 'energy', 'snapshots']
   character(len=*), parameter :: series_path(n_series) = [character(len=18) :: '/tip/t', '/tip/u', '/tip/v', &
      & '/tip/reaction', '/energy/t', '/energy/E', '/energy/work', '/energy/dissipated', '/energy/damped']
   character(len=*), parameter :: series_units(n_series) = [character(len=4) :: 's', 'm', 'm/s', 'N', 's', &
      & 'J', 'J', 'J', 'J']
   integer, parameter :: series_column(n_series) = [col_t, col_u, col_v, col_reaction, col_t, col_energy, &
      & col_work, col_dissipated, col_damped]

   !> Recorder writing an HDF5 file.
   type, extends(recorder_type) :: hdf5_recorder
      !> File name.
      character(len=:), allocatable :: path
      !> Message of the first failure.
      character(len=:), allocatable :: message
      integer(hid_t) :: file = -1
      integer(hid_t) :: series(n_series) = -1
      integer(hid_t) :: snap_t = -1, snap_u = -1
      integer(hsize_t) :: written = 0, snaps_written = 0
      integer :: fill = 0
      integer :: nodes = 0
      !> Buffered rows (buffer_rows, n_columns): each series a contiguous column.
      real(wp), allocatable :: buffer(:, :)
      !> Scene of the run (for checkpoints).
      type(scene_type) :: scene
      !> Buffered snapshots: times and shapes (nodes, snapshot_rows).
      real(wp), allocatable :: snap_t_buffer(:), snap_u_buffer(:, :)
      integer :: snap_fill = 0, snapshot_rows = 0
      !> Print a progress line on stderr.
      logical :: show_progress = .false.
      !> Stops along the span m, their two series (records x m) and buffers (m, stops_rows).
      integer :: stops = 0
      integer(hid_t) :: stops_u = -1, stops_reaction = -1
      real(wp), allocatable :: stops_u_buffer(:, :), stops_r_buffer(:, :)
      integer :: stops_fill = 0, stops_rows = 0
      integer(hsize_t) :: stops_written = 0
   contains
      procedure :: open => open_file
      procedure :: reopen
      procedure :: record
      procedure :: record_stops
      procedure :: checkpoint
      procedure :: snapshot
      procedure :: progress
      procedure :: finish
   end type hdf5_recorder

contains

   !> Create the file, its datasets and the scene's attributes; status 'running'.
   subroutine open_file(self, path, scene, model, error)
      !> Recorder.
      class(hdf5_recorder), intent(inout) :: self
      !> File to create (replaced if it exists).
      character(len=*), intent(in) :: path
      !> Scene of the run.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> Set when the file cannot be created.
      type(error_type), allocatable, intent(out) :: error
      integer :: hdferr, i
      integer(hid_t) :: group
      logical :: ok
      call prepare(self, path, scene, model)
      call remove_file(checkpoint_path(path))
      call h5fcreate_f(path, H5F_ACC_TRUNC_F, self%file, hdferr)
      if (hdferr /= 0) then
         call fatal_error(error, path//': cannot create the HDF5 file')
         self%failed = .true.
         return
      end if
      do i = 1, 3
         call h5gcreate_f(self%file, trim(group_names(i)), group, hdferr)
         call h5gclose_f(group, hdferr)
      end do
      do i = 1, n_series
         call create_series(self, trim(series_path(i)), trim(series_units(i)), 1, self%series(i))
      end do
      if (scene%snapshot_every > 0) then
         call create_series(self, '/snapshots/t', 's', 1, self%snap_t)
         call create_series(self, '/snapshots/u', 'm', self%nodes, self%snap_u)
      end if
      call allocate_stops_buffer(self)
      call write_vector(self%file, '/snapshots/x', model%x, ok)
      if (.not. ok) call fail(self, 'cannot write dataset /snapshots/x')
      if (stop_count(scene) > 0) call create_stops(self, scene, model)
      call attribute_text(self, 'status', status_running)
      call attribute_text(self, 'version', version)
      call attribute_real(self, 'length', scene%length)
      call attribute_real(self, 'k2', scene%k2)
      call attribute_real(self, 'mass_per_length', scene%mass_per_length)
      call attribute_real(self, 'amplitude', scene%amplitude)
      call attribute_real(self, 'omega', scene%omega)
      if (stop_count(scene) == 0) then
         call attribute_real(self, 'lower', scene%lower)
         call attribute_real(self, 'upper', scene%upper)
      else
         call attribute_int(self, 'stops', int(stop_count(scene), ik))
      end if
      call attribute_text(self, 'law', law_name(scene%law))
      if (scene%law == law_compliance) call attribute_real(self, 'stiffness_per_mass', scene%stiffness_per_mass)
      call attribute_int(self, 'elements', int(scene%elements, ik))
      call attribute_real(self, 'dt', scene%dt)
      call attribute_real(self, 't_end', scene%t_end)
      call attribute_real(self, 'beta', scene%beta)
      call attribute_text(self, 'load_rule', merge('centered', 'paper   ', scene%centered_load))
      call attribute_text(self, 'start', merge('taylor', 'euler ', scene%taylor_start))
      call attribute_int(self, 'record_every', int(scene%record_every, ik))
      call attribute_int(self, 'snapshot_every', int(scene%snapshot_every, ik))
      call attribute_int(self, 'allow_unstable', merge(1_ik, 0_ik, scene%allow_unstable))
      call attribute_real(self, 'max_output_gb', scene%max_output_gb)
      call attribute_real(self, 'kappa_h', model%kappa_h)
      call attribute_real(self, 'kappa_bound', model%kappa_bound)
      call attribute_real(self, 'dt_limit_newmark', model%dt_newmark)
      call attribute_real(self, 'dt_limit_paper', model%dt_paper_exact)
      call attribute_real(self, 'dt_limit_paper_bound', model%dt_paper_bound)
      if (self%failed) then
         call fatal_error(error, self%message)
         return
      end if
      call h5fflush_f(self%file, H5F_SCOPE_GLOBAL_F, hdferr)
   end subroutine open_file

   !> Buffer one row; write the buffer when full.
   subroutine record(self, row)
      class(hdf5_recorder), intent(inout) :: self
      real(wp), intent(in) :: row(n_columns)
      self%fill = self%fill + 1
      self%buffer(self%fill, :) = row
      if (self%fill == buffer_rows) call write_buffer(self)
   end subroutine record

   !> Buffer the stops' values of the row that follows; write the buffers when full.
   subroutine record_stops(self, u, reaction)
      class(hdf5_recorder), intent(inout) :: self
      real(wp), intent(in) :: u(:)
      real(wp), intent(in) :: reaction(:)
      if (self%stops == 0) return
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
      call write_vector(self%file, '/stops/x', model%stops%x, ok(1))
      call write_vector(self%file, '/stops/node', real(scene%stop_nodes, wp), ok(2))
      call write_vector(self%file, '/stops/lower', scene%stop_lower, ok(3))
      call write_vector(self%file, '/stops/upper', scene%stop_upper, ok(4))
      if (.not. all(ok)) call fail(self, 'cannot write the datasets of /stops')
      call create_series(self, '/stops/u', 'm', stop_count(scene), self%stops_u, matrix=.true.)
      call create_series(self, '/stops/reaction', 'N', stop_count(scene), self%stops_reaction, matrix=.true.)
   end subroutine create_stops

   !> Buffers of the stops' series (when the scene has stops along the span).
   subroutine allocate_stops_buffer(self)
      class(hdf5_recorder), intent(inout) :: self
      self%stops = stop_count(self%scene)
      if (self%stops == 0) return
      self%stops_rows = max(1, min(buffer_rows, 2**19/self%stops))
      allocate (self%stops_u_buffer(self%stops, self%stops_rows), self%stops_r_buffer(self%stops, self%stops_rows))
   end subroutine allocate_stops_buffer

   !> Buffer one snapshot; write the buffer when full.
   subroutine snapshot(self, t, u)
      class(hdf5_recorder), intent(inout) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: u(:)
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
      if (step == steps) write (0, '(a)') ''
      flush (0)
   end subroutine progress

   !> Write what is buffered, the results as attributes and the final status; close the file.
   subroutine finish(self, summary, error)
      !> Recorder.
      class(hdf5_recorder), intent(inout) :: self
      !> Outcome of the run.
      type(run_summary), intent(in) :: summary
      !> Set when the file could not be completed.
      type(error_type), allocatable, intent(out) :: error
      integer :: hdferr
      if (self%file < 0) return
      call write_buffer(self)
      call attribute_int(self, 'steps', summary%steps)
      call attribute_real(self, 't_final', summary%t_final)
      call attribute_real(self, 'cpu_seconds', summary%cpu_seconds)
      call attribute_int(self, 'impacts', summary%impacts)
      call attribute_real(self, 'max_violation', summary%max_violation)
      if (allocated(summary%message)) call attribute_text(self, 'message', summary%message)
      call h5fflush_f(self%file, H5F_SCOPE_GLOBAL_F, hdferr)
      if (.not. self%failed) call attribute_text(self, 'status', summary%status)
      call h5fclose_f(self%file, hdferr)
      self%file = -1
      if (summary%status == status_complete .and. .not. self%failed .and. hdferr == 0) &
         & call remove_file(checkpoint_path(self%path))
      if (self%failed .or. hdferr /= 0) then
         if (.not. allocated(self%message)) self%message = self%path//': cannot close the HDF5 file'
         call fatal_error(error, self%message)
      end if
   end subroutine finish

   !> Open the output of an interrupted run to continue it: its series are cut back to the
   !> `records` and `snapshots` of the checkpoint, its status is 'incomplete' again.
   subroutine reopen(self, path, scene, model, records, snapshots, error)
      !> Recorder.
      class(hdf5_recorder), intent(inout) :: self
      !> Output file of the interrupted run.
      character(len=*), intent(in) :: path
      !> Scene of the run.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> Records and snapshots written before the checkpoint.
      integer(ik), intent(in) :: records, snapshots
      !> Set when the file cannot be opened or lacks a series.
      type(error_type), allocatable, intent(out) :: error
      integer :: hdferr, i
      call prepare(self, path, scene, model)
      call h5fopen_f(path, H5F_ACC_RDWR_F, self%file, hdferr)
      if (hdferr /= 0) then
         self%failed = .true.
         call fatal_error(error, path//': cannot reopen the output of the interrupted run')
         return
      end if
      do i = 1, n_series
         call reopen_series(trim(series_path(i)), self%series(i), [records])
      end do
      if (scene%snapshot_every > 0) then
         call reopen_series('/snapshots/t', self%snap_t, [snapshots])
         call reopen_series('/snapshots/u', self%snap_u, [int(self%nodes, ik), snapshots])
      end if
      call allocate_stops_buffer(self)
      if (self%stops > 0) then
         call reopen_series('/stops/u', self%stops_u, [int(self%stops, ik), records])
         call reopen_series('/stops/reaction', self%stops_reaction, [int(self%stops, ik), records])
      end if
      self%written = records
      self%snaps_written = snapshots
      self%stops_written = records
      call attribute_text(self, 'status', status_running)
      if (self%failed) call fatal_error(error, self%message)

   contains

      subroutine reopen_series(name, dset, dims)
         character(len=*), intent(in) :: name
         integer(hid_t), intent(out) :: dset
         integer(ik), intent(in) :: dims(:)
         call h5dopen_f(self%file, name, dset, hdferr)
         if (hdferr == 0) call h5dset_extent_f(dset, int(dims, hsize_t), hdferr)
         if (hdferr /= 0) call fail(self, 'the output of the interrupted run has no series '//name)
      end subroutine reopen_series
   end subroutine reopen

   !> Write what is buffered, flush the file, then the checkpoint (atomically).
   subroutine checkpoint(self, state)
      class(hdf5_recorder), intent(inout) :: self
      type(state_type), intent(in) :: state
      type(error_type), allocatable :: error
      integer :: hdferr
      if (self%failed) return
      call write_buffer(self)
      call h5fflush_f(self%file, H5F_SCOPE_GLOBAL_F, hdferr)
      if (hdferr /= 0) call fail(self, 'cannot flush the HDF5 file')
      if (self%failed) return
      call write_checkpoint(checkpoint_path(self%path), self%scene, state, int(self%written, ik), &
         & int(self%snaps_written, ik), error)
      if (allocated(error)) call fail(self, error%message)
   end subroutine checkpoint

   !> What opening and reopening share: the run's names and sizes, the buffers, the HDF5
   !> library (its own error printing off: failures become messages).
   subroutine prepare(self, path, scene, model)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      integer :: hdferr
      self%path = path
      self%scene = scene
      self%nodes = size(model%x)
      allocate (self%buffer(buffer_rows, n_columns))
      if (scene%snapshot_every > 0) then
         self%snapshot_rows = max(1, min(buffer_rows, 2**20/self%nodes))
         allocate (self%snap_t_buffer(self%snapshot_rows), self%snap_u_buffer(self%nodes, self%snapshot_rows))
      end if
      call h5open_f(hdferr)
      call h5eset_auto_f(0, hdferr)
   end subroutine prepare

   !> Write the buffered records and snapshots.
   subroutine write_buffer(self)
      class(hdf5_recorder), intent(inout) :: self
      integer :: i
      do i = 1, n_series
         call append(self, self%series(i), 1, self%written, self%fill, self%buffer(:, series_column(i)))
      end do
      self%written = self%written + self%fill
      self%fill = 0
      if (self%stops_fill > 0) then
         call append(self, self%stops_u, self%stops, self%stops_written, self%stops_fill, self%stops_u_buffer, &
            & matrix=.true.)
         call append(self, self%stops_reaction, self%stops, self%stops_written, self%stops_fill, self%stops_r_buffer, &
            & matrix=.true.)
         self%stops_written = self%stops_written + self%stops_fill
         self%stops_fill = 0
      end if
      if (self%snap_fill > 0) then
         call append(self, self%snap_t, 1, self%snaps_written, self%snap_fill, self%snap_t_buffer)
         call append(self, self%snap_u, self%nodes, self%snaps_written, self%snap_fill, self%snap_u_buffer)
         self%snaps_written = self%snaps_written + self%snap_fill
         self%snap_fill = 0
      end if
   end subroutine write_buffer

   !> Append `rows` rows of `width` values (stored row after row in `values`) at row `offset`;
   !> a series of one value per row is 1-D unless `matrix`.
   subroutine append(self, dset, width, offset, rows, values, matrix)
      class(hdf5_recorder), intent(inout) :: self
      integer(hid_t), intent(in) :: dset
      integer, intent(in) :: width, rows
      integer(hsize_t), intent(in) :: offset
      real(wp), intent(in) :: values(*)
      logical, intent(in), optional :: matrix
      integer(hid_t) :: filespace, memspace
      integer(hsize_t) :: dims(2), start(2), count(2)
      integer :: hdferr, rank
      if (self%failed .or. rows == 0) return
      rank = merge(1, 2, width == 1)
      if (present(matrix)) rank = merge(2, rank, matrix)
      if (rank == 1) then
         dims(1) = offset + rows; start(1) = offset; count(1) = rows
      else
         dims = [int(width, hsize_t), offset + rows]; start = [0_hsize_t, offset]
         count = [int(width, hsize_t), int(rows, hsize_t)]
      end if
      call h5dset_extent_f(dset, dims(:rank), hdferr)
      call h5dget_space_f(dset, filespace, hdferr)
      call h5sselect_hyperslab_f(filespace, H5S_SELECT_SET_F, start(:rank), count(:rank), hdferr)
      call h5screate_simple_f(rank, count(:rank), memspace, hdferr)
      call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, values, count(:rank), hdferr, memspace, filespace)
      if (hdferr /= 0) call fail(self, 'cannot write to the HDF5 file (disk full?)')
      call h5sclose_f(memspace, hdferr)
      call h5sclose_f(filespace, hdferr)
   end subroutine append

   !> An extendable, chunked dataset of rows of `width` doubles (1-D for width 1 unless `matrix`).
   subroutine create_series(self, path, units, width, dset, matrix)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: path, units
      integer, intent(in) :: width
      integer(hid_t), intent(out) :: dset
      logical, intent(in), optional :: matrix
      integer(hid_t) :: space, plist
      integer(hsize_t) :: dims(2), maxdims(2), chunk(2)
      integer :: hdferr, rank
      rank = merge(1, 2, width == 1)
      if (present(matrix)) rank = merge(2, rank, matrix)
      if (rank == 1) then
         dims(1) = 0; maxdims(1) = H5S_UNLIMITED_F; chunk(1) = buffer_rows
      else
         dims = [int(width, hsize_t), 0_hsize_t]; maxdims = [int(width, hsize_t), H5S_UNLIMITED_F]
         chunk = [int(width, hsize_t), int(max(1, min(256, 65536/width)), hsize_t)]
      end if
      call h5screate_simple_f(rank, dims(:rank), space, hdferr, maxdims(:rank))
      call h5pcreate_f(H5P_DATASET_CREATE_F, plist, hdferr)
      call h5pset_chunk_f(plist, rank, chunk(:rank), hdferr)
      call h5dcreate_f(self%file, path, H5T_NATIVE_DOUBLE, space, dset, hdferr, plist)
      if (hdferr /= 0) call fail(self, 'cannot create dataset '//path)
      call h5pclose_f(plist, hdferr)
      call h5sclose_f(space, hdferr)
      call dataset_units(dset, units)
   end subroutine create_series

   subroutine dataset_units(dset, units)
      integer(hid_t), intent(in) :: dset
      character(len=*), intent(in) :: units
      call text_attribute_on(dset, 'units', units)
   end subroutine dataset_units

   subroutine attribute_text(self, name, value)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: name, value
      if (self%failed) return
      call text_attribute_on(self%file, name, value)
   end subroutine attribute_text

   !> Create or replace a scalar string attribute.
   subroutine text_attribute_on(object, name, value)
      integer(hid_t), intent(in) :: object
      character(len=*), intent(in) :: name, value
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
      call h5awrite_f(attr, atype, value, dims, hdferr)
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
      if (hdferr /= 0) call fail(self, 'cannot write attribute '//name)
      call h5aclose_f(attr, hdferr)
      call h5sclose_f(space, hdferr)
   end subroutine attribute_scalar

   subroutine fail(self, what)
      class(hdf5_recorder), intent(inout) :: self
      character(len=*), intent(in) :: what
      if (.not. self%failed) self%message = self%path//': '//what
      self%failed = .true.
   end subroutine fail
end module beamstops_recorder_hdf5
