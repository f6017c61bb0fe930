!> Normal compliance (penalty) at the tip: a spring of stiffness 1/epsilon per unit
!> mass acting beyond the stops, p(u) = -k [max(u - g2, 0) - max(g1 - u, 0)].
!> Its implicit Newmark part is a piecewise-linear scalar equation, solved exactly.
module beamstops_contact_compliance
   use beamstops_kinds, only: wp
   implicit none
   private
   public :: spring_force, solve_spring_tip

contains

   !> Spring force per unit mass p(u) on the tip (m^2/s^2 per m of beam).
   pure elemental function spring_force(u, lower, upper, stiffness) result(p)
      !> Tip displacement (m).
      real(wp), intent(in) :: u
      !> Lower stop (m).
      real(wp), intent(in) :: lower
      !> Upper stop (m).
      real(wp), intent(in) :: upper
      !> Stiffness per unit mass 1/epsilon (1/s^2).
      real(wp), intent(in) :: stiffness
      real(wp) :: p
      p = -stiffness*(max(u - upper, 0.0_wp) - max(lower - u, 0.0_wp))
   end function spring_force

   !> Solve y = trial + w p(y) for the tip value y, with w = dt^2 beta z_tip >= 0
   !> (the implicit part of the Newmark-weighted spring force); exact and unique.
   pure function solve_spring_tip(trial, lower, upper, stiffness, w) result(y)
      !> Tip value without the implicit spring force (m).
      real(wp), intent(in) :: trial
      !> Lower stop (m).
      real(wp), intent(in) :: lower
      !> Upper stop (m).
      real(wp), intent(in) :: upper
      !> Stiffness per unit mass (1/s^2).
      real(wp), intent(in) :: stiffness
      !> Weight dt^2 beta z_tip of the implicit force.
      real(wp), intent(in) :: w
      real(wp) :: y, c
      c = w*stiffness
      if (trial > upper) then
         y = (trial + c*upper)/(1 + c)
      else if (trial < lower) then
         y = (trial + c*lower)/(1 + c)
      else
         y = trial
      end if
   end function solve_spring_tip
end module beamstops_contact_compliance
