!> The Newmark-weighted sums of a step (the load average, the explicit part of the compliance
!> spring, the work of the load, the discrete energy), formed in src/beamstops/newmark.c with every
!> fused multiply-add written out, so that every loop (one scene, lockstep, span stops) rounds them
!> the same way wherever they are inlined: written in Fortran, gfortran fused their products by beta
!> into the sums differently from one loop to the other (beta other than 0, 1/4, 1/2), and a
!> lockstep member parted from the same scene run alone.
module beamstops_newmark
   use, intrinsic :: iso_c_binding, only: c_double
   implicit none
   private

   public :: newmark_average, newmark_explicit, newmark_work, newmark_energy

   interface
      !> beta next + (1 - 2 beta) now + beta prev (the load average weight of a step; the
      !> Newmark-weighted spring force).
      pure function newmark_average(beta, next, now, prev) result(w) bind(C, name='beamstops_newmark_average')
         import :: c_double
         !> Newmark beta and the values at steps n+1, n and n-1.
         real(c_double), value, intent(in) :: beta, next, now, prev
         real(c_double) :: w
      end function newmark_average

      !> dt2 ((1 - 2 beta) now + beta prev): dt^2 times the explicit part of the Newmark-weighted
      !> spring force (normal compliance).
      pure function newmark_explicit(dt2, beta, now, prev) result(f) bind(C, name='beamstops_newmark_explicit')
         import :: c_double
         !> dt^2, Newmark beta and the spring forces of u^n and u^{n-1}.
         real(c_double), value, intent(in) :: dt2, beta, now, prev
         real(c_double) :: f
      end function newmark_explicit

      !> work + 1/2 weight (gd + gd_prev): the work of the load with step n's 1/2 G^n.(u^{n+1} - u^{n-1}).
      pure function newmark_work(work, weight, gd, gd_prev) result(w) bind(C, name='beamstops_newmark_work')
         import :: c_double
         !> Work so far, the load average weight of the step, g.d^n and g.d^{n-1}.
         real(c_double), value, intent(in) :: work, weight, gd, gd_prev
         real(c_double) :: w
      end function newmark_work

      !> Discrete energy E^{n+1/2} per unit mass (SPEC 6) from d.M d, u.S u, d.S u and u^n.S u^n.
      pure function newmark_energy(dt2, beta, dmd, usu, dsu, usu_old) result(e) bind(C, name='beamstops_newmark_energy')
         import :: c_double
         !> dt^2, Newmark beta, d.M d, u.S u, d.S u and u^n.S u^n.
         real(c_double), value, intent(in) :: dt2, beta, dmd, usu, dsu, usu_old
         real(c_double) :: e
      end function newmark_energy
   end interface
end module beamstops_newmark
