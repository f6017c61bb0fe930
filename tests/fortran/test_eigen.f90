!> Spectrum of the discrete beam: cantilever frequencies and their h^4 convergence,
!> kappa_h, the paper's bound kappa_tilde and the stability limits built on them.
module test_eigen
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use testing
   use test_support, only: band_eigenvalues, dense_eigenvalues
   use beamstops, only: scene_type, model_type, build_model
   use beamstops_hermite, only: element_mass, element_stiffness
   use beamstops_band, only: kd, assemble_band, largest_eigenvalue_iterative
   implicit none
   private
   public :: collect_eigen

   !> beta_n L of a clamped-free beam, roots of cos x cosh x = -1 (SPEC 3).
   real(wp), parameter :: beta_l(5) = [1.8751040687_wp, 4.6940911330_wp, 7.8547574382_wp, &
      & 10.9955407349_wp, 14.1371683910_wp]

contains

   !> Tests of the suite.
   subroutine collect_eigen(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('beta_n L are roots of cos x cosh x = -1', test_roots), &
         & new_unittest('first five frequencies at J = 19 (from above, within bounds)', test_frequencies), &
         & new_unittest('frequencies converge as h^4 (J = 10 -> 20, modes 1-3)', test_convergence), &
         & new_unittest('kappa_h of the paper''s scene = 2.6035e10', test_kappa_h), &
         & new_unittest('paper''s bound kappa_tilde: 2 sqrt(2/kappa_tilde) = 3.3469e-6 s', test_kappa_bound), &
         & new_unittest('exact limits: 1.7529e-5 s (beta = 1/4), 1.2395e-5 s (beta = 0)', test_limits), &
         & new_unittest('inverse iteration agrees with dsbgv at J = 1000', test_iterative) &
         & ]
   end subroutine collect_eigen

   !> Eigen-frequencies sqrt(lambda) of (S, M) of a scene with J elements.
   subroutine frequencies(elements, omega, error)
      integer, intent(in) :: elements
      real(wp), allocatable, intent(out) :: omega(:)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      real(wp), allocatable :: w(:)
      scene%elements = elements
      call build_model(scene, model, error)
      if (allocated(error)) return
      call band_eigenvalues(model%stiffness, model%mass, w, error)
      if (allocated(error)) return
      omega = sqrt(w)
   end subroutine frequencies

   !> Analytic cantilever frequencies of the default scene.
   function exact_frequencies() result(omega)
      real(wp) :: omega(5)
      type(scene_type) :: scene
      omega = beta_l**2*sqrt(scene%k2)/scene%length**2
   end function exact_frequencies

   subroutine test_roots(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      do i = 1, 5
         ! cos x + 1/cosh x = 0, scaled so that 10 digits of x give about 1e-10
         call check(error, cos(beta_l(i)) + 1/cosh(beta_l(i)), 0.0_wp, 'cos x + 1/cosh x at beta_l('// &
            & achar(48 + i)//')', thr=1e-9_wp)
         if (allocated(error)) return
      end do
   end subroutine test_roots

   subroutine test_frequencies(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: bound(5) = [1e-7_wp, 5e-6_wp, 4e-5_wp, 1.5e-4_wp, 4e-4_wp]
      real(wp), allocatable :: omega(:)
      real(wp) :: exact(5), rel_err
      character(len=160) :: line
      integer :: i
      call frequencies(19, omega, error)
      if (allocated(error)) return
      exact = exact_frequencies()
      do i = 1, 5
         rel_err = omega(i)/exact(i) - 1
         write (line, '(a,i0,a,f12.5,a,f12.5,a,es10.3)') 'mode ', i, ': omega_h = ', omega(i), &
            & ', exact = ', exact(i), ', relative error = ', rel_err
         call note(trim(line))
         ! Rayleigh-Ritz: conforming elements approximate eigenvalues from above
         call check(error, rel_err > -1e-12_wp, 'mode '//achar(48 + i)//' from above: '//trim(line))
         if (allocated(error)) return
         call check(error, rel_err < bound(i), 'mode '//achar(48 + i)//' error below '//real_text(bound(i))// &
            & ': '//trim(line))
         if (allocated(error)) return
      end do
   end subroutine test_frequencies

   subroutine test_convergence(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: omega10(:), omega20(:)
      real(wp) :: exact(5), order
      character(len=160) :: line
      integer :: i
      call frequencies(10, omega10, error)
      if (allocated(error)) return
      call frequencies(20, omega20, error)
      if (allocated(error)) return
      exact = exact_frequencies()
      do i = 1, 3
         order = log((omega10(i)/exact(i) - 1)/(omega20(i)/exact(i) - 1))/log(2.0_wp)
         write (line, '(a,i0,a,es10.3,a,es10.3,a,f7.4)') 'mode ', i, ': error J=10 ', omega10(i)/exact(i) - 1, &
            & ', J=20 ', omega20(i)/exact(i) - 1, ', observed order ', order
         call note(trim(line))
         call check(error, order >= 3.7_wp .and. order <= 4.3_wp, 'order in [3.7, 4.3]: '//trim(line))
         if (allocated(error)) return
      end do
   end subroutine test_convergence

   subroutine test_kappa_h(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      real(wp), allocatable :: w(:)
      call build_model(scene, model, error)
      if (allocated(error)) return
      call note('kappa_h = '//real_text(model%kappa_h)//' ('//model%kappa_method//')')
      call check(error, model%kappa_h, 2.6035e10_wp, 'kappa_h (SPEC 6)', thr=1e-4_wp, rel=.true.)
      if (allocated(error)) return
      call band_eigenvalues(model%stiffness, model%mass, w, error)
      if (allocated(error)) return
      call check(error, model%kappa_h, w(size(w)), 'kappa_h against the largest eigenvalue by the test', &
         & thr=1e-12_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, model%kappa_h <= model%kappa_bound, 'kappa_h <= kappa_tilde')
   end subroutine test_kappa_h

   subroutine test_kappa_bound(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      real(wp) :: h
      scene%beta = 0.25_wp
      call build_model(scene, model, error)
      if (allocated(error)) return
      h = scene%length/scene%elements
      call note('kappa_tilde = '//real_text(model%kappa_bound)//', 2 sqrt(2/kappa_tilde) = '// &
         & real_text(2*sqrt(2/model%kappa_bound))//' s')
      call check(error, model%kappa_bound, 24.0_wp*420*19**2/37*scene%k2/h**4, 'kappa_tilde = (24 420 19^2/37) k2/h^4', &
         & thr=1e-13_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, model%kappa_bound, 7.1416e11_wp, 'kappa_tilde (SPEC 6)', thr=1e-4_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, 2*sqrt(2/model%kappa_bound), 3.3469e-6_wp, '2 sqrt(2/kappa_tilde) (paper)', thr=1e-4_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, model%dt_paper_bound, 2*sqrt(2/model%kappa_bound), 'dt_paper_bound at beta = 1/4', &
         & thr=1e-13_wp, rel=.true.)
   end subroutine test_kappa_bound

   subroutine test_limits(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      scene%beta = 0.25_wp
      call build_model(scene, model, error)
      if (allocated(error)) return
      call note('beta = 1/4: dt_paper_exact = '//real_text(model%dt_paper_exact)//' s')
      call check(error, model%dt_paper_exact, 1.7529e-5_wp, 'dt_paper_exact at beta = 1/4 (SPEC 6)', thr=1e-4_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, model%dt_paper_exact, 2/sqrt(0.5_wp*model%kappa_h), '2/sqrt((1-2 beta) kappa_h)', &
         & thr=1e-13_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, ieee_is_finite(model%dt_newmark), .false., 'Newmark beta = 1/4 unconditionally stable (dt_newmark = +Inf)')
      if (allocated(error)) return
      scene%beta = 0
      scene%dt = 1e-6_wp
      call build_model(scene, model, error)
      if (allocated(error)) return
      call note('beta = 0: dt_newmark = '//real_text(model%dt_newmark)//' s')
      call check(error, model%dt_newmark, 1.2395e-5_wp, 'dt_newmark at beta = 0 (SPEC 6)', thr=1e-4_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, model%dt_newmark, 2/sqrt(model%kappa_h), '2/sqrt(kappa_h)', thr=1e-13_wp, rel=.true.)
      if (allocated(error)) return
      scene%beta = 0.5_wp
      call build_model(scene, model, error)
      if (allocated(error)) return
      call check(error, ieee_is_finite(model%dt_paper_exact), .false., 'beta = 1/2: no condition (3.1) (+Inf)')
   end subroutine test_limits

   subroutine test_iterative(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: elements = 1000, n = 2*elements
      real(wp), parameter :: length = 1.501_wp, k2 = 282.84_wp
      real(wp), allocatable :: mb(:, :), sb(:, :), w(:), we(:)
      real(wp) :: h, shift, kappa
      h = length/elements
      allocate (mb(kd + 1, n), sb(kd + 1, n))
      call assemble_band(elements, element_mass(h), mb)
      call assemble_band(elements, element_stiffness(h, k2), sb)
      ! an upper bound: the largest eigenvalue of one element (Rayleigh quotients add element by element)
      call dense_eigenvalues(element_stiffness(h, k2), element_mass(h), we, error)
      if (allocated(error)) return
      shift = we(4)*(1 + 1e-6_wp)
      call band_eigenvalues(sb, mb, w, error)
      if (allocated(error)) return
      call check(error, w(n) <= we(4), 'element bound '//real_text(we(4))//' >= kappa_h '//real_text(w(n)))
      if (allocated(error)) return
      call largest_eigenvalue_iterative(sb, mb, shift, kappa, error)
      if (allocated(error)) return
      call note('J = 1000: dsbgv '//real_text(w(n))//', inverse iteration '//real_text(kappa)// &
         & ', relative difference '//real_text(kappa/w(n) - 1))
      call check(error, kappa, w(n), 'inverse iteration against dsbgv', thr=1e-8_wp, rel=.true.)
   end subroutine test_iterative
end module test_eigen
