!> Error object travelling through the engine: the library never stops,
!> it allocates an error_type and returns; only the program (or the Python
!> wrapper) turns it into an exit status or an exception.
module beamstops_error
   implicit none
   private
   public :: error_type, fatal_error

   !> A failure with a human-readable message.
   type :: error_type
      !> What went wrong, naming file, group, key and allowed range when it is an input error.
      character(len=:), allocatable :: message
   end type error_type

contains

   !> Allocate `error` with `message`.
   subroutine fatal_error(error, message)
      !> The error to create (already allocated errors are replaced).
      type(error_type), allocatable, intent(inout) :: error
      !> Message to carry.
      character(len=*), intent(in) :: message
      if (allocated(error)) deallocate (error)
      allocate (error)
      error%message = message
   end subroutine fatal_error
end module beamstops_error
