!> The recorder interface: the time loop hands every `record_every`-th step's
!> tip and energy values (and those of the stops along the span, just before), and every
!> `snapshot_every`-th step's shape, to a recorder.
!> Implementations: the HDF5 file writer (program) and the array recorder (Python).
!> A recorder never sees the loop's state: checkpoints are taken by the caller of the loop
!> (beamstops_run), which flushes the recorder first.
module beamstops_recorder
   use beamstops_kinds, only: wp, ik
   implicit none
   private
   public :: recorder_type, n_columns, col_t, col_u, col_v, col_reaction, col_energy, col_work, col_dissipated
   public :: col_damped, all_finite

   !> Columns of a record row; col_damped: the energy the Rayleigh damping took so far (J).
   integer, parameter :: col_t = 1, col_u = 2, col_v = 3, col_reaction = 4, col_energy = 5, &
      & col_work = 6, col_dissipated = 7, col_damped = 8, n_columns = 8

   !> Receives records from the time loop.
   type, abstract :: recorder_type
      !> Set by an implementation that can no longer write; the loop stops.
      logical :: failed = .false.
      !> What failed, naming the file (when the implementation says).
      character(len=:), allocatable :: message
      !> Set by `stop_keeping` when values handed over were not finite (the solution blew up): from
      !> then on nothing more is kept, and the loop's caller ends the run 'diverged'.
      logical :: blew_up = .false.
      !> The time of those values (s).
      real(wp) :: blew_up_at = 0
   contains
      !> Keep nothing more: values handed over were not finite.
      procedure :: stop_keeping
      !> Take one row (t, tip u, tip v, reaction, energy, work, dissipated, damped).
      procedure(record_interface), deferred :: record
      !> Take one snapshot of the physical displacement at the nodes x_0..x_J.
      procedure(snapshot_interface), deferred :: snapshot
      !> Take the stops' values of the row that follows: u~ and reaction of each stop along the
      !> span (default: nothing).
      procedure :: record_stops
      !> Told between blocks of steps how far the run is (default: nothing).
      procedure :: progress
      !> Put everything taken so far into storage and say how many records and snapshots that is
      !> (before a checkpoint; default: nothing is stored).
      procedure :: flush => flush_nothing
   end type recorder_type

   abstract interface
      subroutine record_interface(self, row)
         import :: recorder_type, wp, n_columns
         class(recorder_type), intent(inout) :: self
         real(wp), intent(in) :: row(n_columns)
      end subroutine record_interface
      subroutine snapshot_interface(self, t, u)
         import :: recorder_type, wp
         class(recorder_type), intent(inout) :: self
         real(wp), intent(in) :: t
         real(wp), intent(in) :: u(:)
      end subroutine snapshot_interface
   end interface

contains

   !> Whether the n values are all finite: no NaN and no infinity among them (the test the HDF5
   !> recorder's stream_row makes of a record row).
   pure function all_finite(n, values) result(ok)
      !> Number of values.
      integer, intent(in) :: n
      !> Values.
      real(wp), intent(in) :: values(n)
      logical :: ok
      ok = all(abs(values) <= huge(values))
   end function all_finite

   !> Values handed over at time t were not finite (all_finite): keep nothing from now on, and
   !> say when it happened first.
   subroutine stop_keeping(self, t)
      !> Recorder.
      class(recorder_type), intent(inout) :: self
      !> Time of the values (s).
      real(wp), intent(in) :: t
      if (self%blew_up) return
      self%blew_up = .true.
      self%blew_up_at = t
   end subroutine stop_keeping

   !> Default progress report: none.
   subroutine progress(self, step, steps)
      !> Recorder.
      class(recorder_type), intent(inout) :: self
      !> Steps done.
      integer(ik), intent(in) :: step
      !> Steps in the run.
      integer(ik), intent(in) :: steps
   end subroutine progress

   !> Default record of the stops along the span: none.
   subroutine record_stops(self, u, reaction)
      !> Recorder.
      class(recorder_type), intent(inout) :: self
      !> Physical displacement u~ at each stop (m) (m).
      real(wp), intent(in) :: u(:)
      !> Reaction of each stop in the step that brought u~ there (N) (m).
      real(wp), intent(in) :: reaction(:)
   end subroutine record_stops

   !> Default flush: nothing is stored.
   subroutine flush_nothing(self, records, snapshots)
      !> Recorder.
      class(recorder_type), intent(inout) :: self
      !> Records stored.
      integer(ik), intent(out) :: records
      !> Snapshots stored.
      integer(ik), intent(out) :: snapshots
      records = 0
      snapshots = 0
   end subroutine flush_nothing
end module beamstops_recorder
