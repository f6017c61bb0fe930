!> The in-memory recorder: fills arrays sized before the run (the Python path).
module beamstops_recorder_array
   use beamstops_kinds, only: wp, ik
   use beamstops_recorder, only: recorder_type, n_columns
   implicit none
   private
   public :: array_recorder

   !> Recorder keeping rows and snapshots in memory.
   type, extends(recorder_type) :: array_recorder
      !> Rows (n_columns, capacity): t, u, v, reaction, energy, work, dissipated.
      real(wp), allocatable :: rows(:, :)
      !> Snapshot times (capacity) and shapes (J+1, capacity).
      real(wp), allocatable :: snap_t(:), snap_u(:, :)
      !> Rows and snapshots filled.
      integer(ik) :: filled = 0, snaps = 0
   contains
      procedure :: reserve
      procedure :: record
      procedure :: snapshot
   end type array_recorder

contains

   !> Size the arrays for `rows` records and `snapshots` snapshots of `nodes` values.
   subroutine reserve(self, rows, snapshots, nodes)
      !> Recorder.
      class(array_recorder), intent(inout) :: self
      !> Records expected.
      integer(ik), intent(in) :: rows
      !> Snapshots expected.
      integer(ik), intent(in) :: snapshots
      !> Nodes per snapshot (J+1).
      integer, intent(in) :: nodes
      allocate (self%rows(n_columns, rows), self%snap_t(snapshots), self%snap_u(nodes, snapshots))
      self%filled = 0
      self%snaps = 0
   end subroutine reserve

   subroutine record(self, row)
      class(array_recorder), intent(inout) :: self
      real(wp), intent(in) :: row(n_columns)
      if (self%filled >= size(self%rows, 2, ik)) then
         self%failed = .true.
         return
      end if
      self%filled = self%filled + 1
      self%rows(:, self%filled) = row
   end subroutine record

   subroutine snapshot(self, t, u)
      class(array_recorder), intent(inout) :: self
      real(wp), intent(in) :: t
      real(wp), intent(in) :: u(:)
      if (self%snaps >= size(self%snap_t, 1, ik)) then
         self%failed = .true.
         return
      end if
      self%snaps = self%snaps + 1
      self%snap_t(self%snaps) = t
      self%snap_u(:, self%snaps) = u
   end subroutine snapshot
end module beamstops_recorder_array
