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
      error%message = one_line(message)
   end subroutine fatal_error

   !> A message on one line: a control character it quotes (a file name holding a newline, say)
   !> written as \n, \r, \t or \xHH.
   pure function one_line(text) result(line)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: line
      character(len=*), parameter :: digits = '0123456789abcdef'
      integer :: i, n, code
      if (scan(text, control_characters()) == 0) then
         line = text
         return
      end if
      allocate (character(len=4*len(text)) :: line)
      n = 0
      do i = 1, len(text)
         code = iachar(text(i:i))
         if (code >= 32 .and. code /= 127) then
            line(n + 1:n + 1) = text(i:i)
            n = n + 1
         else if (code == 10) then
            line(n + 1:n + 2) = '\n'
            n = n + 2
         else if (code == 13) then
            line(n + 1:n + 2) = '\r'
            n = n + 2
         else if (code == 9) then
            line(n + 1:n + 2) = '\t'
            n = n + 2
         else
            line(n + 1:n + 4) = '\x'//digits(code/16 + 1:code/16 + 1)//digits(mod(code, 16) + 1:mod(code, 16) + 1)
            n = n + 4
         end if
      end do
      line = line(:n)
   end function one_line

   !> The ASCII control characters (0-31 and 127).
   pure function control_characters() result(set)
      character(len=33) :: set
      integer :: i
      do i = 0, 31
         set(i + 1:i + 1) = achar(i)
      end do
      set(33:33) = achar(127)
   end function control_characters
end module beamstops_error
