!> Lockstep ensembles (SPEC 13, beamstops_lockstep): every member of a group run in lockstep
!> equals the same scene run alone (simulate, the one-scene fused path) bit for bit: every
!> column of every record, every snapshot, the summary. Groups of K = 1, 3, 5, 8, 13 (not
!> multiples of the vector width) whose members differ in omega, amplitude, tip stops, load
!> rule, start and record cadences; without contact, with Signorini stops and with
!> compliance; runs long enough to cross blocks (block_steps), load restarts and contacts.
!> The summaries too: counts, the energy ledger, the shock log and the statistics tables.
!> Groups that cannot share A are refused with a message naming the member and the key.
module test_lockstep
   use, intrinsic :: iso_fortran_env, only: int64
   use testing
   use beamstops, only: ik, scene_type, model_type, array_recorder, run_summary, validate_scene, prepare_run, &
      & simulate, record_count, snapshot_count, law_none, law_signorini, law_compliance, status_complete, &
      & prepare_lockstep, simulate_lockstep
   use beamstops_recorder, only: n_columns
   use beamstops_ensemble, only: perturbation_of, run_members
   use beamstops_observe_statistics, only: statistics_table, ensemble_table
   use beamstops_scheme, only: start_state, run_scheme
   use beamstops_state, only: state_type
   use beamstops_model, only: build_model
   use beamstops_band, only: band_matvec
   use beamstops_band_solve, only: band_solver, band_diagonals, prepare_solver, prepare_diagonals, diagonal_matvec, &
      & forward_substitution, forward_substitution_energy, energy_dots, back_substitution, dot, &
      & back_substitution_edge, back_substitution_update, load_work_product
   use beamstops_band_solve_lockstep, only: lockstep_lanes, lockstep_work_columns, lockstep_matvec, &
      & lockstep_forward, lockstep_energy_dots, lockstep_back, lockstep_dot, lockstep_update, lockstep_back_edge, &
      & lockstep_back_update, lockstep_matvec_rhs, lockstep_periodic_rows, lockstep_matvec_rhs_forward, lockstep_load_work
   use beamstops_band_solve_lockstep_narrow, only: narrow_forward_rows, narrow_back_rows, narrow_back_update_rows, &
      & narrow_periodic_rows, narrow_matvec_rhs_forward_rows
   use beamstops_band_solve_lockstep_wide, only: wide_forward_rows, wide_back_rows, wide_back_update_rows, &
      & wide_periodic_rows, wide_matvec_rhs_forward_rows
   use beamstops_machine, only: vector_registers
   use beamstops_contact_tip_contact, only: update
   use test_support, only: base_scene
   implicit none
   private
   public :: collect_lockstep
   ! the helpers of the suite lockstep_general (damping, restitution, mass redistribution)
   public :: members_of, compare_group, expect_refusal, compare_run_members, check_failing_member, &
      & same_bits, same_summary, same_records
   ! and of the suite lockstep_span (stops along the span)
   public :: compare_members

   !> The meshes (J) of the kernel tests: every J from the smallest lockstep handles to 13 (each
   !> remainder of the three-row turns and of the eight-row sums), the paper's 19, 20, 100, 101.
   integer, parameter :: kernel_meshes(14) = [4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 19, 20, 100, 101]

   !> Columns of a record, for messages.
   character(len=10), parameter :: column_names(n_columns) = [character(len=10) :: 't', 'u', 'v', 'reaction', &
      & 'energy', 'work', 'dissipated', 'damped']

contains

   !> Tests of the suite.
   subroutine collect_lockstep(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('kernels: each lane equals the one-member kernel to the bit, J = 4..13, 19, 20, 100, 101', &
         & test_kernels), &
         & new_unittest('kernel shapes: the wide rows (32 vector registers) and the narrow ones (16) give the same '// &
         & 'bits, J = 4..13, 19, 20, 100, 101', test_kernel_shapes), &
         & new_unittest('energy sums: each lane equals energy_dots to the bit and the dot products to round-off, '// &
         & 'n = 1..25, a band of random values', test_energy_sums), &
         & new_unittest('K = 1, Signorini, beta = 1/2', test_one), &
         & new_unittest('K = 3, no stops, beta = 1/4, different omega and amplitude', test_free_three), &
         & new_unittest('K = 3, 6, 9, no stops, beta = 0.3, J = 5, different omega and amplitude', test_free_three_beta), &
         & new_unittest('K = 5, Signorini, beta = 1/2, different stops, omega, amplitude, cadences', test_signorini_five), &
         & new_unittest('K = 8, compliance 1e8, beta = 1/4', test_compliance_eight), &
         & new_unittest('K = 13, Signorini, beta = 1/4, paper''s load and Euler start for some, checkpoint_every set', &
         & test_signorini_thirteen), &
         & new_unittest('K = 8, J = 100, Signorini, beta = 1/2', test_fine_eight), &
         & new_unittest('a member whose recorder fails stops; the others go on, still bit for bit', test_failing_member), &
         & new_unittest('K = 6 ensemble members (perturbed initial displacements), Signorini: each as run alone', &
         & test_ensemble), &
         & new_unittest('&ensemble members = 6: run_members (in lockstep) gives the table of the members run '// &
         & 'one after the other', test_run_members), &
         & new_unittest('members that do not share A are refused', test_refused) &
         & ]
   end subroutine collect_lockstep

   !> K members of a base scene, member k varied by k: omega, amplitude, stops, cadences; the
   !> load rule and the start of some members switched when `vary_rules`.
   function members_of(base, k_members, vary_rules) result(scenes)
      type(scene_type), intent(in) :: base
      integer, intent(in) :: k_members
      logical, intent(in) :: vary_rules
      type(scene_type) :: scenes(k_members)
      integer :: k
      real(wp) :: s
      do k = 1, k_members
         scenes(k) = base
         s = real(k - 1, wp)/max(1, k_members - 1)
         if (k_members > 1) then
            scenes(k)%omega = 8.0_wp + 6.0_wp*s
            scenes(k)%amplitude = 0.25_wp - 0.1_wp*s
            scenes(k)%lower = -0.08_wp - 0.04_wp*mod(k, 3)
            scenes(k)%upper = 0.07_wp + 0.05_wp*s
         end if
         scenes(k)%record_every = 1 + mod(k - 1, 4)*2
         scenes(k)%snapshot_every = merge(0, 97*k, mod(k, 3) == 0)
         if (vary_rules) then
            scenes(k)%centered_load = mod(k, 2) == 1
            scenes(k)%taylor_start = mod(k, 4) /= 2
         end if
      end do
   end function members_of

   !> Run the members in lockstep and each alone; compare them to the bit. With `contact`, some
   !> member must have hit a stop.
   subroutine compare_group(scenes, error, contact)
      type(scene_type), intent(in) :: scenes(:)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: contact
      type(run_summary) :: summaries(size(scenes))
      call compare_members(scenes, summaries, error)
      if (allocated(error)) return
      if (present(contact)) then
         if (contact) call check(error, sum(summaries%impacts) > 0, 'some member hit a stop (impacts: '// &
            & int_text(sum(summaries%impacts))//')')
      end if
   end subroutine compare_group

   !> Run the members in lockstep and each alone; compare them to the bit: status, summary,
   !> records, snapshots and, with `stops`, the records of the stops along the span.
   subroutine compare_members(scenes, summaries, error, stops)
      type(scene_type), intent(in) :: scenes(:)
      !> The lockstep run's summaries.
      type(run_summary), intent(out) :: summaries(:)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: stops
      type(array_recorder), allocatable :: group(:)
      type(array_recorder) :: alone
      type(run_summary) :: summary
      type(model_type) :: model
      integer :: k, nk
      character(len=:), allocatable :: who

      nk = size(scenes)
      do k = 1, nk
         call validate_scene(scenes(k), 'member '//int_text(k), error)
         if (allocated(error)) return
      end do
      call prepare_lockstep(scenes, 'test group', model, error)
      if (allocated(error)) return
      allocate (group(nk))
      do k = 1, nk
         call reserve(group(k), scenes(k), stops)
      end do
      call simulate_lockstep(scenes, model, group, summaries, error)
      if (allocated(error)) return
      do k = 1, nk
         who = 'member '//int_text(k)//' of '//int_text(nk)
         call run_alone(scenes(k), alone, summary, error, stops)
         if (allocated(error)) return
         call check(error, summaries(k)%status == status_complete .and. summary%status == status_complete, &
            & who//': both runs complete ('//summaries(k)%status//', '//summary%status//')')
         if (allocated(error)) return
         call same_summary(summaries(k), summary, who, error)
         if (allocated(error)) return
         call same_records(group(k), alone, who, error)
         if (allocated(error)) return
         if (.not. with_stops(stops)) cycle
         call check(error, group(k)%stops_filled == alone%stops_filled .and. alone%stops_filled == alone%filled, &
            & who//': '//int_text(group(k)%stops_filled)//' and '//int_text(alone%stops_filled)//' records of the stops')
         if (allocated(error)) return
         call check(error, all(same_bits(group(k)%stops_u, alone%stops_u)) .and. &
            & all(same_bits(group(k)%stops_reaction, alone%stops_reaction)), who//': the stops'' records')
         if (allocated(error)) return
      end do
   end subroutine compare_members

   !> Whether the optional `stops` is present and true.
   pure function with_stops(stops) result(yes)
      logical, intent(in), optional :: stops
      logical :: yes
      yes = .false.
      if (present(stops)) yes = stops
   end function with_stops

   !> Room for every record and snapshot of a scene (with `stops`, for the records of its stops
   !> along the span too).
   subroutine reserve(rec, scene, stops)
      type(array_recorder), intent(inout) :: rec
      type(scene_type), intent(in) :: scene
      logical, intent(in), optional :: stops
      if (with_stops(stops)) then
         call rec%reserve(record_count(scene), snapshot_count(scene), scene%elements + 1, size(scene%stop_nodes))
      else
         call rec%reserve(record_count(scene), snapshot_count(scene), scene%elements + 1)
      end if
   end subroutine reserve

   !> The scene run alone: prepare_run and simulate (the one-scene fused path; advance_span with
   !> stops along the span), every record kept (`stops`: as reserve).
   subroutine run_alone(scene, rec, summary, error, stops)
      type(scene_type), intent(in) :: scene
      type(array_recorder), intent(out) :: rec
      type(run_summary), intent(out) :: summary
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: stops
      type(model_type) :: model
      call prepare_run(scene, 'test scene', model, error)
      if (allocated(error)) return
      call reserve(rec, scene, stops)
      call simulate(scene, model, rec, summary, error)
   end subroutine run_alone

   !> The summaries agree (but for the CPU time).
   subroutine same_summary(a, b, who, error)
      type(run_summary), intent(in) :: a, b
      character(len=*), intent(in) :: who
      type(error_type), allocatable, intent(out) :: error
      call check(error, a%steps == b%steps .and. a%impacts == b%impacts, who//': steps '//int_text(a%steps)//' and '// &
         & int_text(b%steps)//', impacts '//int_text(a%impacts)//' and '//int_text(b%impacts))
      if (allocated(error)) return
      call check(error, same_bits(a%max_violation, b%max_violation), who//': max_violation '// &
         & real_text(a%max_violation)//' and '//real_text(b%max_violation))
      if (allocated(error)) return
      call check(error, same_bits(a%t_final, b%t_final), who//': t_final')
      if (allocated(error)) return
      call check(error, a%contact_phases == b%contact_phases .and. same_bits(a%work, b%work) .and. &
         & same_bits(a%dissipated, b%dissipated) .and. same_bits(a%damped, b%damped) .and. &
         & same_bits(a%energy_residual, b%energy_residual), who//': the ledger (work '//real_text(a%work)//' and '// &
         & real_text(b%work)//', residual '//real_text(a%energy_residual)//' and '//real_text(b%energy_residual)//')')
      if (allocated(error)) return
      call same_observations(a, b, who, error)
   end subroutine same_summary

   !> The shock logs and the statistics tables of two summaries, bit for bit.
   subroutine same_observations(a, b, who, error)
      type(run_summary), intent(in) :: a, b
      character(len=*), intent(in) :: who
      type(error_type), allocatable, intent(out) :: error
      integer :: q
      call check(error, allocated(a%shocks) .eqv. allocated(b%shocks), who//': shock logs kept alike')
      if (allocated(error)) return
      if (allocated(a%shocks)) then
         call check(error, all(shape(a%shocks) == shape(b%shocks)), who//': '//int_text(size(a%shocks, 2))//' and '// &
            & int_text(size(b%shocks, 2))//' shocks')
         if (allocated(error)) return
         call check(error, all(same_bits(a%shocks, b%shocks)), who//': the shock log')
         if (allocated(error)) return
      end if
      call check(error, allocated(a%statistics%quantity) .eqv. allocated(b%statistics%quantity), &
         & who//': statistics kept alike')
      if (allocated(error) .or. .not. allocated(a%statistics%quantity)) return
      call check(error, size(a%statistics%quantity) == size(b%statistics%quantity), who//': statistics tables')
      if (allocated(error)) return
      do q = 1, size(a%statistics%quantity)
         associate (x => a%statistics%quantity(q), y => b%statistics%quantity(q))
            call check(error, x%name == y%name .and. size(x%value) == size(y%value), who//': statistic '//x%name)
            if (allocated(error)) return
            call check(error, all(same_bits(x%value, y%value)) .and. all(same_bits(x%half_width, y%half_width)), &
               & who//': statistic '//x%name//' (value and half-width)')
            if (allocated(error)) return
         end associate
      end do
   end subroutine same_observations

   !> Every record and snapshot, bit for bit.
   subroutine same_records(a, b, who, error)
      type(array_recorder), intent(in) :: a, b
      character(len=*), intent(in) :: who
      type(error_type), allocatable, intent(out) :: error
      integer(ik) :: i
      integer :: c
      call check(error, a%filled == b%filled .and. a%snaps == b%snaps, who//': '//int_text(a%filled)//' and '// &
         & int_text(b%filled)//' records, '//int_text(a%snaps)//' and '//int_text(b%snaps)//' snapshots')
      if (allocated(error)) return
      do i = 1, a%filled
         do c = 1, n_columns
            if (same_bits(a%rows(c, i), b%rows(c, i))) cycle
            call test_failed(error, who//': record '//int_text(i)//' (t = '//real_text(b%rows(1, i))//'), column '// &
               & trim(column_names(c))//': lockstep '//real_text(a%rows(c, i))//', alone '//real_text(b%rows(c, i)))
            return
         end do
      end do
      do i = 1, a%snaps
         if (.not. same_bits(a%snap_t(i), b%snap_t(i)) .or. &
            & any(transfer(a%snap_u(:, i), 1_int64, size(a%snap_u, 1)) /= &
            & transfer(b%snap_u(:, i), 1_int64, size(b%snap_u, 1)))) then
            call test_failed(error, who//': snapshot '//int_text(i)//' (t = '//real_text(b%snap_t(i))//') differs')
            return
         end if
      end do
      call check(error, a%filled > 0, who//': records were kept')
   end subroutine same_records

   !> Two reals with the same bits.
   elemental function same_bits(a, b) result(same)
      real(wp), intent(in) :: a, b
      logical :: same
      same = transfer(a, 1_int64) == transfer(b, 1_int64)
   end function same_bits

   !> lockstep_energy_dots against energy_dots (src/beamstops/energy_rows.c) on every n from 1 to
   !> 25: the first and last rows under a mask, lanes with no row (n < 8), one or more whole turns.
   !> A band of random values (of either sign) in place of M; u, d and su random. Each lane's three
   !> sums equal energy_dots's to the bit, and the exact sums to n eps times the sums of the terms'
   !> magnitudes.
   subroutine test_energy_sums(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: lanes = lockstep_lanes
      type(band_diagonals) :: m
      real(wp), allocatable :: u(:, :), d(:, :), su(:, :), full(:, :)
      real(wp) :: usu(lanes), dsu(lanes), dmd(lanes), e(3), f(3), g(3)
      integer :: n, k, i, j, rep
      character(len=:), allocatable :: where
      do n = 1, 25
         where = 'n = '//int_text(n)//': '
         m%n = n
         if (allocated(m%a)) deallocate (m%a, u, d, su, full)
         allocate (m%a(n, 0:3), u(lanes, n), d(lanes, n), su(lanes, n), full(n, n))
         do rep = 1, 5
            call random_number(m%a)
            call random_number(u)
            call random_number(d)
            call random_number(su)
            m%a = m%a - 0.5_wp
            d = d - 0.5_wp
            su = su - 0.5_wp
            ! the symmetric matrix of the band: m%a(j, k) is row j - k, column j
            full = 0
            do j = 1, n
               full(j, j) = m%a(j, 0)
               do i = max(1, j - 3), j - 1
                  full(i, j) = m%a(j, j - i)
                  full(j, i) = m%a(j, j - i)
               end do
            end do
            call lockstep_energy_dots(m, u, d, su, usu, dsu, dmd)
            do k = 1, lanes
               call energy_dots(m, u(k, :), d(k, :), su(k, :), e(1), e(2), e(3))
               if (.not. (same_bits(e(1), usu(k)) .and. same_bits(e(2), dsu(k)) .and. same_bits(e(3), dmd(k)))) then
                  call test_failed(error, where//'lane '//int_text(k)//' is not energy_dots''s sums to the bit')
                  return
               end if
               f = [dot_product(u(k, :), su(k, :)), dot_product(d(k, :), su(k, :)), dot_product(d(k, :), matmul(full, d(k, :)))]
               g = [dot_product(abs(u(k, :)), abs(su(k, :))), dot_product(abs(d(k, :)), abs(su(k, :))), &
                  & dot_product(abs(d(k, :)), matmul(abs(full), abs(d(k, :))))]
               if (any(abs(f - e) > 8*n*epsilon(1.0_wp)*g)) then
                  call test_failed(error, where//'lane '//int_text(k)//': the sums are not the dot products')
                  return
               end if
            end do
         end do
      end do
   end subroutine test_energy_sums

   !> The paper's scene with `elements` elements and dt = 1e-5 s, its model, the factor of A as a
   !> band_solver and S by diagonals: what the kernel tests run on.
   subroutine kernel_model(elements, model, solver, s, error)
      integer, intent(in) :: elements
      type(model_type), intent(out) :: model
      type(band_solver), intent(out) :: solver
      type(band_diagonals), intent(out) :: s
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene%elements = elements
      scene%dt = 1.0e-5_wp
      call build_model(scene, model, error)
      if (allocated(error)) return
      call prepare_solver(model%factor, solver)
      call prepare_diagonals(model%stiffness, s)
   end subroutine kernel_model

   !> The kernels of beamstops_band_solve_lockstep against those of beamstops_band_solve, lane by
   !> lane, on random vectors: the product by S, both substitutions (with and without the
   !> energy sums), the dot product, the update. The place to look first when the one-scene
   !> path or the compiler changes: the lockstep kernels reproduce where the compiled
   !> one-member kernels round (see the notes of beamstops_band_solve_lockstep).
   subroutine test_kernels(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: meshes(14) = kernel_meshes
      integer, parameter :: lanes = lockstep_lanes
      type(scene_type) :: scene
      type(model_type) :: model
      type(band_solver) :: solver
      type(band_diagonals) :: s, m
      real(wp), allocatable :: x(:, :), y(:, :), b(:, :), u(:, :), d(:, :), ub(:, :), v(:), w(:), uk(:)
      real(wp) :: work(lanes, lockstep_work_columns), usu(lanes), dsu(lanes), dmd(lanes), dd(lanes), c(lanes)
      real(wp) :: e(3), f(3), g(3), rows(7, 2)
      real(wp), allocatable :: w2(:, :)
      logical :: periodic
      integer :: a, rep, k, n
      character(len=:), allocatable :: where
      do a = 1, size(meshes)
         call kernel_model(meshes(a), model, solver, s, error)
         if (allocated(error)) return
         call prepare_diagonals(model%mass, m)
         n = model%n
         if (allocated(x)) deallocate (x, y, b, u, d, ub, v, w, uk, w2)
         allocate (x(lanes, n), y(lanes, n), b(lanes, n), u(lanes, n), d(lanes, n), ub(lanes, n), v(n), w(n), uk(n), &
            & w2(lanes, n))
         do rep = 1, 20
            call random_number(x)
            call random_number(u)
            call random_number(d)
            call random_number(c)
            x = x - 0.5_wp
            u = u - 0.5_wp
            d = d - 0.5_wp
            where = 'J = '//int_text(meshes(a))//': '
            call lockstep_matvec(s, x, y)
            do k = 1, lanes
               call diagonal_matvec(s, x(k, :), v)
               if (.not. all(same_bits(v, y(k, :)))) call test_failed(error, where//'S x, lane '//int_text(k))
            end do
            ! the product by S with the interior rows' coefficients kept in registers: a uniform
            ! mesh's S has period-2 interior rows, and the kernel gives lockstep_matvec_rhs's bits
            call lockstep_periodic_rows(s, periodic, rows)
            if (.not. periodic) call test_failed(error, where//'the interior rows of S repeat with period 2')
            call lockstep_matvec_rhs(s, x, c, u, 1.0e-10_wp, d(:, 1), y, b)
            call lockstep_matvec_rhs(s, x, c, u, 1.0e-10_wp, d(:, 1), ub, w2, rows)
            if (.not. (all(same_bits(y, ub)) .and. all(same_bits(b, w2)))) &
               & call test_failed(error, where//'S x and the right-hand side with period-2 rows')
            ! the product and the forward substitution in one pass: the two kernels' bits
            call lockstep_forward(solver, b)
            call lockstep_matvec_rhs_forward(s, solver, rows, x, c, u, 1.0e-10_wp, d(:, 1), ub, w2)
            if (.not. (all(same_bits(y, ub)) .and. all(same_bits(b, w2)))) &
               & call test_failed(error, where//'S x and the forward substitution in one pass')
            b = x
            call lockstep_forward(solver, b)
            do k = 1, lanes
               v = x(k, :)
               call forward_substitution(solver, v)
               if (.not. all(same_bits(v, b(k, :)))) call test_failed(error, where//'forward substitution, lane '//int_text(k))
            end do
            b = x
            call lockstep_back(solver, b)
            do k = 1, lanes
               v = x(k, :)
               call back_substitution(solver, v)
               if (.not. all(same_bits(v, b(k, :)))) call test_failed(error, where//'back substitution, lane '//int_text(k))
            end do
            call lockstep_energy_dots(m, u, d, y, usu, dsu, dmd)
            do k = 1, lanes
               call energy_dots(m, u(k, :), d(k, :), y(k, :), e(1), e(2), e(3))
               if (.not. same_bits(e(1), usu(k))) call test_failed(error, where//'u.S u, lane '//int_text(k))
               if (.not. same_bits(e(2), dsu(k))) call test_failed(error, where//'d.S u, lane '//int_text(k))
               if (.not. same_bits(e(3), dmd(k))) call test_failed(error, where//'d.M d, lane '//int_text(k))
               ! the sums themselves: dot products, to round-off (n eps times the sums of |terms|)
               call band_matvec(model%mass, d(k, :), w)
               f = [dot_product(u(k, :), y(k, :)), dot_product(d(k, :), y(k, :)), dot_product(d(k, :), w)]
               call band_matvec(abs(model%mass), abs(d(k, :)), w)
               g = [dot_product(abs(u(k, :)), abs(y(k, :))), dot_product(abs(d(k, :)), abs(y(k, :))), &
                  & dot_product(abs(d(k, :)), w)]
               if (any(abs(f - e) > 4*n*epsilon(1.0_wp)*g)) call test_failed(error, where//'energy sums against '// &
                  & 'dot products, lane '//int_text(k))
               ! the sums taken halfway down the forward substitution: the bits of the two apart
               v = x(k, :)
               w = x(k, :)
               call forward_substitution(solver, v)
               call forward_substitution_energy(solver, m, u(k, :), d(k, :), y(k, :), w, f(1), f(2), f(3))
               if (.not. (all(same_bits(v, w)) .and. all(same_bits(f, e)))) call test_failed(error, where// &
                  & 'forward substitution with the energy sums, lane '//int_text(k))
            end do
            call lockstep_dot(n, u, d, work, dd)
            do k = 1, lanes
               if (.not. same_bits(dot(u(k, :), d(k, :)), dd(k))) call test_failed(error, where//'dot, lane '//int_text(k))
               if (abs(dd(k) - sum(u(k, :)*d(k, :))) > n*epsilon(1.0_wp)*sum(abs(u(k, :)*d(k, :)))) &
                  & call test_failed(error, where//'dot against the sum of its terms, lane '//int_text(k))
            end do
            b = d
            y = u
            call lockstep_update(n, x, c, model%z, b, y)
            do k = 1, lanes
               v = d(k, :) + x(k, :) + c(k)*model%z
               w = u(k, :) + v
               if (.not. (all(same_bits(v, b(k, :))) .and. all(same_bits(w, y(k, :))))) &
                  & call test_failed(error, where//'update, lane '//int_text(k))
            end do
            ! the back substitution with the update riding on it: back substitution, then update
            b = x
            call lockstep_back_edge(solver, b)
            y = d
            ub = u
            ! (with g.d^n taken on the way: w2 stands for the load vectors)
            call random_number(w2)
            call lockstep_back_update(solver, b, c, model%z, w2, y, ub, dd)
            do k = 1, lanes
               v = x(k, :)
               call back_substitution(solver, v)
               w = d(k, :)
               uk = u(k, :)
               call update(v, c(k), model%z, w, uk)
               if (.not. (all(same_bits(w, y(k, :))) .and. all(same_bits(uk, ub(k, :))))) &
                  & call test_failed(error, where//'back substitution with the update, d and u, lane '//int_text(k))
               if (.not. same_bits(load_work_product(w2(k, :), w), dd(k))) &
                  & call test_failed(error, where//'g.d taken by the back substitution, lane '//int_text(k))
               ! and the one-member version of it (advance_fused's)
               call same_back_update(solver, model%z, x(k, :), c(k), w2(k, :), d(k, :), u(k, :), where, error)
            end do
            ! g.d in the back substitution's order on its own (the general loop's), and that order
            ! against the sum itself, to round-off (n eps times the sum of |terms|)
            call lockstep_load_work(n, w2, y, dd)
            do k = 1, lanes
               if (.not. same_bits(load_work_product(w2(k, :), y(k, :)), dd(k))) &
                  & call test_failed(error, where//'g.d in the order of the back substitution, lane '//int_text(k))
               if (abs(dd(k) - sum(w2(k, :)*y(k, :))) > n*epsilon(1.0_wp)*sum(abs(w2(k, :)*y(k, :)))) &
                  & call test_failed(error, where//'g.d against the sum of its terms, lane '//int_text(k))
            end do
            if (allocated(error)) return
         end do
      end do
      ! the one-member back substitution with the update on meshes too small for lockstep
      scene%dt = 1.0e-5_wp
      do a = 1, 3
         scene%elements = a
         call build_model(scene, model, error)
         if (allocated(error)) return
         call prepare_solver(model%factor, solver)
         n = model%n
         deallocate (v, w, uk)
         allocate (v(n), w(n), uk(n))
         call random_number(v)
         call random_number(w)
         call random_number(uk)
         call same_back_update(solver, model%z, v - 0.5_wp, 0.3_wp, w + 1, w, uk, 'J = '//int_text(a)//': ', error)
         if (allocated(error)) return
      end do
   end subroutine test_kernels

   !> The two shapes of the lockstep kernels' inner rows (beamstops_band_solve_lockstep_wide for 32
   !> vector registers, beamstops_band_solve_lockstep_narrow for 16) on the same random inputs: the
   !> same bits, every output. The build runs one of them (beamstops_machine); test_kernels and
   !> the whole runs check that one against the one-scene path, and this test carries the check
   !> over to the other.
   subroutine test_kernel_shapes(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: lanes = lockstep_lanes
      type(model_type) :: model
      type(band_solver) :: solver
      type(band_diagonals) :: s
      real(wp), allocatable :: x(:, :), g(:, :), d(:, :), u(:, :), y(:, :, :), b(:, :, :), dd(:, :, :), uu(:, :, :)
      real(wp) :: c(lanes), a(lanes), spring(lanes), gd(lanes, 2), rows(7, 2)
      logical :: periodic
      integer :: m, rep, n
      character(len=:), allocatable :: where
      call check(error, vector_registers == 16 .or. vector_registers == 32, 'vector registers: 16 or 32, not '// &
         & int_text(vector_registers))
      if (allocated(error)) return
      do m = 1, size(kernel_meshes)
         call kernel_model(kernel_meshes(m), model, solver, s, error)
         if (allocated(error)) return
         call lockstep_periodic_rows(s, periodic, rows)
         n = model%n
         if (allocated(x)) deallocate (x, g, d, u, y, b, dd, uu)
         allocate (x(lanes, n), g(lanes, n), d(lanes, n), u(lanes, n), y(lanes, n, 2), b(lanes, n, 2), &
            & dd(lanes, n, 2), uu(lanes, n, 2))
         where = 'J = '//int_text(kernel_meshes(m))//': '
         do rep = 1, 10
            call random_number(x)
            call random_number(g)
            call random_number(d)
            call random_number(u)
            call random_number(c)
            call random_number(a)
            call random_number(spring)
            x = x - 0.5_wp
            d = d - 0.5_wp
            u = u - 0.5_wp
            b(:, :, 1) = x
            b(:, :, 2) = x
            call wide_forward_rows(n, solver%off, solver%inv_d2, b(:, :, 1))
            call narrow_forward_rows(n, solver%off, solver%inv_d2, b(:, :, 2))
            call same_shapes(b, where//'forward substitution', error)
            b(:, :, 1) = x
            b(:, :, 2) = x
            call wide_back_rows(n, solver%off, b(:, :, 1))
            call narrow_back_rows(n, solver%off, b(:, :, 2))
            call same_shapes(b, where//'back substitution', error)
            dd(:, :, 1) = d
            dd(:, :, 2) = d
            uu(:, :, 1) = u
            uu(:, :, 2) = u
            call wide_back_update_rows(n, solver%off, x, c, model%z, g, dd(:, :, 1), uu(:, :, 1), gd(:, 1))
            call narrow_back_update_rows(n, solver%off, x, c, model%z, g, dd(:, :, 2), uu(:, :, 2), gd(:, 2))
            call same_shapes(dd, where//'back substitution with the update, d', error)
            call same_shapes(uu, where//'back substitution with the update, u', error)
            call check(error, all(same_bits(gd(:, 1), gd(:, 2))), where//'g.d taken with the back substitution')
            if (allocated(error)) return
            y = 0
            b = 0
            call wide_periodic_rows(n, rows, x, a, g, 1.0e-10_wp, y(:, :, 1), b(:, :, 1))
            call narrow_periodic_rows(n, rows, x, a, g, 1.0e-10_wp, y(:, :, 2), b(:, :, 2))
            call same_shapes(y, where//'S x, period-2 rows', error)
            call same_shapes(b, where//'the right-hand side, period-2 rows', error)
            call wide_matvec_rhs_forward_rows(n, s%a, solver%off, solver%inv_d2, rows, x, a, g, 1.0e-10_wp, spring, &
               & y(:, :, 1), b(:, :, 1))
            call narrow_matvec_rhs_forward_rows(n, s%a, solver%off, solver%inv_d2, rows, x, a, g, 1.0e-10_wp, spring, &
               & y(:, :, 2), b(:, :, 2))
            call same_shapes(y, where//'S x of the product with the forward substitution', error)
            call same_shapes(b, where//'the product with the forward substitution', error)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_kernel_shapes

   !> Fails unless the two shapes' outputs v(:, :, 1) and v(:, :, 2) are the same bits.
   subroutine same_shapes(v, what, error)
      real(wp), intent(in) :: v(:, :, :)
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(inout) :: error
      if (allocated(error)) return
      if (.not. all(same_bits(v(:, :, 1), v(:, :, 2)))) call test_failed(error, what//': the wide and narrow '// &
         & 'shapes differ')
   end subroutine same_shapes

   !> back_substitution_edge then back_substitution_update (x not stored, the update riding on
   !> the substitution) against back_substitution then update: d and u to the bit, and g.d^n
   !> as load_work_product takes it.
   subroutine same_back_update(solver, z, b, c, g, d, u, where, error)
      type(band_solver), intent(in) :: solver
      real(wp), intent(in) :: z(:), b(:), c, g(:), d(:), u(:)
      character(len=*), intent(in) :: where
      type(error_type), allocatable, intent(inout) :: error
      real(wp) :: x(size(b)), d1(size(b)), u1(size(b)), d2(size(b)), u2(size(b)), gd
      x = b
      call back_substitution(solver, x)
      d1 = d
      u1 = u
      call update(x, c, z, d1, u1)
      x = b
      d2 = d
      u2 = u
      call back_substitution_edge(solver, x)
      call back_substitution_update(solver, x, c, z, g, d2, u2, gd)
      if (.not. (all(same_bits(d1, d2)) .and. all(same_bits(u1, u2)))) &
         & call test_failed(error, where//'one-member back substitution with the update, d and u')
      if (.not. same_bits(load_work_product(g, d1), gd)) &
         & call test_failed(error, where//'one-member back substitution with the update, g.d')
   end subroutine same_back_update

   subroutine test_one(error)
      type(error_type), allocatable, intent(out) :: error
      call compare_group(members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.2_wp), 1, .false.), error, &
         & contact=.true.)
   end subroutine test_one

   subroutine test_free_three(error)
      type(error_type), allocatable, intent(out) :: error
      call compare_group(members_of(base_scene(19, 1.0e-5_wp, 0.25_wp, law_none, 0.2_wp), 3, .true.), error)
   end subroutine test_free_three

   !> beta = 0.3: its products beta*x round (at 1/4 and 1/2 they are exact), so the members'
   !> load averages and energies must be formed as the one-scene path forms them to the bit.
   subroutine test_free_three_beta(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      do k = 3, 9, 3
         call compare_group(members_of(base_scene(5, 1.0e-5_wp, 0.3_wp, law_none, 0.2_wp), k, .true.), error)
         if (allocated(error)) return
      end do
   end subroutine test_free_three_beta

   subroutine test_signorini_five(error)
      type(error_type), allocatable, intent(out) :: error
      call compare_group(members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.25_wp), 5, .false.), error, &
         & contact=.true.)
   end subroutine test_signorini_five

   subroutine test_compliance_eight(error)
      type(error_type), allocatable, intent(out) :: error
      call compare_group(members_of(base_scene(19, 4.0e-6_wp, 0.25_wp, law_compliance, 0.15_wp), 8, .true.), error, &
         & contact=.true.)
   end subroutine test_compliance_eight

   subroutine test_signorini_thirteen(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type), allocatable :: scenes(:)
      integer :: k
      scenes = members_of(base_scene(13, 2.0e-5_wp, 0.25_wp, law_signorini, 0.3_wp), 13, .true.)
      do k = 1, size(scenes)
         scenes(k)%checkpoint_every = 5000
      end do
      call compare_group(scenes, error, contact=.true.)
   end subroutine test_signorini_thirteen

   subroutine test_fine_eight(error)
      type(error_type), allocatable, intent(out) :: error
      call compare_group(members_of(base_scene(100, 4.0e-6_wp, 0.5_wp, law_signorini, 0.12_wp), 8, .false.), error, &
         & contact=.true.)
   end subroutine test_fine_eight

   !> K = 3, member 2 records every third step into room for 3000 rows: member 2 ends 'failed' after the block in which its
   !> recorder failed (as the same scene alone), members 1 and 3 complete and equal their runs
   !> alone.
   subroutine test_failing_member(error)
      type(error_type), allocatable, intent(out) :: error
      call check_failing_member(members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.25_wp), 3, .false.), &
         & error)
   end subroutine test_failing_member

   !> test_failing_member on three given members: member 2's 3000 records fill up within the
   !> loop's second block (as with t_end 0.25 s at dt = 1e-5 s); `stops`: as reserve.
   subroutine check_failing_member(scenes, error, stops)
      type(scene_type), intent(in) :: scenes(3)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: stops
      type(array_recorder) :: group(3), alone
      type(run_summary) :: summaries(3), summary
      type(model_type) :: model
      integer :: k
      do k = 1, 3
         call validate_scene(scenes(k), 'member '//int_text(k), error)
         if (allocated(error)) return
      end do
      call prepare_lockstep(scenes, 'test group', model, error)
      if (allocated(error)) return
      do k = 1, 3
         call reserve(group(k), scenes(k), stops)
      end do
      deallocate (group(2)%rows)
      allocate (group(2)%rows(n_columns, 3000))
      call simulate_lockstep(scenes, model, group, summaries, error)
      if (allocated(error)) return
      call check(error, summaries(2)%status == 'failed' .and. summaries(2)%steps == 16384, &
         & 'member 2 failed at the end of its second block: '//summaries(2)%status//' after '// &
         & int_text(summaries(2)%steps)//' steps')
      if (allocated(error)) return
      do k = 1, 3, 2
         call run_alone(scenes(k), alone, summary, error, stops)
         if (allocated(error)) return
         call check(error, summaries(k)%status == status_complete, 'member '//int_text(k)//' completes')
         if (allocated(error)) return
         call same_summary(summaries(k), summary, 'member '//int_text(k), error)
         if (allocated(error)) return
         call same_records(group(k), alone, 'member '//int_text(k), error)
         if (allocated(error)) return
      end do
   end subroutine check_failing_member

   !> The members of an &ensemble (ensemble.f90: model%u0 plus perturbation_of(delta, seed, k)),
   !> in lockstep through the initial displacements, against each run alone on a model with that
   !> u0 (what run_members does).
   subroutine test_ensemble(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: nk = 6
      type(scene_type) :: scenes(nk)
      type(array_recorder) :: group(nk), alone(nk)
      type(run_summary) :: summaries(nk), summary
      type(model_type) :: model, member_model
      real(wp), allocatable :: u0(:, :)
      integer :: k
      scenes = base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.3_wp)
      call prepare_lockstep(scenes, 'test group', model, error)
      if (allocated(error)) return
      allocate (u0(model%n, nk))
      do k = 1, nk
         u0(:, k) = model%u0 + perturbation_of(1.0e-4_wp, 7, k, model%n)
         call reserve(group(k), scenes(k))
      end do
      call simulate_lockstep(scenes, model, group, summaries, error, initial_displacement=u0)
      if (allocated(error)) return
      do k = 1, nk
         member_model = model
         member_model%u0 = u0(:, k)
         call reserve(alone(k), scenes(k))
         call simulate(scenes(k), member_model, alone(k), summary, error)
         if (allocated(error)) return
         call same_summary(summaries(k), summary, 'ensemble member '//int_text(k), error)
         if (allocated(error)) return
         call same_records(group(k), alone(k), 'ensemble member '//int_text(k), error)
         if (allocated(error)) return
      end do
      call check(error, any(group(1)%rows(2, :group(1)%filled) /= group(2)%rows(2, :group(2)%filled)), &
         & 'the members differ')
   end subroutine test_ensemble

   !> run_members (ensemble.f90, members 2..K in lockstep) against the members run one after the
   !> other as it ran them before (start_state + run_scheme on a model with the perturbed u0, no
   !> records): the same ensemble table, bit for bit.
   subroutine test_run_members(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene = base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.3_wp)
      scene%members = 6
      scene%perturbation = 1.0e-4_wp
      scene%seed = 3
      call compare_run_members(scene, error)
   end subroutine test_run_members

   !> run_members of `scene` (&ensemble members = 6) against its members run one after the other:
   !> the same ensemble table, bit for bit.
   subroutine compare_run_members(scene, error)
      type(scene_type), intent(in) :: scene
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: member_scene
      type(model_type) :: model, member_model
      type(array_recorder) :: rec
      type(array_recorder) :: quiet
      type(run_summary) :: summary, member
      type(state_type) :: state
      type(statistics_table) :: tables(6), reference
      integer :: k
      call prepare_run(scene, 'test ensemble', model, error)
      if (allocated(error)) return
      call reserve(rec, scene)
      member_scene = scene
      member_scene%members = 1
      call simulate(member_scene, model, rec, summary, error)
      if (allocated(error)) return
      tables(1) = summary%statistics
      call run_members(scene, model, summary, error)
      if (allocated(error)) return
      member_scene%snapshot_every = 0
      member_scene%record_every = huge(1)
      call quiet%reserve(1_ik, 0_ik, scene%elements + 1)
      do k = 2, 6
         member_model = model
         member_model%u0 = model%u0 + perturbation_of(scene%perturbation, scene%seed, k, size(model%u0))
         quiet%filled = 0
         call start_state(member_scene, member_model, state, quiet, error)
         if (allocated(error)) return
         member = run_summary()
         call run_scheme(member_scene, member_model, state, quiet, member)
         call check(error, member%status == status_complete, 'member '//int_text(k)//' completes')
         if (allocated(error)) return
         tables(k) = member%statistics
      end do
      call ensemble_table(tables, reference, error)
      if (allocated(error)) return
      call check(error, summary%ensemble_members == 6, 'six members: '//int_text(summary%ensemble_members))
      if (allocated(error)) return
      call check(error, allocated(reference%quantity), 'an ensemble table')
      if (allocated(error)) return
      call check(error, size(reference%quantity) > 0, 'an ensemble table with quantities')
      if (allocated(error)) return
      block
         type(run_summary) :: a, b
         a%statistics = summary%ensemble
         b%statistics = reference
         call same_observations(a, b, 'the ensemble table', error)
      end block
   end subroutine compare_run_members

   !> Members that differ in what A depends on (damping: test_lockstep_general), in the law, in
   !> the steps, or with stops along the span where member 1 has none, are refused, the message naming the member and the key.
   subroutine test_refused(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scenes(3)
      type(model_type) :: model
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(3)%dt = 2.0e-5_wp
      call expect_refusal(scenes, 'member 3: &time dt', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(2)%elements = 20
      call expect_refusal(scenes, 'member 2: &mesh elements', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(2)%law = law_compliance
      scenes(2)%stiffness_per_mass = 1.0e8_wp
      call expect_refusal(scenes, 'member 2: &stops law', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(3)%k2 = 300.0_wp
      call expect_refusal(scenes, 'member 3: &beam k2', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(2)%t_end = 0.02_wp
      call expect_refusal(scenes, 'member 2: &time steps', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(2)%stop_nodes = [10, 19]
      scenes(2)%stop_lower = [-0.05_wp, -0.1_wp]
      scenes(2)%stop_upper = [0.05_wp, 0.1_wp]
      call expect_refusal(scenes, 'member 2: &stops nodes (or x) gives 2 stops along the span, member 1''s 0', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(2)%modes = 6
      call expect_refusal(scenes, 'member 2 is a reduced model', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(19, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      scenes(1)%damping_mass = 1.0_wp
      call expect_refusal(scenes, 'member 2: &damping mass_coefficient', error)
      if (allocated(error)) return
      scenes = members_of(base_scene(3, 1.0e-5_wp, 0.5_wp, law_signorini, 0.01_wp), 3, .false.)
      call expect_refusal(scenes, '&mesh elements = 3', error)
      if (allocated(error)) return
      call prepare_lockstep(scenes(1:0), 'test group', model, error)
      call check(error, allocated(error), 'an empty group is refused')
      if (allocated(error)) then
         if (index(error%message, 'no members') > 0) deallocate (error)
      end if
   end subroutine test_refused

   !> prepare_lockstep refuses the group with a message containing `expected`.
   subroutine expect_refusal(scenes, expected, error)
      type(scene_type), intent(in) :: scenes(:)
      character(len=*), intent(in) :: expected
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(error_type), allocatable :: refusal
      call prepare_lockstep(scenes, 'test group', model, refusal)
      if (.not. allocated(refusal)) then
         call test_failed(error, 'not refused: '//expected)
         return
      end if
      call check(error, index(refusal%message, expected) > 0, 'the message "'//refusal%message// &
         & '" names "'//expected//'"')
   end subroutine expect_refusal
end module test_lockstep
