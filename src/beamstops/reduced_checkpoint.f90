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
   use beamstops_checkpoint, only: scene_signature, create_checkpoint, commit_checkpoint, open_checkpoint, check_scalars, &
      & close_checkpoint, write_observer, read_observer, write_scene_text
   use beamstops_loop_scalars, only: n_loop_scalars, loop_scalars_vector, restore_loop_scalars
   use beamstops_recorder_hdf5_vector, only: write_vector, read_vector
   use beamstops_reduced, only: reduced_model_type
   use beamstops_reduced_scheme, only: reduced_state_type, resume_reduced
   implicit none
   private
   public :: write_reduced_checkpoint, read_reduced_checkpoint

   !> The dataset `scalars`: the loop's (loop_scalars_vector), then the energy the damping took.
   integer, parameter :: n_scalars = n_loop_scalars + 1

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
      integer(hid_t) :: file
      logical :: ok(5)
      call create_checkpoint(path, file, error)
      if (allocated(error)) return
      call write_vector(file, 'signature', scene_signature(scene), ok(1))
      if (ok(1)) call write_scene_text(file, scene, ok(1))
      call write_vector(file, 'scalars', [loop_scalars_vector(state%loop_scalars_type, records, snapshots), &
         & state%damped], ok(2))
      call write_vector(file, 'q', state%q, ok(3))
      call write_vector(file, 'd', state%d, ok(4))
      ok(5) = .true.
      if (allocated(state%stop_reaction)) call write_vector(file, 'stop_reaction', state%stop_reaction, ok(5))
      if (ok(5)) call write_observer(file, state%observer, ok(5))
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
      real(wp), allocatable :: signature(:)
      real(wp) :: scalars(n_scalars)
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
      if (ok(5) .and. scene%statistics) call read_observer(file, state%observer, ok(5))
      call close_checkpoint(path, file, all(ok), signature, scene, error)
      if (allocated(error)) return
      call check_scalars(path, scene, scalars(:n_loop_scalars), [state%q, state%d, scalars(n_loop_scalars + 1:)], error)
      if (allocated(error)) return
      call restore_loop_scalars(scalars(:n_loop_scalars), state%loop_scalars_type, records, snapshots)
      state%damped = scalars(n_scalars)
      call resume_reduced(reduced, state, error)
   end subroutine read_reduced_checkpoint
end module beamstops_reduced_checkpoint
