!> Numbers as text (beamstops_strings' fmt_real): the text reads back as the same double, and no
!> text with one significant digit fewer does; with `digits` and a rounding direction, the text
!> stays on its side of the value and has at most that many significant digits.
module test_strings
   use testing
   use beamstops_strings, only: fmt_real
   implicit none
   private
   public :: collect_strings

contains

   !> Tests of the suite.
   subroutine collect_strings(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('shortest text that reads back: random doubles from 1e-300 to 1e300, both signs', &
         & test_shortest), &
         & new_unittest('the forms of the text: 2e-05, 0.25, 1.501, 2.6035e+10, 0, -0.5', test_forms), &
         & new_unittest('digits with rounding down and up: at most that many digits (or those before the '// &
         & 'point), on the value''s side', &
         & test_rounded) &
         & ]
   end subroutine collect_strings

   !> fmt_real(x) reads back as x, and x rounded to one significant digit fewer does not.
   subroutine test_shortest(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(2), x
      integer :: k, digits
      character(len=:), allocatable :: s
      do k = 1, 4000
         call random_number(r)
         x = (r(1) + 0.05_wp)*10.0_wp**(nint(600*r(2)) - 300)
         if (mod(k, 2) == 0) x = -x
         ! a few values of few digits too (input-like)
         if (mod(k, 10) == 0) x = real(nint(1000*r(1)), wp)/8
         s = fmt_real(x)
         call check(error, value_of(s) == x, 'fmt_real('//real_text(x)//') = '//s//' reads back as the same double')
         if (allocated(error)) return
         digits = significant_digits(s)
         if (digits > 1) then
            call check(error, value_of(rounded_text(x, digits - 1)) /= x, 'fmt_real('//real_text(x)//') = '//s// &
               & ': one digit fewer does not read back')
            if (allocated(error)) return
         end if
      end do
   end subroutine test_shortest

   !> The text's forms: fixed notation for exponents -4 .. 5, else a mantissa and a signed
   !> exponent of at least two digits; no trailing zeros.
   subroutine test_forms(error)
      type(error_type), allocatable, intent(out) :: error
      call same(error, fmt_real(2.0e-5_wp), '2e-05')
      call same(error, fmt_real(0.25_wp), '0.25')
      call same(error, fmt_real(1.501_wp), '1.501')
      call same(error, fmt_real(2.6035e10_wp), '2.6035e+10')
      call same(error, fmt_real(0.0_wp), '0')
      call same(error, fmt_real(-0.5_wp), '-0.5')
      call same(error, fmt_real(1.0e-310_wp), '1e-310')
   end subroutine test_forms

   !> fmt_real(x, d, 'down') <= x <= fmt_real(x, d, 'up'), each with at most d significant digits
   !> (or the digits before the point of fixed notation: rounding up may add one, 9999.5 -> 10000).
   subroutine test_rounded(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: r(2), x
      integer :: k, d
      character(len=:), allocatable :: down, up
      do k = 1, 2000
         call random_number(r)
         x = (r(1) + 0.05_wp)*10.0_wp**(nint(40*r(2)) - 20)
         if (mod(k, 2) == 0) x = -x
         d = 1 + mod(k, 6)
         down = fmt_real(x, d, 'down')
         up = fmt_real(x, d, 'up')
         call check(error, value_of(down) <= x .and. x <= value_of(up), real_text(x)//' lies between '//down// &
            & ' and '//up)
         if (allocated(error)) return
         call check(error, significant_digits(down) <= max(d, whole_digits(x)) .and. &
            & significant_digits(up) <= max(d, whole_digits(x) + 1), down//' and '//up//' have at most '// &
            & int_text(d)//' significant digits, or the digits before the point')
         if (allocated(error)) return
      end do
   end subroutine test_rounded

   subroutine same(error, actual, expected)
      type(error_type), allocatable, intent(inout) :: error
      character(len=*), intent(in) :: actual, expected
      if (allocated(error)) return
      call check(error, actual == expected, 'text '//actual//', expected '//expected)
   end subroutine same

   !> The double a text reads back as.
   real(wp) function value_of(s)
      character(len=*), intent(in) :: s
      read (s, *) value_of
   end function value_of

   !> x rounded to the nearest with `digits` significant digits, as text.
   function rounded_text(x, digits) result(s)
      real(wp), intent(in) :: x
      integer, intent(in) :: digits
      character(len=:), allocatable :: s
      character(len=40) :: buf
      character(len=20) :: fmt
      write (fmt, '(a,i0,a)') '(es30.', digits - 1, 'e3)'
      write (buf, fmt) x
      s = trim(adjustl(buf))
   end function rounded_text

   !> Significant digits of a text such as -1.2345e+10 or 0.00125.
   integer function significant_digits(s)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: m
      integer :: e, first, last, i
      e = scan(s, 'eE')
      m = s
      if (e > 0) m = s(:e - 1)
      first = verify(m, '-+0.')
      last = verify(m, '0.', back=.true.)
      significant_digits = 0
      if (first == 0) return
      significant_digits = count([(verify(m(i:i), '0123456789') == 0, i=first, last)])
   end function significant_digits

   !> Digits before the point of |x| in fixed notation (0 below 1; 1e6 and above are written with
   !> an exponent).
   integer function whole_digits(x)
      real(wp), intent(in) :: x
      whole_digits = 0
      if (abs(x) >= 1 .and. abs(x) < 1.0e6_wp) whole_digits = 1 + int(log10(abs(x)))
   end function whole_digits

end module test_strings
