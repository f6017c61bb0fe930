!> The in-memory recorder: fills arrays sized before the run (the Python path).
module beamstops_recorder_array
   use beamstops_kinds, only: wp, ik
   use beamstops_recorder, only: recorder_type, n_columns, col_t, all_finite
   implicit none
   private
   public :: array_recorder

   !> Recorder keeping rows and snapshots in memory.
   type, extends(recorder_type) :: array_recorder
      !> Rows (n_columns, capacity): t, u, v, reaction, energy, work, dissipated, damped.
      real(wp), allocatable :: rows(:, :)
      !> Snapshot times (capacity) and shapes (J+1, capacity).
      real(wp), allocatable :: snap_t(:), snap_u(:, :)
      !> Rows and snapshots filled.
      integer(ik) :: filled = 0, snaps = 0
      !> Stops along the span: u~ and reaction (N) of each stop at each record (m, capacity);
      !> zero-sized unless reserved.
      real(wp), allocatable :: stops_u(:, :), stops_reaction(:, :)
      !> Records of the stops filled.
      integer(ik) :: stops_filled = 0
   contains
      procedure :: reserve
      procedure :: record
      procedure :: record_stops
      procedure :: snapshot
   end type array_recorder

contains

   !> Size the arrays for `rows` records and `snapshots` snapshots of `nodes` values, and for
   !> the records of `stops` stops along the span (default 0: not kept).
   subroutine reserve(self, rows, snapshots, nodes, stops)
      !> Recorder.
      class(array_recorder), intent(inout) :: self
      !> Records expected.
      integer(ik), intent(in) :: rows
      !> Snapshots expected.
      integer(ik), intent(in) :: snapshots
      !> Nodes per snapshot (J+1).
      integer, intent(in) :: nodes
      !> Stops along the span whose records are kept.
      integer, intent(in), optional :: stops
      integer :: m
      m = 0
      if (present(stops)) m = stops
      allocate (self%rows(n_columns, rows), self%snap_t(snapshots), self%snap_u(nodes, snapshots))
      allocate (self%stops_u(m, rows), self%stops_reaction(m, rows))
      self%filled = 0
      self%snaps = 0
      self%stops_filled = 0
   end subroutine reserve

   subroutine record_stops(self, u, reaction)
      class(array_recorder), intent(inout) :: self
      real(wp), intent(in) :: u(:)
      real(wp), intent(in) :: reaction(:)
      if (.not. allocated(self%stops_u) .or. self%blew_up) return
      if (size(self%stops_u, 1) /= size(u)) return
      if (self%stops_filled >= size(self%stops_u, 2, ik)) then
         self%failed = .true.
         return
      end if
      self%stops_filled = self%stops_filled + 1
      self%stops_u(:, self%stops_filled) = u
      self%stops_reaction(:, self%stops_filled) = reaction
   end subroutine record_stops

   subroutine record(self, row)
      class(array_recorder), intent(inout) :: self
      real(wp), intent(in) :: row(n_columns)
      if (self%blew_up .or. .not. all_finite(n_columns, row)) then
         call self%stop_keeping(row(col_t))
         ! the stops' values of this row came just before it
         if (self%stops_filled > self%filled) self%stops_filled = self%filled
         return
      end if
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
      if (self%blew_up .or. .not. all_finite(size(u), u)) then
         call self%stop_keeping(t)
         return
      end if
      if (self%snaps >= size(self%snap_t, 1, ik)) then
         self%failed = .true.
         return
      end if
      self%snaps = self%snaps + 1
      self%snap_t(self%snaps) = t
      self%snap_u(:, self%snaps) = u
   end subroutine snapshot
end module beamstops_recorder_array
