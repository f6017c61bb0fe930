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

   !> A message on one line, in valid UTF-8: a control character it quotes (a file name holding a
   !> newline, say) written as \n, \r, \t or \xHH, and so is each byte that is not part of a
   !> well-formed UTF-8 character (a name in Latin-1, a file's binary content); C1 controls (U+0080
   !> to U+009F, NEL among them, a line break on some terminals) as \xC2\xHH.
   pure function one_line(text) result(line)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: line
      integer :: i, n, code, length
      if (plain(text)) then
         line = text
         return
      end if
      allocate (character(len=4*len(text)) :: line)
      n = 0
      i = 1
      do while (i <= len(text))
         code = iachar(text(i:i))
         length = 1
         if (code >= 128) length = utf8_length(text(i:))
         if (code >= 32 .and. code < 127 .or. length > 1) then
            if (length == 2 .and. code == 194 .and. iachar(text(i + 1:min(i + 1, len(text)))) < 160) then
               line(n + 1:n + 8) = hex(code)//hex(iachar(text(i + 1:i + 1)))
               n = n + 8
            else
               line(n + 1:n + length) = text(i:i + length - 1)
               n = n + length
            end if
            i = i + length
            cycle
         end if
         select case (code)
         case (10)
            line(n + 1:n + 2) = '\n'
            n = n + 2
         case (13)
            line(n + 1:n + 2) = '\r'
            n = n + 2
         case (9)
            line(n + 1:n + 2) = '\t'
            n = n + 2
         case default
            line(n + 1:n + 4) = hex(code)
            n = n + 4
         end select
         i = i + 1
      end do
      line = line(:n)
   end function one_line

   !> Whether a text is printable ASCII throughout (then one_line leaves it as it is).
   pure logical function plain(text)
      character(len=*), intent(in) :: text
      integer :: i, code
      plain = .false.
      do i = 1, len(text)
         code = iachar(text(i:i))
         if (code < 32 .or. code >= 127) return
      end do
      plain = .true.
   end function plain

   !> The bytes of the well-formed UTF-8 character that starts a text with a byte >= 128 (2 to
   !> 4; no overlong form, no surrogate, nothing past U+10FFFF), or 1 when it starts none.
   pure integer function utf8_length(text) result(length)
      character(len=*), intent(in) :: text
      integer :: lead, low, high, k
      lead = iachar(text(1:1))
      length = 1
      low = 128
      high = 191
      select case (lead)
      case (194:223)
         length = 2
      case (224)
         length = 3
         low = 160
      case (225:236, 238:239)
         length = 3
      case (237)
         length = 3
         high = 159
      case (240)
         length = 4
         low = 144
      case (241:243)
         length = 4
      case (244)
         length = 4
         high = 143
      case default
         return
      end select
      if (len(text) < length) then
         length = 1
         return
      end if
      do k = 2, length
         if (iachar(text(k:k)) < low .or. iachar(text(k:k)) > high) then
            length = 1
            return
         end if
         low = 128
         high = 191
      end do
   end function utf8_length

   !> A byte as \xHH.
   pure function hex(code) result(text)
      integer, intent(in) :: code
      character(len=4) :: text
      character(len=*), parameter :: digits = '0123456789abcdef'
      text = '\x'//digits(code/16 + 1:code/16 + 1)//digits(mod(code, 16) + 1:mod(code, 16) + 1)
   end function hex
end module beamstops_error
