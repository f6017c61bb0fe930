!> Hermite cubic elements, band assembly, band products, Gauss rule and load vectors,
!> against values worked out by hand or by exact polynomial integration in the test.
module test_hermite
   use testing
   use test_support, only: exact_element, dense_assembly, lift, lift_prime, simpson_load
   use beamstops, only: ik, scene_type, model_type, build_model, law_none
   use beamstops_hermite, only: element_mass, element_stiffness, gauss_points, gauss_weights
   use beamstops_band, only: kd, assemble_band, band_to_dense, band_matvec
   implicit none
   private
   public :: collect_hermite

contains

   !> Tests of the suite.
   subroutine collect_hermite(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('element matrices at h = 1, k2 = 1 (hand values)', test_unit_element), &
         & new_unittest('element matrices equal exact integrals of the Hermite basis', test_exact_integrals), &
         & new_unittest('element matrices are symmetric', test_symmetry), &
         & new_unittest('stiffness annihilates rigid translation and rotation', test_rigid_modes), &
         & new_unittest('mass integrates 1, x and x^2', test_mass_moments), &
         & new_unittest('band assembly equals dense assembly, J = 3', test_assembly_3), &
         & new_unittest('band assembly equals dense assembly, J = 5', test_assembly_5), &
         & new_unittest('band_matvec equals dense matmul, J = 1, 2, 3, 4, 7', test_matvec), &
         & new_unittest('Gauss rule: weights, symmetry, x^7 exact, x^8 not', test_gauss), &
         & new_unittest('load vector equals an independent quadrature', test_load), &
         & new_unittest('load: value rows sum to L - h/2, slope rows to -h^2/12', test_load_sums), &
         & new_unittest('initial data interpolate -a omega h(x)', test_initial_data) &
         & ]
   end subroutine collect_hermite

   ! ---------------------------------------------------------------- tests

   subroutine test_unit_element(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: me(4, 4), se(4, 4)
      me = element_mass(1.0_wp)
      se = element_stiffness(1.0_wp, 1.0_wp)
      call check(error, me(1, 1), 156.0_wp/420, 'Me(1,1)', thr=1e-15_wp); if (allocated(error)) return
      call check(error, me(1, 2), 22.0_wp/420, 'Me(1,2)', thr=1e-15_wp); if (allocated(error)) return
      call check(error, me(1, 3), 54.0_wp/420, 'Me(1,3)', thr=1e-15_wp); if (allocated(error)) return
      call check(error, me(1, 4), -13.0_wp/420, 'Me(1,4)', thr=1e-15_wp); if (allocated(error)) return
      call check(error, me(2, 2), 4.0_wp/420, 'Me(2,2)', thr=1e-15_wp); if (allocated(error)) return
      call check(error, me(2, 4), -3.0_wp/420, 'Me(2,4)', thr=1e-15_wp); if (allocated(error)) return
      call check(error, me(3, 4), -22.0_wp/420, 'Me(3,4)', thr=1e-15_wp); if (allocated(error)) return
      call check(error, se(1, 1), 12.0_wp, 'Se(1,1)', thr=1e-14_wp); if (allocated(error)) return
      call check(error, se(1, 2), 6.0_wp, 'Se(1,2)', thr=1e-14_wp); if (allocated(error)) return
      call check(error, se(1, 3), -12.0_wp, 'Se(1,3)', thr=1e-14_wp); if (allocated(error)) return
      call check(error, se(2, 2), 4.0_wp, 'Se(2,2)', thr=1e-14_wp); if (allocated(error)) return
      call check(error, se(2, 4), 2.0_wp, 'Se(2,4)', thr=1e-14_wp); if (allocated(error)) return
      call check(error, se(4, 4), 4.0_wp, 'Se(4,4)', thr=1e-14_wp); if (allocated(error)) return
   end subroutine test_unit_element

   subroutine test_exact_integrals(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: hs(3) = [0.37_wp, 1.0_wp, 2.3_wp], k2s(3) = [2.5_wp, 282.84_wp, 1.0e-3_wp]
      real(wp) :: me(4, 4), se(4, 4), mx(4, 4), sx(4, 4)
      integer :: t, i, j
      character(len=64) :: what
      do t = 1, size(hs)
         me = element_mass(hs(t))
         se = element_stiffness(hs(t), k2s(t))
         call exact_element(hs(t), k2s(t), mx, sx)
         do j = 1, 4
            do i = 1, 4
               write (what, '(a,i0,a,i0,a,es9.2)') 'Me(', i, ',', j, ') at h =', hs(t)
               call check(error, me(i, j), mx(i, j), trim(what), thr=1e-13_wp*maxval(abs(mx)))
               if (allocated(error)) return
               write (what, '(a,i0,a,i0,a,es9.2)') 'Se(', i, ',', j, ') at h =', hs(t)
               call check(error, se(i, j), sx(i, j), trim(what), thr=1e-13_wp*maxval(abs(sx)))
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_exact_integrals

   subroutine test_symmetry(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: me(4, 4), se(4, 4)
      me = element_mass(0.79_wp)
      se = element_stiffness(0.79_wp, 3.7_wp)
      call check(error, maxval(abs(me - transpose(me))), 0.0_wp, 'max |Me - Me^T|'); if (allocated(error)) return
      call check(error, maxval(abs(se - transpose(se))), 0.0_wp, 'max |Se - Se^T|'); if (allocated(error)) return
   end subroutine test_symmetry

   subroutine test_rigid_modes(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: h = 0.43_wp, k2 = 17.0_wp
      real(wp) :: se(4, 4), translation(4), rotation(4), tol
      se = element_stiffness(h, k2)
      tol = 1e-13_wp*maxval(abs(se))
      translation = [1.0_wp, 0.0_wp, 1.0_wp, 0.0_wp]   ! u = 1
      rotation = [0.0_wp, 1.0_wp, h, 1.0_wp]           ! u = x
      call check(error, maxval(abs(matmul(se, translation))), 0.0_wp, 'max |Se t|', thr=tol)
      if (allocated(error)) return
      call check(error, maxval(abs(matmul(se, rotation))), 0.0_wp, 'max |Se r|', thr=tol)
      if (allocated(error)) return
      ! and nothing else is free: u = x^2 costs bending energy k2 int (2)^2 = 4 k2 h
      call check(error, dot_product([0.0_wp, 0.0_wp, h**2, 2*h], matmul(se, [0.0_wp, 0.0_wp, h**2, 2*h])), &
         & 4*k2*h, 'bending energy of u = x^2', thr=1e-13_wp, rel=.true.)
   end subroutine test_rigid_modes

   subroutine test_mass_moments(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: h = 0.61_wp
      real(wp) :: me(4, 4), one(4), x(4), x2(4)
      me = element_mass(h)
      one = [1.0_wp, 0.0_wp, 1.0_wp, 0.0_wp]
      x = [0.0_wp, 1.0_wp, h, 1.0_wp]
      x2 = [0.0_wp, 0.0_wp, h**2, 2*h]
      ! sum of the value entries: 1^T Me 1 = int 1 = h
      call check(error, sum(me(1::2, 1::2)), h, 'sum of value entries of Me', thr=1e-15_wp, rel=.true.)
      if (allocated(error)) return
      ! Me 1 = (int phi_i): h/2, h^2/12, h/2, -h^2/12
      call check(error, dot_product(me(1, :), one), h/2, '(Me 1)_1 = int phi_1', thr=1e-15_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, dot_product(me(2, :), one), h**2/12, '(Me 1)_2 = int phi_2', thr=1e-15_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, dot_product(me(3, :), one), h/2, '(Me 1)_3 = int phi_3', thr=1e-15_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, dot_product(me(4, :), one), -h**2/12, '(Me 1)_4 = int phi_4', thr=1e-15_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, dot_product(x, matmul(me, x)), h**3/3, 'x^T Me x = int x^2', thr=1e-14_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, dot_product(one, matmul(me, x2)), h**3/3, '1^T Me x2 = int x^2', thr=1e-14_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, dot_product(x2, matmul(me, x2)), h**5/5, 'x2^T Me x2 = int x^4', thr=1e-14_wp, rel=.true.)
   end subroutine test_mass_moments

   subroutine assembly_case(elements, error)
      integer, intent(in) :: elements
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: h = 0.3_wp, k2 = 5.0_wp
      real(wp), allocatable :: mb(:, :), sb(:, :), md(:, :), sd(:, :)
      integer :: n, i, j
      character(len=80) :: what
      n = 2*elements
      allocate (mb(kd + 1, n), sb(kd + 1, n))
      call assemble_band(elements, element_mass(h), mb)
      call assemble_band(elements, element_stiffness(h, k2), sb)
      md = dense_assembly(elements, element_mass(h))
      sd = dense_assembly(elements, element_stiffness(h, k2))
      ! the dense matrices are banded with kd = 3
      do j = 1, n
         do i = 1, n
            if (abs(i - j) > kd) then
               call check(error, abs(md(i, j)) + abs(sd(i, j)), 0.0_wp, 'dense entry outside the band')
               if (allocated(error)) return
            end if
         end do
      end do
      ! LAPACK upper band storage: ab(kd+1+i-j, j) = A(i, j) for j-kd <= i <= j; the rest is zero
      do j = 1, n
         do i = 1, kd + 1
            write (what, '(a,i0,a,i0,a)') 'band entry (', i, ',', j, ')'
            if (j - (kd + 1 - i) >= 1) then
               call check(error, mb(i, j), md(j - (kd + 1 - i), j), 'M '//trim(what), thr=1e-15_wp)
               if (allocated(error)) return
               call check(error, sb(i, j), sd(j - (kd + 1 - i), j), 'S '//trim(what), thr=1e-12_wp)
               if (allocated(error)) return
            else
               call check(error, abs(mb(i, j)) + abs(sb(i, j)), 0.0_wp, 'unused '//trim(what))
               if (allocated(error)) return
            end if
         end do
      end do
      call check(error, maxval(abs(band_to_dense(mb) - md)), 0.0_wp, 'max |band_to_dense(M) - M|', thr=1e-15_wp)
      if (allocated(error)) return
      call check(error, maxval(abs(band_to_dense(sb) - sd)), 0.0_wp, 'max |band_to_dense(S) - S|', &
         & thr=1e-14_wp*maxval(abs(sd)))
      if (allocated(error)) return
      ! the tip node carries one element only: M(n-1, n-1) = 156 h/420, interior nodes two
      call check(error, md(n - 1, n - 1), 156*h/420, 'M(tip, tip)', thr=1e-15_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, md(1, 1), 312*h/420, 'M(1, 1)', thr=1e-15_wp, rel=.true.)
   end subroutine assembly_case

   subroutine test_assembly_3(error)
      type(error_type), allocatable, intent(out) :: error
      call assembly_case(3, error)
   end subroutine test_assembly_3

   subroutine test_assembly_5(error)
      type(error_type), allocatable, intent(out) :: error
      call assembly_case(5, error)
   end subroutine test_assembly_5

   subroutine test_matvec(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: sizes(5) = [1, 2, 3, 4, 7]
      real(wp), allocatable :: ab(:, :), x(:), y(:), dense(:, :)
      real(wp) :: e(4, 4)
      integer :: i, k, n
      ! a symmetric element matrix with all 16 entries distinct in magnitude
      e = element_stiffness(0.2_wp, 3.0_wp) + element_mass(0.2_wp)
      do k = 1, size(sizes)
         n = 2*sizes(k)
         if (allocated(ab)) deallocate (ab, x, y)
         allocate (ab(kd + 1, n), x(n), y(n))
         call assemble_band(sizes(k), e, ab)
         dense = dense_assembly(sizes(k), e)
         x = [(sin(1.7_wp*i) + 0.3_wp*cos(5.1_wp*i), i=1, n)]
         call band_matvec(ab, x, y)
         call check(error, maxval(abs(y - matmul(dense, x))), 0.0_wp, 'max |band_matvec - matmul| for J = '// &
            & int_text(sizes(k)), thr=1e-13_wp*maxval(abs(dense)))
         if (allocated(error)) return
      end do
   end subroutine test_matvec

   subroutine test_gauss(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, sum(gauss_weights), 1.0_wp, 'sum of weights', thr=4*epsilon(1.0_wp)); if (allocated(error)) return
      call check(error, maxval(abs(gauss_points + gauss_points(4:1:-1) - 1)), 0.0_wp, 'points symmetric about 1/2', &
         & thr=4*epsilon(1.0_wp)); if (allocated(error)) return
      call check(error, all(gauss_points > 0 .and. gauss_points < 1), 'points inside (0, 1)'); if (allocated(error)) return
      call check(error, sum(gauss_weights*gauss_points**7), 1.0_wp/8, 'int x^7', thr=1e-15_wp); if (allocated(error)) return
      call check(error, sum(gauss_weights*gauss_points**6), 1.0_wp/7, 'int x^6', thr=1e-15_wp); if (allocated(error)) return
      call check(error, sum(gauss_weights*gauss_points**3), 1.0_wp/4, 'int x^3', thr=1e-15_wp); if (allocated(error)) return
      ! a 4-point rule is not exact for degree 8: its error on x^8 is (4!)^4 8!/(9 (8!)^3) = 2.3e-5
      call check(error, abs(sum(gauss_weights*gauss_points**8) - 1.0_wp/9) > 1e-7_wp, 'x^8 is not integrated exactly')
   end subroutine test_gauss

   subroutine test_load(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      real(wp), allocatable :: expected(:), bh(:), b1(:)
      integer :: i
      scene%elements = 5
      scene%amplitude = 0.3_wp
      scene%omega = 7.0_wp
      scene%law = law_none
      call build_model(scene, model, error)
      if (allocated(error)) return
      call simpson_load(scene%elements, scene%length, bh, b1)
      ! f = -h phi'' + (8 k2/L^4) phi, phi = a sin(omega t): G(t) = sin(omega t) a (omega^2 (h, phi_i) + 8k2/L^4 (1, phi_i))
      expected = scene%amplitude*(scene%omega**2*bh + 8*scene%k2/scene%length**4*b1)
      call check(error, size(model%load), size(expected), 'size of the load vector'); if (allocated(error)) return
      do i = 1, size(expected)
         call check(error, model%load(i), expected(i), 'load row '//int_text(i), thr=1e-10_wp*maxval(abs(expected)))
         if (allocated(error)) return
      end do
   end subroutine test_load

   subroutine test_load_sums(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      real(wp) :: h, scale
      scene%elements = 7
      scene%amplitude = 0.25_wp
      scene%omega = 0       ! only the (1, phi_i) part is left
      scene%law = law_none
      call build_model(scene, model, error)
      if (allocated(error)) return
      h = scene%length/scene%elements
      scale = scene%amplitude*8*scene%k2/scene%length**4
      call check(error, sum(model%load(1::2))/scale, scene%length - h/2, 'sum over value rows of int phi_i', &
         & thr=1e-13_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, sum(model%load(2::2))/scale, -h**2/12, 'sum over slope rows of int phi_i', &
         & thr=1e-12_wp, rel=.true.)
   end subroutine test_load_sums

   subroutine test_initial_data(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      real(wp) :: x
      integer :: i
      scene%elements = 6
      call build_model(scene, model, error)
      if (allocated(error)) return
      call check(error, maxval(abs(model%u0)), 0.0_wp, 'u0 = 0 (beam at rest, phi(0) = 0)'); if (allocated(error)) return
      do i = 1, scene%elements
         x = i*scene%length/scene%elements
         call check(error, model%v0(2*i - 1), -scene%amplitude*scene%omega*lift(x, scene%length), &
            & 'v0 value at node '//int_text(i), thr=1e-14_wp)
         if (allocated(error)) return
         call check(error, model%v0(2*i), -scene%amplitude*scene%omega*lift_prime(x, scene%length), &
            & 'v0 slope at node '//int_text(i), thr=1e-14_wp)
         if (allocated(error)) return
      end do
      ! h(L) = 0: the tip's homogeneous and physical displacements agree
      call check(error, model%v0(model%tip), 0.0_wp, 'v0 at the tip', thr=1e-14_wp)
   end subroutine test_initial_data
end module test_hermite
