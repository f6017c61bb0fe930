!> Normal compliance (penalty) at the tip: a spring of stiffness 1/epsilon per unit
!> mass acting beyond the stops, p(u) = -k [max(u - g2, 0) - max(g1 - u, 0)].
!> Its implicit Newmark part is a piecewise-linear scalar equation, solved exactly.
module beamstops_contact_compliance
   use beamstops_kinds, only: wp
   use beamstops_newmark, only: newmark_average
   implicit none
   private
   public :: spring_force, solve_spring_tip, compliance_step

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

   !> One step of normal compliance at the tip (SPEC 5), shared by every loop: the tip value of
   !> the step from its trial value, the multiple c = dt^2 beta p_{n+1} of z, the Newmark-weighted
   !> reaction of the step, and the spring forces moved on (p_{n-1} <- p_n <- p_{n+1}).
   pure subroutine compliance_step(trial, lower, upper, stiffness, dt2, beta, z_tip, p_prev, p_now, tip_value, c, &
      & r_step, contact)
      !> Trial tip value, stops (m) and stiffness per unit mass (1/s^2).
      real(wp), intent(in) :: trial, lower, upper, stiffness
      !> dt^2, beta and z_tip = (A^{-1} e_tip)_tip.
      real(wp), intent(in) :: dt2, beta, z_tip
      !> Spring forces p(u^{n-1}), p(u^n) on entry, p(u^n), p(u^{n+1}) on return.
      real(wp), intent(inout) :: p_prev, p_now
      !> Tip value of the step, multiple of z and reaction of the step (per unit mass).
      real(wp), intent(out) :: tip_value, c, r_step
      !> Whether the spring acts during the step.
      logical, intent(out) :: contact
      real(wp) :: p_next
      tip_value = solve_spring_tip(trial, lower, upper, stiffness, dt2*beta*z_tip)
      p_next = spring_force(tip_value, lower, upper, stiffness)
      c = dt2*beta*p_next
      r_step = newmark_average(beta, p_next, p_now, p_prev)
      p_prev = p_now
      p_now = p_next
      contact = r_step /= 0
   end subroutine compliance_step
end module beamstops_contact_compliance
