!> Placeholder (filled below).
module test_restitution
   use testing
   implicit none
   private
   public :: collect_restitution
contains
   !> Tests of the suite.
   subroutine collect_restitution(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      allocate (tests(0))
   end subroutine collect_restitution
end module test_restitution
