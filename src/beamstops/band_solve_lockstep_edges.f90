!> The rows of the lockstep kernels that both of their shapes share (beamstops_band_solve_lockstep:
!> beamstops_band_solve_lockstep_narrow for 16 vector registers, beamstops_band_solve_lockstep_wide
!> for 32): the lanes, the first and last rows of the two substitutions and of the product by S,
!> and g.d in the back substitution's order. Arrays (lanes, n), member index innermost; each row a
!> loop over the lanes, marked for vectorization. Per lane, the operations of the one-member rows
!> of beamstops_band_solve in the same order (the notes of beamstops_band_solve_lockstep).
module beamstops_band_solve_lockstep_edges
   use beamstops_kinds, only: wp
   use beamstops_band, only: kd
   implicit none
   private
   public :: lockstep_lanes, forward_first_rows, forward_last_rows, back_first_rows, back_last_rows
   public :: back_update_first_rows, back_update_last_rows
   public :: matvec_rhs_first_rows, matvec_rhs_last_rows, lockstep_load_work, load_work_first_rows, load_work_last_rows

   !> Members the kernels advance at once (the first extent of their arrays): one AVX-512
   !> register of doubles, two of AVX2.
   integer, parameter :: lockstep_lanes = 8

contains

   !> The first three rows of the forward substitution of every lane: b(:, 1:3) replaced by
   !> D^{-2} w(:, 1:3), w(:, 1:3) returned in xa, xb, xc (beamstops_band_solve's first_rows).
   pure subroutine forward_first_rows(off, inv_d2, n, b, xa, xb, xc)
      !> Unknowns, the factor's off-diagonals and 1/U(j,j)^2 (beamstops_band_solve's band_solver).
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
      !> Right-hand sides (lanes, n), their first three rows replaced.
      real(wp), intent(inout) :: b(lockstep_lanes, n)
      !> w(:, 1:3).
      real(wp), intent(out) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         xa(k) = b(k, 1)
         xb(k) = b(k, 2) - off(3, 2)*xa(k)
         xc(k) = b(k, 3) - off(2, 3)*xa(k) - off(3, 3)*xb(k)
         b(k, 1) = xa(k)*inv_d2(1)
         b(k, 2) = xb(k)*inv_d2(2)
         b(k, 3) = xc(k)*inv_d2(3)
      end do
   end subroutine forward_first_rows

   !> The rows j and j+1 (those of them <= n) left after a forward substitution's loop by three
   !> (beamstops_band_solve's last_rows); xa, xb, xc hold w_{j-3}, w_{j-2}, w_{j-1}.
   pure subroutine forward_last_rows(off, inv_d2, j, n, b, xa, xb, xc)
      !> First row left, and unknowns.
      integer, intent(in) :: j, n
      !> The factor's off-diagonals and 1/U(j,j)^2.
      real(wp), intent(in) :: off(kd, n), inv_d2(n)
      !> Right-hand sides (lanes, n), rows j and j+1 replaced.
      real(wp), intent(inout) :: b(lockstep_lanes, n)
      !> The running values.
      real(wp), intent(inout) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: k
      if (j <= n) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, j) - off(1, j)*xa(k) - off(2, j)*xb(k) - off(3, j)*xc(k)
            b(k, j) = xa(k)*inv_d2(j)
         end do
      end if
      if (j + 1 <= n) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            b(k, j + 1) = (b(k, j + 1) - off(1, j + 1)*xb(k) - off(2, j + 1)*xc(k) - off(3, j + 1)*xa(k))*inv_d2(j + 1)
         end do
      end if
   end subroutine forward_last_rows

   !> The last kd rows of the back substitution of every lane, x_n, x_{n-1}, x_{n-2} (farthest
   !> value first, as beamstops_band_solve's back_rows), returned in xa, xb, xc too.
   pure subroutine back_first_rows(off, n, b, xa, xb, xc)
      !> The factor's off-diagonals, and unknowns.
      integer, intent(in) :: n
      real(wp), intent(in) :: off(kd, n)
      !> D^{-2} w (lanes, n), its last kd rows replaced by those of x.
      real(wp), intent(inout) :: b(lockstep_lanes, n)
      !> x_n, x_{n-1}, x_{n-2}.
      real(wp), intent(out) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         ! the edge rows, farthest value first (as back_rows)
         b(k, n - 1) = b(k, n - 1) - off(3, n)*b(k, n)
         b(k, n - 2) = b(k, n - 2) - off(2, n)*b(k, n) - off(3, n - 1)*b(k, n - 1)
         xa(k) = b(k, n)
         xb(k) = b(k, n - 1)
         xc(k) = b(k, n - 2)
      end do
   end subroutine back_first_rows

   !> The rows i and i-1 (those of them >= 1) left after a back substitution's loop by three;
   !> xa, xb, xc hold x_{i+3}, x_{i+2}, x_{i+1}.
   pure subroutine back_last_rows(off, i, n, b, xa, xb, xc)
      !> First row left, and unknowns.
      integer, intent(in) :: i, n
      !> The factor's off-diagonals.
      real(wp), intent(in) :: off(kd, n)
      !> D^{-2} w (lanes, n), rows i and i-1 replaced by those of x.
      real(wp), intent(inout) :: b(lockstep_lanes, n)
      !> The running values.
      real(wp), intent(inout) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: k
      if (i >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, i) - off(1, i + 3)*xa(k) - off(2, i + 2)*xb(k) - off(3, i + 1)*xc(k)
            b(k, i) = xa(k)
         end do
      end if
      if (i - 1 >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            b(k, i - 1) = b(k, i - 1) - off(1, i + 2)*xb(k) - off(2, i + 1)*xc(k) - off(3, i)*xa(k)
         end do
      end if
   end subroutine back_last_rows

   !> The last kd rows of the update that rides on the back substitution (d = d + x + c z, u = u + d)
   !> from those of x (lockstep_back_edge's), returned in xa, xb, xc.
   pure subroutine back_update_first_rows(n, b, c, z, d, u, xa, xb, xc)
      !> Unknowns, D^{-2} w with its last kd rows those of x (lanes, n), the multiples of z
      !> (lanes) and z (n).
      integer, intent(in) :: n
      real(wp), intent(in) :: b(lockstep_lanes, n), c(lockstep_lanes), z(n)
      !> d and u (lanes, n), their last kd rows updated.
      real(wp), intent(inout) :: d(lockstep_lanes, n), u(lockstep_lanes, n)
      !> x_n, x_{n-1}, x_{n-2}.
      real(wp), intent(out) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         xa(k) = b(k, n)
         xb(k) = b(k, n - 1)
         xc(k) = b(k, n - 2)
         d(k, n) = d(k, n) + xa(k) + c(k)*z(n)
         u(k, n) = u(k, n) + d(k, n)
         d(k, n - 1) = d(k, n - 1) + xb(k) + c(k)*z(n - 1)
         u(k, n - 1) = u(k, n - 1) + d(k, n - 1)
         d(k, n - 2) = d(k, n - 2) + xc(k) + c(k)*z(n - 2)
         u(k, n - 2) = u(k, n - 2) + d(k, n - 2)
      end do
   end subroutine back_update_first_rows

   !> back_last_rows with the update of those rows riding on them (d = d + x + c z, u = u + d),
   !> x not stored.
   pure subroutine back_update_last_rows(off, i, n, b, c, z, d, u, xa, xb, xc)
      !> First row left, and unknowns.
      integer, intent(in) :: i, n
      !> The factor's off-diagonals, D^{-2} w (lanes, n), the multiples of z (lanes) and z (n).
      real(wp), intent(in) :: off(kd, n), b(lockstep_lanes, n), c(lockstep_lanes), z(n)
      !> d and u (lanes, n), rows i and i-1 updated.
      real(wp), intent(inout) :: d(lockstep_lanes, n), u(lockstep_lanes, n)
      !> The running values.
      real(wp), intent(inout) :: xa(lockstep_lanes), xb(lockstep_lanes), xc(lockstep_lanes)
      integer :: k
      if (i >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xa(k) = b(k, i) - off(1, i + 3)*xa(k) - off(2, i + 2)*xb(k) - off(3, i + 1)*xc(k)
            d(k, i) = d(k, i) + xa(k) + c(k)*z(i)
            u(k, i) = u(k, i) + d(k, i)
         end do
      end if
      if (i - 1 >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            xb(k) = b(k, i - 1) - off(1, i + 2)*xb(k) - off(2, i + 1)*xc(k) - off(3, i)*xa(k)
            d(k, i - 1) = d(k, i - 1) + xb(k) + c(k)*z(i - 1)
            u(k, i - 1) = u(k, i - 1) + d(k, i - 1)
         end do
      end if
   end subroutine back_update_last_rows

   !> The first kd rows of the product by S and the right-hand side (beamstops_band_solve's
   !> edge_rows, then rhs = a g - b y).
   pure subroutine matvec_rhs_first_rows(n, s, x, a, g, b, y, rhs)
      !> Unknowns, S by diagonals, x (lanes, n), dt^2 times the load weights (lanes), the load
      !> vectors (lanes, n), dt^2.
      integer, intent(in) :: n
      real(wp), intent(in) :: s(n, 0:kd), x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b
      !> S x and the right-hand sides (lanes, n), their first kd rows set.
      real(wp), intent(inout) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      integer :: k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         y(k, 1) = s(1, 0)*x(k, 1) + s(2, 1)*x(k, 2) + s(3, 2)*x(k, 3) + s(4, 3)*x(k, 4)
         y(k, 2) = s(2, 1)*x(k, 1) + s(2, 0)*x(k, 2) + s(3, 1)*x(k, 3) + s(4, 2)*x(k, 4) + s(5, 3)*x(k, 5)
         y(k, 3) = s(3, 2)*x(k, 1) + s(3, 1)*x(k, 2) + s(3, 0)*x(k, 3) + s(4, 1)*x(k, 4) + s(5, 2)*x(k, 5) &
            & + s(6, 3)*x(k, 6)
         rhs(k, 1) = a(k)*g(k, 1) - b*y(k, 1)
         rhs(k, 2) = a(k)*g(k, 2) - b*y(k, 2)
         rhs(k, 3) = a(k)*g(k, 3) - b*y(k, 3)
      end do
   end subroutine matvec_rhs_first_rows

   !> The last kd rows of the product by S and the right-hand side, and the spring term of the
   !> tip row n-1.
   pure subroutine matvec_rhs_last_rows(n, s, x, a, g, b, spring, y, rhs)
      !> As matvec_rhs_first_rows, and the force term of the tip row (lanes).
      integer, intent(in) :: n
      real(wp), intent(in) :: s(n, 0:kd), x(lockstep_lanes, n), a(lockstep_lanes), g(lockstep_lanes, n), b, &
         & spring(lockstep_lanes)
      !> S x and the right-hand sides (lanes, n), their last kd rows set.
      real(wp), intent(inout) :: y(lockstep_lanes, n), rhs(lockstep_lanes, n)
      integer :: k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         y(k, n - 2) = s(n - 2, 3)*x(k, n - 5) + s(n - 2, 2)*x(k, n - 4) + s(n - 2, 1)*x(k, n - 3) &
            & + s(n - 2, 0)*x(k, n - 2) + s(n - 1, 1)*x(k, n - 1) + s(n, 2)*x(k, n)
         y(k, n - 1) = s(n - 1, 3)*x(k, n - 4) + s(n - 1, 2)*x(k, n - 3) + s(n - 1, 1)*x(k, n - 2) &
            & + s(n - 1, 0)*x(k, n - 1) + s(n, 1)*x(k, n)
         y(k, n) = s(n, 3)*x(k, n - 3) + s(n, 2)*x(k, n - 2) + s(n, 1)*x(k, n - 1) + s(n, 0)*x(k, n)
         rhs(k, n - 2) = a(k)*g(k, n - 2) - b*y(k, n - 2)
         rhs(k, n - 1) = a(k)*g(k, n - 1) - b*y(k, n - 1)
         rhs(k, n) = a(k)*g(k, n) - b*y(k, n)
         rhs(k, n - 1) = rhs(k, n - 1) + spring(k)
      end do
   end subroutine matvec_rhs_last_rows

   !> g.d of every lane in the order of beamstops_band_solve's load_work_product (row j in sum
   !> mod(n - j, 3) + 1 from the last row down, then (s1 + s2) + s3), n >= kd: after the back
   !> substitution (the narrow kernels', the general and span loops'; the wide kernels take it
   !> on the way, with load_work_first_rows and load_work_last_rows).
   pure subroutine lockstep_load_work(n, g, d, gd)
      !> Unknowns.
      integer, intent(in) :: n
      !> Load vectors and d (lanes, n).
      real(wp), intent(in) :: g(lockstep_lanes, n), d(lockstep_lanes, n)
      !> The products (lanes).
      real(wp), intent(out) :: gd(lockstep_lanes)
      real(wp) :: ga(lockstep_lanes), gb(lockstep_lanes), gc(lockstep_lanes)
      integer :: i, k
      call load_work_first_rows(n, g, d, ga, gb, gc)
      do i = n - kd, 3, -3
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            ga(k) = ga(k) + g(k, i)*d(k, i)
            gb(k) = gb(k) + g(k, i - 1)*d(k, i - 1)
            gc(k) = gc(k) + g(k, i - 2)*d(k, i - 2)
         end do
      end do
      call load_work_last_rows(i, n, g, d, ga, gb, gc, gd)
   end subroutine lockstep_load_work

   !> The three partial sums of lockstep_load_work started with the last kd rows' terms.
   pure subroutine load_work_first_rows(n, g, d, ga, gb, gc)
      !> Unknowns.
      integer, intent(in) :: n
      !> Load vectors and d (lanes, n).
      real(wp), intent(in) :: g(lockstep_lanes, n), d(lockstep_lanes, n)
      !> g_n d_n, g_{n-1} d_{n-1}, g_{n-2} d_{n-2} (lanes).
      real(wp), intent(out) :: ga(lockstep_lanes), gb(lockstep_lanes), gc(lockstep_lanes)
      integer :: k
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         ga(k) = g(k, n)*d(k, n)
         gb(k) = g(k, n - 1)*d(k, n - 1)
         gc(k) = g(k, n - 2)*d(k, n - 2)
      end do
   end subroutine load_work_first_rows

   !> The terms of rows i and i-1 (those of them >= 1) left after the loop by three, added into
   !> their partial sums, and g.d = (ga + gb) + gc.
   pure subroutine load_work_last_rows(i, n, g, d, ga, gb, gc, gd)
      !> First row left, and unknowns.
      integer, intent(in) :: i, n
      !> Load vectors and d (lanes, n).
      real(wp), intent(in) :: g(lockstep_lanes, n), d(lockstep_lanes, n)
      !> The partial sums (lanes).
      real(wp), intent(inout) :: ga(lockstep_lanes), gb(lockstep_lanes), gc(lockstep_lanes)
      !> The products (lanes).
      real(wp), intent(out) :: gd(lockstep_lanes)
      integer :: k
      if (i >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            ga(k) = ga(k) + g(k, i)*d(k, i)
         end do
      end if
      if (i - 1 >= 1) then
!GCC$ ivdep
!GCC$ vector
         do k = 1, lockstep_lanes
            gb(k) = gb(k) + g(k, i - 1)*d(k, i - 1)
         end do
      end if
!GCC$ ivdep
!GCC$ vector
      do k = 1, lockstep_lanes
         gd(k) = (ga(k) + gb(k)) + gc(k)
      end do
   end subroutine load_work_last_rows

end module beamstops_band_solve_lockstep_edges
