!> Support motion phi(t) = a sin(omega t), the lifting shape h(x) of SPEC 1 and
!> the time averages of the transformed load under the two load rules.
module beamstops_forcing
   use beamstops_kinds, only: wp, ik
   implicit none
   private
   public :: lift_shape, lift_slope, support_position, load_average

contains

   !> h(x) = 1 - 2s^2 + 4/3 s^3 - 1/3 s^4, s = x/L: h(0) = 1, h'(0) = 0, h(L) = 0, h''(L) = 0.
   pure elemental function lift_shape(x, length) result(y)
      !> Abscissa (m).
      real(wp), intent(in) :: x
      !> Beam length (m).
      real(wp), intent(in) :: length
      real(wp) :: y, s
      s = x/length
      y = 1 - 2*s**2 + (4*s**3)/3 - s**4/3
   end function lift_shape

   !> Derivative h'(x) of the lifting shape.
   pure elemental function lift_slope(x, length) result(y)
      !> Abscissa (m).
      real(wp), intent(in) :: x
      !> Beam length (m).
      real(wp), intent(in) :: length
      real(wp) :: y, s
      s = x/length
      y = (-4*s + 4*s**2 - (4*s**3)/3)/length
   end function lift_slope

   !> Support position phi(t) = amplitude sin(omega t).
   pure elemental function support_position(t, amplitude, omega) result(phi)
      !> Time (s).
      real(wp), intent(in) :: t
      !> Amplitude (m).
      real(wp), intent(in) :: amplitude
      !> Angular frequency (rad/s).
      real(wp), intent(in) :: omega
      real(wp) :: phi
      phi = amplitude*sin(omega*t)
   end function support_position

   !> Time average of sin(omega t) over the interval of step k: [t_k, t_k+dt] for the
   !> paper's rule, [t_k-dt/2, t_k+dt/2] for the centred rule; exact, without cancellation:
   !> sin(omega c) sinc(omega dt/2) with c the centre of the interval.
   pure function load_average(k, dt, omega, centered) result(s)
      !> Step index.
      integer(ik), intent(in) :: k
      !> Time step (s).
      real(wp), intent(in) :: dt
      !> Angular frequency (rad/s).
      real(wp), intent(in) :: omega
      !> Centred rule when true, the paper's rule otherwise.
      logical, intent(in) :: centered
      real(wp) :: s, centre, x
      if (centered) then
         centre = real(k, wp)*dt
      else
         centre = (real(k, wp) + 0.5_wp)*dt
      end if
      x = 0.5_wp*omega*dt
      if (abs(x) < 1.0e-8_wp) then
         s = sin(omega*centre)*(1 - x**2/6)
      else
         s = sin(omega*centre)*sin(x)/x
      end if
   end function load_average
end module beamstops_forcing
