!> Mass redistribution (SPEC 10): the matrix M^rho (zero rows and columns at the constrained
!> values, positive definite on the rest, mass and first and second moments kept, frequencies
!> still converging in h) and the scheme with it (no velocity jump at the tip, the stops' energy
!> -> 0, KKT every step, the energy balance, pointwise convergence through the first contact
!> period where the consistent mass shows none).
module test_redistribution
   use testing
   use test_support, only: run_recorded, band_eigenvalues
   use physics_support, only: open_run, step_once
   use beamstops, only: ik, scene_type, model_type, build_model, state_type, array_recorder, run_summary, &
      & steps_of, validate_scene
   use beamstops_band, only: kd, band_matvec, cholesky_factor
   use beamstops_hermite, only: element_mass
   use beamstops_contact_mass_redistribution, only: redistributed_element
   use beamstops_recorder, only: col_t, col_u, col_energy, col_work, col_dissipated, col_damped
   use beamstops_scheme, only: advance
   implicit none
   private
   public :: collect_redistribution

contains

   !> Tests of the suite.
   subroutine collect_redistribution(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('element: mass, first and second moments of the consistent element', test_element), &
         & new_unittest('M^rho (tip; span nodes 7, 19): zero rows, positive definite on the rest, moments kept', &
         &              test_matrix), &
         & new_unittest('frequencies of (S, M^rho) converge in h', test_frequencies), &
         & new_unittest('paper''s scene, beta = 1/4: KKT every step, no velocity jump of the unknowns with mass, balance', &
         &              test_kkt), &
         & new_unittest('the stops'' energy -> 0 as dt -> 0', test_stop_energy), &
         & new_unittest('tip converges on [0.08, 0.125] s (order >= 1.2), the consistent mass does not', &
         &              test_convergence), &
         & new_unittest('stops along the span (tube, interior nodes): balance and no violation', test_span), &
         & new_unittest('fused and reference paths agree (massless tip, with mass damping)', test_paths) &
         & ]
   end subroutine collect_redistribution

   !> v^T A w for a symmetric band matrix.
   function form(ab, v, w) result(s)
      real(wp), intent(in) :: ab(:, :), v(:), w(:)
      real(wp) :: s, aw(size(w))
      call band_matvec(ab, w, aw)
      s = dot_product(v, aw)
   end function form

   subroutine test_element(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: h = 0.3_wp
      real(wp) :: one(4), x(4), me(4, 4), mr(4, 4)
      character :: side
      integer :: k
      ! u = 1: values 1, slopes 0; u = x: values 0 and h, slopes 1
      one = [1.0_wp, 0.0_wp, 1.0_wp, 0.0_wp]
      x = [0.0_wp, 1.0_wp, h, 1.0_wp]
      me = element_mass(h)
      do k = 1, 2
         side = merge('R', 'L', k == 1)
         mr = redistributed_element(h, side)
         call check(error, dot_product(one, matmul(mr, one)), dot_product(one, matmul(me, one)), side//': mass', &
            & thr=1.0e-14_wp, rel=.true.)
         if (allocated(error)) return
         call check(error, dot_product(one, matmul(mr, x)), h**2/2, side//': first moment', thr=1.0e-14_wp, rel=.true.)
         if (allocated(error)) return
         call check(error, dot_product(x, matmul(mr, x)), h**3/3, side//': second moment', thr=1.0e-14_wp, rel=.true.)
         if (allocated(error)) return
         call check(error, maxval(abs(mr(merge(3, 1, k == 1), :))) == 0, side//': the constrained row is zero')
         if (allocated(error)) return
      end do
   end subroutine test_element

   !> M^rho of a scene against M: the rows of the massless values zero, positive definite once
   !> a unit diagonal replaces them, and 1.M 1, 1.M x, x.M x those of M.
   subroutine check_matrix(scene, what, error)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: plain
      type(model_type) :: consistent, model
      real(wp), allocatable :: one(:), x(:), reduced(:, :)
      integer :: i, k, j
      plain = scene
      plain%redistributed_mass = .false.
      call build_model(plain, consistent, error)
      if (allocated(error)) return
      call build_model(scene, model, error)
      if (allocated(error)) return
      allocate (one(model%n), x(model%n))
      one = 0
      one(1::2) = 1
      x(1::2) = consistent%x(2:)
      x(2::2) = 1
      call check(error, form(model%mass, one, one), form(consistent%mass, one, one), what//': mass', thr=1.0e-13_wp, &
         & rel=.true.)
      if (allocated(error)) return
      call check(error, form(model%mass, one, x), form(consistent%mass, one, x), what//': first moment', &
         & thr=1.0e-13_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, form(model%mass, x, x), form(consistent%mass, x, x), what//': second moment', &
         & thr=1.0e-13_wp, rel=.true.)
      if (allocated(error)) return
      reduced = model%mass
      do i = 1, size(model%massless)
         k = model%massless(i)
         do j = max(1, k - kd), min(model%n, k + kd)
            if (model%mass(kd + 1 + min(j, k) - max(j, k), max(j, k)) /= 0) then
               call test_failed(error, what//': entry ('//int_text(k)//', '//int_text(j)//') of M^rho is not zero')
               return
            end if
         end do
         reduced(kd + 1, k) = 1
      end do
      call cholesky_factor(reduced, 'M^rho with unit massless diagonal', error)
   end subroutine check_matrix

   subroutine test_matrix(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      scene%beta = 0.25_wp
      scene%redistributed_mass = .true.
      call check_matrix(scene, 'tip', error)
      if (allocated(error)) return
      scene%stop_nodes = [7, 19]
      scene%stop_lower = [-0.1_wp, -0.1_wp]
      scene%stop_upper = [0.1_wp, 0.1_wp]
      call check_matrix(scene, 'nodes 7 and 19', error)
   end subroutine test_matrix

   subroutine test_frequencies(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: beta_l(3) = [1.8751040687_wp, 4.6940911330_wp, 7.8547574382_wp]
      integer, parameter :: meshes(4) = [4, 8, 16, 32]
      type(scene_type) :: scene
      type(model_type) :: model
      real(wp) :: exact(3), err(3, 4), order
      integer :: i, m
      character(len=:), allocatable :: line
      scene%beta = 0.25_wp
      scene%redistributed_mass = .true.
      scene%law = 1
      exact = beta_l**2*sqrt(scene%k2)/scene%length**2
      do i = 1, size(meshes)
         scene%elements = meshes(i)
         call build_model(scene, model, error)
         if (allocated(error)) return
         call eigen(model, err(:, i), error)
         if (allocated(error)) return
         err(:, i) = abs(err(:, i)/exact - 1)
      end do
      do m = 1, 3
         line = 'mode '//int_text(m)//': relative error'
         do i = 1, size(meshes)
            line = line//' '//real_text(err(m, i))
         end do
         order = log(err(m, 3)/err(m, 4))/log(2.0_wp)
         call note(line//' (J = 4, 8, 16, 32); order '//real_text(order))
         call check(error, order > 1.8_wp, 'mode '//int_text(m)//': order in h')
         if (allocated(error)) return
         call check(error, err(m, 4) < 1.0e-3_wp, 'mode '//int_text(m)//': within 1e-3 at J = 32')
         if (allocated(error)) return
      end do
   contains
      subroutine eigen(model, w, error)
         type(model_type), intent(in) :: model
         real(wp), intent(out) :: w(3)
         type(error_type), allocatable, intent(out) :: error
         real(wp), allocatable :: kappa(:)
         ! (M^rho, S): mu = 1/kappa, the massless mode at mu = 0
         call band_eigenvalues(model%mass, model%stiffness, kappa, error)
         if (allocated(error)) return
         w = sqrt(1/kappa(size(kappa):size(kappa) - 2:-1))
      end subroutine eigen
   end subroutine test_frequencies

   !> The paper's scene up to t = 0.125 s (the first contact period), beta = 1/4, centred load,
   !> Taylor start.
   function first_period(dt, redistributed) result(scene)
      real(wp), intent(in) :: dt
      logical, intent(in) :: redistributed
      type(scene_type) :: scene
      scene%beta = 0.25_wp
      scene%dt = dt
      scene%t_end = 0.125_wp
      scene%record_every = nint(1.0e-5_wp/dt)
      scene%redistributed_mass = redistributed
   end function first_period

   !> Stepped one step at a time: KKT of the tip every step; the largest change in a step of the
   !> velocity d^n/dt of the values of the nodes 1..J-1 (the unknowns that keep their mass; the
   !> massless tip value is slaved to them by its equilibrium, so its own velocity switches to 0
   !> when it reaches a stop, in the semi-discrete problem too), and the balance defect.
   subroutine stepped(dt, redistributed, jump, defect, error)
      real(wp), intent(in) :: dt
      logical, intent(in) :: redistributed
      real(wp), intent(out) :: jump, defect
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: tol = 1.0e-14_wp
      type(scene_type) :: scene
      type(model_type) :: model
      type(state_type) :: state
      type(array_recorder) :: rec
      real(wp) :: tip
      real(wp), allocatable :: d_old(:)
      integer(ik) :: step, j
      scene = first_period(dt, redistributed)
      call open_run(scene, model, state, rec, error)
      if (allocated(error)) return
      jump = 0
      do step = 1, steps_of(scene)
         d_old = state%d(1:model%tip - 2:2)
         call step_once(scene, model, state, rec)
         tip = state%u(model%tip)
         jump = max(jump, maxval(abs(state%d(1:model%tip - 2:2) - d_old))/dt)
         if (tip < scene%lower - tol .or. tip > scene%upper + tol .or. (state%in_contact .and. &
            & min(abs(tip - scene%lower), abs(tip - scene%upper)) > tol)) then
            call test_failed(error, 'KKT fails at step '//int_text(step)//': tip '//real_text(tip))
            return
         end if
      end do
      defect = 0
      do j = 1, rec%filled
         defect = max(defect, abs(rec%rows(col_energy, j) - rec%rows(col_energy, 1) - rec%rows(col_work, j) &
            & + rec%rows(col_dissipated, j)))
      end do
   end subroutine stepped

   subroutine test_kkt(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: jc(2), jr(2), defect
      call stepped(1.25e-6_wp, .false., jc(1), defect, error)
      if (allocated(error)) return
      call stepped(6.25e-7_wp, .false., jc(2), defect, error)
      if (allocated(error)) return
      call stepped(1.25e-6_wp, .true., jr(1), defect, error)
      if (allocated(error)) return
      call stepped(6.25e-7_wp, .true., jr(2), defect, error)
      if (allocated(error)) return
      call note('largest change in a step of a velocity of the values of nodes 1..J-1 (dt = 1.25e-6, 6.25e-7): '// &
         & 'consistent '//real_text(jc(1))//', '//real_text(jc(2))//' m/s; redistributed '//real_text(jr(1))//', '// &
         & real_text(jr(2))//' m/s; balance defect '//real_text(defect)//' J')
      call check(error, jr(2) < 0.7_wp*jr(1), 'redistributed: it shrinks with dt (no jump)')
      if (allocated(error)) return
      call check(error, jr(2) < 0.2_wp*jc(2), 'redistributed: five times below the consistent mass''s jumps')
      if (allocated(error)) return
      call check(error, defect < 1.0e-10_wp, 'energy balance E - E0 = W - D within 1e-10 J')
   end subroutine test_kkt

   subroutine test_stop_energy(error)
      type(error_type), allocatable, intent(out) :: error
      type(array_recorder) :: a, b
      type(run_summary) :: summary
      real(wp) :: ea, eb, order
      call run_recorded(first_period(1.5625e-7_wp, .true.), a, summary, error)
      if (allocated(error)) return
      call run_recorded(first_period(7.8125e-8_wp, .true.), b, summary, error)
      if (allocated(error)) return
      ea = a%rows(col_dissipated, a%filled)
      eb = b%rows(col_dissipated, b%filled)
      order = log(abs(ea/eb))/log(2.0_wp)
      call note('stops'' energy at t = 0.125 s: '//real_text(ea)//' J (dt = 1.5625e-7), '//real_text(eb)// &
         & ' J (dt = 7.8125e-8); order '//real_text(order)//'; work of the support '//real_text(b%rows(col_work, b%filled)))
      call check(error, order > 1.5_wp, 'the stops'' energy -> 0 at order > 1.5')
      if (allocated(error)) return
      call check(error, abs(eb) < 1.0e-6_wp*b%rows(col_work, b%filled), 'below 1e-6 of the work')
   end subroutine test_stop_energy

   !> max |u_tip - reference| on [0.08, 0.125] s at the common record times (every 1e-5 s).
   function distance(a, ref) result(e)
      type(array_recorder), intent(in) :: a, ref
      real(wp) :: e
      e = maxval(abs(a%rows(col_u, 1:a%filled) - ref%rows(col_u, 1:ref%filled)), &
         & mask=a%rows(col_t, 1:a%filled) >= 0.08_wp - 1.0e-12_wp)
   end function distance

   subroutine test_convergence(error)
      type(error_type), allocatable, intent(out) :: error
      type(array_recorder) :: ref, a, b
      type(run_summary) :: summary
      real(wp) :: ea, eb, ca, cb, order
      call run_recorded(first_period(3.90625e-8_wp, .true.), ref, summary, error)
      if (allocated(error)) return
      call run_recorded(first_period(6.25e-7_wp, .true.), a, summary, error)
      if (allocated(error)) return
      call run_recorded(first_period(1.5625e-7_wp, .true.), b, summary, error)
      if (allocated(error)) return
      ea = distance(a, ref)
      eb = distance(b, ref)
      order = log(ea/eb)/log(4.0_wp)
      call run_recorded(first_period(3.90625e-8_wp, .false.), ref, summary, error)
      if (allocated(error)) return
      call run_recorded(first_period(6.25e-7_wp, .false.), a, summary, error)
      if (allocated(error)) return
      call run_recorded(first_period(1.5625e-7_wp, .false.), b, summary, error)
      if (allocated(error)) return
      ca = distance(a, ref)
      cb = distance(b, ref)
      call note('error on [0.08, 0.125] s against dt = 3.90625e-8: redistributed '//real_text(ea)//', '// &
         & real_text(eb)//' m (order '//real_text(order)//'); consistent '//real_text(ca)//', '//real_text(cb)// &
         & ' m (dt = 6.25e-7, 1.5625e-7)')
      call check(error, order >= 1.2_wp, 'redistributed: order >= 1.2')
      if (allocated(error)) return
      call check(error, cb > 10*eb, 'the consistent mass ten times farther at dt = 1.5625e-7')
   end subroutine test_convergence

   subroutine test_span(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(array_recorder) :: rec
      type(run_summary) :: summary
      real(wp) :: defect, scale
      integer(ik) :: j
      scene%length = 1.5_wp
      scene%k2 = 2.0e11_wp*1.6881e-10_wp/(8.0e3_wp*1.4923e-5_wp)
      scene%mass_per_length = 8.0e3_wp*1.4923e-5_wp
      scene%amplitude = 0.002_wp
      scene%omega = 40.0_wp
      scene%elements = 30
      scene%stop_nodes = [10, 20, 30]
      scene%stop_lower = [-0.002_wp, -0.002_wp, -0.004_wp]
      scene%stop_upper = [0.002_wp, 0.002_wp, 0.004_wp]
      scene%dt = 1.0e-5_wp
      scene%t_end = 0.5_wp
      scene%beta = 0.25_wp
      scene%redistributed_mass = .true.
      call run_recorded(scene, rec, summary, error)
      if (allocated(error)) return
      defect = 0
      do j = 1, rec%filled
         defect = max(defect, abs(rec%rows(col_energy, j) - rec%rows(col_energy, 1) - rec%rows(col_work, j) &
            & + rec%rows(col_dissipated, j)))
      end do
      scale = maxval(abs(rec%rows(col_energy, 1:rec%filled)))
      call note('tube, redistributed: '//int_text(summary%impacts)//' contact phases, stops'' energy '// &
         & real_text(rec%rows(col_dissipated, rec%filled))//' J, balance defect '//real_text(defect/scale)// &
         & ' of max |E|, violation '//real_text(summary%max_violation)//' m')
      call check(error, summary%impacts > 0, 'the stops act')
      if (allocated(error)) return
      call check(error, defect < 1.0e-10_wp*scale, 'balance within 1e-10 of max |E|')
      if (allocated(error)) return
      call check(error, summary%max_violation < 1.0e-14_wp, 'no violation beyond round-off')
   end subroutine test_span

   subroutine test_paths(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(state_type) :: fused, reference
      type(array_recorder) :: a, b
      real(wp) :: gap
      scene = first_period(1.0e-6_wp, .true.)
      scene%t_end = 0.1_wp
      scene%record_every = 1
      scene%damping_mass = 1.0_wp
      call open_run(scene, model, fused, a, error)
      if (allocated(error)) return
      call advance(scene, model, fused, a, steps_of(scene))
      call open_run(scene, model, reference, b, error)
      if (allocated(error)) return
      reference%lapack_solve = .true.
      call advance(scene, model, reference, b, steps_of(scene))
      gap = maxval(abs(a%rows(col_u, 1:a%filled) - b%rows(col_u, 1:b%filled)))
      call note('tip: fused vs reference '//real_text(gap)//' m through '//int_text(fused%impacts)// &
         & ' contact phases; damped '//real_text(a%rows(col_damped, a%filled))//' J')
      call check(error, fused%impacts > 0, 'the tip reaches a stop')
      if (allocated(error)) return
      call check(error, gap < 1.0e-12_wp, 'the two paths agree to round-off')
   end subroutine test_paths
end module test_redistribution
