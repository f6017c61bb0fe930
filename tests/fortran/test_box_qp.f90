!> The box-constrained program of stops along the span (contact/box_qp.f90): the KKT
!> conditions on many random problems (well and badly conditioned, degenerate ones with
!> weakly active stops, trial values on the bounds, lo = hi), known solutions built
!> backwards, agreement with the enumeration of all 3^m active sets for m <= 6, m = 1
!> against the tip projection, and the constructor's refusals.
module test_box_qp
   use testing
   use test_support, only: solve_spd
   use beamstops_contact_box_qp, only: box_qp_type, new_box_qp, qp_solved, qp_message
   use beamstops_contact_tip_projection, only: project_tip
   implicit none
   private
   public :: collect_box_qp

contains

   !> Tests of the suite.
   subroutine collect_box_qp(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('m = 1 is the tip projection, bit for bit', test_single), &
         & new_unittest('all trial values inside: lambda = 0, no iteration', test_inside), &
         & new_unittest('diagonal C: independent projections, bit for bit', test_diagonal), &
         & new_unittest('KKT on 6000 random problems, m = 1..12', test_random_kkt), &
         & new_unittest('KKT on ill-conditioned C (nearly coincident stops)', test_ill_conditioned), &
         & new_unittest('degenerate: weakly active stops, trial on bounds, lo = hi', test_degenerate), &
         & new_unittest('known solutions built backwards, m = 2..20', test_manufactured), &
         & new_unittest('agrees with the enumeration of all active sets, m <= 6', test_enumeration), &
         & new_unittest('m = 40: KKT and iteration count', test_large), &
         & new_unittest('constructor refuses non-square, asymmetric, indefinite C', test_refusals), &
         & new_unittest('m = 0 and repeated solves on one workspace', test_reuse) &
         & ]
   end subroutine collect_box_qp

   !> A fixed seed for the intrinsic generator: every run draws the same problems.
   subroutine seed(k)
      integer, intent(in) :: k
      integer :: n, i
      integer, allocatable :: s(:)
      call random_seed(size=n)
      allocate (s(n))
      s = [(104729*k + 7919*i + 17, i=1, n)]
      call random_seed(put=s)
   end subroutine seed

   !> Uniform in [a, b].
   function uniform(a, b) result(x)
      real(wp), intent(in) :: a, b
      real(wp) :: x
      call random_number(x)
      x = a + (b - a)*x
   end function uniform

   !> A random SPD matrix B^T B + shift I times 10^(e), e uniform in [-2, 2].
   function random_spd(m, shift) result(c)
      integer, intent(in) :: m
      real(wp), intent(in) :: shift
      real(wp) :: c(m, m), b(m, m)
      integer :: i
      call random_number(b)
      b = 2*b - 1
      c = matmul(transpose(b), b)
      do i = 1, m
         c(i, i) = c(i, i) + shift
      end do
      c = c*10.0_wp**uniform(-2.0_wp, 2.0_wp)
   end function random_spd

   !> Random bounds: mostly lo < 0 < hi, sometimes a box away from zero, sometimes lo = hi.
   subroutine random_bounds(m, lo, hi, allow_equal)
      integer, intent(in) :: m
      real(wp), intent(out) :: lo(m), hi(m)
      logical, intent(in) :: allow_equal
      integer :: i
      real(wp) :: pick
      do i = 1, m
         call random_number(pick)
         if (pick < 0.6_wp) then
            lo(i) = -uniform(0.01_wp, 1.0_wp)
            hi(i) = uniform(0.01_wp, 1.0_wp)
         else if (pick < 0.85_wp .or. .not. allow_equal) then
            lo(i) = uniform(-2.0_wp, 2.0_wp)
            hi(i) = lo(i) + uniform(0.0_wp, 0.5_wp)
         else
            lo(i) = uniform(-1.0_wp, 1.0_wp)
            hi(i) = lo(i)
         end if
      end do
   end subroutine random_bounds

   !> Build the program of c and solve it; error when the constructor or solve fails.
   subroutine solve_problem(qp, c, trial, lo, hi, lambda, y, error)
      type(box_qp_type), intent(inout) :: qp
      real(wp), intent(in) :: c(:, :), trial(:), lo(:), hi(:)
      real(wp), intent(out) :: lambda(:), y(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: info
      call new_box_qp(qp, c, error)
      if (allocated(error)) return
      call qp%solve(trial, lo, hi, lambda, y, info)
      if (info /= qp_solved) call test_failed(error, 'solve: '//qp_message(info))
   end subroutine solve_problem

   !> The KKT conditions: y = y' + C lambda (to round-off), lo <= y <= hi exactly, lambda = 0
   !> exactly strictly inside, lambda >= 0 on lo, <= 0 on hi (to round-off of lambda).
   subroutine check_kkt(c, trial, lo, hi, lambda, y, what, error)
      real(wp), intent(in) :: c(:, :), trial(:), lo(:), hi(:), lambda(:), y(:)
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(inout) :: error
      real(wp) :: scale, residual, lambda_tol, cl, cl_abs
      integer :: i, j, m
      character(len=8) :: buf
      m = size(trial)
      scale = max(maxval(abs(trial)), maxval(abs(lo)), maxval(abs(hi)))
      residual = 0
      do i = 1, m
         cl = 0
         cl_abs = 0
         do j = 1, m
            cl = cl + c(i, j)*lambda(j)
            cl_abs = cl_abs + abs(c(i, j)*lambda(j))
         end do
         scale = max(scale, cl_abs)
         residual = max(residual, abs(y(i) - trial(i) - cl))
      end do
      call check(error, residual <= 64*m*epsilon(1.0_wp)*scale, what//': |y - y'' - C lambda| = '// &
         & real_text(residual)//' against the scale '//real_text(scale))
      if (allocated(error)) return
      lambda_tol = 64*m*epsilon(1.0_wp)*maxval(abs(lambda))
      do i = 1, m
         write (buf, '(i0)') i
         call check(error, y(i) >= lo(i) .and. y(i) <= hi(i), what//': stop '//trim(buf)//' y = '//real_text(y(i))// &
            & ' outside ['//real_text(lo(i))//', '//real_text(hi(i))//']')
         if (allocated(error)) return
         if (y(i) > lo(i) .and. y(i) < hi(i)) then
            call check(error, lambda(i), 0.0_wp, what//': stop '//trim(buf)//' strictly inside, its multiplier', thr=0.0_wp)
         else if (lo(i) < hi(i) .and. y(i) == lo(i)) then
            call check(error, lambda(i) >= -lambda_tol, what//': stop '//trim(buf)//' on its lower bound, multiplier '// &
               & real_text(lambda(i))//' < 0')
         else if (lo(i) < hi(i)) then
            call check(error, lambda(i) <= lambda_tol, what//': stop '//trim(buf)//' on its upper bound, multiplier '// &
               & real_text(lambda(i))//' > 0')
         end if
         if (allocated(error)) return
      end do
   end subroutine check_kkt

   subroutine test_single(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      real(wp), parameter :: c11s(4) = [0.04_wp, 1.0_wp, 3.7e-3_wp, 52.9_wp]
      real(wp) :: lambda(1), y(1), c, projected, trial, c11
      integer :: i, j, info
      do j = 1, 4
         c11 = c11s(j)
         call new_box_qp(qp, reshape([c11], [1, 1]), error)
         if (allocated(error)) return
         do i = -300, 300
            trial = 0.001_wp*i + 1e-17_wp*j
            call qp%solve([trial], [-0.1_wp], [0.2_wp], lambda, y, info)
            call check(error, info, qp_solved, 'info'); if (allocated(error)) return
            call project_tip(trial, -0.1_wp, 0.2_wp, c11, c, projected)
            call check(error, lambda(1), c, 'lambda against project_tip at trial '//real_text(trial), thr=0.0_wp)
            if (allocated(error)) return
            call check(error, y(1), projected, 'y against project_tip at trial '//real_text(trial), thr=0.0_wp)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_single

   subroutine test_inside(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      real(wp) :: c(5, 5), trial(5), lambda(5), y(5), lo(5), hi(5)
      integer :: info
      call seed(1)
      c = random_spd(5, 0.5_wp)
      lo = -0.1_wp
      hi = 0.1_wp
      trial = [-0.1_wp, 0.0_wp, 0.05_wp, 0.1_wp, -0.0999_wp]
      call new_box_qp(qp, c, error)
      if (allocated(error)) return
      call qp%solve(trial, lo, hi, lambda, y, info)
      call check(error, info, qp_solved, 'info'); if (allocated(error)) return
      call check(error, qp%iterations, 0, 'iterations'); if (allocated(error)) return
      call check(error, qp%n_active, 0, 'active stops'); if (allocated(error)) return
      call check(error, all(lambda == 0), 'lambda = 0'); if (allocated(error)) return
      call check(error, all(y == trial), 'y = trial')
   end subroutine test_inside

   subroutine test_diagonal(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      integer, parameter :: m = 7
      real(wp) :: c(m, m), trial(m), lambda(m), y(m), lo(m), hi(m), cc, projected
      integer :: i, k
      call seed(2)
      do k = 1, 50
         c = 0
         do i = 1, m
            c(i, i) = uniform(0.01_wp, 10.0_wp)
            trial(i) = uniform(-2.0_wp, 2.0_wp)
         end do
         call random_bounds(m, lo, hi, .false.)
         call solve_problem(qp, c, trial, lo, hi, lambda, y, error)
         if (allocated(error)) return
         do i = 1, m
            call project_tip(trial(i), lo(i), hi(i), c(i, i), cc, projected)
            call check(error, lambda(i), cc, 'lambda of stop against its own projection', thr=0.0_wp)
            if (allocated(error)) return
            call check(error, y(i), projected, 'y of stop against its own projection', thr=0.0_wp)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_diagonal

   subroutine test_random_kkt(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      real(wp), allocatable :: c(:, :), trial(:), lambda(:), y(:), lo(:), hi(:)
      integer :: m, k, most, total, active_total
      character(len=128) :: buf
      call seed(3)
      most = 0
      total = 0
      active_total = 0
      do m = 1, 12
         allocate (trial(m), lambda(m), y(m), lo(m), hi(m))
         do k = 1, 500
            c = random_spd(m, uniform(1e-3_wp, 2.0_wp))
            call random_bounds(m, lo, hi, .true.)
            call random_number(trial)
            trial = (2*trial - 1)*uniform(0.5_wp, 4.0_wp)
            call solve_problem(qp, c, trial, lo, hi, lambda, y, error)
            if (allocated(error)) return
            write (buf, '(a,i0,a,i0)') 'm = ', m, ', problem ', k
            call check_kkt(c, trial, lo, hi, lambda, y, trim(buf), error)
            if (allocated(error)) return
            most = max(most, qp%iterations - qp%n_active)
            total = total + qp%iterations
            active_total = active_total + qp%n_active
         end do
         deallocate (trial, lambda, y, lo, hi)
      end do
      write (buf, '(a,i0,a,i0,a,i0)') 'iterations ', total, ' for ', active_total, &
         & ' active stops; most extra iterations in one solve ', most
      call note(trim(buf))
   end subroutine test_random_kkt

   subroutine test_ill_conditioned(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      integer, parameter :: m = 6
      real(wp) :: c(m, m), trial(m), lambda(m), y(m), lo(m), hi(m), x(m)
      integer :: k, i, j
      character(len=32) :: buf
      call seed(4)
      do k = 1, 300
         ! The Green's function of a string between close points: nearly dependent columns.
         call random_number(x)
         x(2) = x(1) + 1e-4_wp
         do j = 1, m
            do i = 1, m
               c(i, j) = min(x(i), x(j))*(1 - max(x(i), x(j))) + merge(1e-9_wp, 0.0_wp, i == j)
            end do
         end do
         call random_bounds(m, lo, hi, .false.)
         call random_number(trial)
         trial = 2*trial - 1
         call solve_problem(qp, c, trial, lo, hi, lambda, y, error)
         if (allocated(error)) return
         write (buf, '(a,i0)') 'problem ', k
         call check_kkt(c, trial, lo, hi, lambda, y, trim(buf), error)
         if (allocated(error)) return
      end do
   end subroutine test_ill_conditioned

   subroutine test_degenerate(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      integer, parameter :: m = 5
      real(wp) :: c(m, m), trial(m), lambda(m), y(m), lo(m), hi(m)
      integer :: k, i
      real(wp) :: pick
      character(len=32) :: buf
      call seed(5)
      do k = 1, 2000
         c = random_spd(m, 0.2_wp)
         call random_bounds(m, lo, hi, .true.)
         do i = 1, m
            call random_number(pick)
            if (pick < 0.3_wp) then
               trial(i) = lo(i)
            else if (pick < 0.6_wp) then
               trial(i) = hi(i)
            else
               trial(i) = uniform(-3.0_wp, 3.0_wp)
            end if
         end do
         call solve_problem(qp, c, trial, lo, hi, lambda, y, error)
         if (allocated(error)) return
         write (buf, '(a,i0)') 'problem ', k
         call check_kkt(c, trial, lo, hi, lambda, y, trim(buf), error)
         if (allocated(error)) return
      end do
   end subroutine test_degenerate

   !> Choose y* and lambda* satisfying the KKT conditions (some stops strongly active, some
   !> weakly: on a bound with a zero multiplier), set y' = y* - C lambda*, solve.
   subroutine test_manufactured(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      real(wp), allocatable :: c(:, :), trial(:), lambda(:), y(:), lo(:), hi(:), ys(:), ls(:)
      integer :: m, k, i
      real(wp) :: pick, scale, dl, dy
      character(len=48) :: buf
      call seed(6)
      do m = 2, 20, 3
         allocate (trial(m), lambda(m), y(m), lo(m), hi(m), ys(m), ls(m))
         do k = 1, 200
            c = random_spd(m, 1.0_wp)
            call random_bounds(m, lo, hi, .false.)
            do i = 1, m
               call random_number(pick)
               ls(i) = 0
               if (pick < 0.25_wp) then
                  ys(i) = lo(i)
                  ls(i) = uniform(0.1_wp, 1.0_wp)
               else if (pick < 0.5_wp) then
                  ys(i) = hi(i)
                  ls(i) = -uniform(0.1_wp, 1.0_wp)
               else if (pick < 0.6_wp) then
                  ys(i) = lo(i)
               else if (pick < 0.7_wp) then
                  ys(i) = hi(i)
               else
                  ys(i) = uniform(lo(i), hi(i))
               end if
            end do
            trial = ys - matmul(c, ls)
            call solve_problem(qp, c, trial, lo, hi, lambda, y, error)
            if (allocated(error)) return
            write (buf, '(a,i0,a,i0)') 'm = ', m, ', problem ', k
            call check_kkt(c, trial, lo, hi, lambda, y, trim(buf), error)
            if (allocated(error)) return
            ! y' carries one rounding per entry: the solution moves by about cond(C) eps.
            scale = maxval(abs(ls))
            dl = maxval(abs(lambda - ls))
            dy = maxval(abs(y - ys))
            call check(error, dl <= 1e-9_wp*scale, trim(buf)//': |lambda - lambda*| = '//real_text(dl))
            if (allocated(error)) return
            call check(error, dy <= 1e-9_wp*max(maxval(abs(lo)), maxval(abs(hi))), trim(buf)//': |y - y*| = '// &
               & real_text(dy))
            if (allocated(error)) return
         end do
         deallocate (trial, lambda, y, lo, hi, ys, ls)
      end do
   end subroutine test_manufactured

   !> Every split of the stops into free, on lo, on hi: the KKT system of the split, solved
   !> densely; those that satisfy the KKT conditions (to round-off) must all be the QP's answer.
   subroutine test_enumeration(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      real(wp), allocatable :: c(:, :), trial(:), lambda(:), y(:), lo(:), hi(:), lb(:), yb(:), cbb(:, :), rhs(:)
      integer, allocatable :: split(:), held(:)
      integer :: m, k, code, i, nb, found, total
      real(wp) :: tol, scale
      logical :: ok
      character(len=48) :: buf
      call seed(7)
      total = 0
      do m = 1, 6
         allocate (trial(m), lambda(m), y(m), lo(m), hi(m), lb(m), yb(m), split(m), held(m))
         do k = 1, 60
            c = random_spd(m, uniform(0.05_wp, 1.0_wp))
            call random_bounds(m, lo, hi, .true.)
            call random_number(trial)
            trial = (2*trial - 1)*3
            call solve_problem(qp, c, trial, lo, hi, lambda, y, error)
            if (allocated(error)) return
            write (buf, '(a,i0,a,i0)') 'm = ', m, ', problem ', k
            scale = max(maxval(abs(trial)), maxval(abs(lo)), maxval(abs(hi)))
            tol = 1e-10_wp*scale
            found = 0
            do code = 0, 3**m - 1
               nb = 0
               do i = 1, m
                  split(i) = mod(code/3**(i - 1), 3)   ! 0 free, 1 on lo, 2 on hi
                  if (split(i) /= 0) then
                     nb = nb + 1
                     held(nb) = i
                  end if
               end do
               lb = 0
               if (nb > 0) then
                  cbb = c(held(:nb), held(:nb))
                  rhs = merge(lo(held(:nb)), hi(held(:nb)), split(held(:nb)) == 1) - trial(held(:nb))
                  lb(held(:nb)) = solve_spd(cbb, rhs)
               end if
               yb = trial + matmul(c, lb)
               ok = .true.
               do i = 1, m
                  select case (split(i))
                  case (0)
                     ok = ok .and. yb(i) >= lo(i) - tol .and. yb(i) <= hi(i) + tol
                  case (1)
                     ok = ok .and. lb(i) >= -tol*maxval(abs(lb))
                  case (2)
                     ok = ok .and. lb(i) <= tol*maxval(abs(lb))
                  end select
               end do
               if (.not. ok) cycle
               found = found + 1
               call check(error, maxval(abs(lb - lambda)) <= 1e-8_wp*max(1.0_wp, maxval(abs(lb))), &
                  & trim(buf)//': an enumerated solution differs in lambda by '//real_text(maxval(abs(lb - lambda))))
               if (allocated(error)) return
               call check(error, maxval(abs(yb - y)) <= 1e-8_wp*scale, &
                  & trim(buf)//': an enumerated solution differs in y by '//real_text(maxval(abs(yb - y))))
               if (allocated(error)) return
            end do
            call check(error, found >= 1, trim(buf)//': the enumeration finds a KKT point')
            if (allocated(error)) return
            total = total + 1
         end do
         deallocate (trial, lambda, y, lo, hi, lb, yb, split, held)
      end do
   end subroutine test_enumeration

   subroutine test_large(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      integer, parameter :: m = 40
      real(wp) :: c(m, m), trial(m), lambda(m), y(m), lo(m), hi(m)
      integer :: k, most, active
      character(len=80) :: buf
      call seed(8)
      most = 0
      active = 0
      do k = 1, 200
         c = random_spd(m, uniform(0.01_wp, 1.0_wp))
         call random_bounds(m, lo, hi, .true.)
         call random_number(trial)
         trial = (2*trial - 1)*uniform(0.5_wp, 3.0_wp)
         call solve_problem(qp, c, trial, lo, hi, lambda, y, error)
         if (allocated(error)) return
         write (buf, '(a,i0)') 'problem ', k
         call check_kkt(c, trial, lo, hi, lambda, y, trim(buf), error)
         if (allocated(error)) return
         most = max(most, qp%iterations)
         active = max(active, qp%n_active)
      end do
      write (buf, '(a,i0,a,i0)') 'm = 40: most iterations in one solve ', most, ', most active stops ', active
      call note(trim(buf))
      call check(error, most <= 3*m, 'at most 3m iterations (got '//trim(buf)//')')
   end subroutine test_large

   subroutine test_refusals(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp
      type(error_type), allocatable :: inner
      real(wp) :: rect(2, 3)
      rect = 0
      call new_box_qp(qp, rect, inner)
      call check(error, allocated(inner), 'a 2 x 3 C is refused'); if (allocated(error)) return
      call check(error, index(inner%message, 'not square') > 0, 'message: '//inner%message); if (allocated(error)) return
      call new_box_qp(qp, reshape([2.0_wp, 1.0_wp, 0.5_wp, 2.0_wp], [2, 2]), inner)
      call check(error, allocated(inner), 'an asymmetric C is refused'); if (allocated(error)) return
      call check(error, index(inner%message, 'not symmetric') > 0, 'message: '//inner%message); if (allocated(error)) return
      call new_box_qp(qp, reshape([1.0_wp, 2.0_wp, 2.0_wp, 1.0_wp], [2, 2]), inner)
      call check(error, allocated(inner), 'an indefinite C is refused'); if (allocated(error)) return
      call check(error, index(inner%message, 'leading minor of order 2') > 0 .and. &
         & index(inner%message, 'not positive definite') > 0, 'message: '//inner%message)
   end subroutine test_refusals

   subroutine test_reuse(error)
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: qp, empty
      real(wp) :: c(4, 4), trial(4), lambda(4), y(4), lo(4), hi(4), l1(4), y1(4), none(0), l0(0), y0(0)
      integer :: info, k
      call new_box_qp(empty, reshape(none, [0, 0]), error)
      if (allocated(error)) return
      call empty%solve(none, none, none, l0, y0, info)
      call check(error, info, qp_solved, 'm = 0'); if (allocated(error)) return
      call seed(9)
      c = random_spd(4, 0.3_wp)
      call new_box_qp(qp, c, error)
      if (allocated(error)) return
      lo = -0.2_wp
      hi = 0.2_wp
      trial = [0.5_wp, -0.7_wp, 0.1_wp, 0.9_wp]
      call qp%solve(trial, lo, hi, l1, y1, info)
      call check(error, info, qp_solved, 'first solve'); if (allocated(error)) return
      do k = 1, 20
         call random_number(lambda)
         call qp%solve(2*lambda - 1, lo, hi, lambda, y, info)
         call check(error, info, qp_solved, 'solve'); if (allocated(error)) return
      end do
      call qp%solve(trial, lo, hi, lambda, y, info)
      call check(error, all(lambda == l1) .and. all(y == y1), 'the same problem again gives the same bits')
   end subroutine test_reuse
end module test_box_qp
