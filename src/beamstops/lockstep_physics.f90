!> Who may join a lockstep group beyond the paper's scheme (SPEC 13 with SPEC 8-10): the
!> physics that enters A = M + dt/2 C + dt^2 beta S must be member 1's, the rest may differ.
!>
!> - Rayleigh damping (SPEC 8): C enters A, so the members share it, given the same way: the
!>   coefficients (&damping mass_coefficient, stiffness_coefficient) equal to member 1's, or the
!>   ratio form with the same ratios and modes (the same mesh and beam then give the same a and
!>   b). A member giving a and b while member 1 gives ratios is refused, even if the values
!>   would agree: the group is formed from the keys, not from a solved eigenproblem.
!> - Mass redistribution (SPEC 10): M^rho enters A; &stops mass is shared.
!> - Restitution (SPEC 9): e enters only the bounds of the tip's projection, so each member
!>   keeps its own (0 for some members, 0.8 for others, in one group).
module beamstops_lockstep_physics
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_strings, only: fmt_real, fmt_int
   use beamstops_scene, only: scene_type
   implicit none
   private
   public :: check_shared_physics

contains

   !> Refuse member k when its damping or mass law differs from member 1's; the message names
   !> the member, the group and the key.
   subroutine check_shared_physics(k, scene, first, error)
      !> The member's index (for messages).
      integer, intent(in) :: k
      !> The member's scene and member 1's.
      type(scene_type), intent(in) :: scene, first
      !> Set when the member cannot share A with member 1.
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: who
      integer :: i
      who = 'lockstep: member '//fmt_int(int(k, ik))//': '
      if (scene%redistributed_mass .neqv. first%redistributed_mass) then
         call fatal_error(error, who//'&stops mass = '''//trim(mass_name(scene))//''' differs from member 1''s '''// &
            & trim(mass_name(first))//'''; the mass matrix enters A, which lockstep members share: run it in '// &
            & 'another group')
         return
      end if
      if (scene%damping_by_ratio .neqv. first%damping_by_ratio) then
         call fatal_error(error, who//'&damping is given by '//trim(damping_form(scene))//', member 1''s by '// &
            & trim(damping_form(first))//'; the damping enters A, which lockstep members share: give it the '// &
            & 'same way, or run it in another group')
         return
      end if
      if (first%damping_by_ratio) then
         do i = 1, 2
            call differ('ratio', scene%damping_ratio(i), first%damping_ratio(i))
            if (allocated(error)) return
            call differ('modes', real(scene%damping_modes(i), wp), real(first%damping_modes(i), wp))
            if (allocated(error)) return
         end do
      else
         call differ('mass_coefficient', scene%damping_mass, first%damping_mass)
         if (allocated(error)) return
         call differ('stiffness_coefficient', scene%damping_stiffness, first%damping_stiffness)
      end if

   contains

      !> Refuse the member when a damping key differs from member 1's.
      subroutine differ(key, value, first_value)
         character(len=*), intent(in) :: key
         real(wp), intent(in) :: value, first_value
         if (value == first_value) return
         call fatal_error(error, who//'&damping '//key//' = '//fmt_real(value)//' differs from member 1''s '// &
            & fmt_real(first_value)//'; the damping C enters A = M + dt/2 C + dt^2 beta S, which lockstep '// &
            & 'members share: run it in another group')
      end subroutine differ
   end subroutine check_shared_physics

   !> The &stops mass key's value.
   pure function mass_name(scene) result(name)
      type(scene_type), intent(in) :: scene
      character(len=13) :: name
      name = merge('redistributed', 'consistent   ', scene%redistributed_mass)
   end function mass_name

   !> How the &damping group gives C.
   pure function damping_form(scene) result(form)
      type(scene_type), intent(in) :: scene
      character(len=48) :: form
      if (scene%damping_by_ratio) then
         form = 'ratio and modes'
      else
         form = 'mass_coefficient and stiffness_coefficient'
      end if
   end function damping_form
end module beamstops_lockstep_physics
