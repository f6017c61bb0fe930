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
      !> At most this many significant digits (default: as many as needed to read back x); a
      !> number written in fixed notation (below 1e6) keeps its digits before the point (4717
      !> with two digits).
      integer, intent(in), optional :: digits
      !> With `digits`: 'down' or 'up' rounds the text toward minus or plus infinity (a bound
      !> shown rounded stays on its side: a value beyond the bound is beyond its text too);
      !> default: to the nearest.
      character(len=*), intent(in), optional :: round
      character(len=:), allocatable :: s
      character(len=40) :: buf, fmt
      character(len=:), allocatable :: mantissa
      character(len=3) :: mode
      integer :: p, e, lo, hi
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
      ! the fewest digits after the point (p) that read back as x: a binary search, since a text
      ! that reads back as x still does with more digits (it only comes nearer x); at most
      ! `digits` significant digits (p <= digits - 1), 17 always read back (p = 16)
      lo = 0
      hi = 16
      if (present(digits)) hi = max(0, min(hi, digits - 1))
      do while (lo < hi)
         p = (lo + hi)/2
         if (reads_back(p)) then
            hi = p
         else
            lo = p + 1
         end if
      end do
      p = lo
      write (buf, es_format(mode, p)) x
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
   contains
      !> Whether x written with p digits after the point (es30.p, in `mode`) reads back as x.
      logical function reads_back(p)
         integer, intent(in) :: p
         character(len=40) :: text
         real(wp) :: y
         integer :: stat
         write (text, es_format(mode, p)) x
         read (text, *, iostat=stat) y
         reads_back = stat == 0 .and. y == x
      end function reads_back
   end function fmt_real

   !> The edit format (mode es30.p e3): mode '' (to the nearest), 'rd,' or 'ru,'.
   pure function es_format(mode, p) result(f)
      character(len=*), intent(in) :: mode
      integer, intent(in) :: p
      character(len=:), allocatable :: f
      character(len=2) :: digits
      write (digits, '(i2)') p
      f = '('//trim(mode)//'es30.'//trim(adjustl(digits))//'e3)'
   end function es_format

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
      ! allocatable: on the heap (a result of the text's length on the stack overflowed it for a
      ! namelist file of 16 MB)
      character(len=:), allocatable :: t
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
