!> Support motion phi(t) = a sin(omega t), the lifting shape h(x) of SPEC 1 and
!> the time averages of the transformed load under the two load rules, and those averages
!> step after step by rotation (load_rotation, the time loop's).
module beamstops_forcing
   use beamstops_kinds, only: wp, ik
   implicit none
   private
   public :: lift_shape, lift_slope, support_position, load_average
   public :: load_rotation, start_loads, next_load, restart_every

   !> The load averages sigma_k = f sin(omega c_k) (load_average; f = sinc(omega dt/2),
   !> c_k the centre of step k's interval) step after step by rotating (f sin, f cos)(omega c_k)
   !> by omega dt: four multiply-adds instead of a sine. Every restart_every steps they restart
   !> from load_average itself, so they differ from it by a few ulps at most.
   type :: load_rotation
      !> Index k of the current value.
      integer(ik) :: k = 0
      !> sigma_k = f sin(omega c_k) and f cos(omega c_k).
      real(wp) :: sigma = 0, cosine = 0
      !> cos(omega dt), sin(omega dt).
      real(wp) :: cos_step = 1, sin_step = 0
      !> Time step (s) and angular frequency (rad/s).
      real(wp) :: dt = 0, omega = 0
      !> Load rule: centred when true, the paper's otherwise.
      logical :: centered = .true.
   end type load_rotation

   !> Steps between two restarts of load_rotation from exact values.
   integer(ik), parameter :: restart_every = 64

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

   !> load_rotation at step k: from load_average at the last multiple of restart_every, then
   !> rotated, so that the value of every step is the same however the run is cut into calls.
   pure subroutine start_loads(loads, k, dt, omega, centered)
      !> The rotation, at step k on return.
      type(load_rotation), intent(out) :: loads
      !> Step index.
      integer(ik), intent(in) :: k
      !> Time step (s).
      real(wp), intent(in) :: dt
      !> Angular frequency of the support (rad/s).
      real(wp), intent(in) :: omega
      !> Centred load rule when true, the paper's otherwise.
      logical, intent(in) :: centered
      loads%dt = dt
      loads%omega = omega
      loads%centered = centered
      call restart_loads(loads, (k/restart_every)*restart_every)
      do while (loads%k < k)
         call next_load(loads)
      end do
   end subroutine start_loads

   !> load_rotation at step k, exact: load_average and the same centre and factor for the cosine.
   pure subroutine restart_loads(loads, k)
      type(load_rotation), intent(inout) :: loads
      integer(ik), intent(in) :: k
      real(wp) :: centre, x, factor
      centre = real(k, wp)*loads%dt
      if (.not. loads%centered) centre = (real(k, wp) + 0.5_wp)*loads%dt
      x = 0.5_wp*loads%omega*loads%dt
      if (abs(x) < 1.0e-8_wp) then
         factor = 1 - x**2/6
      else
         factor = sin(x)/x
      end if
      loads%k = k
      loads%sigma = load_average(k, loads%dt, loads%omega, loads%centered)
      loads%cosine = factor*cos(loads%omega*centre)
      loads%cos_step = cos(loads%omega*loads%dt)
      loads%sin_step = sin(loads%omega*loads%dt)
   end subroutine restart_loads

   !> load_rotation moved on to step k + 1.
   pure subroutine next_load(loads)
      !> The rotation.
      type(load_rotation), intent(inout) :: loads
      real(wp) :: sigma
      if (mod(loads%k + 1, restart_every) == 0) then
         call restart_loads(loads, loads%k + 1)
         return
      end if
      sigma = loads%sigma*loads%cos_step + loads%cosine*loads%sin_step
      loads%cosine = loads%cosine*loads%cos_step - loads%sigma*loads%sin_step
      loads%sigma = sigma
      loads%k = loads%k + 1
   end subroutine next_load
end module beamstops_forcing
