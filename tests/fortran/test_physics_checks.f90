!> Placeholder (filled below).
module test_physics_checks
   use testing
   implicit none
   private
   public :: collect_physics_checks
contains
   !> Tests of the suite.
   subroutine collect_physics_checks(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      allocate (tests(0))
   end subroutine collect_physics_checks
end module test_physics_checks
