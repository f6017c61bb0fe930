!> Mass redistribution (SPEC 10; Khenous, Laborde & Renard 2008): the constrained displacement
!> unknowns (the tip value, or the value at each stop node) carry no mass. Only the elements
!> touching a constrained node change; every other element keeps the consistent matrix.
!>
!> The construction (per unit mass, element of length h, local x in [0, h]). On an element whose
!> right node value w_R is constrained, the mass goes to (w_L, theta_L, theta_R):
!>
!>     M^rho = h [[1, 7h/24, 5h/24], [7h/24, 11h^2/120, 3h^2/40], [5h/24, 3h^2/40, 11h^2/120]]
!>
!> (the w_R row and column zero). It is the unique choice with these three properties plus
!> the three entries chosen in SPEC 10; the properties are that the mass form reproduces the
!> moments of the element exactly for every linear field, the ones the rigid motions see:
!>   - total mass:     u = 1 (w_L = 1, theta = 0):           1^T M 1 = M_11 = h = int 1 dx;
!>   - first moment:   u = x (w_L = 0, theta_L = theta_R = 1, w_R = h, which carries no mass):
!>                     1^T M x = M_12 + M_13 = 7h^2/24 + 5h^2/24 = h^2/2 = int x dx;
!>   - second moment:  x^T M x = M_22 + 2 M_23 + M_33 = (11 + 18 + 11) h^3/120 = h^3/3 = int x^2 dx.
!> (The consistent matrix on (w_L, theta_L, w_R, theta_R) keeps the same three; zeroing its w_R
!> row alone loses 156/420 of the node's share, 3.3 % of the beam's mass at J = 19, and shifts
!> the frequencies by 7 %.) It is positive definite: its leading minors are h, h^3 19/2880 and
!> h^5/8640 (exact fractions), all > 0.
!>
!> An element whose LEFT node value is constrained (the element after an interior stop node)
!> takes the mirror image x -> h - x: values unchanged, slopes change sign, so on
!> (theta_L, w_R, theta_R):
!>
!>     M^rho = h [[11h^2/120, -5h/24, 3h^2/40], [-5h/24, 1, -7h/24], [3h^2/40, -7h/24, 11h^2/120]]
!>
!> which keeps the same mass and first and second moments (of x about either end). An interior
!> stop node thus has both its elements changed; each keeps its own mass and moments, so the
!> beam keeps its total mass and its first and second moments. Two constrained nodes on one
!> element are refused by validate_physics (the element would keep no translation mass).
!> An element whose left node is the clamped node 0 drops its left values as every element
!> does (they are not unknowns).
module beamstops_contact_mass_redistribution
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   use beamstops_hermite, only: element_mass
   use beamstops_band_solve, only: band_diagonals, diagonal_row
   implicit none
   private
   public :: redistributed_element, assemble_redistributed_mass, equilibrium_rows, massless_reaction

contains

   !> The redistributed element matrix on (w_L, theta_L, w_R, theta_R), per unit mass, with the
   !> value of the constrained side ('L' or 'R') carrying no mass (its row and column zero).
   pure function redistributed_element(h, side) result(me)
      !> Element length (m).
      real(wp), intent(in) :: h
      !> Which node's value is constrained: 'L' (left) or 'R' (right).
      character, intent(in) :: side
      real(wp) :: me(4, 4)
      integer :: p(3)
      real(wp) :: block(3, 3), s
      ! block on (w_free, theta_free, theta_constrained_node); s = sign of the slopes (mirror).
      s = 1
      if (side == 'L') s = -1
      block(1, :) = [h, s*7*h**2/24, s*5*h**2/24]
      block(2, :) = [s*7*h**2/24, 11*h**3/120, 3*h**3/40]
      block(3, :) = [s*5*h**2/24, 3*h**3/40, 11*h**3/120]
      if (side == 'R') then
         p = [1, 2, 4]   ! w_L, theta_L, theta_R
      else
         p = [3, 4, 2]   ! w_R, theta_R, theta_L
      end if
      me = 0
      me(p, p) = block
   end function redistributed_element

   !> The mass matrix M^rho in band storage: J elements, the values of the nodes `constrained`
   !> (1..J, no two on one element) without mass.
   pure subroutine assemble_redistributed_mass(elements, h, constrained, ab)
      !> Number of elements J.
      integer, intent(in) :: elements
      !> Element length (m).
      real(wp), intent(in) :: h
      !> Constrained nodes (1..J).
      integer, intent(in) :: constrained(:)
      !> Band storage (kd+1, 2J), overwritten.
      real(wp), intent(out) :: ab(:, :)
      real(wp) :: me(4, 4)
      integer :: e, a, b, i, j
      ab = 0
      do e = 1, elements
         ! element e joins nodes e-1 and e
         if (any(constrained == e)) then
            me = redistributed_element(h, 'R')
         else if (any(constrained == e - 1)) then
            me = redistributed_element(h, 'L')
         else
            me = element_mass(h)
         end if
         do b = 1, 4
            j = 2*(e - 1) - 2 + b
            if (j < 1) cycle
            do a = 1, b
               i = 2*(e - 1) - 2 + a
               if (i < 1) cycle
               ab(kd + 1 + i - j, j) = ab(kd + 1 + i - j, j) + me(a, b)
            end do
         end do
      end do
   end subroutine assemble_redistributed_mass

   !> The right-hand side rows of the massless unknowns: each is stepped as an equilibrium at
   !> t_{n+1}, (S u^{n+1})_k = sigma_{n+1} g_k (+ the stops' reaction), not as the Newmark row
   !> (which, massless, has a double root -1 at beta = 1/4: a sawtooth the energy cannot see).
   !> The row k of A = M^rho + dt^2 beta S is row_scale S_k (its mass row is zero), so with
   !> u^{n+1} = u^n + d^{n-1} + x and A x = rhs that equation is
   !>   rhs_k = row_scale (sigma_{n+1} g_k - (S u^n)_k - (S d^{n-1})_k);
   !> A and z do not change, nor does the projection.
   pure subroutine equilibrium_rows(massless, row_scale, sigma_next, g, su, stiffness, d, rhs)
      !> The massless unknowns.
      integer, intent(in) :: massless(:)
      !> Their rows of A over those of S (dt^2 beta).
      real(wp), intent(in) :: row_scale
      !> Load average sigma_{n+1}.
      real(wp), intent(in) :: sigma_next
      !> Load vector, S u^n and d^{n-1} (n).
      real(wp), intent(in) :: g(:), su(:), d(:)
      !> S by diagonals.
      type(band_diagonals), intent(in) :: stiffness
      !> Right-hand side (n); the rows `massless` replaced.
      real(wp), intent(inout) :: rhs(:)
      integer :: i, k
      do i = 1, size(massless)
         k = massless(i)
         rhs(k) = row_scale*(sigma_next*g(k) - (su(k) + diagonal_row(stiffness, d, k)))
      end do
   end subroutine equilibrium_rows

   !> The reaction of the step at a massless unknown k, per unit mass, as the residual of the
   !> scheme's own (Newmark) row there, whose mass term is zero:
   !>   r_k = (S (u^n + beta (d^n - d^{n-1})))_k - weight g_k,
   !> from (S u^n)_k, (S d^{n-1})_k and (S d^n)_k. With it the energy identity of SPEC 6 holds
   !> exactly (E with M^rho): the stops take D^n = -1/2 r_k (d^n_k + d^{n-1}_k). It is zero off
   !> the stops (the equilibrium rows make the Newmark average of (S u)_k its load), but for
   !> the load rule's average versus the value at t_{n+1}.
   pure function massless_reaction(beta, weight, g_k, s_u, s_d_prev, s_d) result(r)
      !> Newmark beta and the load average weight of the step.
      real(wp), intent(in) :: beta, weight
      !> g_k, (S u^n)_k, (S d^{n-1})_k, (S d^n)_k.
      real(wp), intent(in) :: g_k, s_u, s_d_prev, s_d
      real(wp) :: r
      r = s_u + beta*(s_d - s_d_prev) - weight*g_k
   end function massless_reaction
end module beamstops_contact_mass_redistribution
