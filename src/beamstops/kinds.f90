!> Working precision of beamstops: every real in the engine has kind wp.
module beamstops_kinds
   use, intrinsic :: iso_fortran_env, only: real64, int64
   implicit none
   private
   public :: wp, ik

   !> Real kind of all floating-point data (IEEE double).
   integer, parameter :: wp = real64
   !> Integer kind for step counters (runs of more than 2**31 steps are legal).
   integer, parameter :: ik = int64
end module beamstops_kinds
