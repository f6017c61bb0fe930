!> The encoders and decoders of the observers' checkpoint vectors (the shock log's pack_log and
!> unpack_log, the statistics' pack_statistics and unpack_statistics): a state is a vector of
!> reals written and read from a position p that each call advances. Integers are stored exactly
!> as reals (huge(1_ik) as +Infinity), logicals as 1 or 0, reals bit for bit. A decoder that
!> meets a value it cannot take sets `bad` to the value's index (when `bad` was 0) and goes on,
!> so that the caller reports the first bad value once, at the end.
module beamstops_observe_pack
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: fmt_real, fmt_int
   implicit none
   private
   public :: put, ik_value, logical_value
   public :: take_header, take_real, take_reals, take_int, take_ik, take_iks, take_logical

contains

   !> Store x at values(p+1:), advance p.
   pure subroutine put(values, p, x)
      !> The vector written.
      real(wp), intent(inout) :: values(:)
      !> Values written so far.
      integer, intent(inout) :: p
      !> The values to store.
      real(wp), intent(in) :: x(:)
      values(p + 1:p + size(x)) = x
      p = p + size(x)
   end subroutine put

   !> An integer(ik) as a real: exact below 2**53; huge(1_ik) as +Infinity.
   elemental function ik_value(x) result(v)
      !> The integer.
      integer(ik), intent(in) :: x
      real(wp) :: v
      if (x == huge(1_ik)) then
         v = ieee_value(v, ieee_positive_inf)
      else
         v = real(x, wp)
      end if
   end function ik_value

   !> A logical as 1 or 0.
   elemental function logical_value(x) result(v)
      !> The logical.
      logical, intent(in) :: x
      real(wp) :: v
      v = merge(1.0_wp, 0.0_wp, x)
   end function logical_value

   !> Check the header of a packed vector: at least size(ints) + 2 values, values(1:2) = tag,
   !> version, then size(ints) integers (the total length first); an error, whose message starts
   !> with `owner`//': unpack: ', when it is not one.
   subroutine take_header(values, owner, tag, version, ints, error)
      !> The packed vector.
      real(wp), intent(in) :: values(:)
      !> Name of what was packed, for the messages.
      character(len=*), intent(in) :: owner
      !> The expected tag and version of the layout.
      real(wp), intent(in) :: tag, version
      !> The integers of the header after the tag and version.
      integer, intent(out) :: ints(:)
      !> Set when the header is not one.
      type(error_type), allocatable, intent(out) :: error
      integer :: i, p, bad, header
      ints = 0
      header = size(ints) + 2
      if (size(values) < header) then
         call fatal_error(error, owner//': unpack: '//fmt_int(int(size(values), ik))// &
            & ' values, too short for the header ('//fmt_int(int(header, ik))//')')
         return
      end if
      if (.not. (values(1) == tag .and. values(2) == version)) then
         call fatal_error(error, owner//': unpack: tag '//fmt_real(values(1))//', version '//fmt_real(values(2))// &
            & '; expected tag '//fmt_real(tag)//', version '//fmt_real(version))
         return
      end if
      bad = 0
      p = 2
      do i = 1, size(ints)
         call take_int(values, p, ints(i), bad)
      end do
      if (bad /= 0) then
         call fatal_error(error, owner//': unpack: header value '//fmt_int(int(bad, ik))//' = '// &
            & fmt_real(values(bad))//' is not an integer')
      end if
   end subroutine take_header

   !> Read values(p+1) as a real, advance p.
   pure subroutine take_real(values, p, x)
      !> The packed vector.
      real(wp), intent(in) :: values(:)
      !> Values read so far.
      integer, intent(inout) :: p
      !> The value.
      real(wp), intent(out) :: x
      p = p + 1
      x = values(p)
   end subroutine take_real

   !> Read n reals into x (explicit shape: an array of any rank by sequence association, in
   !> array element order), advance p.
   pure subroutine take_reals(values, p, n, x)
      !> The packed vector.
      real(wp), intent(in) :: values(:)
      !> Values read so far.
      integer, intent(inout) :: p
      !> Number of values.
      integer, intent(in) :: n
      !> The values.
      real(wp), intent(out) :: x(n)
      x = values(p + 1:p + n)
      p = p + n
   end subroutine take_reals

   !> Read values(p+1) as a default integer, advance p; bad = p when it is not one.
   pure subroutine take_int(values, p, x, bad)
      !> The packed vector.
      real(wp), intent(in) :: values(:)
      !> Values read so far.
      integer, intent(inout) :: p
      !> The value (0 when it is not an integer).
      integer, intent(out) :: x
      !> Index of the first bad value, 0 while there is none.
      integer, intent(inout) :: bad
      real(wp) :: v
      p = p + 1
      v = values(p)
      x = 0
      if (abs(v) <= real(huge(x), wp) .and. aint(v) == v) then
         x = int(v)
      else if (bad == 0) then
         bad = p
      end if
   end subroutine take_int

   !> Read values(p+1) as an integer(ik) (an integer of at most 2**62 in magnitude; +Infinity as
   !> huge(1_ik), the inverse of ik_value, unless `finite`), advance p; bad = p when it is not
   !> one (and bad was 0).
   pure subroutine take_ik(values, p, x, bad, finite)
      !> The packed vector.
      real(wp), intent(in) :: values(:)
      !> Values read so far.
      integer, intent(inout) :: p
      !> The value (0 when it is not one).
      integer(ik), intent(out) :: x
      !> Index of the first bad value, 0 while there is none.
      integer, intent(inout) :: bad
      !> Refuse +Infinity (default: .false.).
      logical, intent(in), optional :: finite
      real(wp) :: v
      logical :: infinity_allowed
      infinity_allowed = .true.
      if (present(finite)) infinity_allowed = .not. finite
      p = p + 1
      v = values(p)
      x = 0
      if (infinity_allowed .and. v > huge(v)) then
         x = huge(1_ik)
      else if (abs(v) <= 2.0_wp**62 .and. aint(v) == v) then
         x = int(v, ik)
      else if (bad == 0) then
         bad = p
      end if
   end subroutine take_ik

   !> Read n integer(ik) into x as take_reals, each as take_ik, advance p.
   pure subroutine take_iks(values, p, n, x, bad, finite)
      !> The packed vector.
      real(wp), intent(in) :: values(:)
      !> Values read so far.
      integer, intent(inout) :: p
      !> Number of values.
      integer, intent(in) :: n
      !> The values.
      integer(ik), intent(out) :: x(n)
      !> Index of the first bad value, 0 while there is none.
      integer, intent(inout) :: bad
      !> Refuse +Infinity (default: .false.).
      logical, intent(in), optional :: finite
      integer :: i
      do i = 1, n
         call take_ik(values, p, x(i), bad, finite)
      end do
   end subroutine take_iks

   !> Read values(p+1) as a logical (1 or 0), advance p; bad = p when it is neither.
   pure subroutine take_logical(values, p, x, bad)
      !> The packed vector.
      real(wp), intent(in) :: values(:)
      !> Values read so far.
      integer, intent(inout) :: p
      !> The value.
      logical, intent(out) :: x
      !> Index of the first bad value, 0 while there is none.
      integer, intent(inout) :: bad
      p = p + 1
      x = values(p) == 1
      if (.not. (values(p) == 1 .or. values(p) == 0) .and. bad == 0) bad = p
   end subroutine take_logical
end module beamstops_observe_pack
