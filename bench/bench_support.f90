!> Helpers of the benchmark programs (bench_kernels, bench_lockstep, bench_reduced): their
!> command-line arguments, the median of timings, `key value` output lines, a value the
!> compiler cannot fold, and the stop on a bad argument.
module bench_support
   use, intrinsic :: iso_fortran_env, only: error_unit
   use beamstops_kinds, only: wp
   implicit none
   private
   public :: runtime_one, median, put, argument, int_argument, fail

contains

   !> 1, but not known to the compiler.
   function runtime_one() result(one)
      real(wp) :: one
      character(len=8) :: text
      call get_environment_variable('BEAMSTOPS_BENCH_NEVER_SET', text)
      one = merge(2.0_wp, 1.0_wp, text == 'two')
   end function runtime_one

   !> Median of some timings.
   function median(t) result(m)
      !> Timings.
      real(wp), intent(in) :: t(:)
      real(wp) :: m, s(size(t)), v
      integer :: i, j
      s = t
      do i = 2, size(s)
         v = s(i)
         j = i - 1
         do while (j >= 1)
            if (s(j) <= v) exit
            s(j + 1) = s(j)
            j = j - 1
         end do
         s(j + 1) = v
      end do
      m = 0.5_wp*(s((size(s) + 1)/2) + s(size(s)/2 + 1))
   end function median

   !> Print a line `key value` (the format scripts/bench.py reads).
   subroutine put(key, value)
      !> Key.
      character(len=*), intent(in) :: key
      !> Value.
      real(wp), intent(in) :: value
      print '(a, 1x, es16.9)', key, value
   end subroutine put

   !> The i-th command-line argument, or `default` without it.
   function argument(i, default) result(text)
      !> Position.
      integer, intent(in) :: i
      !> Value without it.
      character(len=*), intent(in) :: default
      character(len=64) :: text
      text = default
      if (command_argument_count() >= i) call get_command_argument(i, text)
   end function argument

   !> The i-th command-line argument as an integer, or `default` without it; stops on a text
   !> that is not an integer.
   function int_argument(i, default) result(value)
      !> Position, and the value without it.
      integer, intent(in) :: i, default
      integer :: value, status
      character(len=64) :: text
      value = default
      if (command_argument_count() < i) return
      call get_command_argument(i, text)
      read (text, *, iostat=status) value
      if (status /= 0) call fail('not an integer: '//trim(text))
   end function int_argument

   !> Stop with `program: message` on standard error (program: the command's own name).
   subroutine fail(message)
      !> What went wrong.
      character(len=*), intent(in) :: message
      character(len=256) :: program
      call get_command_argument(0, program)
      write (error_unit, '(a)') trim(program(index(program, '/', back=.true.) + 1:))//': '//message
      error stop 1
   end subroutine fail
end module bench_support
