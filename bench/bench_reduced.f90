!> Reduced (modal) models (SPEC 11): cost and accuracy against the number of modes r.
!>
!>   bench_reduced cost J STEPS EVERY r1 r2 ...  ns per step of the reduced loop (paper's scene, tip
!>                                            stops, beta = 1/2, a record every EVERY steps to a
!>                                            recorder that keeps nothing) for each r, and of the
!>                                            full engine's loop; plus the time to build each model
!>   bench_reduced tube J STEPS EVERY r1 r2 ...  the same for the tube of input/tube_supports.nml
!>                                            (stops at J/3, 2J/3 and the tip; J a multiple of 3)
!>   bench_reduced damped J STEPS EVERY r1 r2 ...  ns per step of the reduced loop (paper's scene) for
!>                                            each r without damping and with Rayleigh damping
!>                                            (a = 2 1/s, b = 1e-5 s: the damped loop variant), and
!>                                            their ratio, measured in the same run
!>   bench_reduced massless J STEPS EVERY r1 r2 ...  ns per step of the full engine with mass
!>                                            redistribution (SPEC 10), then for each r of the plain
!>                                            reduced loop (consistent mass) and of the massless
!>                                            boundary (mass redistributed), their ratio and the
!>                                            speed-up of the massless boundary over the full
!>                                            redistributed engine, measured in the same run
!>   bench_reduced stats J DT T0 T1 r1 r2 ...  power the stops take (W), RMS tip (m) and impacts
!>                                            per second over [T0, T1] (paper's scene, beta = 1/2,
!>                                            a record every 10 steps), full model then each r
!>   bench_reduced error J DT r1 r2 ...       largest tip difference to the full model (same J, dt)
!>                                            over t <= 0.08 s (before the first impact) and over
!>                                            t <= 0.2 s, for each r
!>
!> Prints `key value` lines. Timings are the thread's CPU time (beamstops_clock; on a shared
!> machine less noisy than wall-clock), best of three.
program bench_reduced
   use, intrinsic :: iso_fortran_env, only: error_unit
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type
   use beamstops_scene, only: scene_type, steps_of, record_count
   use beamstops_model, only: model_type, build_model
   use beamstops_run, only: prepare_run, simulate
   use beamstops_summary, only: run_summary
   use beamstops_recorder_array, only: array_recorder
   use beamstops_recorder, only: col_t, col_u, col_dissipated
   use beamstops_reduced, only: reduced_model_type, build_reduced, stop_unknowns
   use beamstops_reduced_scheme, only: simulate_reduced
   use bench_null_recorder, only: null_recorder
   use bench_support, only: argument, int_argument
   use beamstops_clock, only: thread_cpu_seconds
   implicit none

   character(len=64) :: what
   what = argument(1, 'cost')
   select case (trim(what))
   case ('cost')
      call bench_cost(int_argument(2, 19), int_argument(3, 100000), int_argument(4, 1))
   case ('tube')
      call bench_cost(int_argument(2, 30), int_argument(3, 100000), int_argument(4, 1), tube=.true.)
   case ('damped')
      call bench_damped(int_argument(2, 19), int_argument(3, 100000), int_argument(4, 1))
   case ('massless')
      call bench_massless(int_argument(2, 19), int_argument(3, 100000), int_argument(4, 1))
   case ('stats')
      call bench_stats(int_argument(2, 19), real_argument(3, 1.0e-5_wp), real_argument(4, 2.0_wp), &
         & real_argument(5, 22.0_wp))
   case ('error')
      call bench_error(int_argument(2, 19), real_argument(3, 1.0e-5_wp))
   case default
      write (error_unit, '(a)') 'usage: bench_reduced cost|tube|damped|massless|stats|error ...'
      error stop 2
   end select

contains

   !> The paper's scene (tip stops, beta = 1/2, centred load) with J elements.
   function paper_scene(elements, dt, t_end) result(scene)
      integer, intent(in) :: elements
      real(wp), intent(in) :: dt, t_end
      type(scene_type) :: scene
      scene%elements = elements
      scene%dt = dt
      scene%t_end = t_end
      scene%beta = 0.5_wp
   end function paper_scene

   subroutine bench_cost(elements, steps, every, tube)
      integer, intent(in) :: elements, steps, every
      logical, intent(in), optional :: tube
      type(scene_type) :: scene
      type(model_type) :: model
      type(reduced_model_type) :: reduced
      type(null_recorder) :: rec
      type(run_summary) :: summary
      type(error_type), allocatable :: error
      real(wp) :: t0, t1
      real(wp) :: best, build
      integer :: k, rep, r
      scene = paper_scene(elements, 1.0e-6_wp, steps*1.0e-6_wp)
      if (present(tube)) then
         scene%beta = 0.25_wp
         scene%length = 1.5_wp
         scene%amplitude = 0.002_wp
         scene%omega = 40.0_wp
         scene%dt = 2e-5_wp
         scene%t_end = steps*scene%dt
         scene%stop_nodes = [elements/3, 2*elements/3, elements]
         scene%stop_lower = [-0.002_wp, -0.002_wp, -0.004_wp]
         scene%stop_upper = [0.002_wp, 0.002_wp, 0.004_wp]
      end if
      scene%record_every = every
      t0 = thread_cpu_seconds()
      call prepare_run(scene, 'bench', model, error)
      t1 = thread_cpu_seconds()
      call fail_on(error)
      call put_int('elements', elements)
      call put('full_build_s', (t1 - t0))
      best = huge(1.0_wp)
      do rep = 1, 3
         t0 = thread_cpu_seconds()
         call simulate(scene, model, rec, summary, error)
         t1 = thread_cpu_seconds()
         call fail_on(error)
         best = min(best, (t1 - t0))
      end do
      call put('full_ns_per_step', 1.0e9_wp*best/steps)
      do k = 5, command_argument_count()
         r = int_argument(k, 1)
         if (r > 2*elements - stop_unknowns(scene)) cycle
         scene%modes = r
         t0 = thread_cpu_seconds()
         call build_reduced(scene, model, reduced, error)
         t1 = thread_cpu_seconds()
         call fail_on(error)
         build = (t1 - t0)
         best = huge(1.0_wp)
         do rep = 1, 3
            t0 = thread_cpu_seconds()
            call simulate_reduced(scene, reduced, rec, summary, error)
            t1 = thread_cpu_seconds()
            call fail_on(error)
            best = min(best, (t1 - t0))
         end do
         write (*, '(a, i0, a, es10.3, a, f10.2)') 'r ', r, ' build_s ', build, ' ns_per_step ', 1.0e9_wp*best/steps
      end do
      if (rec%sink == 12345.678_wp) print *, rec%sink
   end subroutine bench_cost

   subroutine bench_damped(elements, steps, every)
      integer, intent(in) :: elements, steps, every
      type(scene_type) :: plain, damped
      real(wp) :: ns_plain, ns_damped
      integer :: k, r
      plain = paper_scene(elements, 1.0e-6_wp, steps*1.0e-6_wp)
      plain%record_every = every
      damped = plain
      damped%damping_mass = 2.0_wp
      damped%damping_stiffness = 1.0e-5_wp
      call put_int('elements', elements)
      do k = 5, command_argument_count()
         r = int_argument(k, 1)
         if (r > 2*elements - stop_unknowns(plain)) cycle
         plain%modes = r
         damped%modes = r
         ns_plain = reduced_ns_per_step(plain, steps)
         ns_damped = reduced_ns_per_step(damped, steps)
         write (*, '(a, i0, a, f10.2, a, f10.2, a, f8.3)') 'r ', r, ' ns_per_step ', ns_plain, ' damped_ns_per_step ', &
            & ns_damped, ' ratio ', ns_damped/ns_plain
      end do
   end subroutine bench_damped

   subroutine bench_massless(elements, steps, every)
      integer, intent(in) :: elements, steps, every
      type(scene_type) :: plain, massless
      type(model_type) :: model
      type(null_recorder) :: rec
      type(run_summary) :: summary
      type(error_type), allocatable :: error
      real(wp) :: ns_plain, ns_massless, ns_full, t0, t1, best
      integer :: k, r, rep
      plain = paper_scene(elements, 1.0e-6_wp, steps*1.0e-6_wp)
      plain%record_every = every
      massless = plain
      massless%redistributed_mass = .true.
      call prepare_run(massless, 'bench', model, error)
      call fail_on(error)
      best = huge(1.0_wp)
      do rep = 1, 3
         t0 = thread_cpu_seconds()
         call simulate(massless, model, rec, summary, error)
         t1 = thread_cpu_seconds()
         call fail_on(error)
         best = min(best, (t1 - t0))
      end do
      ns_full = 1.0e9_wp*best/steps
      call put_int('elements', elements)
      call put('full_redistributed_ns_per_step', ns_full)
      do k = 5, command_argument_count()
         r = int_argument(k, 1)
         if (r > 2*elements - stop_unknowns(plain)) cycle
         plain%modes = r
         massless%modes = r
         ns_plain = reduced_ns_per_step(plain, steps)
         ns_massless = reduced_ns_per_step(massless, steps)
         write (*, '(a, i0, a, f10.2, a, f10.2, a, f8.3, a, f8.2)') 'r ', r, ' ns_per_step ', ns_plain, &
            & ' massless_ns_per_step ', ns_massless, ' ratio ', ns_massless/ns_plain, ' speedup_over_full ', &
            & ns_full/ns_massless
      end do
      if (rec%sink == 12345.678_wp) print *, rec%sink
   end subroutine bench_massless

   !> Best of three: ns per step of the reduced loop of a scene (modes > 0).
   function reduced_ns_per_step(scene, steps) result(ns)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: steps
      real(wp) :: ns
      type(model_type) :: model
      type(reduced_model_type) :: reduced
      type(null_recorder) :: rec
      type(run_summary) :: summary
      type(error_type), allocatable :: error
      real(wp) :: t0, t1, best
      integer :: rep
      call build_model(scene, model, error)
      call fail_on(error)
      call build_reduced(scene, model, reduced, error)
      call fail_on(error)
      best = huge(1.0_wp)
      do rep = 1, 3
         t0 = thread_cpu_seconds()
         call simulate_reduced(scene, reduced, rec, summary, error)
         t1 = thread_cpu_seconds()
         call fail_on(error)
         best = min(best, (t1 - t0))
      end do
      ns = 1.0e9_wp*best/steps
      if (rec%sink == 12345.678_wp) print *, rec%sink
   end function reduced_ns_per_step

   subroutine bench_error(elements, dt)
      integer, intent(in) :: elements
      real(wp), intent(in) :: dt
      type(scene_type) :: scene
      type(model_type) :: model
      type(array_recorder) :: full, red
      type(run_summary) :: summary
      type(error_type), allocatable :: error
      real(wp) :: before, through
      integer(ik) :: j
      integer :: k, r
      scene = paper_scene(elements, dt, 0.2_wp)
      call prepare_run(scene, 'bench', model, error)
      call fail_on(error)
      call full%reserve(record_count(scene), 0_ik, elements + 1)
      call simulate(scene, model, full, summary, error)
      call fail_on(error)
      call put_int('elements', elements)
      call put('dt', dt)
      call put_int('full_impacts_to_0.2s', int(summary%impacts))
      do k = 4, command_argument_count()
         r = int_argument(k, 1)
         if (r > 2*elements - stop_unknowns(scene)) cycle
         scene%modes = r
         call run_reduced_recorded(scene, model, red, summary)
         before = 0
         through = 0
         do j = 1, full%filled
            if (full%rows(col_t, j) <= 0.08_wp) before = max(before, abs(full%rows(col_u, j) - red%rows(col_u, j)))
            through = max(through, abs(full%rows(col_u, j) - red%rows(col_u, j)))
         end do
         write (*, '(a, i0, a, es10.3, a, es10.3, a, i0)') 'r ', r, ' tip_error_to_0.08s_m ', before, &
            & ' tip_error_to_0.2s_m ', through, ' impacts ', summary%impacts
      end do
   end subroutine bench_error

   subroutine bench_stats(elements, dt, t0, t1)
      integer, intent(in) :: elements
      real(wp), intent(in) :: dt, t0, t1
      type(scene_type) :: scene
      type(model_type) :: model
      type(array_recorder) :: rec
      type(run_summary) :: summary
      type(error_type), allocatable :: error
      integer :: k, r
      scene = paper_scene(elements, dt, t1)
      scene%record_every = 10
      call prepare_run(scene, 'bench', model, error)
      call fail_on(error)
      call put_int('elements', elements)
      call put('dt', dt)
      call rec%reserve(record_count(scene), 0_ik, elements + 1)
      call simulate(scene, model, rec, summary, error)
      call fail_on(error)
      call report('full', rec, summary, t0, t1)
      do k = 6, command_argument_count()
         r = int_argument(k, 1)
         if (r > 2*elements - stop_unknowns(scene)) cycle
         scene%modes = r
         call run_reduced_recorded(scene, model, rec, summary)
         write (*, '(a, i0, a)', advance='no') 'r ', r, ' '
         call report('', rec, summary, t0, t1)
      end do
   end subroutine bench_stats

   !> The reduced model of `scene` (scene%modes modes) built and run into `rec`, reserved anew for
   !> every record.
   subroutine run_reduced_recorded(scene, model, rec, summary)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(array_recorder), intent(inout) :: rec
      type(run_summary), intent(out) :: summary
      type(reduced_model_type) :: reduced
      type(error_type), allocatable :: error
      call build_reduced(scene, model, reduced, error)
      call fail_on(error)
      if (allocated(rec%rows)) deallocate (rec%rows, rec%snap_t, rec%snap_u, rec%stops_u, rec%stops_reaction)
      call rec%reserve(record_count(scene), 0_ik, scene%elements + 1)
      call simulate_reduced(scene, reduced, rec, summary, error)
      call fail_on(error)
   end subroutine run_reduced_recorded

   subroutine report(name, rec, summary, t0, t1)
         character(len=*), intent(in) :: name
         type(array_recorder), intent(in) :: rec
         type(run_summary), intent(in) :: summary
         real(wp), intent(in) :: t0, t1
         integer(ik) :: j, i0, i1
         real(wp) :: power, rms
         i0 = 0
         i1 = 0
         rms = 0
         do j = 1, rec%filled
            if (rec%rows(col_t, j) >= t0 .and. i0 == 0) i0 = j
            if (rec%rows(col_t, j) >= t0) then
               rms = rms + rec%rows(col_u, j)**2
               i1 = j
            end if
         end do
         rms = sqrt(rms/real(i1 - i0 + 1, wp))
         power = (rec%rows(col_dissipated, i1) - rec%rows(col_dissipated, i0))/(rec%rows(col_t, i1) - rec%rows(col_t, i0))
         write (*, '(a, a, f8.4, a, f8.5, a, f9.2, a, f8.2)') name, ' stop_power_W ', power, ' rms_tip_m ', rms, &
            & ' impacts_per_s ', real(summary%impacts, wp)/t1, ' cpu_s ', summary%cpu_seconds
   end subroutine report

   subroutine fail_on(error)
      type(error_type), allocatable, intent(in) :: error
      if (allocated(error)) then
         write (error_unit, '(a)') error%message
         error stop 1
      end if
   end subroutine fail_on

   subroutine put(key, value)
      character(len=*), intent(in) :: key
      real(wp), intent(in) :: value
      write (*, '(a, 1x, es12.5)') key, value
   end subroutine put

   subroutine put_int(key, value)
      character(len=*), intent(in) :: key
      integer, intent(in) :: value
      write (*, '(a, 1x, i0)') key, value
   end subroutine put_int

   function real_argument(i, default) result(v)
      integer, intent(in) :: i
      real(wp), intent(in) :: default
      real(wp) :: v
      character(len=64) :: s
      v = default
      if (command_argument_count() < i) return
      call get_command_argument(i, s)
      read (s, *) v
   end function real_argument
end program bench_reduced
