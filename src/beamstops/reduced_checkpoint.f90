!> Checkpoints of reduced (modal) runs (&mesh modes > 0): the reduced loop's state (q, d, the
!> scalars, the stops' reactions, the energy the damping took, the observer), the number of
!> records and snapshots already in the output, and the scene's signature (which holds `modes`),
!> in the checkpoint file of beamstops_checkpoint (same frame: written atomically, refused for
!> another scene). The reduced model itself is rebuilt from the scene on resume (the same
!> operations give the same bits), so a resumed run continues bit for bit.
module beamstops_reduced_checkpoint
   use hdf5, only: hid_t
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type
   use beamstops_scene, only: scene_type, stop_count
   use beamstops_checkpoint, only: scene_signature, create_checkpoint, commit_checkpoint, open_checkpoint, &
      & close_checkpoint
   use beamstops_recorder_hdf5_vector, only: write_vector, read_vector
   use beamstops_reduced, only: reduced_model_type
   use beamstops_reduced_scheme, only: reduced_state_type, resume_reduced
   implicit none
   private
   public :: write_reduced_checkpoint, read_reduced_checkpoint

   integer, parameter :: n_scalars = 17

contains

   !> Write the checkpoint `path` of a reduced run atomically.
   subroutine write_reduced_checkpoint(path, scene, state, records, snapshots, error)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      !> Scene of the run.
      type(scene_type), intent(in) :: scene
      !> State after the last step done.
      type(reduced_state_type), intent(in) :: state
      !> Records and snapshots already in the output file.
      integer(ik), intent(in) :: records, snapshots
      !> Set when the file cannot be written.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: observer(:)
      integer(hid_t) :: file
      logical :: ok(5)
      call create_checkpoint(path, file, error)
      if (allocated(error)) return
      call write_vector(file, 'signature', scene_signature(scene), ok(1))
      call write_vector(file, 'scalars', scalars_of(state, records, snapshots), ok(2))
      call write_vector(file, 'q', state%q, ok(3))
      call write_vector(file, 'd', state%d, ok(4))
      ok(5) = .true.
      if (allocated(state%stop_reaction)) call write_vector(file, 'stop_reaction', state%stop_reaction, ok(5))
      if (ok(5) .and. state%observer%active) then
         call state%observer%pack(observer)
         call write_vector(file, 'observer_length', [real(size(observer), wp)], ok(5))
         if (ok(5)) call write_vector(file, 'observer', observer, ok(5))
      end if
      call commit_checkpoint(path, file, all(ok), error)
   end subroutine write_reduced_checkpoint

   !> Read the checkpoint `path` of a reduced run of `scene`: the state, ready to run
   !> (resume_reduced), and the records and snapshots the output held at that moment.
   subroutine read_reduced_checkpoint(path, scene, reduced, state, records, snapshots, error)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      !> Scene of the run to resume (must be the checkpoint's).
      type(scene_type), intent(in) :: scene
      !> Its reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> State restored.
      type(reduced_state_type), intent(out) :: state
      !> Records and snapshots the output held at the checkpoint.
      integer(ik), intent(out) :: records, snapshots
      !> Set when the file is unreadable or belongs to another scene.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: signature(:), observer(:)
      type(error_type), allocatable :: failure
      real(wp) :: scalars(n_scalars), length(1)
      integer(hid_t) :: file
      logical :: ok(5)
      records = 0
      snapshots = 0
      signature = scene_signature(scene)
      allocate (state%q(reduced%size), state%d(reduced%size))
      if (stop_count(scene) > 0) allocate (state%stop_reaction(stop_count(scene)))
      call open_checkpoint(path, file, error)
      if (allocated(error)) return
      call read_vector(file, 'signature', signature, ok(1))
      call read_vector(file, 'scalars', scalars, ok(2))
      call read_vector(file, 'q', state%q, ok(3))
      call read_vector(file, 'd', state%d, ok(4))
      ok(5) = .true.
      if (allocated(state%stop_reaction)) call read_vector(file, 'stop_reaction', state%stop_reaction, ok(5))
      if (ok(5) .and. scene%statistics) then
         call read_vector(file, 'observer_length', length, ok(5))
         if (ok(5)) then
            allocate (observer(nint(length(1))))
            call read_vector(file, 'observer', observer, ok(5))
         end if
         if (ok(5)) then
            call state%observer%unpack(observer, failure)
            ok(5) = .not. allocated(failure)
         end if
      end if
      call close_checkpoint(path, file, all(ok), signature, scene, error)
      if (allocated(error)) return
      call restore_scalars(scalars, state, records, snapshots)
      call resume_reduced(reduced, state, error)
   end subroutine read_reduced_checkpoint

   !> The state's scalars, the record counts included, as one vector (integers are exact in it).
   pure function scalars_of(state, records, snapshots) result(v)
      type(reduced_state_type), intent(in) :: state
      integer(ik), intent(in) :: records, snapshots
      real(wp) :: v(n_scalars)
      v = [real(state%step, wp), state%sigma_prev, state%sigma_now, state%gd_prev, state%p_prev, state%p_now, &
         & state%work, state%dissipated, state%energy0, state%reaction, merge(1.0_wp, 0.0_wp, state%in_contact), &
         & real(state%impacts, wp), state%cpu_seconds, state%max_violation, real(records, wp), real(snapshots, wp), &
         & state%damped]
   end function scalars_of

   pure subroutine restore_scalars(v, state, records, snapshots)
      real(wp), intent(in) :: v(n_scalars)
      type(reduced_state_type), intent(inout) :: state
      integer(ik), intent(out) :: records, snapshots
      state%step = nint(v(1), ik)
      state%sigma_prev = v(2)
      state%sigma_now = v(3)
      state%gd_prev = v(4)
      state%p_prev = v(5)
      state%p_now = v(6)
      state%work = v(7)
      state%dissipated = v(8)
      state%energy0 = v(9)
      state%reaction = v(10)
      state%in_contact = v(11) /= 0
      state%impacts = nint(v(12), ik)
      state%cpu_seconds = v(13)
      state%max_violation = v(14)
      records = nint(v(15), ik)
      snapshots = nint(v(16), ik)
      state%damped = v(17)
   end subroutine restore_scalars
end module beamstops_reduced_checkpoint
