!> Validation of the physics of SPEC 8-10 in a scene: Rayleigh damping, the restitution
!> coefficient and mass redistribution. Messages name the source, the namelist group, the key,
!> the value and what is allowed. Called by validate_scene after the other checks.
module beamstops_physics_checks
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type, law_signorini, law_name, stop_count, fmt_real, fmt_int
   use beamstops_model, only: kappa_bound_constant
   implicit none
   private
   public :: validate_physics

   !> Namelist keys of the fields checked here.
   character(len=*), parameter :: key_mass = 'mass_coefficient', key_stiffness = 'stiffness_coefficient', &
      & key_ratio = 'ratio', key_modes = 'modes', key_restitution = 'restitution'
   !> The most damping the Rayleigh coefficients may give, as the damping ratio of the mode each
   !> damps least: a (zeta = a/(2 omega)) the mesh's highest mode, b (zeta = b omega/2) the
   !> first. Every mode more than 100 times critical is far beyond any real structure (zeta of
   !> 1e-3 to 0.1), and beyond what &damping ratio (zeta < 1 at two modes of the mesh) gives.
   real(wp), parameter :: max_damping_ratio = 100
   !> beta_1 L of the cantilever's first mode (1 + cos cosh = 0): omega_1 = beta_1^2 sqrt(k2)/L^2.
   real(wp), parameter :: first_mode_root = 1.8751040687119611_wp

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
      real(wp) :: omega_high, omega_1, mass_max, stiffness_max

      n = 2*scene%elements
      ! &damping: the least damped mode at most max_damping_ratio times critical. a damps the
      ! highest frequency of the mesh least, sqrt(kappa_h) <= sqrt(kappa_tilde) (the paper's
      ! bound); b the first, omega_1 of the cantilever (the mesh's is above it).
      omega_high = sqrt(kappa_bound_constant*scene%k2)*(scene%elements/scene%length)**2
      omega_1 = first_mode_root**2*sqrt(scene%k2)/scene%length**2
      mass_max = 2*max_damping_ratio*omega_high
      stiffness_max = 2*max_damping_ratio/omega_1
      if (.not. (scene%damping_mass >= 0 .and. scene%damping_mass <= mass_max)) then
         call say('damping', key_mass, fmt_real(scene%damping_mass), '0 <= '//key_mass//' <= '// &
            & fmt_real(mass_max, 3, 'down')//' 1/s (a damping ratio a/(2 omega) <= '//fmt_real(max_damping_ratio)// &
            & ' at the highest frequency of the mesh, omega <= sqrt(kappa_tilde) = '//fmt_real(omega_high, 3)//' rad/s)')
         return
      end if
      if (.not. (scene%damping_stiffness >= 0 .and. scene%damping_stiffness <= stiffness_max)) then
         call say('damping', key_stiffness, fmt_real(scene%damping_stiffness), '0 <= '//key_stiffness//' <= '// &
            & fmt_real(stiffness_max, 3, 'down')//' s (a damping ratio b omega/2 <= '//fmt_real(max_damping_ratio)// &
            & ' at the first mode, omega_1 = 1.8751^2 sqrt(k2)/length^2 = '//fmt_real(omega_1, 3)//' rad/s)')
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
