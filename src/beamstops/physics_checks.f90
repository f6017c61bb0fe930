!> Validation of the physics of SPEC 8-10 in a scene: Rayleigh damping, the restitution
!> coefficient and mass redistribution. Messages name the source, the namelist group, the key,
!> the value and what is allowed. Called by validate_scene after the other checks.
module beamstops_physics_checks
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type, law_signorini, law_name, stop_count, fmt_real, fmt_int
   implicit none
   private
   public :: validate_physics

   !> Namelist keys of the fields checked here.
   character(len=*), parameter :: key_mass = 'mass_coefficient', key_stiffness = 'stiffness_coefficient', &
      & key_ratio = 'ratio', key_modes = 'modes', key_restitution = 'restitution'

contains

   !> Check the damping, restitution and mass redistribution of a scene (whose other values are
   !> valid): the first violation found is reported.
   subroutine validate_physics(scene, source, error)
      !> Scene, its other values already validated.
      type(scene_type), intent(in) :: scene
      !> Where the scene came from (file name or 'scene'), the message's first word.
      character(len=*), intent(in) :: source
      !> Set on the first value out of range.
      type(error_type), allocatable, intent(out) :: error
      integer :: n, i
      integer, allocatable :: nodes(:)

      n = 2*scene%elements
      ! &damping
      if (.not. (scene%damping_mass >= 0)) then
         call say('damping', key_mass, fmt_real(scene%damping_mass), key_mass//' >= 0 (1/s)')
         return
      end if
      if (.not. (scene%damping_stiffness >= 0)) then
         call say('damping', key_stiffness, fmt_real(scene%damping_stiffness), key_stiffness//' >= 0 (s)')
         return
      end if
      if (scene%damping_by_ratio) then
         if (scene%damping_mass /= 0 .or. scene%damping_stiffness /= 0) then
            call fatal_error(error, source//': &damping '//key_ratio//' is given together with '//key_mass// &
               & ' = '//fmt_real(scene%damping_mass)//' and '//key_stiffness//' = '// &
               & fmt_real(scene%damping_stiffness)//'; allowed: either the ratios or the coefficients')
            return
         end if
         do i = 1, 2
            if (.not. (scene%damping_ratio(i) >= 0 .and. scene%damping_ratio(i) < 1)) then
               call say('damping', key_ratio, fmt_real(scene%damping_ratio(i)), '0 <= '//key_ratio//' < 1')
               return
            end if
         end do
         if (any(scene%damping_modes < 1) .or. any(scene%damping_modes > n) .or. &
            & scene%damping_modes(1) == scene%damping_modes(2)) then
            call say('damping', key_modes, fmt_int(int(scene%damping_modes(1), ik))//', '// &
               & fmt_int(int(scene%damping_modes(2), ik)), 'two distinct modes, 1 <= mode <= 2 elements = '// &
               & fmt_int(int(n, ik)))
            return
         end if
      end if
      ! &stops restitution
      if (.not. (scene%restitution >= 0 .and. scene%restitution <= 1)) then
         call say('stops', key_restitution, fmt_real(scene%restitution), '0 <= '//key_restitution//' <= 1')
         return
      end if
      if (scene%restitution > 0 .and. scene%law /= law_signorini) then
         call fatal_error(error, source//': &stops '//key_restitution//' = '//fmt_real(scene%restitution)// &
            & ' is out of range for law = '''//law_name(scene%law)//'''; allowed: '//key_restitution// &
            & ' = 0 unless law = ''signorini''')
         return
      end if
      ! &stops redistributed_mass
      if (scene%redistributed_mass) then
         if (.not. (scene%beta > 0)) then
            call fatal_error(error, source//': &stops mass = ''redistributed'' needs beta > 0; '// &
               & 'allowed: &time beta > 0 (got beta = '//fmt_real(scene%beta)//')')
            return
         end if
         if (scene%damping_stiffness > 0 .or. scene%damping_by_ratio) then
            call fatal_error(error, source//': &stops mass = ''redistributed'' with stiffness-proportional '// &
               & 'damping (&damping '//key_stiffness//' or '//key_ratio//') is not supported; allowed: '// &
               & key_mass//' alone (C = a M^rho leaves the massless rows undamped)')
            return
         end if
         if (scene%law /= law_signorini) then
            call fatal_error(error, source//': &stops mass = ''redistributed'' is out of range for law = '''// &
               & law_name(scene%law)//'''; allowed: law = ''signorini'' (the constrained unknowns lose their mass)')
            return
         end if
         if (stop_count(scene) > 0) then
            nodes = scene%stop_nodes
            do i = 1, size(nodes)
               if (any(abs(nodes - nodes(i)) == 1)) then
                  call fatal_error(error, source//': &stops mass = ''redistributed'' with stops at the '// &
                     & 'neighbouring nodes '//fmt_int(int(nodes(i), ik))//' and '// &
                     & fmt_int(int(nodes(i) + merge(1, -1, any(nodes == nodes(i) + 1)), ik))// &
                     & '; allowed: no element between two stops (the element would keep no translation mass)')
                  return
               end if
            end do
         end if
      end if

   contains

      !> The common message: value out of range, and what is allowed.
      subroutine say(group, key, value, allowed)
         character(len=*), intent(in) :: group, key, value, allowed
         call fatal_error(error, source//': &'//group//' '//key//' = '//value//' is out of range; allowed: '//allowed)
      end subroutine say
   end subroutine validate_physics
end module beamstops_physics_checks
