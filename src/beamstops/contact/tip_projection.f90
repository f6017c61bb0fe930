!> Exact Signorini contact at the tip (the paper's Lemma 4.1): the constrained
!> solution is the unconstrained one corrected along z = A^{-1} e_tip so that
!> the tip value is the projection of the trial tip value on [lower, upper].
module beamstops_contact_tip_projection
   use beamstops_kinds, only: wp
   implicit none
   private
   public :: project_tip

contains

   !> Correction coefficient c (u = u' + c z) and the projected tip value.
   !> c = 0 when the trial value lies between the stops; the contact
   !> reaction per unit mass is c/dt^2 (negative at the upper stop).
   pure subroutine project_tip(trial, lower, upper, z_tip, c, projected)
      !> Tip value u'_tip of the unconstrained solution (m).
      real(wp), intent(in) :: trial
      !> Lower stop g1 (m).
      real(wp), intent(in) :: lower
      !> Upper stop g2 (m).
      real(wp), intent(in) :: upper
      !> Tip entry of z = A^{-1} e_tip (> 0).
      real(wp), intent(in) :: z_tip
      !> Correction coefficient.
      real(wp), intent(out) :: c
      !> Projected tip value P[lower, upper](trial).
      real(wp), intent(out) :: projected
      projected = min(max(trial, lower), upper)
      c = (projected - trial)/z_tip
   end subroutine project_tip
end module beamstops_contact_tip_projection
