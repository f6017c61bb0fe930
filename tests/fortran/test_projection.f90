!> Signorini contact at the tip: the KKT conditions at every recorded step of the
!> paper's scene, and unit checks of the projection and of the compliance solve.
module test_projection
   use testing
   use test_support, only: run_recorded
   use beamstops, only: ik, scene_type, array_recorder, run_summary, law_signorini
   use beamstops_recorder, only: col_t, col_u, col_reaction
   use beamstops_contact_tip_projection, only: project_tip
   use beamstops_contact_compliance, only: spring_force, solve_spring_tip
   implicit none
   private
   public :: collect_projection

contains

   !> Tests of the suite.
   subroutine collect_projection(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('paper''s scene: KKT at every step, no violation, impacts', test_kkt), &
         & new_unittest('project_tip: inside, above, below', test_project_tip), &
         & new_unittest('solve_spring_tip solves y = trial + w p(y)', test_spring_equation), &
         & new_unittest('solve_spring_tip is monotone and continuous in trial', test_spring_monotone) &
         & ]
   end subroutine collect_projection

   subroutine test_kkt(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      real(wp) :: u_next, r
      integer(ik) :: j, upper_contacts, lower_contacts
      character(len=:), allocatable :: where
      scene%law = law_signorini
      scene%beta = 0.5_wp
      scene%dt = 5e-5_wp
      scene%t_end = 0.5_wp
      call run_recorded(scene, rec, summary, error)
      if (allocated(error)) return
      call note('impacts '//int_text(summary%impacts)//', max_violation '//real_text(summary%max_violation))
      call check(error, summary%max_violation, 0.0_wp, 'summary max_violation'); if (allocated(error)) return
      call check(error, summary%impacts > 0, 'impacts > 0 (got '//int_text(summary%impacts)//')'); if (allocated(error)) return
      upper_contacts = 0
      lower_contacts = 0
      do j = 1, rec%filled
         where = ' at t = '//real_text(rec%rows(col_t, j))
         call check(error, rec%rows(col_u, j) >= scene%lower .and. rec%rows(col_u, j) <= scene%upper, &
            & 'tip u = '//real_text(rec%rows(col_u, j))//' within the stops'//where)
         if (allocated(error)) return
         ! The reaction of step n-1 is (A u^n - F^{n-1})_tip/dt^2, an element of -d psi(u^n):
         ! the row of t_n holds u^n and that reaction, so each row pairs with itself.
         r = rec%rows(col_reaction, j)
         u_next = rec%rows(col_u, j)
         if (r < 0) then
            upper_contacts = upper_contacts + 1
            call check(error, u_next, scene%upper, 'negative reaction '//real_text(r)//' needs u^n at the upper stop'// &
               & where, thr=0.0_wp)
         else if (r > 0) then
            lower_contacts = lower_contacts + 1
            call check(error, u_next, scene%lower, 'positive reaction '//real_text(r)//' needs u^n at the lower stop'// &
               & where, thr=0.0_wp)
         end if
         if (allocated(error)) return
         if (u_next > scene%lower .and. u_next < scene%upper) then
            call check(error, r, 0.0_wp, 'reaction with u^n strictly between the stops'//where, thr=0.0_wp)
            if (allocated(error)) return
         end if
      end do
      call note('steps with reaction at the upper stop '//int_text(upper_contacts)//', at the lower stop '// &
         & int_text(lower_contacts))
      call check(error, upper_contacts + lower_contacts > 0, 'some reaction is recorded')
   end subroutine test_kkt

   subroutine test_project_tip(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: lower = -0.1_wp, upper = 0.2_wp, z_tip = 0.04_wp
      real(wp) :: c, p
      call project_tip(0.05_wp, lower, upper, z_tip, c, p)
      call check(error, p, 0.05_wp, 'inside: projected value', thr=0.0_wp); if (allocated(error)) return
      call check(error, c, 0.0_wp, 'inside: correction', thr=0.0_wp); if (allocated(error)) return
      call project_tip(upper, lower, upper, z_tip, c, p)
      call check(error, c, 0.0_wp, 'on the stop: correction', thr=0.0_wp); if (allocated(error)) return
      call project_tip(0.3_wp, lower, upper, z_tip, c, p)
      call check(error, p, upper, 'above: projected value', thr=0.0_wp); if (allocated(error)) return
      ! u = u' + c z moves the tip by c z_tip onto the stop
      call check(error, c, (upper - 0.3_wp)/z_tip, 'above: correction', thr=1e-14_wp, rel=.true.); if (allocated(error)) return
      call check(error, c < 0, 'above: reaction c/dt^2 <= 0'); if (allocated(error)) return
      call check(error, 0.3_wp + c*z_tip, upper, 'above: trial + c z_tip', thr=1e-15_wp); if (allocated(error)) return
      call project_tip(-0.5_wp, lower, upper, z_tip, c, p)
      call check(error, p, lower, 'below: projected value', thr=0.0_wp); if (allocated(error)) return
      call check(error, c > 0, 'below: reaction c/dt^2 >= 0'); if (allocated(error)) return
      call check(error, -0.5_wp + c*z_tip, lower, 'below: trial + c z_tip', thr=1e-15_wp)
   end subroutine test_project_tip

   subroutine test_spring_equation(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: lower = -0.1_wp, upper = 0.1_wp
      real(wp), parameter :: stiffness(3) = [1e2_wp, 1e8_wp, 1e12_wp], w(3) = [0.0_wp, 3e-12_wp, 2e-9_wp]
      real(wp) :: trial, y, residual
      integer :: i, a, b
      do a = 1, size(stiffness)
         do b = 1, size(w)
            do i = -200, 200
               trial = 0.3_wp*i/200
               y = solve_spring_tip(trial, lower, upper, stiffness(a), w(b))
               residual = y - (trial + w(b)*spring_force(y, lower, upper, stiffness(a)))
               ! y = (trial + c g)/(1 + c), c = w k: round-off of y is amplified by 1 + c in w p(y)
               call check(error, residual, 0.0_wp, 'y - trial - w p(y) for trial '//real_text(trial)//', k '// &
                  & real_text(stiffness(a))//', w '//real_text(w(b)), &
                  & thr=4*epsilon(1.0_wp)*(abs(trial) + (1 + w(b)*stiffness(a))*max(abs(lower), abs(upper))))
               if (allocated(error)) return
               ! a spring pushes back but never past the stop
               if (trial > upper) call check(error, y >= upper .and. y <= trial, 'upper stop: upper <= y <= trial')
               if (trial < lower) call check(error, y <= lower .and. y >= trial, 'lower stop: trial <= y <= lower')
               if (trial >= lower .and. trial <= upper) call check(error, y, trial, 'between the stops y = trial', thr=0.0_wp)
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_spring_equation

   subroutine test_spring_monotone(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: lower = -0.1_wp, upper = 0.1_wp, stiffness = 1e8_wp, w = 2.5e-11_wp*0.04_wp
      real(wp) :: y, previous, trial, step
      integer :: i
      step = 1e-5_wp
      previous = -huge(1.0_wp)
      do i = -40000, 40000
         trial = i*step
         y = solve_spring_tip(trial, lower, upper, stiffness, w)
         call check(error, y >= previous, 'nondecreasing at trial '//real_text(trial)//': '//real_text(y)//' < '// &
            & real_text(previous))
         if (allocated(error)) return
         ! Lipschitz with constant 1 (no jump at the stops)
         if (i > -40000) call check(error, y - previous <= step*(1 + 1e-9_wp) + 1e-16_wp, &
            & 'jump of '//real_text(y - previous)//' at trial '//real_text(trial))
         if (allocated(error)) return
         previous = y
      end do
   end subroutine test_spring_monotone
end module test_projection
