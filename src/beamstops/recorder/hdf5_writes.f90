!> The HDF5 recorder's writes of records, as orders the writer thread carries out
!> (beamstops_writer_thread) while the time loop goes on: an order holds full buffers of
!> records, of the stops' values and of snapshots, the datasets they go to and the rows they
!> start at. The recorder fills one set of buffers while the writer stores the other; it hands
!> an order over only when the previous one is done, and reads `failed` only then.
module beamstops_recorder_hdf5_writes
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_f_pointer, c_loc, c_int64_t, c_associated
   use hdf5
   use beamstops_kinds, only: wp
   use beamstops_recorder_disk_space, only: disk_reservation, reserve
   use beamstops_recorder, only: col_t, col_u, col_v, col_reaction, col_energy, col_work, col_dissipated, col_damped
   use beamstops_writer_thread, only: writer_thread, post_order
   implicit none
   private
   public :: write_order, hand_over, n_series, series_column

   !> The series of one value a record: /tip/t, u, v, reaction, /energy/t, E, work,
   !> dissipated, damped.
   integer, parameter :: n_series = 9
   !> The column of a record row that goes to each series.
   integer, parameter :: series_column(n_series) = [col_t, col_u, col_v, col_reaction, col_t, col_energy, &
      & col_work, col_dissipated, col_damped]

   !> What the writer stores, and where: the file's datasets (the recorder creates, reopens and
   !> closes them here), the rows an order holds and where they start.
   type :: write_order
      !> Datasets: the record series, the stops' u and reaction, the snapshots' t and u.
      integer(hid_t) :: series(n_series) = -1, stops_u = -1, stops_reaction = -1, snap_t = -1, snap_u = -1
      !> Row of each dataset where the order's rows start.
      integer(hsize_t) :: written = 0, stops_written = 0, snaps_written = 0
      !> Stops along the span and nodes of a snapshot.
      integer :: stops = 0, nodes = 0
      !> Records (columns, rows), the stops' values (stops, rows), snapshot times and shapes (nodes, rows).
      real(wp), allocatable :: rows(:, :), stops_u_rows(:, :), stops_r_rows(:, :), snap_t_rows(:), snap_u_rows(:, :)
      !> The records as columns (rows, columns): each a series, picked out of `rows` in one pass.
      real(wp), allocatable :: columns(:, :)
      !> How many of each the order holds.
      integer :: fill = 0, stops_fill = 0, snap_fill = 0
      !> Set when a write failed (HDF5 said so); the recorder then fails with its own message.
      logical :: failed = .false.
      !> The disk space reserved ahead of the file's writes.
      type(disk_reservation) :: space
      !> When set, the order creates the file instead (beamstops_recorder_hdf5's create_file): the
      !> recorder whose file it is, and the run's model.
      type(c_ptr) :: creating = c_null_ptr, model = c_null_ptr
   end type write_order

   interface
      !> Create the file of the recorder at `recorder` (c_loc of a beamstops_recorder_hdf5
      !> hdf5_recorder), for the run's model at `model`.
      subroutine create_file(recorder, model) bind(c, name='beamstops_create_file')
         import :: c_ptr
         type(c_ptr), value :: recorder, model
      end subroutine create_file
   end interface

contains

   !> Give the order to the writer (which carries it out at once when it has no thread).
   subroutine hand_over(writer, order)
      !> The writer.
      type(writer_thread), intent(in) :: writer
      !> The order; it must stay where it is until the writer is done with it (wait_orders).
      type(write_order), intent(inout), target :: order
      call post_order(writer, c_loc(order))
   end subroutine hand_over

   !> The writer thread's job (called by writer_thread.c): carry out the order at `arg` (c_loc
   !> of a write_order): create the file, or append the order's rows.
   subroutine write_order_job(arg) bind(c, name='beamstops_write_order')
      !> The order.
      type(c_ptr), value :: arg
      type(write_order), pointer :: order
      integer :: hdferr
      ! HDF5 built thread-safe keeps an error stack per thread: its printing is off on this one
      ! too (failures become the recorder's message)
      call h5eset_auto_f(0, hdferr)
      call c_f_pointer(arg, order)
      if (c_associated(order%creating)) then
         call create_file(order%creating, order%model)
         order%creating = c_null_ptr
         order%model = c_null_ptr
         return
      end if
      call write_rows(order)
   end subroutine write_order_job

   !> Append the order's rows to their datasets, in space reserved ahead of them (none of them when
   !> the disk or the file-size limit has no room left: the order fails).
   subroutine write_rows(order)
      type(write_order), intent(inout) :: order
      integer :: i
      logical :: room
      ! no room: nothing of the order is written, and the file closes readable in its reserved room
      call reserve(order%space, order_bytes(order), room)
      if (.not. room) order%failed = .true.
      if (order%failed) return
      if (order%fill > 0) call to_columns(order)
      do i = 1, n_series
         call append(order, order%series(i), 1, order%written, order%fill, order%columns(:, series_column(i)))
      end do
      if (order%stops_fill > 0) then
         call append(order, order%stops_u, order%stops, order%stops_written, order%stops_fill, order%stops_u_rows, &
            & matrix=.true.)
         call append(order, order%stops_reaction, order%stops, order%stops_written, order%stops_fill, &
            & order%stops_r_rows, matrix=.true.)
      end if
      if (order%snap_fill > 0) then
         call append(order, order%snap_t, 1, order%snaps_written, order%snap_fill, order%snap_t_rows)
         call append(order, order%snap_u, order%nodes, order%snaps_written, order%snap_fill, order%snap_u_rows)
      end if
   end subroutine write_rows

   !> The records' columns, in one pass over their rows. Picking each series out of the rows
   !> (nine passes, each a copy with a stride of 64 bytes) took the writer thread 17-20 ms of the
   !> Figure 4 run, and the time loop on the other CPU read 3-4 ns a step slower meanwhile (the
   !> least and median of 20 alternated runs, with the disk space reserved in both). A later
   !> prototype without any pick-out (the rows written as they are, timing only) left the loop and
   !> the process's CPU time where they were: the memory reads move to pwrite's copy
   !> (docs/performance_notes.md, "The writer thread on the loop's CPU").
   subroutine to_columns(order)
      type(write_order), intent(inout) :: order
      integer :: r
      if (.not. allocated(order%columns)) allocate (order%columns(size(order%rows, 2), size(order%rows, 1)))
      do r = 1, order%fill
         order%columns(r, :) = order%rows(:, r)
      end do
   end subroutine to_columns

   !> The bytes of data an order adds to the file.
   pure function order_bytes(order) result(bytes)
      type(write_order), intent(in) :: order
      integer(c_int64_t) :: bytes
      bytes = 8*(int(order%fill, c_int64_t)*n_series + int(order%stops_fill, c_int64_t)*2*order%stops + &
         & int(order%snap_fill, c_int64_t)*(1 + order%nodes))
   end function order_bytes

   !> Append `rows` rows of `width` values (stored row after row in `values`) at row `offset`;
   !> a series of one value per row is 1-D unless `matrix`.
   subroutine append(order, dset, width, offset, rows, values, matrix)
      type(write_order), intent(inout) :: order
      integer(hid_t), intent(in) :: dset
      integer, intent(in) :: width, rows
      integer(hsize_t), intent(in) :: offset
      real(wp), intent(in) :: values(*)
      logical, intent(in), optional :: matrix
      integer(hid_t) :: filespace, memspace
      integer(hsize_t) :: dims(2), start(2), count(2)
      integer :: hdferr, rank
      if (order%failed .or. rows == 0) return
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
      if (hdferr /= 0) order%failed = .true.
      call h5sclose_f(memspace, hdferr)
      call h5sclose_f(filespace, hdferr)
   end subroutine append
end module beamstops_recorder_hdf5_writes
