!> Microbenchmarks of the hot loop; prints `key value` lines (times in ns, medians of repeats).
!>
!>   bench_kernels fma [repeats]                    latency of one dependent multiply-add (the
!>                                                  least of the repeats), and the peak rate of
!>                                                  independent (vectorized) ones (the best)
!>   bench_kernels solve J [repeats]                one solve with A = M + dt^2 beta S (dt = 1e-6,
!>                                                  beta = 1/2): LAPACK dpbtrs against the fused
!>                                                  substitutions, each solve feeding the next
!>   bench_kernels step J LAW EVERY STEPS [repeats [both|fused|lapack]]
!>                                                  engine steps (start_state + advance) with a
!>                                                  recorder that keeps nothing, fused and LAPACK
!>                                                  paths; LAW signorini|compliance|none; EVERY
!>                                                  = record_every (0: never)
!>   bench_kernels triad KB [repeats]               bandwidth of a = b + s c over 3 arrays of KB
!>                                                  kilobytes each (GB/s, 24 bytes an element):
!>                                                  memory, or a cache level for small KB
!>
!> Timings are the CPU time of the thread (beamstops_clock, as the program's cpu_seconds) of
!> the code under test only, so that the moments the thread waits for a core on a shared machine
!> are not counted; the repeats of the variants that are compared are interleaved, so that a
!> slow moment hits both. A latency is a least time: nothing makes a dependent chain faster than
!> it is, only slower (another thread on the core, a lower clock).
program bench_kernels
   use, intrinsic :: iso_fortran_env, only: int64, error_unit
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type
   use beamstops_scene, only: scene_type, law_code, law_none, law_signorini, law_compliance, steps_of
   use beamstops_model, only: model_type, build_model
   use beamstops_band, only: cholesky_solve
   use beamstops_band_solve, only: band_solver, prepare_solver, fused_solve
   use beamstops_scheme, only: state_type, start_state, advance
   use beamstops_clock, only: thread_cpu_seconds
   use bench_null_recorder, only: null_recorder
   use bench_support, only: runtime_one, median, put, argument, int_argument, fail
   implicit none

   character(len=64) :: what
   integer :: repeats

   what = argument(1, 'fma')
   select case (trim(what))
   case ('fma')
      repeats = int_argument(2, 7)
      call put('fma_latency_ns', min_of(fma_latency, max(repeats, 7)))
      call put('fma_per_ns', -min_of(negated_throughput, max(repeats, 3)))
   case ('solve')
      call bench_solve(int_argument(2, 19), int_argument(3, 7))
   case ('step')
      call bench_step(int_argument(2, 19), argument(3, 'signorini'), int_argument(4, 1), &
         & int_argument(5, 200000), int_argument(6, 5), argument(7, 'both'))
   case ('triad')
      call bench_triad(int_argument(2, 256000), int_argument(3, 5))
   case default
      write (error_unit, '(a)') 'usage: bench_kernels fma|solve|step|triad ...'
      error stop 2
   end select

contains

   !> Nanoseconds per dependent multiply-add x = b - a x (the operation that links one row
   !> of a substitution to the next): the least of 10 chains of 2e6 (a chain short enough that
   !> most of them run undisturbed, long enough that the clock's reads do not count).
   function fma_latency() result(ns)
      real(wp) :: ns
      integer, parameter :: count = 2000000, chains = 10
      real(wp) :: a, b, x, t0
      integer :: k, chain
      a = 0.999_wp
      b = 1.0e-3_wp
      x = runtime_one()
      ns = huge(1.0_wp)
      do chain = 1, chains
         t0 = thread_cpu_seconds()
         do k = 1, count
            x = b - a*x
         end do
         ns = min(ns, 1.0e9_wp*(thread_cpu_seconds() - t0)/count)
      end do
      if (x == 12345) print *, x
   end function fma_latency

   !> Independent multiply-adds per nanosecond: 64 accumulators, vectorized; the best of 10
   !> bursts of 2e5 turns in thread CPU time (a shared core only ever lowers a rate).
   function fma_throughput() result(per_ns)
      real(wp) :: per_ns
      integer, parameter :: count = 200000, width = 64, bursts = 10
      real(wp) :: acc(width), a, b, t0
      integer :: k, burst
      a = 0.999_wp*runtime_one()
      b = 1.0e-3_wp
      acc = [(real(k, wp)/width, k=1, width)]
      per_ns = 0
      do burst = 1, bursts
         t0 = thread_cpu_seconds()
         do k = 1, count
            acc = acc*a + b
         end do
         per_ns = max(per_ns, real(count, wp)*width/(1.0e9_wp*(thread_cpu_seconds() - t0)))
      end do
      if (sum(acc) == 12345) print *, acc(1)
   end function fma_throughput

   !> One solve of the Figure 4 matrix, LAPACK against fused.
   subroutine bench_solve(elements, repeats)
      integer, intent(in) :: elements, repeats
      type(scene_type) :: scene
      type(model_type) :: model
      type(band_solver) :: solver
      type(error_type), allocatable :: error
      real(wp), allocatable :: r(:), b(:)
      real(wp) :: t_lapack(repeats), t_fused(repeats), t_fma(repeats), zero, t0
      integer :: rep, k, count
      call paper_scene(scene, elements, 1.0e-6_wp, 0.5_wp, law_signorini)
      call build_model(scene, model, error)
      if (allocated(error)) call fail(error%message)
      call prepare_solver(model%factor, solver)
      allocate (r(model%n), b(model%n))
      call random_number(r)
      zero = runtime_one() - 1
      count = max(10, int(4.0e7_wp/model%n))
      do rep = 1, repeats
         t_fma(rep) = fma_latency()
         b = r
         t0 = thread_cpu_seconds()
         do k = 1, count
            call cholesky_solve(model%factor, b)
            b = r + zero*b
         end do
         t_lapack(rep) = 1.0e9_wp*(thread_cpu_seconds() - t0)/count
         b = r
         t0 = thread_cpu_seconds()
         do k = 1, count
            call fused_solve(solver, b)
            b = r + zero*b
         end do
         t_fused(rep) = 1.0e9_wp*(thread_cpu_seconds() - t0)/count
      end do
      call put('n', real(model%n, wp))
      call put('fma_latency_ns', minval(t_fma))
      call put('solve_lapack_ns', median(t_lapack))
      call put('solve_fused_ns', median(t_fused))
      call put('solve_lapack_fmas', median(t_lapack/t_fma))
      call put('solve_fused_fmas', median(t_fused/t_fma))
   end subroutine bench_solve

   !> Engine steps with a recorder that keeps nothing: the fused path and the LAPACK path.
   subroutine bench_step(elements, law_text, every, steps, repeats, paths)
      integer, intent(in) :: elements, every, steps, repeats
      character(len=*), intent(in) :: law_text, paths
      type(scene_type) :: scene
      type(model_type) :: model
      type(error_type), allocatable :: error
      real(wp) :: t_fused(repeats), t_lapack(repeats), t_fma(repeats), beta
      integer :: rep, law
      law = law_code(law_text)
      if (law < 0) call fail('unknown law '//trim(law_text))
      beta = merge(0.25_wp, 0.5_wp, law == law_compliance)
      call paper_scene(scene, elements, 1.0e-6_wp, beta, law)
      scene%t_end = 1.0e-6_wp*(steps + 1)
      scene%record_every = huge(1)
      if (every > 0) scene%record_every = every
      call build_model(scene, model, error)
      if (allocated(error)) call fail(error%message)
      do rep = 1, repeats
         t_fma(rep) = fma_latency()
         t_fused(rep) = 0
         t_lapack(rep) = 0
         if (paths /= 'lapack') t_fused(rep) = time_steps(scene, model, steps, .false.)
         if (paths /= 'fused') t_lapack(rep) = time_steps(scene, model, steps, .true.)
      end do
      call put('n', real(model%n, wp))
      call put('fma_latency_ns', minval(t_fma))
      call put('step_fused_ns', median(t_fused))
      call put('step_lapack_ns', median(t_lapack))
      call put('step_fused_min_ns', minval(t_fused))
      call put('step_lapack_min_ns', minval(t_lapack))
      call put('step_fused_fmas', median(t_fused/t_fma))
      call put('step_fused_fmas_min', minval(t_fused/t_fma))
      call put('step_lapack_fmas', median(t_lapack/t_fma))
   end subroutine bench_step

   !> Nanoseconds per step of `steps` steps from the start, on the fused or the LAPACK path.
   function time_steps(scene, model, steps, lapack) result(ns)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      integer, intent(in) :: steps
      logical, intent(in) :: lapack
      real(wp) :: ns
      type(state_type) :: state
      type(null_recorder) :: recorder
      type(error_type), allocatable :: error
      real(wp) :: t0
      call start_state(scene, model, state, recorder, error)
      if (allocated(error)) call fail(error%message)
      state%lapack_solve = lapack
      t0 = thread_cpu_seconds()
      call advance(scene, model, state, recorder, int(steps, ik))
      ns = 1.0e9_wp*(thread_cpu_seconds() - t0)/steps
      if (recorder%sink == 12345) print *, recorder%sink
   end function time_steps

   !> Bandwidth of a = b + s c (GB/s, 24 bytes per element as STREAM counts them) over three
   !> arrays of `kilobytes` each.
   subroutine bench_triad(kilobytes, repeats)
      integer, intent(in) :: kilobytes, repeats
      real(wp), allocatable :: a(:), b(:), c(:)
      real(wp) :: s, rates(repeats)
      integer(int64) :: t0, t1, rate
      integer :: n, rep, k, passes
      n = max(8, int(int(kilobytes, int64)*1000_int64/8))
      passes = max(10, int(2.0e9_wp/(24.0_wp*n)))
      allocate (a(n), b(n), c(n))
      a = 0
      b = 1
      c = 2
      s = runtime_one()
      do rep = 1, repeats
         call system_clock(t0, rate)
         do k = 1, passes
            a = b + s*c
            b(1) = a(n)
         end do
         call system_clock(t1)
         rates(rep) = 24.0_wp*n*passes/(real(t1 - t0, wp)/real(rate, wp))/1.0e9_wp
      end do
      call put('triad_GBps', median(rates))
      if (a(1) == 12345) print *, a(1)
   end subroutine bench_triad

   !> The paper's scene (defaults of scene_type) with J elements, dt, beta and a contact law;
   !> the compliance stiffness is the paper's 1/epsilon = 1e8 per unit mass.
   subroutine paper_scene(scene, elements, dt, beta, law)
      type(scene_type), intent(out) :: scene
      integer, intent(in) :: elements, law
      real(wp), intent(in) :: dt, beta
      scene%elements = elements
      scene%dt = dt
      scene%beta = beta
      scene%law = law
      if (law == law_compliance) scene%stiffness_per_mass = 1.0e8_wp
      scene%output_file = 'unused.h5'
   end subroutine paper_scene

   !> -fma_throughput, for min_of (the best rate is the least of its negatives).
   function negated_throughput() result(y)
      real(wp) :: y
      y = -fma_throughput()
   end function negated_throughput

   !> The least of `repeats` calls of f.
   function min_of(f, repeats) result(m)
      interface
         function f() result(y)
            import :: wp
            real(wp) :: y
         end function f
      end interface
      integer, intent(in) :: repeats
      real(wp) :: m
      integer :: k
      m = huge(1.0_wp)
      do k = 1, repeats
         m = min(m, f())
      end do
   end function min_of
end program bench_kernels
