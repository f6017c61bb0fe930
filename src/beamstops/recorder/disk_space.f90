!> Disk space reserved ahead of an output file as its records are appended
!> (src/beamstops/recorder/disk_space.c): the HDF5 recorder's writer reserves the blocks its next
!> writes go to, so that the file system does not allocate them one write at a time, and keeps
!> `margin` more reserved for what closing the file writes: a write that finds no room on the
!> disk (or under the file-size limit) is refused before it starts, and the file still closes
!> readable. A run that is killed leaves its partial file with at most one reservation of blocks
!> past its end; they are released when the run is resumed and ends, or when the file is removed.
module beamstops_recorder_disk_space
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_int64_t, c_null_char
   implicit none
   private
   public :: disk_reservation, open_reservation, reserve, close_reservation

   !> Bytes reserved at a time: four times what the write asks for, at least 1 MiB (the paper's
   !> Figure 4 run, 1.2 MB an order of the writer, reserves 4.7 MB every fourth order).
   integer(c_int64_t), parameter :: least_ahead = 2_c_int64_t**20
   !> Bytes kept reserved past the data for what closing the file adds at its end (on the Figure 4
   !> scene, stopped by the file-size limit: 168 bytes past the last records; the rest of the close
   !> rewrites metadata inside the file).
   integer(c_int64_t), parameter :: margin = 2_c_int64_t**16

   !> The reservation of one file: a descriptor of it (-1: none, nothing is checked) and the end
   !> of what is reserved (-1: the file system takes no reservation; the file-size limit is still
   !> checked before each write).
   type :: disk_reservation
      integer(c_int) :: fd = -1
      integer(c_int64_t) :: reserved = 0
   end type disk_reservation

   interface
      function c_open(path) bind(c, name='beamstops_reservation_open') result(fd)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: fd
      end function c_open
      function c_extend(fd, bytes, ahead, reserved) bind(c, name='beamstops_reservation_extend') result(new_end)
         import :: c_int, c_int64_t
         integer(c_int), value :: fd
         integer(c_int64_t), value :: bytes, ahead, reserved
         integer(c_int64_t) :: new_end
      end function c_extend
      subroutine c_close(fd) bind(c, name='beamstops_reservation_close')
         import :: c_int
         integer(c_int), value :: fd
      end subroutine c_close
   end interface

contains

   !> Start reserving space for the file at `path` (nothing is reserved yet; where the file
   !> cannot be opened again, no reservation is made).
   subroutine open_reservation(reservation, path)
      !> The reservation (a previous one is ended first).
      type(disk_reservation), intent(inout) :: reservation
      !> The file, which exists.
      character(len=*), intent(in) :: path
      call close_reservation(reservation)
      reservation%fd = c_open(path//c_null_char)
      reservation%reserved = merge(0_c_int64_t, -1_c_int64_t, reservation%fd >= 0)
   end subroutine open_reservation

   !> Make sure the next `bytes` past the file's end are reserved, and `margin` more; `room` is
   !> false when the disk, or the file-size limit, has no room for them (the write must not start).
   subroutine reserve(reservation, bytes, room)
      !> The reservation.
      type(disk_reservation), intent(inout) :: reservation
      !> Bytes the next writes add to the file.
      integer(c_int64_t), intent(in) :: bytes
      !> Whether they may be written.
      logical, intent(out) :: room
      integer(c_int64_t) :: new_end
      room = .true.
      if (reservation%fd < 0) return
      new_end = c_extend(reservation%fd, bytes + margin, max(least_ahead, 4*bytes) + margin, reservation%reserved)
      room = new_end /= -2
      if (room) reservation%reserved = new_end
   end subroutine reserve

   !> End the reservation: the blocks reserved past the file's end are released.
   subroutine close_reservation(reservation)
      !> The reservation.
      type(disk_reservation), intent(inout) :: reservation
      if (reservation%fd >= 0) call c_close(reservation%fd)
      reservation = disk_reservation()
   end subroutine close_reservation
end module beamstops_recorder_disk_space
