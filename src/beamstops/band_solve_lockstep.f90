!> The kd = 3 substitutions, products and dot products of beamstops_band_solve for K
!> right-hand sides at once, the member index innermost: arrays (K, n), column j holding row j
!> of every member, so that each multiply-add of a row acts on K members (SIMD across members)
!> and the chain of a step is shared by all of them.
!>
!> Bit for bit: every routine performs, for each member, the floating-point operations of its
!> one-member counterpart in beamstops_band_solve in the same order and with the same
!> expressions (so that the compiler contracts the same multiply-adds): the same row formula
!> b - o3 x3 - o2 x2 - o1 x1 of the substitutions, the same first and last rows, the same
!> sums beside the forward substitution, the same eight partial sums of `dot`. Only the place
!> where the values wait between rows differs (the columns of the arrays instead of three
!> registers), which changes no operation. tests/fortran/test_lockstep.f90 checks the result
!> against the one-scene path to the bit.
!>
!> n >= 2 kd + 2 (J >= 4) is assumed; beamstops_lockstep refuses smaller meshes.
module beamstops_band_solve_lockstep
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   use beamstops_band_solve, only: band_solver, band_diagonals
   implicit none
   private
   public :: lockstep_forward, lockstep_forward_energy, lockstep_back, lockstep_matvec, lockstep_dot
   public :: lockstep_min_unknowns, lockstep_work_columns

   !> Fewest unknowns these routines handle (J >= 4).
   integer, parameter :: lockstep_min_unknowns = 2*kd + 2
   !> Columns of the work arrays of these routines.
   integer, parameter :: lockstep_work_columns = 8

contains

   !> Forward substitution (I + N)^T w = b of every member (beamstops_band_solve's
   !> forward_substitution): b replaced by D^{-2} w. Row j scales row j - 3, the last it needs.
   pure subroutine lockstep_forward(solver, b)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> Right-hand sides (K, n), replaced by D^{-2} w.
      real(wp), intent(inout), contiguous :: b(:, :)
      integer :: j, n
      n = solver%n
      associate (off => solver%off, inv_d2 => solver%inv_d2)
         b(:, 2) = b(:, 2) - off(3, 2)*b(:, 1)
         b(:, 3) = b(:, 3) - off(2, 3)*b(:, 1) - off(3, 3)*b(:, 2)
         do j = kd + 1, n
            b(:, j) = b(:, j) - off(1, j)*b(:, j - 3) - off(2, j)*b(:, j - 2) - off(3, j)*b(:, j - 1)
            b(:, j - 3) = b(:, j - 3)*inv_d2(j - 3)
         end do
         do j = n - 2, n
            b(:, j) = b(:, j)*inv_d2(j)
         end do
      end associate
   end subroutine lockstep_forward

   !> lockstep_forward with the dot products of the discrete energy of each member beside it
   !> (beamstops_band_solve's forward_substitution_energy): usu = u.su, dsu = d.su, dmd = d.M d.
   pure subroutine lockstep_forward_energy(solver, mass, u, d, su, b, usu, dsu, dmd, work)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> M by diagonals.
      type(band_diagonals), intent(in) :: mass
      !> u, d and su of every member (K, n).
      real(wp), intent(in), contiguous :: u(:, :), d(:, :), su(:, :)
      !> Right-hand sides (K, n), replaced by D^{-2} w.
      real(wp), intent(inout), contiguous :: b(:, :)
      !> u.su, d.su and d.M d of every member (K).
      real(wp), intent(out), contiguous :: usu(:), dsu(:), dmd(:)
      !> Work array (K, lockstep_work_columns).
      real(wp), intent(out), contiguous :: work(:, :)
      integer :: j, n, last_triple
      n = solver%n
      last_triple = kd + ((n - kd)/3)*3
      associate (off => solver%off, inv_d2 => solver%inv_d2, m => mass%a)
         b(:, 2) = b(:, 2) - off(3, 2)*b(:, 1)
         b(:, 3) = b(:, 3) - off(2, 3)*b(:, 1) - off(3, 3)*b(:, 2)
         usu = u(:, 1)*su(:, 1) + u(:, 2)*su(:, 2) + u(:, 3)*su(:, 3)
         dsu = d(:, 1)*su(:, 1) + d(:, 2)*su(:, 2) + d(:, 3)*su(:, 3)
         dmd = d(:, 1)*m(1, 0)*d(:, 1) + d(:, 2)*(m(2, 0)*d(:, 2) + 2*m(2, 1)*d(:, 1)) &
            & + d(:, 3)*(m(3, 0)*d(:, 3) + 2*(m(3, 1)*d(:, 2) + m(3, 2)*d(:, 1)))
         do j = kd + 1, n
            b(:, j) = b(:, j) - off(1, j)*b(:, j - 3) - off(2, j)*b(:, j - 2) - off(3, j)*b(:, j - 1)
            b(:, j - 3) = b(:, j - 3)*inv_d2(j - 3)
            if (j <= last_triple .or. n - last_triple == 1) then
               usu = usu + u(:, j)*su(:, j)
               dsu = dsu + d(:, j)*su(:, j)
               dmd = dmd + d(:, j)*(m(j, 0)*d(:, j) + 2*(m(j, 1)*d(:, j - 1) + m(j, 2)*d(:, j - 2) &
                  & + m(j, 3)*d(:, j - 3)))
            else
               ! two rows after the last triple: each term rounded before it is added
               work(:, 1) = u(:, j)*su(:, j)
               work(:, 2) = d(:, j)*su(:, j)
               work(:, 3) = d(:, j)*(m(j, 0)*d(:, j) + 2*(m(j, 1)*d(:, j - 1) + m(j, 2)*d(:, j - 2) &
                  & + m(j, 3)*d(:, j - 3)))
               usu = usu + work(:, 1)
               dsu = dsu + work(:, 2)
               dmd = dmd + work(:, 3)
            end if
         end do
         do j = n - 2, n
            b(:, j) = b(:, j)*inv_d2(j)
         end do
      end associate
   end subroutine lockstep_forward_energy

   !> Back substitution (I + N) x = b of every member (beamstops_band_solve's
   !> back_substitution, its edge rows included).
   pure subroutine lockstep_back(solver, b, work)
      !> Solver from prepare_solver.
      type(band_solver), intent(in) :: solver
      !> D^{-2} w (K, n), replaced by x.
      real(wp), intent(inout), contiguous :: b(:, :)
      !> Work array (K, lockstep_work_columns).
      real(wp), intent(out), contiguous :: work(:, :)
      integer :: i, n
      n = solver%n
      associate (off => solver%off)
         ! the edge rows, each product rounded before its subtraction (see the module's notes)
         work(:, 1) = off(3, n)*b(:, n)
         b(:, n - 1) = b(:, n - 1) - work(:, 1)
         work(:, 1) = off(2, n)*b(:, n)
         b(:, n - 2) = b(:, n - 2) - work(:, 1)
         work(:, 1) = off(3, n - 1)*b(:, n - 1)
         b(:, n - 2) = b(:, n - 2) - work(:, 1)
         do i = n - kd, 1, -1
            b(:, i) = b(:, i) - off(1, i + 3)*b(:, i + 3) - off(2, i + 2)*b(:, i + 2) - off(3, i + 1)*b(:, i + 1)
         end do
      end associate
   end subroutine lockstep_back

   !> y = A x of every member for a symmetric band matrix by diagonals (beamstops_band_solve's
   !> diagonal_matvec, n >= 2 kd + 1).
   pure subroutine lockstep_matvec(diagonals, x, y)
      !> Matrix by diagonals.
      type(band_diagonals), intent(in) :: diagonals
      !> Vectors (K, n).
      real(wp), intent(in), contiguous :: x(:, :)
      !> Products (K, n).
      real(wp), intent(out), contiguous :: y(:, :)
      integer :: j, n
      n = diagonals%n
      associate (a => diagonals%a)
         y(:, 1) = a(1, 0)*x(:, 1) + a(2, 1)*x(:, 2) + a(3, 2)*x(:, 3) + a(4, 3)*x(:, 4)
         y(:, 2) = a(2, 1)*x(:, 1) + a(2, 0)*x(:, 2) + a(3, 1)*x(:, 3) + a(4, 2)*x(:, 4) + a(5, 3)*x(:, 5)
         y(:, 3) = a(3, 2)*x(:, 1) + a(3, 1)*x(:, 2) + a(3, 0)*x(:, 3) + a(4, 1)*x(:, 4) + a(5, 2)*x(:, 5) &
            & + a(6, 3)*x(:, 6)
         do j = kd + 1, n - kd
            y(:, j) = a(j, 3)*x(:, j - 3) + a(j, 2)*x(:, j - 2) + a(j, 1)*x(:, j - 1) + a(j, 0)*x(:, j) &
               & + a(j + 1, 1)*x(:, j + 1) + a(j + 2, 2)*x(:, j + 2) + a(j + 3, 3)*x(:, j + 3)
         end do
         y(:, n - 2) = a(n - 2, 3)*x(:, n - 5) + a(n - 2, 2)*x(:, n - 4) + a(n - 2, 1)*x(:, n - 3) &
            & + a(n - 2, 0)*x(:, n - 2) + a(n - 1, 1)*x(:, n - 1) + a(n, 2)*x(:, n)
         y(:, n - 1) = a(n - 1, 3)*x(:, n - 4) + a(n - 1, 2)*x(:, n - 3) + a(n - 1, 1)*x(:, n - 2) &
            & + a(n - 1, 0)*x(:, n - 1) + a(n, 1)*x(:, n)
         y(:, n) = a(n, 3)*x(:, n - 3) + a(n, 2)*x(:, n - 2) + a(n, 1)*x(:, n - 1) + a(n, 0)*x(:, n)
      end associate
   end subroutine lockstep_matvec

   !> s_k = x_k . y_k of every member with the eight partial sums of beamstops_band_solve's dot.
   pure subroutine lockstep_dot(x, y, partial, s)
      !> Vectors (K, n).
      real(wp), intent(in), contiguous :: x(:, :), y(:, :)
      !> Work array (K, 8).
      real(wp), intent(out), contiguous :: partial(:, :)
      !> The dot products (K).
      real(wp), intent(out), contiguous :: s(:)
      integer :: j, n
      n = size(x, 2)
      partial = 0
      do j = 1, n - 7, 8
         partial(:, 1) = partial(:, 1) + x(:, j)*y(:, j)
         partial(:, 2) = partial(:, 2) + x(:, j + 1)*y(:, j + 1)
         partial(:, 3) = partial(:, 3) + x(:, j + 2)*y(:, j + 2)
         partial(:, 4) = partial(:, 4) + x(:, j + 3)*y(:, j + 3)
         partial(:, 5) = partial(:, 5) + x(:, j + 4)*y(:, j + 4)
         partial(:, 6) = partial(:, 6) + x(:, j + 5)*y(:, j + 5)
         partial(:, 7) = partial(:, 7) + x(:, j + 6)*y(:, j + 6)
         partial(:, 8) = partial(:, 8) + x(:, j + 7)*y(:, j + 7)
      end do
      s = ((partial(:, 1) + partial(:, 5)) + (partial(:, 2) + partial(:, 6))) &
         & + ((partial(:, 3) + partial(:, 7)) + (partial(:, 4) + partial(:, 8)))
      ! the rows after the last eight: by fours, each product rounded and added in order, then
      ! the last (at most three) by multiply-adds (see the module's notes)
      if (n - j + 1 >= 4) then
         do j = j, n - 3, 4
            partial(:, 1:4) = x(:, j:j + 3)*y(:, j:j + 3)
            s = s + partial(:, 1)
            s = s + partial(:, 2)
            s = s + partial(:, 3)
            s = s + partial(:, 4)
         end do
      end if
      do j = j, n
         s = s + x(:, j)*y(:, j)
      end do
   end subroutine lockstep_dot
end module beamstops_band_solve_lockstep
