!> Support of the f2py layer (wrap/beamstops_wrap.f90), which f2py parses alone:
!> a scene from flat scalars, and error objects turned into (status, message).
!> f2py never reads this file; it is compiled into the extension with the wrapper.
module beamstops_wrap_support
   use beamstops, only: wp, ik, error_type, fatal_error, scene_type
   implicit none
   private
   public :: make_scene, report, law_as_int

contains

   !> Fill a scene from the flat scalars the wrapper receives (integers as 64-bit,
   !> logicals as integers 0/1); the scene is not validated here.
   subroutine make_scene(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
      & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
      & max_output_gb, stop_nodes, stop_lower, stop_upper, source, scene, error)
      !> &beam, &support, &stops values (SI units, see scene_type).
      real(wp), intent(in) :: length, k2, mass_per_length, amplitude, omega, lower, upper, stiffness_per_mass
      !> &time values (s, s, -) and &output max_output_gb (1e9 bytes).
      real(wp), intent(in) :: dt, t_end, beta, max_output_gb
      !> Contact-law code (law_none, law_signorini, law_compliance).
      integer(ik), intent(in) :: law
      !> &mesh elements, &output record_every and snapshot_every.
      integer(ik), intent(in) :: elements, record_every, snapshot_every
      !> Flags: nonzero for .true.
      integer(ik), intent(in) :: centered_load, taylor_start, allow_unstable
      !> Stops along the span: nodes (1..J) and their lower and upper stops (m); none: the tip form.
      integer(ik), intent(in) :: stop_nodes(:)
      !> Lower stops (m) of stop_nodes.
      real(wp), intent(in) :: stop_lower(:)
      !> Upper stops (m) of stop_nodes.
      real(wp), intent(in) :: stop_upper(:)
      !> Where the scene came from, for messages.
      character(len=*), intent(in) :: source
      !> Scene filled.
      type(scene_type), intent(out) :: scene
      !> Set when an integer does not fit the scene's default integers.
      type(error_type), allocatable, intent(out) :: error
      scene%length = length
      scene%k2 = k2
      scene%mass_per_length = mass_per_length
      scene%amplitude = amplitude
      scene%omega = omega
      scene%lower = lower
      scene%upper = upper
      scene%law = law_as_int(law)
      scene%stiffness_per_mass = stiffness_per_mass
      call fit('mesh', 'elements', elements, scene%elements); if (allocated(error)) return
      scene%dt = dt
      scene%t_end = t_end
      scene%beta = beta
      scene%centered_load = centered_load /= 0
      scene%taylor_start = taylor_start /= 0
      scene%allow_unstable = allow_unstable /= 0
      call fit('output', 'record_every', record_every, scene%record_every); if (allocated(error)) return
      call fit('output', 'snapshot_every', snapshot_every, scene%snapshot_every); if (allocated(error)) return
      scene%max_output_gb = max_output_gb
      if (size(stop_nodes) > 0) then
         if (any(abs(stop_nodes) > huge(1))) then
            call fatal_error(error, source//': &stops nodes is out of range; allowed: 1 <= nodes <= elements')
            return
         end if
         scene%stop_nodes = int(stop_nodes)
         scene%stop_lower = stop_lower
         scene%stop_upper = stop_upper
      end if

   contains

      subroutine fit(group, key, wide, narrow)
         character(len=*), intent(in) :: group, key
         integer(ik), intent(in) :: wide
         integer, intent(out) :: narrow
         character(len=24) :: text
         if (abs(wide) <= huge(narrow)) then
            narrow = int(wide)
            return
         end if
         narrow = 0
         write (text, '(i0)') wide
         call fatal_error(error, source//': &'//group//' '//key//' = '//trim(text)// &
            & ' is out of range; allowed: |'//key//'| < 2**31')
      end subroutine fit
   end subroutine make_scene

   !> A law code as a default integer; codes that do not fit become -1 (unknown).
   pure integer function law_as_int(law)
      !> Law code.
      integer(ik), intent(in) :: law
      law_as_int = -1
      if (abs(law) <= huge(law_as_int)) law_as_int = int(law)
   end function law_as_int

   !> Turn an error object into status (0: none, 1: error) and a fixed-length message.
   subroutine report(error, status, message)
      !> Error, if any.
      type(error_type), allocatable, intent(in) :: error
      !> 0 without error, 1 with.
      integer, intent(out) :: status
      !> The error's message (truncated to the buffer), blank without error.
      character(len=*), intent(out) :: message
      status = 0
      message = ''
      if (.not. allocated(error)) return
      status = 1
      message = error%message
   end subroutine report
end module beamstops_wrap_support
