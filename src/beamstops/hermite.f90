!> Hermite cubic elements: element matrices, basis functions, Gauss quadrature.
module beamstops_hermite
   use beamstops_kinds, only: wp
   implicit none
   private
   public :: element_mass, element_stiffness, hermite_basis, gauss_points, gauss_weights

   !> 4-point Gauss-Legendre abscissae on [0, 1].
   real(wp), parameter :: gauss_points(4) = 0.5_wp + 0.5_wp*[ &
      & -0.861136311594052575223946488892809505_wp, -0.339981043584856264802665759103244687_wp, &
      &  0.339981043584856264802665759103244687_wp,  0.861136311594052575223946488892809505_wp]
   !> 4-point Gauss-Legendre weights on [0, 1] (they sum to 1).
   real(wp), parameter :: gauss_weights(4) = 0.5_wp*[ &
      & 0.347854845137453857373063949221999407_wp, 0.652145154862546142626936050778000593_wp, &
      & 0.652145154862546142626936050778000593_wp, 0.347854845137453857373063949221999407_wp]

contains

   !> Consistent mass matrix of an element of length h (per unit mass).
   pure function element_mass(h) result(me)
      !> Element length (m).
      real(wp), intent(in) :: h
      real(wp) :: me(4, 4)
      me = reshape([156*h, 22*h**2, 54*h, -13*h**2, &
         &          22*h**2, 4*h**3, 13*h**2, -3*h**3, &
         &          54*h, 13*h**2, 156*h, -22*h**2, &
         &          -13*h**2, -3*h**3, -22*h**2, 4*h**3], [4, 4])/420
   end function element_mass

   !> Bending stiffness matrix k^2 * int(phi_i'' phi_j'') of an element of length h.
   pure function element_stiffness(h, k2) result(se)
      !> Element length (m).
      real(wp), intent(in) :: h
      !> k^2 = EI/(rho S) (m^4/s^2).
      real(wp), intent(in) :: k2
      real(wp) :: se(4, 4)
      se = reshape([6.0_wp, 3*h, -6.0_wp, 3*h, &
         &          3*h, 2*h**2, -3*h, h**2, &
         &          -6.0_wp, -3*h, 6.0_wp, -3*h, &
         &          3*h, h**2, -3*h, 2*h**2], [4, 4])*(2*k2/h**3)
   end function element_stiffness

   !> Values of the four Hermite shape functions at xi in [0, 1] on an element of length h,
   !> ordered (value left, slope left, value right, slope right).
   pure function hermite_basis(xi, h) result(n)
      !> Local coordinate in [0, 1].
      real(wp), intent(in) :: xi
      !> Element length (m).
      real(wp), intent(in) :: h
      real(wp) :: n(4)
      n = [1 - 3*xi**2 + 2*xi**3, h*(xi - 2*xi**2 + xi**3), 3*xi**2 - 2*xi**3, h*(xi**3 - xi**2)]
   end function hermite_basis
end module beamstops_hermite
