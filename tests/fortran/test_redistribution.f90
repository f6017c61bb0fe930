!> Placeholder (filled below).
module test_redistribution
   use testing
   implicit none
   private
   public :: collect_redistribution
contains
   !> Tests of the suite.
   subroutine collect_redistribution(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      allocate (tests(0))
   end subroutine collect_redistribution
end module test_redistribution
