!> The harness itself: a check must be able to fail, and its message must show both values.
module test_harness
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use testing
   implicit none
   private
   public :: collect_harness

contains

   !> Tests of the suite.
   subroutine collect_harness(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('real check fails and shows both values', test_real_fails), &
         & new_unittest('relative and absolute thresholds', test_thresholds), &
         & new_unittest('NaN never passes', test_nan), &
         & new_unittest('integer and logical checks fail on mismatch', test_int_logical), &
         & new_unittest('a declared failure', test_declared_failure, should_fail=.true.) &
         & ]
   end subroutine collect_harness

   subroutine test_real_fails(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: inner
      call check(inner, 1.5_wp, 2.5_wp, 'x', thr=0.1_wp)
      call check(error, allocated(inner), 'check(1.5, 2.5, thr=0.1) fails')
      if (allocated(error)) return
      call check(error, index(inner%message, '1.5') > 0 .and. index(inner%message, '2.5') > 0 &
         & .and. index(inner%message, 'x:') == 1, 'message shows both values: '//inner%message)
   end subroutine test_real_fails

   subroutine test_thresholds(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: inner
      call check(inner, 1000.5_wp, 1000.0_wp, thr=1e-3_wp, rel=.true.)
      call check(error, .not. allocated(inner), 'relative 5e-4 passes thr 1e-3'); if (allocated(error)) return
      call check(inner, 1000.5_wp, 1000.0_wp, thr=1e-3_wp)
      call check(error, allocated(inner), 'absolute 0.5 fails thr 1e-3'); if (allocated(error)) return
      deallocate (inner)
      call check(inner, 1.0_wp + epsilon(1.0_wp), 1.0_wp)
      call check(error, .not. allocated(inner), 'one ulp passes the default threshold'); if (allocated(error)) return
      call check(inner, 1.0_wp + 4*epsilon(1.0_wp), 1.0_wp)
      call check(error, allocated(inner), 'four ulp fail the default threshold')
   end subroutine test_thresholds

   subroutine test_nan(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: inner
      real(wp) :: nan
      nan = ieee_value(1.0_wp, ieee_quiet_nan)
      call check(inner, nan, 1.0_wp, thr=huge(1.0_wp))
      call check(error, allocated(inner), 'NaN against 1 fails'); if (allocated(error)) return
      deallocate (inner)
      call check(inner, 1.0_wp, nan, thr=huge(1.0_wp), rel=.true.)
      call check(error, allocated(inner), '1 against NaN fails')
   end subroutine test_nan

   subroutine test_int_logical(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: inner
      call check(inner, 3, 4, 'n')
      call check(error, allocated(inner), 'check(3, 4) fails'); if (allocated(error)) return
      call check(error, index(inner%message, '3') > 0 .and. index(inner%message, '4') > 0, &
         & 'message shows both integers: '//inner%message); if (allocated(error)) return
      deallocate (inner)
      call check(inner, .true., .false., 'flag')
      call check(error, allocated(inner), 'check(T, F) fails'); if (allocated(error)) return
      deallocate (inner)
      call check(inner, .false., 'must hold')
      call check(error, allocated(inner), 'check(.false., message) fails')
   end subroutine test_int_logical

   subroutine test_declared_failure(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, 1, 2, 'declared to fail')
   end subroutine test_declared_failure
end module test_harness
