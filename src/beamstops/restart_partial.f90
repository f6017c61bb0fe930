!> What `beamstops run --restart` checks of the partial file it extends, beyond its series (the
!> recorder's reopen: each holds the rows its checkpoint counts): that it is the output of the
!> scene being resumed. Its root attribute `scene` (the scene as the run read it) is read back
!> and compared, key by key, with the values a restart must find unchanged (beamstops_checkpoint's
!> signature_text). The output of another run copied or left at OUT.h5.partial, with a checkpoint
!> of this one, was extended and marked complete: a file whose first rows and attributes were the
!> other scene's.
module beamstops_restart_partial
   use hdf5
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type
   use beamstops_namelist, only: scene_from_text
   use beamstops_checkpoint, only: signature_text, key_changes
   implicit none
   private
   public :: check_partial_scene

contains

   !> An error when the partial file `partial` is not the output of `scene` (its `scene`
   !> attribute missing, unreadable, or of another scene: the keys that differ are named).
   subroutine check_partial_scene(partial, scene, error)
      !> The partial file of the interrupted run.
      character(len=*), intent(in) :: partial
      !> Scene of the run to resume.
      type(scene_type), intent(in) :: scene
      !> Set when the file is not its output.
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text, changed
      type(scene_type) :: old
      type(error_type), allocatable :: unread
      logical :: opened, ok
      call read_scene_attribute(partial, text, opened, ok)
      ! a file HDF5 cannot open is the recorder's to tell (reopen: it first mends what a kill during
      ! HDF5's own flush may leave, then says how to go on)
      if (.not. opened) return
      if (ok) call scene_from_text(text, partial, old, unread)
      if (.not. ok .or. allocated(unread)) then
         call fatal_error(error, partial//', the output of the interrupted run, has no readable scene (its root '// &
            & 'attribute scene); allowed: the partial file the interrupted run wrote (or run without --restart)')
         return
      end if
      changed = key_changes(signature_text(old), signature_text(scene), 'the partial file')
      if (len(changed) > 0) call fatal_error(error, partial//', the output of the interrupted run, belongs to '// &
         & 'another scene: '//changed//'; allowed: the partial file of the same namelist values (or run without '// &
         & '--restart)')
   end subroutine check_partial_scene

   !> The root attribute `scene` (a scalar fixed-length string) of an HDF5 file; opened false when
   !> HDF5 cannot open the file, ok false when the attribute cannot be read.
   subroutine read_scene_attribute(path, text, opened, ok)
      character(len=*), intent(in) :: path
      character(len=:), allocatable, intent(out) :: text
      logical, intent(out) :: opened, ok
      integer(hid_t) :: file, attr, stored, memory
      integer(size_t) :: length
      integer(hsize_t) :: dims(1) = 1
      integer :: hdferr, ignored
      logical :: found
      ok = .false.
      text = ''
      call h5open_f(hdferr)
      call h5eset_auto_f(0, hdferr)
      call h5fopen_f(path, H5F_ACC_RDONLY_F, file, hdferr)
      opened = hdferr == 0
      if (.not. opened) return
      call h5aexists_f(file, 'scene', found, hdferr)
      if (hdferr == 0 .and. found) then
         call h5aopen_f(file, 'scene', attr, hdferr)
         if (hdferr == 0) then
            call h5aget_type_f(attr, stored, hdferr)
            if (hdferr == 0) call h5tget_size_f(stored, length, hdferr)
            if (hdferr == 0 .and. length > 0 .and. length < 100000000_size_t) then
               text = repeat(' ', int(length))
               call h5tcopy_f(H5T_C_S1, memory, hdferr)
               if (hdferr == 0) call h5tset_size_f(memory, length, hdferr)
               if (hdferr == 0) call h5aread_f(attr, memory, text, dims, hdferr)
               ok = hdferr == 0
               call h5tclose_f(memory, ignored)
            end if
            call h5tclose_f(stored, ignored)
            call h5aclose_f(attr, ignored)
         end if
      end if
      call h5fclose_f(file, ignored)
   end subroutine read_scene_attribute
end module beamstops_restart_partial
