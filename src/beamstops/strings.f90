!> Text helpers shared by the engine: numbers as the shortest text that reads back the same,
!> integers, lower case, blanks removed, namelist values quoted.
module beamstops_strings
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use beamstops_kinds, only: wp, ik
   implicit none
   private
   public :: fmt_real, fmt_int, itoa, lower, squeeze, real_literal, quoted

contains

   !> Shortest text that reads back as the same real (e.g. 2e-05, 0.25, 1.501, 2.6035e+10).
   function fmt_real(x, digits, round) result(s)
      !> Value.
      real(wp), intent(in) :: x
      !> At most this many significant digits (default: as many as needed to read back x).
      integer, intent(in), optional :: digits
      !> With `digits`: 'down' or 'up' rounds the text toward minus or plus infinity (a bound
      !> shown rounded stays on its side: a value beyond the bound is beyond its text too);
      !> default: to the nearest.
      character(len=*), intent(in), optional :: round
      character(len=:), allocatable :: s
      character(len=40) :: buf, fmt
      character(len=:), allocatable :: mantissa
      character(len=3) :: mode
      real(wp) :: y
      integer :: p, e, stat
      if (.not. ieee_is_finite(x)) then
         write (buf, '(g0)') x
         s = trim(adjustl(buf))
         return
      end if
      mode = ''
      if (present(round)) then
         if (round == 'down') mode = 'rd,'
         if (round == 'up') mode = 'ru,'
      end if
      do p = 0, 16
         write (fmt, '(a,i0,a)') '('//trim(mode)//'es30.', p, 'e3)'
         write (buf, fmt) x
         read (buf, *, iostat=stat) y
         if (stat == 0 .and. y == x) exit
         if (present(digits)) then
            if (p + 1 >= digits) exit
         end if
      end do
      buf = adjustl(buf)
      mantissa = buf(:index(buf, 'E') - 1)
      read (buf(index(buf, 'E') + 1:), *) e
      if (index(mantissa, '.') > 0) then
         mantissa = mantissa(:verify(mantissa, '0', back=.true.))
         if (mantissa(len(mantissa):) == '.') mantissa = mantissa(:len(mantissa) - 1)
      end if
      if (e >= -4 .and. e < 6) then
         write (fmt, '(a,i0,a)') '('//trim(mode)//'f0.', max(0, p - e), ')'
         write (buf, fmt) x
         s = trim(adjustl(buf))
         if (index(s, '.') > 0) then
            s = s(:verify(s, '0', back=.true.))
            if (s(len(s):) == '.') s = s(:len(s) - 1)
         end if
         if (s(1:1) == '.') s = '0'//s
         if (s(1:2) == '-.') s = '-0'//s(2:)
         if (s == '' .or. s == '-') s = '0'
      else
         write (buf, '(sp,i5.2)') e
         s = mantissa//'e'//trim(adjustl(buf))
      end if
   end function fmt_real

   !> Text of an integer.
   pure function fmt_int(i) result(s)
      !> Value.
      integer(ik), intent(in) :: i
      character(len=:), allocatable :: s
      character(len=24) :: buf
      write (buf, '(i0)') i
      s = trim(buf)
   end function fmt_int

   !> Text of a default integer.
   pure function itoa(i) result(s)
      !> Value.
      integer, intent(in) :: i
      character(len=:), allocatable :: s
      s = fmt_int(int(i, ik))
   end function itoa

   !> A real as a namelist literal that reads back exactly and always looks real
   !> (holds '.' or 'e': 10.0, 2e-05, -0.1); infinities and NaN as gfortran writes them.
   function real_literal(x) result(s)
      !> Value.
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      s = fmt_real(x)
      if (.not. ieee_is_finite(x)) return
      if (scan(s, '.eE') == 0) s = s//'.0'
   end function real_literal

   !> A string between single quotes, its quotes doubled (a namelist character literal).
   pure function quoted(text) result(s)
      !> Text.
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: s
      integer :: i
      s = "'"
      do i = 1, len(text)
         if (text(i:i) == "'") then
            s = s//"''"
         else
            s = s//text(i:i)
         end if
      end do
      s = s//"'"
   end function quoted

   !> Lower case of ASCII letters.
   pure function lower(s) result(t)
      !> Text.
      character(len=*), intent(in) :: s
      character(len=len(s)) :: t
      integer :: i
      t = s
      do i = 1, len(s)
         if (s(i:i) >= 'A' .and. s(i:i) <= 'Z') t(i:i) = achar(iachar(s(i:i)) + 32)
      end do
   end function lower

   !> A string without its blanks.
   pure function squeeze(s) result(t)
      !> Text.
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: t
      integer :: i
      t = ''
      do i = 1, len(s)
         if (s(i:i) /= ' ') t = t//s(i:i)
      end do
   end function squeeze
end module beamstops_strings
