!> The restitution coefficient of Paoli and Schatzman (SPEC 9): e = 0 is the paper's scheme;
!> for e > 0 the combination (u^{n+1} + e u^{n-1})/(1+e) satisfies the contact conditions every
!> step (tip and stops along the span), u^{n+1} itself may pass a stop by a violation that is
!> reported and shrinks with dt, and a free mass hitting a stop rebounds with -e times its velocity
!> as dt -> 0.
module test_restitution
   use testing
   use test_support, only: run_recorded
   use physics_support, only: open_run, step_once
   use beamstops, only: ik, scene_type, model_type, state_type, array_recorder, run_summary, law_signorini, &
      & steps_of
   use beamstops_forcing, only: support_position
   use beamstops_recorder, only: col_t, col_u, col_reaction, n_columns
   implicit none
   private
   public :: collect_restitution

contains

   !> Tests of the suite.
   subroutine collect_restitution(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('e = 0: the paper''s scheme to the bit', test_zero), &
         & new_unittest('tip, e = 0.5 and 1: KKT of the combination every step; violation of u^{n+1} shrinks with dt', &
         &              test_tip_kkt), &
         & new_unittest('stops along the span, e = 0.5: KKT of the combination every step', test_span_kkt), &
         & new_unittest('free mass on a stop (J = 1): rebound velocity ratio -> e as dt -> 0', test_rebound), &
         & new_unittest('one stop along the span at the tip is the tip path to the bit (e = 0.5; also massless)', &
         &              test_one_stop) &
         & ]
   end subroutine collect_restitution

   !> The paper's scene, beta = 1/4.
   function paper(dt, t_end, e) result(scene)
      real(wp), intent(in) :: dt, t_end, e
      type(scene_type) :: scene
      scene%dt = dt
      scene%t_end = t_end
      scene%beta = 0.25_wp
      scene%restitution = e
   end function paper

   subroutine test_zero(error)
      type(error_type), allocatable, intent(out) :: error
      type(array_recorder) :: a, b
      type(run_summary) :: summary
      type(scene_type) :: scene
      integer :: c
      scene = paper(1.0e-5_wp, 0.5_wp, 0.0_wp)
      call run_recorded(scene, a, summary, error)
      if (allocated(error)) return
      scene = paper(1.0e-5_wp, 0.5_wp, 0.5_wp)
      scene%restitution = 0
      call run_recorded(scene, b, summary, error)
      if (allocated(error)) return
      do c = 1, n_columns
         if (any(a%rows(c, 1:a%filled) /= b%rows(c, 1:b%filled))) then
            call test_failed(error, 'column '//int_text(c)//' differs')
            return
         end if
      end do
   end subroutine test_zero

   !> Step a tip scene one step at a time, checking the KKT conditions of the combination;
   !> returns the largest violation of u^{n+1} and the number of contact steps.
   subroutine tip_kkt(scene, worst, contacts, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(out) :: worst
      integer, intent(out) :: contacts
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: tol = 1.0e-14_wp
      type(model_type) :: model
      type(state_type) :: state
      type(array_recorder) :: rec
      real(wp) :: e, u_old, w, r
      integer(ik) :: step
      integer :: tip
      worst = 0
      contacts = 0
      e = scene%restitution
      call open_run(scene, model, state, rec, error)
      if (allocated(error)) return
      tip = model%tip
      do step = 1, steps_of(scene)
         u_old = state%u(tip) - state%d(tip)
         call step_once(scene, model, state, rec)
         w = (state%u(tip) + e*u_old)/(1 + e)
         r = state%reaction
         if (w < scene%lower - tol .or. w > scene%upper + tol .or. (r > 0 .and. abs(w - scene%lower) > tol) .or. &
            & (r < 0 .and. abs(w - scene%upper) > tol)) then
            call test_failed(error, 'KKT of the combination fails at step '//int_text(step)//': w = '//real_text(w)// &
               & ', reaction '//real_text(r))
            return
         end if
         if (r /= 0) contacts = contacts + 1
      end do
      worst = state%max_violation
   end subroutine tip_kkt

   subroutine test_tip_kkt(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: coarse, fine, e
      integer :: contacts, i
      do i = 1, 2
         e = 0.5_wp*i
         call tip_kkt(paper(1.0e-5_wp, 0.4_wp, e), coarse, contacts, error)
         if (allocated(error)) return
         call check(error, contacts > 0, 'the tip hits the stops')
         if (allocated(error)) return
         call tip_kkt(paper(2.5e-6_wp, 0.4_wp, e), fine, contacts, error)
         if (allocated(error)) return
         call note('e = '//real_text(e)//': largest violation of u^{n+1} '//real_text(coarse)//' m at dt = 1e-5, '// &
            & real_text(fine)//' m at dt = 2.5e-6')
         call check(error, coarse > 0, 'u^{n+1} itself passes the stop (reported, not hidden)')
         if (allocated(error)) return
         call check(error, fine < 0.5_wp*coarse, 'the violation shrinks with dt')
         if (allocated(error)) return
      end do
   end subroutine test_tip_kkt

   subroutine test_span_kkt(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: tol = 1.0e-13_wp, e = 0.5_wp
      type(scene_type) :: scene
      type(model_type) :: model
      type(state_type) :: state
      type(array_recorder) :: rec
      real(wp), allocatable :: u_old(:)
      real(wp) :: w, r, phi_next, phi_old
      integer(ik) :: step
      integer :: i, k, contacts
      ! the tube of input/tube_supports.nml, one second
      scene%length = 1.5_wp
      scene%k2 = 2.0e11_wp*1.6881e-10_wp/(8.0e3_wp*1.4923e-5_wp)
      scene%mass_per_length = 8.0e3_wp*1.4923e-5_wp
      scene%amplitude = 0.002_wp
      scene%omega = 40.0_wp
      scene%elements = 30
      scene%stop_nodes = [10, 20, 30]
      scene%stop_lower = [-0.002_wp, -0.002_wp, -0.004_wp]
      scene%stop_upper = [0.002_wp, 0.002_wp, 0.004_wp]
      scene%dt = 2.0e-5_wp
      scene%t_end = 1.0_wp
      scene%beta = 0.25_wp
      scene%restitution = e
      call open_run(scene, model, state, rec, error)
      if (allocated(error)) return
      contacts = 0
      do step = 1, steps_of(scene)
         u_old = state%u(model%stops%unknown) - state%d(model%stops%unknown)
         call step_once(scene, model, state, rec)
         phi_next = support_position(real(step + 1, wp)*scene%dt, scene%amplitude, scene%omega)
         phi_old = support_position(real(step - 1, wp)*scene%dt, scene%amplitude, scene%omega)
         do i = 1, model%stops%m
            k = model%stops%unknown(i)
            ! the physical displacements: u~ = u + h(x_i) phi
            w = ((state%u(k) + model%stops%lift(i)*phi_next) + e*(u_old(i) + model%stops%lift(i)*phi_old))/(1 + e)
            r = state%stop_reaction(i)
            if (w < scene%stop_lower(i) - tol .or. w > scene%stop_upper(i) + tol .or. &
               & (r > 0 .and. abs(w - scene%stop_lower(i)) > tol) .or. (r < 0 .and. abs(w - scene%stop_upper(i)) > tol)) then
               call test_failed(error, 'KKT of the combination fails at step '//int_text(step)//', stop '// &
                  & int_text(i)//': w = '//real_text(w)//', reaction '//real_text(r))
               return
            end if
            if (r /= 0) contacts = contacts + 1
         end do
      end do
      call note(int_text(contacts)//' contact steps; largest violation of u^{n+1} '//real_text(state%max_violation)//' m')
      call check(error, contacts > 0, 'the stops act')
   end subroutine test_span_kkt

   !> Rebound ratio -v_after/v_before at the first impact of a J = 1 beam launched at 1 m/s
   !> towards a stop 1 mm away, without support motion: the spring force is negligible over the
   !> millisecond of flight, a free mass hitting a rigid stop.
   function rebound(dt, e, error) result(ratio)
      real(wp), intent(in) :: dt, e
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: ratio
      type(scene_type) :: scene
      type(model_type) :: model
      type(state_type) :: state
      type(array_recorder) :: rec
      integer(ik) :: step, first, last
      real(wp) :: v_before, v_after
      ratio = 0
      scene%elements = 1
      scene%amplitude = 0
      scene%lower = -1.0e-3_wp
      scene%upper = 1.0e-3_wp
      scene%beta = 0.25_wp
      scene%dt = dt
      scene%t_end = 3.0e-3_wp
      scene%taylor_start = .false.
      scene%restitution = e
      call open_run(scene, model, state, rec, error, v0=[1.0_wp, 0.0_wp])
      if (allocated(error)) return
      first = 0
      last = 0
      v_before = 0
      do step = 1, steps_of(scene)
         if (first == 0) v_before = state%d(model%tip)/dt
         call step_once(scene, model, state, rec)
         if (state%reaction /= 0 .and. first == 0) first = step
         if (first > 0 .and. state%reaction == 0) then
            last = step
            v_after = state%d(model%tip)/dt
            exit
         end if
      end do
      if (first == 0 .or. last == 0) then
         call test_failed(error, 'no complete impact at dt = '//real_text(dt))
         return
      end if
      ratio = -v_after/v_before
   end function rebound

   subroutine test_rebound(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: e, r(3), dts(3)
      integer :: i, j
      dts = [1.0e-5_wp, 1.0e-6_wp, 1.0e-7_wp]
      do j = 1, 3
         e = 0.25_wp*(j + 1)
         do i = 1, 3
            r(i) = rebound(dts(i), e, error)
            if (allocated(error)) return
         end do
         call note('e = '//real_text(e)//': rebound ratio '//real_text(r(1))//', '//real_text(r(2))//', '// &
            & real_text(r(3))//' at dt = 1e-5, 1e-6, 1e-7')
         call check(error, abs(r(3) - e) < 0.01_wp, 'rebound ratio within 0.01 of e at dt = 1e-7')
         if (allocated(error)) return
         call check(error, abs(r(3) - e) <= abs(r(1) - e) + 1.0e-3_wp, 'the ratio approaches e as dt -> 0')
         if (allocated(error)) return
      end do
   end subroutine test_rebound

   subroutine test_one_stop(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: tip, span
      type(array_recorder) :: a, b
      type(run_summary) :: summary
      integer :: c, k
      do k = 1, 2
         tip = paper(1.0e-5_wp, 0.5_wp, 0.5_wp)
         tip%redistributed_mass = k == 2
         span = tip
         span%stop_nodes = [19]
         span%stop_lower = [tip%lower]
         span%stop_upper = [tip%upper]
         call run_recorded(tip, a, summary, error)
         if (allocated(error)) return
         call run_recorded(span, b, summary, error)
         if (allocated(error)) return
         do c = 1, n_columns
            if (any(a%rows(c, 1:a%filled) /= b%rows(c, 1:b%filled))) then
               call test_failed(error, merge('massless  ', 'consistent', k == 2)//': column '//int_text(c)//' differs')
               return
            end if
         end do
      end do
   end subroutine test_one_stop
end module test_restitution
