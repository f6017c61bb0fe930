!> The kernels of the massless boundary's step (mass redistribution on a reduced model, SPEC 10,
!> 11; beamstops_reduced builds it, advance_massless in beamstops_reduced_scheme runs it): tip
!> stops, m = 1, q = (a, p) with p the massless tip value, S_r = [[Lambda_c + G G^T/S_bb, G],
!> [G^T, S_bb]], M_r = diag(I, 0). Each is one allocation-free sweep of O(r). Also the build's
!> condensed interior stiffness and the condensed spectrum of (S_r, M_r).
module beamstops_reduced_massless
   use beamstops_kinds, only: wp
   use beamstops_error, only: error_type, fatal_error
   use beamstops_band, only: kd
   use beamstops_lapack, only: dpotrf, dpotrf_message
   implicit none
   private
   public :: coupling_dots, massless_rhs, massless_update, equilibrium_start, condense_stiffness, massless_condensation
   public :: span_massless_rhs, span_massless_update

contains

   !> G.a and G.d_a in one sweep (O(r)).
   pure subroutine coupling_dots(r, g, q, d, g_q, g_d)
      !> Modes r.
      integer, intent(in) :: r
      !> G (r), q and d (r + 1).
      real(wp), intent(in) :: g(r), q(r + 1), d(r + 1)
      !> G.a and G.d_a.
      real(wp), intent(out) :: g_q, g_d
      integer :: i
      g_q = 0
      g_d = 0
      do i = 1, r
         g_q = g_q + g(i)*q(i)
         g_d = g_d + g(i)*d(i)
      end do
   end subroutine coupling_dots

   !> The modal rows of the massless boundary's step in one sweep (O(r)), gs = G/S_bb:
   !> x_a = D^{-1} (dt^2 (weight l_a - Lambda_c a - G s_u/S_bb) [- dt (C_r d^{n-1})_a] - gs y_p)
   !> and acc = G.x_a.
   pure subroutine massless_rhs(r, dinv, gs, lambda, g, load, q, dt2, weight, s_u, y_p, x, acc, cd, dt)
      !> Modes r.
      integer, intent(in) :: r
      !> D^{-1}, G/S_bb, Lambda_c and G (r); l_r and q^n (r + 1); dt^2, the load weight,
      !> s_u = (S_r q^n)_p and the tip's right-hand side y_p.
      real(wp), intent(in) :: dinv(r), gs(r), lambda(r), g(r), load(r + 1), q(r + 1), dt2, weight, s_u, y_p
      !> x_a set on return (r + 1; x_p untouched).
      real(wp), intent(inout) :: x(r + 1)
      !> G.x_a.
      real(wp), intent(out) :: acc
      !> C_r d^{n-1} and dt, with damping only.
      real(wp), intent(in), optional :: cd(r + 1), dt
      integer :: i
      real(wp) :: xi
      acc = 0
      if (present(cd)) then
         do i = 1, r
            xi = dinv(i)*((dt2*(weight*load(i) - lambda(i)*q(i) - gs(i)*s_u) - dt*cd(i)) - gs(i)*y_p)
            x(i) = xi
            acc = acc + g(i)*xi
         end do
      else
         do i = 1, r
            xi = dinv(i)*(dt2*(weight*load(i) - lambda(i)*q(i) - gs(i)*s_u) - gs(i)*y_p)
            x(i) = xi
            acc = acc + g(i)*xi
         end do
      end if
   end subroutine massless_rhs

   !> The update of the massless boundary's step: d^n = d^{n-1} + x + c z, q^{n+1} = q^n + d^n,
   !> gd = l_r.d^n and g_d = G.d^n_a, in one sweep (O(r)).
   pure subroutine massless_update(r, z, load, g, c, x, d, q, gd, g_d)
      !> Modes r.
      integer, intent(in) :: r
      !> z_r = A_r^{-1} e_p and l_r (r + 1), G (r), the contact's multiple c of z_r, A_r^{-1} rhs (r + 1).
      real(wp), intent(in) :: z(r + 1), load(r + 1), g(r), c, x(r + 1)
      !> d^{n-1}, q^n on entry; d^n, q^{n+1} on return (r + 1).
      real(wp), intent(inout) :: d(r + 1), q(r + 1)
      !> l_r.d^n and G.d^n_a.
      real(wp), intent(out) :: gd, g_d
      integer :: i
      gd = 0
      g_d = 0
      do i = 1, r
         d(i) = d(i) + (x(i) + c*z(i))
         q(i) = q(i) + d(i)
         gd = gd + load(i)*d(i)
         g_d = g_d + g(i)*d(i)
      end do
      d(r + 1) = d(r + 1) + (x(r + 1) + c*z(r + 1))
      q(r + 1) = q(r + 1) + d(r + 1)
      gd = gd + load(r + 1)*d(r + 1)
   end subroutine massless_update

   !> The unconstrained increment x = A_r^{-1} rhs of the massless boundary with m stops along the
   !> span (S_bb diagonal), each stop row its equilibrium at t_{n+1}, in O(r m), allocation-free:
   !> s_u = (S_r q^n)_p, s_d = (S_r d^{n-1})_p, y_p = dt^2 beta (sigma_{n+1} l_p - s_u - s_d),
   !> x_a = D^{-1} (dt^2 (weight l_a - Lambda_c a - B s_u) [- dt (C_r d^{n-1})_a] - B y_p)
   !> (B = G S_bb^{-1}), x_p = S_bb^{-1} (y_p/(dt^2 beta) - G^T x_a).
   pure subroutine span_massless_rhs(r, m, dinv, bg, lambda, g, sbb, load, q, d, dt2, row_scale, weight, &
      & sigma_next, s_u, s_d, x, cd, dt)
      !> Modes r and stops m.
      integer, intent(in) :: r, m
      !> D^{-1} (r), B = G S_bb^{-1} (r, m), Lambda_c (r), G (r, m), S_bb (m, m, diagonal).
      real(wp), intent(in) :: dinv(:), bg(:, :), lambda(:), g(:, :), sbb(:, :)
      !> l_r, q^n and d^{n-1} (r + m).
      real(wp), intent(in) :: load(:), q(:), d(:)
      !> dt^2, dt^2 beta, the load average weight and sigma_{n+1}.
      real(wp), intent(in) :: dt2, row_scale, weight, sigma_next
      !> (S_r q^n)_p and (S_r d^{n-1})_p on return (m).
      real(wp), intent(out) :: s_u(:), s_d(:)
      !> x (r + m).
      real(wp), intent(out) :: x(:)
      !> C_r d^{n-1} and dt, with damping only.
      real(wp), intent(in), optional :: cd(:), dt
      integer :: i, j
      real(wp) :: acc, xi
      do j = 1, m
         s_u(j) = dot_product(g(:, j), q(1:r)) + sbb(j, j)*q(r + j)
         s_d(j) = dot_product(g(:, j), d(1:r)) + sbb(j, j)*d(r + j)
         x(r + j) = row_scale*(sigma_next*load(r + j) - (s_u(j) + s_d(j)))
      end do
      do i = 1, r
         acc = weight*load(i) - lambda(i)*q(i)
         do j = 1, m
            acc = acc - bg(i, j)*s_u(j)
         end do
         xi = dt2*acc
         if (present(cd)) xi = xi - dt*cd(i)
         do j = 1, m
            xi = xi - bg(i, j)*x(r + j)
         end do
         x(i) = dinv(i)*xi
      end do
      do j = 1, m
         x(r + j) = (x(r + j)/row_scale - dot_product(g(:, j), x(1:r)))/sbb(j, j)
      end do
   end subroutine span_massless_rhs

   !> The update with m stops along the span: d^n = d^{n-1} + x + sum_active lambda_k z_k,
   !> q^{n+1} = q^n + d^n and gd = l_r.d^n, O((r + m) active).
   pure subroutine span_massless_update(n_active, active, lambda, z, load, x, d, q, gd)
      !> Active stops and their indices (n_active).
      integer, intent(in) :: n_active, active(:)
      !> Multipliers of all stops (m), the columns z = A_r^{-1} e_p (r + m, m), l_r and x (r + m).
      real(wp), intent(in) :: lambda(:), z(:, :), load(:), x(:)
      !> d^{n-1}, q^n on entry; d^n, q^{n+1} on return.
      real(wp), intent(inout) :: d(:), q(:)
      !> l_r.d^n.
      real(wp), intent(out) :: gd
      integer :: i, k
      real(wp) :: xi
      gd = 0
      do i = 1, size(x)
         xi = x(i)
         do k = 1, n_active
            xi = xi + lambda(active(k))*z(i, active(k))
         end do
         d(i) = d(i) + xi
         q(i) = q(i) + d(i)
         gd = gd + load(i)*d(i)
      end do
   end subroutine span_massless_update

   !> The massless boundary at the start: each stop coordinate of q^1 from the equilibrium of its
   !> row at t_1, (S_r q^1)_p = sigma_1 l_p, the modal amplitudes fixed (the full model's
   !> equilibrium_start in the reduced basis).
   pure subroutine equilibrium_start(r, m, g, s_pp, load, sigma, q)
      !> Modes r and stop coordinates m.
      integer, intent(in) :: r, m
      !> G (r, m), S_bb (m, m), l_r (r + m).
      real(wp), intent(in) :: g(r, m), s_pp(m, m), load(r + m)
      !> Load average sigma_1.
      real(wp), intent(in) :: sigma
      !> q^1: its stop coordinates set (r + m).
      real(wp), intent(inout) :: q(r + m)
      integer :: j, k
      real(wp) :: others
      do k = 1, m
         others = dot_product(g(:, k), q(1:r))
         do j = 1, m
            if (j /= k) others = others + s_pp(k, j)*q(r + j)
         end do
         q(r + k) = (sigma*load(r + k) - others)/s_pp(k, k)
      end do
   end subroutine equilibrium_start
   !> S_ii - S_ib S_bb^{-1} S_bi in band storage on the interior unknowns: the stiffness of the
   !> interior with the massless stop unknowns b condensed. No two stop nodes share an element, so
   !> their values are more than kd apart and S_bb is diagonal: the correction is one rank-1 term
   !> S_ib_k S_bi_k/S_bkbk a stop, touching its neighbours only. Those of the tip value (2J-3, 2J-2,
   !> 2J) stay within kd = 3 of each other once b is removed; those of a value along the span
   !> (2i-3, 2i-2, 2i, 2i+1, 2i+2) are five consecutive interior unknowns: the condensed band
   !> needs a half-bandwidth kd + 1 (the caller gives sc kd + 2 rows then). The band of sc is its
   !> first dimension minus one.
   pure subroutine condense_stiffness(stiffness, interior, b, sc)
      !> S in band storage (kd + 1, n).
      real(wp), intent(in) :: stiffness(:, :)
      !> The interior unknowns (ascending) and the stop unknowns b (no two within kd).
      integer, intent(in) :: interior(:), b(:)
      !> S_ii in band storage (kc + 1, n - m) on entry, condensed on return.
      real(wp), intent(inout) :: sc(:, :)
      real(wp) :: sib(size(interior)), sbb
      integer :: ii, jj, i, k, kc, first, last
      kc = size(sc, 1) - 1
      do k = 1, size(b)
         sbb = stiffness(kd + 1, b(k))
         first = size(interior) + 1
         last = 0
         do ii = 1, size(interior)
            i = interior(ii)
            sib(ii) = 0
            if (i < b(k) .and. b(k) - i <= kd) sib(ii) = stiffness(kd + 1 + i - b(k), b(k))
            if (i > b(k) .and. i - b(k) <= kd) sib(ii) = stiffness(kd + 1 + b(k) - i, i)
            if (sib(ii) /= 0) then
               first = min(first, ii)
               last = max(last, ii)
            end if
         end do
         do jj = first, last
            if (sib(jj) == 0) cycle
            do ii = max(first, jj - kc), jj
               if (sib(ii) /= 0) sc(kc + 1 + ii - jj, jj) = sc(kc + 1 + ii - jj, jj) - sib(ii)*sib(jj)/sbb
            end do
         end do
      end do
   end subroutine condense_stiffness

   !> The finite spectrum of (S_r, M_r) with M_r = diag(I, 0) (the massless boundary): that of
   !> the modal block with the massless coordinates condensed, Lambda - G S_bb^{-1} G^T (mass I),
   !> the full model's finite spectrum of (S, M^rho) in the reduced basis. mr and sr become r x r.
   subroutine massless_condensation(r, m, mr, sr, error)
      integer, intent(in) :: r, m
      real(wp), allocatable, intent(inout) :: mr(:, :), sr(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: sbb(:, :), g(:, :)
      integer :: info, i
      sbb = sr(r + 1:, r + 1:)
      g = transpose(sr(1:r, r + 1:))
      call dpotrf('U', m, sbb, m, info)
      if (info /= 0) then
         call fatal_error(error, 'reduced model: '//dpotrf_message(info, 'S_bb (the massless boundary)'))
         return
      end if
      ! g = R^{-T} G^T, so G S_bb^{-1} G^T = g^T g.
      call solve_upper_transposed(m, r, sbb, g)
      sr = sr(1:r, 1:r) - matmul(transpose(g), g)
      sr = 0.5_wp*(sr + transpose(sr))
      deallocate (mr)
      allocate (mr(r, r))
      mr = 0
      do i = 1, r
         mr(i, i) = 1
      end do
   end subroutine massless_condensation

   !> x = R^{-T} x for an upper triangular R (m x m), x (m x k), by forward substitution.
   pure subroutine solve_upper_transposed(m, k, rf, x)
      integer, intent(in) :: m, k
      real(wp), intent(in) :: rf(:, :)
      real(wp), intent(inout) :: x(:, :)
      integer :: i, j, c
      do c = 1, k
         do i = 1, m
            do j = 1, i - 1
               x(i, c) = x(i, c) - rf(j, i)*x(j, c)
            end do
            x(i, c) = x(i, c)/rf(i, i)
         end do
      end do
   end subroutine solve_upper_transposed
end module beamstops_reduced_massless
