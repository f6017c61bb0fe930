!> A polite stop (C side: stop_signals.c). Around a time loop (one scene's: continue_run,
!> continue_reduced; a lockstep group's: simulate_group) the program, and the Python layer in its
!> main thread, catch SIGINT and SIGTERM (catch_stop_signals, release_stop_signals); a signal
!> then only leaves a note, which the loop reads between two of its blocks (stop_signal): the
!> run stops there with its records flushed, a checkpoint saved where the loop has one, status
!> 'interrupted', and `--restart` continues it bit for bit. Elsewhere stop_signal is 0 and a
!> signal has its usual effect; caught_signal says afterwards which signal it was.
module beamstops_stop_signals
   use, intrinsic :: iso_c_binding, only: c_int, c_ptr, c_char, c_f_pointer
   use beamstops_kinds, only: wp
   use beamstops_strings, only: fmt_real
   implicit none
   private
   public :: catch_stop_signals, release_stop_signals, stop_signal, caught_signal, signal_name, interrupted_at

   interface
      !> Note SIGINT and SIGTERM from now on instead of their default action (a second one takes it).
      subroutine catch_stop_signals() bind(c, name='beamstops_catch_stop_signals')
      end subroutine catch_stop_signals
      !> Give SIGINT and SIGTERM back the actions they had before catch_stop_signals.
      subroutine release_stop_signals() bind(c, name='beamstops_release_stop_signals')
      end subroutine release_stop_signals
      !> The signal noted since catch_stop_signals, while the signals are caught (0: none, or
      !> released).
      function stop_signal() bind(c, name='beamstops_stop_signal') result(signum)
         import :: c_int
         integer(c_int) :: signum
      end function stop_signal
      !> The signal noted the last time the signals were caught (0: none), for the run's report.
      function caught_signal() bind(c, name='beamstops_caught_signal') result(signum)
         import :: c_int
         integer(c_int) :: signum
      end function caught_signal
      function c_signal_name(signum) bind(c, name='beamstops_stop_signal_name') result(name)
         import :: c_int, c_ptr
         integer(c_int), value :: signum
         type(c_ptr) :: name
      end function c_signal_name
   end interface

contains

   !> 'SIGINT', 'SIGTERM' (or 'signal') for a number stop_signal gave.
   function signal_name(signum) result(name)
      !> Signal number.
      integer(c_int), intent(in) :: signum
      character(len=:), allocatable :: name
      character(kind=c_char), pointer :: text(:)
      integer :: k
      call c_f_pointer(c_signal_name(signum), text, [8])
      name = ''
      do k = 1, 8
         if (text(k) == char(0)) exit
         name = name//text(k)
      end do
   end function signal_name

   !> 'interrupted by SIGINT at t = ... s': how a loop without a summary of its own (the studies'
   !> three-level form and states) says that a signal ended it at time t.
   function interrupted_at(signum, t) result(text)
      !> Signal number.
      integer(c_int), intent(in) :: signum
      !> Time reached (s).
      real(wp), intent(in) :: t
      character(len=:), allocatable :: text
      text = 'interrupted by '//signal_name(signum)//' at t = '//fmt_real(t, 6)//' s'
   end function interrupted_at
end module beamstops_stop_signals
