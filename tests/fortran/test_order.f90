!> Order of accuracy in time without stops (SPEC 4): the centred load rule is second
!> order, the paper's rule (load averaged over [t_n, t_n + dt], centred at t_n + dt/2) first.
!>
!> The beam starts at rest on a support that starts moving: u_t(0, 0) = -a omega h(0) /= 0
!> violates the clamp, so every finite-element mode is excited, up to omega_max = sqrt(kappa_h).
!> The trapezoidal rule (beta = 1/4) shifts the phase of a mode by omega^3 dt^2 t/12; the
!> observed order is the asymptotic one only when that is small for omega_max. At J = 19
!> (omega_max = 1.6e5 1/s) and dt = 4e-5 it is 5e4 rad, and the errors at t = 0.2 are
!> erratic in dt. The time discretization is the same for every J, so its order is measured
!> on meshes whose whole spectrum is resolved: J = 1 with dt = 4e-5, 2e-5, 1e-5 and
!> J = 4 with dt eight times smaller; each test checks that premise.
module test_order
   use testing
   use test_support, only: run_recorded
   use beamstops, only: ik, scene_type, model_type, build_model, array_recorder, run_summary, law_none, steps_of
   use beamstops_recorder, only: col_t, col_u
   implicit none
   private
   public :: collect_order

   !> Final time (end of the first contact-free flight of the paper's scene).
   real(wp), parameter :: t_end = 0.2_wp
   !> Largest phase error of the top mode (rad) for which the asymptotic order is expected.
   real(wp), parameter :: max_phase_error = 0.2_wp

contains

   !> Tests of the suite.
   subroutine collect_order(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('centred load rule, J = 1, dt = 4e-5..1e-5: order 2', test_centered_1), &
         & new_unittest('paper''s load rule, J = 1, dt = 4e-5..1e-5: order 1', test_paper_1), &
         & new_unittest('centred load rule, J = 4, dt = 5e-6..1.25e-6: order 2', test_centered_4), &
         & new_unittest('paper''s load rule, J = 4, dt = 5e-6..1.25e-6: order 1', test_paper_4) &
         & ]
   end subroutine collect_order

   !> The scene: no stops, beta = 1/4, t_end = 0.2, records at t = 0 and t_end only.
   function order_scene(elements, centered, dt) result(scene)
      integer, intent(in) :: elements
      logical, intent(in) :: centered
      real(wp), intent(in) :: dt
      type(scene_type) :: scene
      scene%elements = elements
      scene%law = law_none
      scene%beta = 0.25_wp
      scene%centered_load = centered
      scene%dt = dt
      scene%t_end = t_end
      scene%record_every = int(steps_of(scene))
   end function order_scene

   !> Tip displacement at t_end.
   subroutine tip_at_end(scene, tip, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(out) :: tip
      type(error_type), allocatable, intent(out) :: error
      type(array_recorder) :: rec
      type(run_summary) :: summary
      tip = 0
      call run_recorded(scene, rec, summary, error)
      if (allocated(error)) return
      call check(error, rec%rows(col_t, rec%filled), t_end, 'time of the last record', thr=1e-12_wp)
      if (allocated(error)) return
      tip = rec%rows(col_u, rec%filled)
   end subroutine tip_at_end

   !> Observed orders between successive steps against a reference run, within [lo, hi].
   subroutine observed_orders(elements, centered, steps, reference_dt, lo, hi, error)
      integer, intent(in) :: elements
      logical, intent(in) :: centered
      real(wp), intent(in) :: steps(:), reference_dt, lo, hi
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(wp) :: reference, tip(size(steps)), err(size(steps)), order, phase
      character(len=200) :: line
      integer :: i
      call build_model(order_scene(elements, centered, steps(1)), model, error)
      if (allocated(error)) return
      phase = sqrt(model%kappa_h)**3*maxval(steps)**2*t_end/12
      write (line, '(a,i0,a,es10.3,a,es10.3,a)') 'J = ', elements, ': omega_max = ', sqrt(model%kappa_h), &
         & ' 1/s, its phase error at the largest dt ', phase, ' rad'
      call note(trim(line))
      call check(error, phase <= max_phase_error, 'premise: '//trim(line)//' <= '//real_text(max_phase_error))
      if (allocated(error)) return
      call tip_at_end(order_scene(elements, centered, reference_dt), reference, error)
      if (allocated(error)) return
      write (line, '(a,es10.3,a,es23.15)') 'reference dt = ', reference_dt, ': tip(0.2) = ', reference
      call note(trim(line))
      do i = 1, size(steps)
         call tip_at_end(order_scene(elements, centered, steps(i)), tip(i), error)
         if (allocated(error)) return
         err(i) = abs(tip(i) - reference)
         write (line, '(a,es10.3,a,es23.15,a,es10.3)') 'dt = ', steps(i), ': tip(0.2) = ', tip(i), ', |error| = ', err(i)
         call note(trim(line))
      end do
      do i = 1, size(steps) - 1
         order = log(err(i)/err(i + 1))/log(steps(i)/steps(i + 1))
         write (line, '(a,es10.3,a,es10.3,a,f7.4)') 'observed order ', steps(i), ' -> ', steps(i + 1), ': ', order
         call note(trim(line))
         call check(error, order >= lo .and. order <= hi, trim(line)//' outside ['//real_text(lo)//', '// &
            & real_text(hi)//']')
         if (allocated(error)) return
      end do
   end subroutine observed_orders

   subroutine test_centered_1(error)
      type(error_type), allocatable, intent(out) :: error
      call observed_orders(1, .true., [4e-5_wp, 2e-5_wp, 1e-5_wp], 1.25e-6_wp, 1.8_wp, 2.2_wp, error)
   end subroutine test_centered_1

   subroutine test_paper_1(error)
      type(error_type), allocatable, intent(out) :: error
      call observed_orders(1, .false., [4e-5_wp, 2e-5_wp, 1e-5_wp], 1.25e-6_wp, 0.8_wp, 1.3_wp, error)
   end subroutine test_paper_1

   subroutine test_centered_4(error)
      type(error_type), allocatable, intent(out) :: error
      call observed_orders(4, .true., [5e-6_wp, 2.5e-6_wp, 1.25e-6_wp], 1.5625e-7_wp, 1.8_wp, 2.2_wp, error)
   end subroutine test_centered_4

   subroutine test_paper_4(error)
      type(error_type), allocatable, intent(out) :: error
      call observed_orders(4, .false., [5e-6_wp, 2.5e-6_wp, 1.25e-6_wp], 1.5625e-7_wp, 0.8_wp, 1.3_wp, error)
   end subroutine test_paper_4
end module test_order
