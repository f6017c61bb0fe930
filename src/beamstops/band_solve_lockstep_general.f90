!> The kernels the general lockstep loop (lockstep_general.f90) adds to those of
!> beamstops_band_solve_lockstep, for lockstep_lanes members at once, the member index innermost
!> (arrays (lanes, n)): the right-hand side with the Rayleigh damping term (SPEC 8) and one row of
!> a product by S (the massless tip of mass redistribution, SPEC 10).
!>
!> Bit for bit, as beamstops_band_solve_lockstep: each lane does the floating-point operations of
!> the one-member code of beamstops_scheme's forward_pass (rhs = a g - b S u - c C d) and of
!> beamstops_band_solve's diagonal_row, in the same order, with the same expressions (so that the
!> compiler forms the same multiply-adds); tests/fortran/test_lockstep_general.f90 checks them
!> lane by lane and in whole runs.
module beamstops_band_solve_lockstep_general
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   use beamstops_band_solve, only: band_diagonals
   use beamstops_band_solve_lockstep, only: lockstep_lanes, lockstep_matvec_rhs
   implicit none
   private
   public :: lockstep_matvec_rhs_damped, lockstep_row

contains

   !> S u and the right-hand sides rhs = a g - b S u - c_scale C d plus `spring` in the tip row n-1
   !> of every lane (beamstops_scheme's forward_pass with damping): lockstep_matvec_rhs without the
   !> spring, then the damping term, then the spring, which rounds as the one expression
   !> a g - b S u - c_scale C d does (test_lockstep_general compares damped members with the
   !> same scenes run alone, bit for bit).
   pure subroutine lockstep_matvec_rhs_damped(stiffness, u, a, g, b, spring, cd, c_scale, su, rhs, rows)
      !> S by diagonals.
      type(band_diagonals), intent(in) :: stiffness
      !> u of every lane (lanes, n).
      real(wp), intent(in) :: u(lockstep_lanes, stiffness%n)
      !> dt^2 times the load weight of every lane (lanes).
      real(wp), intent(in) :: a(lockstep_lanes)
      !> Load vectors (lanes, n).
      real(wp), intent(in) :: g(lockstep_lanes, stiffness%n)
      !> dt^2.
      real(wp), intent(in) :: b
      !> Force term of the tip row (lanes).
      real(wp), intent(in) :: spring(lockstep_lanes)
      !> C d^{n-1} of every lane (lanes, n).
      real(wp), intent(in) :: cd(lockstep_lanes, stiffness%n)
      !> Its coefficient (dt).
      real(wp), intent(in) :: c_scale
      !> S u (lanes, n).
      real(wp), intent(out) :: su(lockstep_lanes, stiffness%n)
      !> Right-hand sides (lanes, n).
      real(wp), intent(out) :: rhs(lockstep_lanes, stiffness%n)
      !> The coefficients of interior rows kd+1 and kd+2 of a periodic S (lockstep_periodic_rows).
      real(wp), intent(in), optional :: rows(2*kd + 1, 2)
      real(wp), parameter :: no_spring(lockstep_lanes) = 0
      integer :: j, k, n
      n = stiffness%n
      call lockstep_matvec_rhs(stiffness, u, a, g, b, no_spring, su, rhs, rows)
      do j = 1, n
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            rhs(k, j) = rhs(k, j) - c_scale*cd(k, j)
         end do
      end do
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         rhs(k, n - 1) = rhs(k, n - 1) + spring(k)
      end do
   end subroutine lockstep_matvec_rhs_damped

   !> Row `row` of A x of every lane, A symmetric by diagonals (beamstops_band_solve's
   !> diagonal_row: the diagonal term, then for j = 1..kd the term j below and the term j above).
   pure subroutine lockstep_row(diagonals, x, row, y)
      !> Matrix by diagonals.
      type(band_diagonals), intent(in) :: diagonals
      !> Vectors (lanes, n).
      real(wp), intent(in) :: x(lockstep_lanes, diagonals%n)
      !> The row (1..n).
      integer, intent(in) :: row
      !> (A x)_row of every lane (lanes).
      real(wp), intent(out) :: y(lockstep_lanes)
      integer :: j, k
      associate (a => diagonals%a)
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            y(k) = a(row, 0)*x(k, row)
         end do
         do j = 1, kd
            if (row - j >= 1) then
!GCC$ ivdep
!GCC$ vector
               do k = 1, lockstep_lanes
                  y(k) = y(k) + a(row, j)*x(k, row - j)
               end do
            end if
            if (row + j <= diagonals%n) then
!GCC$ ivdep
!GCC$ vector
               do k = 1, lockstep_lanes
                  y(k) = y(k) + a(row + j, j)*x(k, row + j)
               end do
            end if
         end do
      end associate
   end subroutine lockstep_row
end module beamstops_band_solve_lockstep_general
