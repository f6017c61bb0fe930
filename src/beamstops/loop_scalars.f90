!> The scalars that every time loop (the full model's and the reduced model's) carries from
!> step n to step n+1, as one parent type of their states, and their place in a checkpoint.
module beamstops_loop_scalars
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use beamstops_kinds, only: wp, ik
   use beamstops_strings, only: fmt_int, fmt_real
   implicit none
   private
   public :: loop_scalars_type, n_loop_scalars, loop_scalars_vector, restore_loop_scalars, implausible_scalars

   !> Length of loop_scalars_vector: the 14 scalars a checkpoint keeps, then the records and snapshots.
   integer, parameter :: n_loop_scalars = 16

   !> The scalars of a time loop (the parent of beamstops_state's state_type and of the reduced
   !> loop's reduced_state_type).
   type :: loop_scalars_type
      !> Index n of the next step (the step that computes u^{n+1}, or q^{n+1}).
      integer(ik) :: step = 1
      !> Load averages sigma_{n-1}, sigma_n.
      real(wp) :: sigma_prev = 0, sigma_now = 0
      !> g . d^{n-1} (l_r . d^{n-1} in the reduced loop).
      real(wp) :: gd_prev = 0
      !> Spring forces p(u^{n-1}), p(u^n) at the tip (compliance).
      real(wp) :: p_prev = 0, p_now = 0
      !> Work of the load W_{n-1} and energy taken by the stops D_{n-1}, per unit mass.
      real(wp) :: work = 0, dissipated = 0
      !> Energy taken by the Rayleigh damping so far, per unit mass (SPEC 8).
      real(wp) :: damped = 0
      !> With damping: d^{n-1}.C d^{n-1}.
      real(wp) :: dcd_prev = 0
      !> Discrete energy E^{1/2} per unit mass (reference for the divergence check).
      real(wp) :: energy0 = 0
      !> Reaction per unit mass at the tip of the step that gave u^n (r_{n-1}; recorded with u^n).
      real(wp) :: reaction = 0
      !> Whether the previous step was in contact.
      logical :: in_contact = .false.
      !> Impacts so far.
      integer(ik) :: impacts = 0
      !> CPU time of the time loop so far (s).
      real(wp) :: cpu_seconds = 0
      !> Largest violation of the stops so far (m).
      real(wp) :: max_violation = 0
   end type loop_scalars_type

contains

   !> The loop's scalars kept by a checkpoint (all but `damped` and `dcd_prev`), then the record
   !> counts, as one vector (integers are exact in it): the dataset `scalars` of a checkpoint.
   pure function loop_scalars_vector(scalars, records, snapshots) result(v)
      !> The loop's scalars.
      type(loop_scalars_type), intent(in) :: scalars
      !> Records and snapshots already in the output file.
      integer(ik), intent(in) :: records, snapshots
      real(wp) :: v(n_loop_scalars)
      v = [real(scalars%step, wp), scalars%sigma_prev, scalars%sigma_now, scalars%gd_prev, scalars%p_prev, &
         & scalars%p_now, scalars%work, scalars%dissipated, scalars%energy0, scalars%reaction, &
         & merge(1.0_wp, 0.0_wp, scalars%in_contact), real(scalars%impacts, wp), scalars%cpu_seconds, &
         & scalars%max_violation, real(records, wp), real(snapshots, wp)]
   end function loop_scalars_vector

   !> Why a vector of loop_scalars_vector (read from a checkpoint) cannot be a checkpoint of a run
   !> of `steps` steps recording every `record_every` steps and a snapshot every `snapshot_every`
   !> (0: none), or '' when it can: a value that is not finite (of the vector or of the state
   !> `values` saved beside it), a step outside 1 .. steps + 1 or not whole, counts of records and
   !> snapshots other than those the loop has written before that step (the first at step 0, then
   !> one every record_every: (step - 1)/record_every + 1), a contact flag other than 0 or 1, or a
   !> negative count, CPU time or violation. An edited or damaged checkpoint was trusted: a step of
   !> 1e9 ran to t = 50,000 s of a 400 s scene and wrote a file marked complete; records = -3 made
   !> HDF5 spin while extending the series.
   function implausible_scalars(v, values, steps, record_every, snapshot_every) result(why)
      !> The vector.
      real(wp), intent(in) :: v(n_loop_scalars)
      !> The state's other values (displacements, increments, ...).
      real(wp), intent(in) :: values(:)
      !> Steps of the run, and its record and snapshot periods (steps; snapshot_every 0: none).
      integer(ik), intent(in) :: steps
      integer, intent(in) :: record_every, snapshot_every
      character(len=:), allocatable :: why
      integer(ik) :: step, expected
      why = ''
      if (.not. (all(ieee_is_finite(v)) .and. all(ieee_is_finite(values)))) then
         why = 'a value is not finite'
         return
      end if
      if (.not. (v(1) >= 1 .and. v(1) <= real(steps, wp) + 1 .and. v(1) == aint(v(1)))) then
         why = 'its step '//fmt_real(v(1))//' is not a step of the run (1 to '//fmt_int(steps + 1)//')'
         return
      end if
      step = nint(v(1), ik)
      expected = (step - 1)/record_every + 1
      if (v(15) /= real(expected, wp)) then
         why = 'it counts '//fmt_real(v(15))//' records where the run has written '//fmt_int(expected)// &
            & ' before step '//fmt_int(step)
         return
      end if
      expected = 0
      if (snapshot_every > 0) expected = (step - 1)/snapshot_every + 1
      if (v(16) /= real(expected, wp)) then
         why = 'it counts '//fmt_real(v(16))//' snapshots where the run has written '//fmt_int(expected)// &
            & ' before step '//fmt_int(step)
         return
      end if
      if (v(11) /= 0 .and. v(11) /= 1) why = 'its contact flag is '//fmt_real(v(11))//' (0 or 1)'
      if (.not. (v(12) >= 0 .and. v(12) <= real(step, wp) .and. v(12) == aint(v(12)))) &
         & why = 'its impacts '//fmt_real(v(12))//' are not a count of the steps so far'
      if (v(13) < 0 .or. v(14) < 0) why = 'a negative CPU time or violation'
   end function implausible_scalars

   !> The inverse of loop_scalars_vector (`damped` and `dcd_prev` are left as they are).
   pure subroutine restore_loop_scalars(v, scalars, records, snapshots)
      !> A vector of loop_scalars_vector.
      real(wp), intent(in) :: v(n_loop_scalars)
      !> The loop's scalars, set from it.
      type(loop_scalars_type), intent(inout) :: scalars
      !> Records and snapshots the output held.
      integer(ik), intent(out) :: records, snapshots
      scalars%step = nint(v(1), ik)
      scalars%sigma_prev = v(2)
      scalars%sigma_now = v(3)
      scalars%gd_prev = v(4)
      scalars%p_prev = v(5)
      scalars%p_now = v(6)
      scalars%work = v(7)
      scalars%dissipated = v(8)
      scalars%energy0 = v(9)
      scalars%reaction = v(10)
      scalars%in_contact = v(11) /= 0
      scalars%impacts = nint(v(12), ik)
      scalars%cpu_seconds = v(13)
      scalars%max_violation = v(14)
      records = nint(v(15), ik)
      snapshots = nint(v(16), ik)
   end subroutine restore_loop_scalars
end module beamstops_loop_scalars
