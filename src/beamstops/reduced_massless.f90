!> The kernels of the massless boundary's step (mass redistribution on a reduced model, SPEC 10,
!> 11; beamstops_reduced builds it, advance_massless in beamstops_reduced_scheme runs it): tip
!> stops, m = 1, q = (a, p) with p the massless tip value, S_r = [[Lambda_c + G G^T/S_bb, G],
!> [G^T, S_bb]], M_r = diag(I, 0). Each is one allocation-free sweep of O(r).
module beamstops_reduced_massless
   use beamstops_kinds, only: wp
   use beamstops_reduced, only: reduced_model_type
   implicit none
   private
   public :: coupling_dots, massless_rhs, massless_update, equilibrium_start

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

   !> The massless boundary at the start: each stop coordinate of q^1 from the equilibrium of its
   !> row at t_1, (S_r q^1)_p = sigma_1 l_p, the modal amplitudes fixed (the full model's
   !> equilibrium_start in the reduced basis).
   pure subroutine equilibrium_start(reduced, sigma, q)
      !> Reduced model (massless).
      type(reduced_model_type), intent(in) :: reduced
      !> Load average sigma_1.
      real(wp), intent(in) :: sigma
      !> q^1: its stop coordinates set.
      real(wp), intent(inout) :: q(:)
      integer :: r, j, k
      real(wp) :: others
      r = reduced%r
      do k = 1, reduced%m
         others = dot_product(reduced%stiffness_coupling(:, k), q(1:r))
         do j = 1, reduced%m
            if (j /= k) others = others + reduced%stiffness_pp(k, j)*q(r + j)
         end do
         q(r + k) = (sigma*reduced%load(r + k) - others)/reduced%stiffness_pp(k, k)
      end do
   end subroutine equilibrium_start
end module beamstops_reduced_massless
