!> The chunks' vectors of a lockstep block (u, d, S u, rhs, g and C d of each chunk, (lanes, n) each)
!> in one allocation whose vectors start on a 64-byte boundary: a row of a chunk (lockstep_lanes
!> = 8 doubles) is then one cache line, so that each whole-register load and store of the
!> kernels touches one line instead of two. ALLOCATE gives the alignment of malloc (16 bytes),
!> so a (lanes, n, chunks) array starts on a line only by chance; measured on the paper's scene
!> (J = 19, K = 8, one chunk), the dependent step of the kernels took 163 ns aligned against
!> 199-207 ns at the seven other offsets.
!>
!> The kernels of beamstops_band_solve_lockstep take explicit-shape arrays, so a vector is
!> handed to them as its first element (store(at(part, c))), by sequence association.
module beamstops_lockstep_store
   use, intrinsic :: iso_c_binding, only: c_loc, c_intptr_t
   use beamstops_kinds, only: wp
   use beamstops_band_solve_lockstep, only: lockstep_lanes
   implicit none
   private
   public :: chunk_store, fill_store, give_back, put_lane
   public :: part_u, part_d, part_su, part_rhs, part_g, part_cd

   !> The vectors of a chunk, in the order they are stored.
   integer, parameter :: part_u = 0, part_d = 1, part_su = 2, part_rhs = 3, part_g = 4, part_cd = 5, parts = 6
   !> Alignment of each vector (bytes) and its value in doubles.
   integer, parameter :: line_bytes = 64, line_values = line_bytes/8

   !> The chunks' vectors, aligned.
   type :: chunk_store
      !> The values; vector `part` of chunk c is store(at(part, c) : at(part, c) + lanes n - 1).
      real(wp), allocatable :: store(:)
      !> Unknowns n, chunks, and the index of the first value on a line boundary.
      integer :: n = 0, chunks = 0, first = 1
   contains
      !> Index of the first value of a chunk's vector.
      procedure :: at
      !> Index of a chunk's vector's row j (its lockstep_lanes values).
      procedure :: row
      !> Index of its last value in row j.
      procedure :: row_end
   end type chunk_store

contains

   !> The store of u, d, S u, g and C d (lanes, n, chunks; C d zero when absent), rhs zero.
   subroutine fill_store(w, u, d, su, g, cd)
      !> The store, allocated and filled.
      type(chunk_store), intent(out), target :: w
      !> The members' vectors (lanes, n, chunks).
      real(wp), intent(in), contiguous :: u(:, :, :), d(:, :, :), su(:, :, :), g(:, :, :)
      !> C d^{n-1} (damping), when the loop carries it.
      real(wp), intent(in), contiguous, optional :: cd(:, :, :)
      integer(c_intptr_t) :: address
      integer :: c, size_of
      w%n = size(u, 2)
      w%chunks = size(u, 3)
      size_of = lockstep_lanes*w%n
      allocate (w%store(parts*size_of*w%chunks + line_values - 1))
      address = transfer(c_loc(w%store(1)), address)
      w%first = 1 + int(mod(line_bytes - mod(address, int(line_bytes, c_intptr_t)), int(line_bytes, c_intptr_t)))/8
      w%store = 0
      do c = 1, w%chunks
         call copy(size_of, u(:, :, c), w%store(w%at(part_u, c)))
         call copy(size_of, d(:, :, c), w%store(w%at(part_d, c)))
         call copy(size_of, su(:, :, c), w%store(w%at(part_su, c)))
         call copy(size_of, g(:, :, c), w%store(w%at(part_g, c)))
         if (present(cd)) call copy(size_of, cd(:, :, c), w%store(w%at(part_cd, c)))
      end do
   end subroutine fill_store

   !> u, d, S u (and C d) back into the members' arrays (lanes, n, chunks).
   subroutine give_back(w, u, d, su, cd)
      !> The store.
      type(chunk_store), intent(in) :: w
      !> The members' vectors.
      real(wp), intent(inout), contiguous :: u(:, :, :), d(:, :, :), su(:, :, :)
      !> C d^{n-1} (damping), when the loop carries it.
      real(wp), intent(inout), contiguous, optional :: cd(:, :, :)
      integer :: c, size_of
      size_of = lockstep_lanes*w%n
      do c = 1, w%chunks
         call copy(size_of, w%store(w%at(part_u, c)), u(:, :, c))
         call copy(size_of, w%store(w%at(part_d, c)), d(:, :, c))
         call copy(size_of, w%store(w%at(part_su, c)), su(:, :, c))
         if (present(cd)) call copy(size_of, w%store(w%at(part_cd, c)), cd(:, :, c))
      end do
   end subroutine give_back

   !> One lane of a chunk's vector into a member's array: x(i, :, c) = that lane's values.
   subroutine put_lane(w, part, c, i, x)
      !> The store.
      type(chunk_store), intent(in) :: w
      !> The vector, chunk and lane.
      integer, intent(in) :: part, c, i
      !> The members' array (lanes, n, chunks).
      real(wp), intent(inout) :: x(:, :, :)
      integer :: j
      do j = 1, w%n
         x(i, j, c) = w%store(w%row(part, c, j) + i - 1)
      end do
   end subroutine put_lane

   !> Index of the first value of vector `part` of chunk c.
   pure integer function at(w, part, c)
      !> The store.
      class(chunk_store), intent(in) :: w
      !> The vector and chunk.
      integer, intent(in) :: part, c
      at = w%first + ((c - 1)*parts + part)*lockstep_lanes*w%n
   end function at

   !> Index of row j (the lockstep_lanes values of unknown j) of vector `part` of chunk c.
   pure integer function row(w, part, c, j)
      !> The store.
      class(chunk_store), intent(in) :: w
      !> The vector, chunk and unknown.
      integer, intent(in) :: part, c, j
      row = w%at(part, c) + (j - 1)*lockstep_lanes
   end function row

   !> Index of the last value of row j of vector `part` of chunk c.
   pure integer function row_end(w, part, c, j)
      !> The store.
      class(chunk_store), intent(in) :: w
      !> The vector, chunk and unknown.
      integer, intent(in) :: part, c, j
      row_end = w%row(part, c, j) + lockstep_lanes - 1
   end function row_end

   !> y = x, m values (explicit shape: sections and elements by sequence association).
   pure subroutine copy(m, x, y)
      integer, intent(in) :: m
      real(wp), intent(in) :: x(m)
      real(wp), intent(out) :: y(m)
      y = x
   end subroutine copy
end module beamstops_lockstep_store
