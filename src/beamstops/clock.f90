!> CPU time of the calling thread (POSIX clock_gettime with CLOCK_THREAD_CPUTIME_ID):
!> unlike cpu_time, it does not count other threads of the process (parallel runs from
!> Python, threaded BLAS).
module beamstops_clock
   use, intrinsic :: iso_c_binding, only: c_int, c_long
   use beamstops_kinds, only: wp
   implicit none
   private
   public :: thread_cpu_seconds

   !> CLOCK_THREAD_CPUTIME_ID on Linux.
   integer(c_int), parameter :: clock_thread_cputime_id = 3

   type, bind(c) :: timespec
      integer(c_long) :: seconds
      integer(c_long) :: nanoseconds
   end type timespec

   interface
      function clock_gettime(clock, time) bind(c, name='clock_gettime') result(status)
         import :: c_int, timespec
         integer(c_int), value :: clock
         type(timespec), intent(out) :: time
         integer(c_int) :: status
      end function clock_gettime
   end interface

contains

   !> CPU seconds used by the calling thread so far (falls back to cpu_time).
   function thread_cpu_seconds() result(seconds)
      real(wp) :: seconds
      type(timespec) :: time
      if (clock_gettime(clock_thread_cputime_id, time) == 0) then
         seconds = real(time%seconds, wp) + 1.0e-9_wp*real(time%nanoseconds, wp)
      else
         call cpu_time(seconds)
      end if
   end function thread_cpu_seconds
end module beamstops_clock
