!> The writer thread of `beamstops run` (C side: writer_thread.c): the HDF5 recorder hands every
!> full buffer of records to it as a write order (beamstops_recorder_hdf5_writes) and the time
!> loop goes on while it writes. One thread per program, shared by all its recorders, so that
!> HDF5 is only ever called by one thread at a time: the loop's thread waits for the order in
!> progress (wait_orders) before it calls HDF5 itself. The program starts it (start_writer) when
!> the process may use more than one CPU and stops it at the end; a recorder without one (the
!> Python layer's, a process bound to one CPU) carries the orders out where it posts them.
module beamstops_writer_thread
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_int, c_double, c_associated
   implicit none
   private
   public :: writer_thread, start_writer, stop_writer, post_order, wait_orders, stream_row

   !> A handle on the writer thread (none: orders are carried out where they are posted).
   type :: writer_thread
      type(c_ptr) :: handle = c_null_ptr
   end type writer_thread

   interface
      function c_usable_cpus() bind(c, name='beamstops_usable_cpus') result(n)
         import :: c_int
         integer(c_int) :: n
      end function c_usable_cpus
      function c_writer_start() bind(c, name='beamstops_writer_start') result(handle)
         import :: c_ptr
         type(c_ptr) :: handle
      end function c_writer_start
      subroutine c_writer_stop(handle) bind(c, name='beamstops_writer_stop')
         import :: c_ptr
         type(c_ptr), value :: handle
      end subroutine c_writer_stop
      subroutine c_writer_wait(handle) bind(c, name='beamstops_writer_wait')
         import :: c_ptr
         type(c_ptr), value :: handle
      end subroutine c_writer_wait
      subroutine c_writer_post(handle, arg) bind(c, name='beamstops_writer_post')
         import :: c_ptr
         type(c_ptr), value :: handle
         type(c_ptr), value :: arg
      end subroutine c_writer_post
      !> Copy a record of 8 values into a buffer that will be posted to the writer, past the
      !> caches (writer_thread.c); post_order makes the copies visible to the writer. Returns
      !> 1 when the values are all finite (beamstops_recorder's all_finite), 0 otherwise.
      function stream_row(dst, src) bind(c, name='beamstops_stream_row') result(finite)
         import :: c_double, c_int
         real(c_double), intent(out) :: dst(8)
         real(c_double), intent(in) :: src(8)
         integer(c_int) :: finite
      end function stream_row
   end interface

contains

   !> Start the writer thread when the process may run on more than one CPU (else, or when the
   !> thread cannot be created, the handle stays empty and the orders run where posted).
   subroutine start_writer(writer)
      !> The writer, started.
      type(writer_thread), intent(out) :: writer
      if (c_usable_cpus() > 1) writer%handle = c_writer_start()
   end subroutine start_writer

   !> Wait for the last order and end the thread.
   subroutine stop_writer(writer)
      !> The writer, stopped (empty on return).
      type(writer_thread), intent(inout) :: writer
      if (.not. c_associated(writer%handle)) return
      call c_writer_stop(writer%handle)
      writer%handle = c_null_ptr
   end subroutine stop_writer

   !> Carry out the write order at `order` (c_loc of a beamstops_recorder_hdf5_writes
   !> write_order) on the writer thread once its previous order is done (at once, here,
   !> without a thread).
   subroutine post_order(writer, order)
      !> The writer.
      type(writer_thread), intent(in) :: writer
      !> The order.
      type(c_ptr), intent(in) :: order
      call c_writer_post(writer%handle, order)
   end subroutine post_order

   !> Wait until no order runs: everything the orders wrote is then visible to the caller.
   subroutine wait_orders(writer)
      !> The writer.
      type(writer_thread), intent(in) :: writer
      call c_writer_wait(writer%handle)
   end subroutine wait_orders
end module beamstops_writer_thread
