!> Lockstep ensembles against one member at a time (SPEC 13), measured in one run; prints a
!> markdown table and `key value` lines, asserts nothing about time.
!>
!>   bench_lockstep [J [steps [repeats [every [observe [damped]]]]]]
!>                                                    defaults: 19, 200000 (J = 19) or 3.8e6/J, 5,
!>                                                    0 (0: nothing recorded), 1 (1: the shock log
!>                                                    and statistics of every member, the scene's
!>                                                    default; 0: &statistics off), 0 (1: also the
!>                                                    same members with Rayleigh damping, zeta =
!>                                                    0.01 at modes 1 and 2: the general lockstep
!>                                                    loop against the plain one, in the same run)
!>
!> Members: the paper's scene (Signorini, beta = 1/2, dt = 1e-6 s) with omega and amplitude
!> varied per member. One at a time: start_state + run_scheme of each member alone (the fused
!> path, start and summary included), as many members as the largest group. Lockstep:
!> simulate_lockstep of K = 1, 2, 4, 8, 16 members (start and summaries included). Recorders keep nothing (bench_null_recorder). Times of the loops only, in CPU
!> seconds of the thread (beamstops_clock: per core, and not inflated when a shared machine
!> runs other work meanwhile); the variants' repeats are interleaved; medians.
!>
!> The floor beside each: a step is bounded by the chain of its two substitutions (2n dependent
!> multiply-adds, shared by the K members of a group: 2n latencies / K per member-step) and by
!> its operations (20 n multiply-adds per member-step, 760 at J = 19; 30 n when recorded) over
!> the peak rate of independent multiply-adds, both measured here by tiny kernels.
program bench_lockstep
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type
   use beamstops_scene, only: scene_type, law_signorini
   use beamstops_model, only: model_type, build_model
   use beamstops_scheme, only: state_type, start_state, run_scheme
   use beamstops_summary, only: run_summary
   use beamstops_lockstep, only: prepare_lockstep, simulate_lockstep
   use beamstops_clock, only: thread_cpu_seconds
   use bench_null_recorder, only: null_recorder
   use bench_support, only: runtime_one, median, put, int_argument, fail
   implicit none

   integer, parameter :: groups(5) = [1, 2, 4, 8, 16]
   integer :: elements, steps, repeats, every, observe, damped, rep, g, n
   real(wp), allocatable :: t_alone(:), t_group(:, :), t_latency(:), t_peak(:), t_alone_damped(:), t_damped(:, :)
   real(wp) :: alone, latency, peak, ns, floor_chain, floor_ops, ops, alone_damped
   type(scene_type), allocatable :: scenes(:), damped_scenes(:)
   character(len=160) :: line

   elements = int_argument(1, 19)
   steps = int_argument(2, max(1000, int(3.8e6_wp/elements)))
   repeats = int_argument(3, 5)
   every = int_argument(4, 0)
   observe = int_argument(5, 1)
   damped = int_argument(6, 0)
   n = 2*elements
   allocate (t_alone(repeats), t_group(repeats, size(groups)), t_latency(repeats), t_peak(repeats))
   allocate (t_alone_damped(repeats), t_damped(repeats, size(groups)))
   allocate (scenes(maxval(groups)))
   call members(scenes)
   damped_scenes = scenes
   damped_scenes%damping_by_ratio = .true.
   do g = 1, size(damped_scenes)
      damped_scenes(g)%damping_ratio = 0.01_wp
   end do

   do rep = 1, repeats
      t_latency(rep) = fma_latency()
      t_peak(rep) = fma_throughput()
      t_alone(rep) = time_alone(scenes)
      do g = 1, size(groups)
         t_group(rep, g) = time_group(scenes(1:groups(g)))
      end do
      if (damped == 0) cycle
      t_alone_damped(rep) = time_alone(damped_scenes)
      do g = 1, size(groups)
         t_damped(rep, g) = time_group(damped_scenes(1:groups(g)))
      end do
   end do

   alone = median(t_alone)
   latency = median(t_latency)
   peak = median(t_peak)
   ops = merge(30.0_wp, 20.0_wp, every > 0)*n
   call put('J', real(elements, wp))
   call put('n', real(n, wp))
   call put('steps', real(steps, wp))
   call put('fma_latency_ns', latency)
   call put('fma_per_ns', peak)
   call put('observe', real(observe, wp))
   call put('alone_ns_per_member_step', alone)
   call put('alone_least_ns_per_member_step', minval(t_alone))
   print '(a)', ''
   write (line, '(a,i0,a,i0,a,i0,a)') '| J = ', elements, ' (n = ', n, '), ', steps, &
      & ' steps | ns per member-step | member-steps per s per core | × one at a time | floor ns | × floor |'
   print '(a)', trim(line)
   print '(a)', '|---|---|---|---|---|---|'
   floor_chain = 2*n*latency
   floor_ops = ops/peak
   call table_row('one at a time', alone, max(floor_chain, floor_ops))
   do g = 1, size(groups)
      ns = median(t_group(:, g))
      write (line, '(a,i0)') 'lockstep K = ', groups(g)
      call table_row(trim(line), ns, max(floor_chain/groups(g), floor_ops))
      write (line, '(a,i0,a)') 'lockstep_', groups(g), '_ns_per_member_step'
      call put(trim(line), ns)
      write (line, '(a,i0,a)') 'lockstep_', groups(g), '_least_ns_per_member_step'
      call put(trim(line), minval(t_group(:, g)))
   end do
   print '(a)', ''
   write (line, '(a,f0.3,a,f0.1,a,f0.0,a)') 'multiply-add latency ', latency, ' ns, peak ', peak, &
      & ' independent multiply-adds per ns; ', ops, ' multiply-adds per member-step'
   print '(a)', trim(line)
   if (damped /= 0) call damped_table()

contains

   !> The damped members (the general lockstep loop) beside the undamped ones of the same run.
   subroutine damped_table()
      character(len=200) :: row
      alone_damped = median(t_alone_damped)
      call put('damped_alone_ns_per_member_step', alone_damped)
      print '(a)', ''
      write (line, '(a,i0,a)') '| damped (zeta = 0.01, modes 1, 2), J = ', elements, &
         & ' | ns per member-step | member-steps per s per core | × damped one at a time | × undamped, same K |'
      print '(a)', trim(line)
      print '(a)', '|---|---|---|---|---|'
      write (row, '(a,f0.1,a,es10.3,a,f0.2,a,f0.2,a)') '| one at a time | ', alone_damped, ' | ', &
         & 1.0e9_wp/alone_damped, ' | 1.00 | ', alone/alone_damped, ' |'
      print '(a)', trim(row)
      do g = 1, size(groups)
         ns = median(t_damped(:, g))
         write (row, '(a,i0,a,f0.1,a,es10.3,a,f0.2,a,f0.2,a)') '| lockstep K = ', groups(g), ' | ', ns, ' | ', &
            & 1.0e9_wp/ns, ' | ', alone_damped/ns, ' | ', median(t_group(:, g))/ns, ' |'
         print '(a)', trim(row)
         write (line, '(a,i0,a)') 'damped_lockstep_', groups(g), '_ns_per_member_step'
         call put(trim(line), ns)
      end do
   end subroutine damped_table

   !> Members: the paper's scene at dt = 1e-6, omega and amplitude varied.
   subroutine members(s)
      type(scene_type), intent(out) :: s(:)
      integer :: k
      do k = 1, size(s)
         s(k)%elements = elements
         s(k)%dt = 1.0e-6_wp
         s(k)%beta = 0.5_wp
         s(k)%law = law_signorini
         s(k)%t_end = 1.0e-6_wp*(steps + 1)
         s(k)%omega = 10.0_wp + 0.25_wp*(k - 1)
         s(k)%amplitude = 0.2_wp + 0.002_wp*(k - 1)
         s(k)%record_every = huge(1)
         if (every > 0) s(k)%record_every = every
         s(k)%output_file = 'unused.h5'
         s(k)%statistics = observe /= 0
      end do
   end subroutine members

   !> ns per member-step, each member run alone on the fused path: start_state + run_scheme (its
   !> loop in blocks and its summary: the work simulate does, as simulate_lockstep does it for the
   !> group, so that both sides include a run's start and end).
   function time_alone(s) result(ns)
      type(scene_type), intent(in) :: s(:)
      real(wp) :: ns
      type(model_type) :: model
      type(state_type) :: state
      type(null_recorder) :: recorder
      type(run_summary) :: summary
      type(error_type), allocatable :: error
      real(wp) :: t0, total, member_steps
      integer :: k
      total = 0
      member_steps = 0
      do k = 1, size(s)
         call build_model(s(k), model, error)
         if (allocated(error)) call fail(error%message)
         t0 = thread_cpu_seconds()
         call start_state(s(k), model, state, recorder, error)
         if (allocated(error)) call fail(error%message)
         call run_scheme(s(k), model, state, recorder, summary)
         total = total + (thread_cpu_seconds() - t0)
         member_steps = member_steps + real(summary%steps, wp)
         if (recorder%sink == 12345) print *, recorder%sink
      end do
      ns = 1.0e9_wp*total/member_steps
   end function time_alone

   !> ns per member-step of the members in lockstep (simulate_lockstep, start included: it is
   !> K one-scene starts, negligible beside the steps).
   function time_group(s) result(ns)
      type(scene_type), intent(in) :: s(:)
      real(wp) :: ns
      type(model_type) :: model
      type(null_recorder) :: recorders(size(s))
      type(run_summary) :: summaries(size(s))
      type(error_type), allocatable :: error
      real(wp) :: t0, t1
      call prepare_lockstep(s, 'bench', model, error)
      if (allocated(error)) call fail(error%message)
      t0 = thread_cpu_seconds()
      call simulate_lockstep(s, model, recorders, summaries, error)
      t1 = thread_cpu_seconds()
      if (allocated(error)) call fail(error%message)
      ns = 1.0e9_wp*(t1 - t0)/(real(summaries(1)%steps, wp)*size(s))
      if (recorders(1)%sink == 12345) print *, recorders(1)%sink
   end function time_group

   subroutine table_row(label, ns, floor)
      character(len=*), intent(in) :: label
      real(wp), intent(in) :: ns, floor
      character(len=200) :: row
      write (row, '(a,f0.1,a,es10.3,a,f0.2,a,f0.1,a,f0.2,a)') '| '//label//' | ', ns, ' | ', 1.0e9_wp/ns, ' | ', &
         & alone/ns, ' | ', floor, ' | ', ns/floor, ' |'
      print '(a)', trim(row)
   end subroutine table_row

   !> ns per dependent multiply-add x = b - a x.
   function fma_latency() result(ns)
      real(wp) :: ns
      integer, parameter :: count = 20000000
      real(wp) :: a, b, x, t0
      integer :: k
      a = 0.999_wp
      b = 1.0e-3_wp
      x = runtime_one()
      t0 = thread_cpu_seconds()
      do k = 1, count
         x = b - a*x
      end do
      ns = 1.0e9_wp*(thread_cpu_seconds() - t0)/count
      if (x == 12345) print *, x
   end function fma_latency

   !> Independent multiply-adds per ns: 64 accumulators, vectorized.
   function fma_throughput() result(per_ns)
      real(wp) :: per_ns
      integer, parameter :: count = 2000000, width = 64
      real(wp) :: acc(width), a, b, t0
      integer :: k
      a = 0.999_wp*runtime_one()
      b = 1.0e-3_wp
      acc = [(real(k, wp)/width, k=1, width)]
      t0 = thread_cpu_seconds()
      do k = 1, count
         acc = acc*a + b
      end do
      per_ns = real(count, wp)*width/(1.0e9_wp*(thread_cpu_seconds() - t0))
      if (sum(acc) == 12345) print *, acc(1)
   end function fma_throughput
end program bench_lockstep
