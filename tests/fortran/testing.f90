!> A small test harness in the shape of test-drive (fortran-lang/test-drive), which
!> is not installable here: a test is `subroutine test_x(error)`, checks allocate
!> `error` with a message showing both values, and a suite prints TAP.
module testing
   use, intrinsic :: iso_fortran_env, only: output_unit
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
   use beamstops, only: wp, ik, error_type, fatal_error
   use beamstops_scene, only: fmt_int
   implicit none
   private
   public :: wp, error_type, fatal_error
   public :: unittest_type, new_unittest, check, test_failed, run_suite, note, real_text, int_text

   abstract interface
      !> A unit test: leaves `error` unallocated when it passes.
      subroutine test_interface(error)
         import :: error_type
         !> Allocated by the first failed check.
         type(error_type), allocatable, intent(out) :: error
      end subroutine test_interface
   end interface

   !> A named unit test.
   type :: unittest_type
      !> Name printed in the TAP line.
      character(len=:), allocatable :: name
      !> The test procedure.
      procedure(test_interface), pointer, nopass :: test => null()
      !> The test is expected to fail (a failure is then reported as ok).
      logical :: should_fail = .false.
   end type unittest_type

   !> Compare actual and expected values; on mismatch allocate `error` with both values.
   interface check
      module procedure check_real, check_int, check_logical, check_condition
   end interface check

   !> Text of an integer, default kind or ik (the engine's fmt_int).
   interface int_text
      module procedure int_text_default, fmt_int
   end interface int_text

contains

   !> A unit test from its name and procedure.
   function new_unittest(name, test, should_fail) result(self)
      !> Name printed in the TAP line.
      character(len=*), intent(in) :: name
      !> The test procedure.
      procedure(test_interface) :: test
      !> Declares an expected failure.
      logical, intent(in), optional :: should_fail
      type(unittest_type) :: self
      self%name = name
      self%test => test
      if (present(should_fail)) self%should_fail = should_fail
   end function new_unittest

   !> Text of a real with all significant digits.
   function real_text(x) result(s)
      !> Value.
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=40) :: buf
      write (buf, '(es24.16e3)') x
      s = trim(adjustl(buf))
   end function real_text

   !> Text of a default integer.
   pure function int_text_default(i) result(s)
      !> Value.
      integer, intent(in) :: i
      character(len=:), allocatable :: s
      s = fmt_int(int(i, ik))
   end function int_text_default

   !> Prefix of a failure message.
   function lead(message) result(s)
      character(len=*), intent(in), optional :: message
      character(len=:), allocatable :: s
      s = ''
      if (present(message)) s = message//': '
   end function lead

   !> Allocate `error` unconditionally.
   subroutine test_failed(error, message)
      !> Error to allocate.
      type(error_type), allocatable, intent(inout) :: error
      !> What failed.
      character(len=*), intent(in) :: message
      call fatal_error(error, message)
   end subroutine test_failed

   !> Reals: |actual - expected| <= thr, or |actual - expected| <= thr |expected| when rel.
   !> NaN never passes. Default threshold: epsilon (relative when rel).
   subroutine check_real(error, actual, expected, message, thr, rel)
      !> Allocated on failure.
      type(error_type), allocatable, intent(inout) :: error
      !> Value obtained.
      real(wp), intent(in) :: actual
      !> Value expected.
      real(wp), intent(in) :: expected
      !> What is compared.
      character(len=*), intent(in), optional :: message
      !> Tolerance (absolute, or relative when rel).
      real(wp), intent(in), optional :: thr
      !> Relative comparison.
      logical, intent(in), optional :: rel
      real(wp) :: tol, diff
      logical :: relative
      character(len=:), allocatable :: kind
      tol = epsilon(1.0_wp)
      if (present(thr)) tol = thr
      relative = .false.
      if (present(rel)) relative = rel
      diff = abs(actual - expected)
      if (relative) then
         if (expected /= 0) diff = diff/abs(expected)
      end if
      if (diff <= tol .and. .not. (ieee_is_nan(actual) .or. ieee_is_nan(expected))) return
      if (relative) then
         kind = 'relative difference '
      else
         kind = 'difference '
      end if
      call fatal_error(error, lead(message)//'expected '//real_text(expected)//', got '//real_text(actual)// &
         & ' ('//kind//real_text(diff)//' > threshold '//real_text(tol)//')')
   end subroutine check_real

   !> Integers: exact equality.
   subroutine check_int(error, actual, expected, message)
      !> Allocated on failure.
      type(error_type), allocatable, intent(inout) :: error
      !> Value obtained.
      integer, intent(in) :: actual
      !> Value expected.
      integer, intent(in) :: expected
      !> What is compared.
      character(len=*), intent(in), optional :: message
      if (actual == expected) return
      call fatal_error(error, lead(message)//'expected '//int_text(expected)//', got '//int_text(actual))
   end subroutine check_int

   !> Logicals: equality.
   subroutine check_logical(error, actual, expected, message)
      !> Allocated on failure.
      type(error_type), allocatable, intent(inout) :: error
      !> Value obtained.
      logical, intent(in) :: actual
      !> Value expected.
      logical, intent(in) :: expected
      !> What is compared.
      character(len=*), intent(in), optional :: message
      if (actual .eqv. expected) return
      call fatal_error(error, lead(message)//'expected '//merge('T', 'F', expected)//', got '//merge('T', 'F', actual))
   end subroutine check_logical

   !> A condition that must hold.
   subroutine check_condition(error, condition, message)
      !> Allocated on failure.
      type(error_type), allocatable, intent(inout) :: error
      !> Must be true.
      logical, intent(in) :: condition
      !> What the condition states (and the values involved).
      character(len=*), intent(in) :: message
      if (condition) return
      call fatal_error(error, 'condition failed: '//message)
   end subroutine check_condition

   !> A TAP diagnostic line ("# message"), for measured numbers.
   subroutine note(message)
      !> Text to print.
      character(len=*), intent(in) :: message
      write (output_unit, '(a)') '# '//message
      flush (output_unit)
   end subroutine note

   !> Run the tests of a suite, print TAP and return the number of failures.
   function run_suite(name, tests) result(failures)
      !> Suite name (printed as a diagnostic).
      character(len=*), intent(in) :: name
      !> Tests to run.
      type(unittest_type), intent(in) :: tests(:)
      integer :: failures
      type(error_type), allocatable :: error
      character(len=:), allocatable :: msg
      integer :: k, i
      failures = 0
      write (output_unit, '(a,i0)') '1..', size(tests)
      write (output_unit, '(a)') '# suite '//name
      flush (output_unit)
      do k = 1, size(tests)
         call tests(k)%test(error)
         if (allocated(error) .neqv. tests(k)%should_fail) then
            failures = failures + 1
            if (allocated(error)) then
               msg = error%message
            else
               msg = 'expected to fail, but passed'
            end if
            do i = 1, len(msg)
               if (iachar(msg(i:i)) < 32) msg(i:i) = ' '
            end do
            write (output_unit, '(a,i0,a)') 'not ok ', k, ' - '//tests(k)%name//' # '//msg
         else
            write (output_unit, '(a,i0,a)') 'ok ', k, ' - '//tests(k)%name
         end if
         flush (output_unit)
         if (allocated(error)) deallocate (error)
      end do
   end function run_suite
end module testing
