!> Checkpoints: the loop's whole state, the number of records and snapshots already in the
!> output, and the scene's signature, in a small HDF5 file written atomically (a temporary
!> file, then rename), so that a killed run resumes exactly where its last checkpoint was.
module beamstops_checkpoint
   use hdf5
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type, scene_table, stop_count, steps_of
   use beamstops_attributes, only: attribute_list, kind_real, kind_text, namelist_text
   use beamstops_model, only: model_type
   use beamstops_state, only: state_type
   use beamstops_loop_scalars, only: n_loop_scalars, loop_scalars_vector, restore_loop_scalars, implausible_scalars
   use beamstops_observe_observer, only: observer_type
   use beamstops_files, only: rename_file, remove_file, file_exists, not_writable_here
   use beamstops_recorder_hdf5_vector, only: write_vector, read_vector
   implicit none
   private
   public :: write_checkpoint, read_checkpoint, checkpoint_path, temporary_path, scene_signature, is_checkpoint
   public :: foreign_checkpoint
   ! (the reduced model's checkpoints, beamstops_reduced_checkpoint, share the file's frame)
   public :: create_checkpoint, commit_checkpoint, open_checkpoint, close_checkpoint, write_observer, read_observer
   public :: write_scene_text, check_scalars, signature_text, key_changes

   !> What checkpoint_state finds: not HDF5 (or HDF5 without a signature), HDF5 that cannot be
   !> opened, a checkpoint.
   integer, parameter :: checkpoint_other = 0, checkpoint_unopened = 1, checkpoint_found = 2

contains

   !> The checkpoint file of an output file.
   pure function checkpoint_path(output) result(path)
      !> Output file.
      character(len=*), intent(in) :: output
      character(len=:), allocatable :: path
      path = output//'.checkpoint'
   end function checkpoint_path

   !> The temporary file a checkpoint is written to before it is moved onto `path`.
   pure function temporary_path(path) result(temporary)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: temporary
      temporary = path//'.tmp'
   end function temporary_path

   !> Every value of a scene that a restart must find unchanged, as numbers: the items of the
   !> scene table marked `signature` (texts as their character codes), in the table's order.
   function scene_signature(scene) result(values)
      !> Scene.
      type(scene_type), intent(in) :: scene
      real(wp), allocatable :: values(:)
      type(attribute_list) :: table
      integer :: i, j
      table = scene_table(scene)
      allocate (values(0))
      do i = 1, table%count
         associate (item => table%items(i))
            if (.not. item%signature) cycle
            select case (item%kind)
            case (kind_real)
               values = [values, item%reals]
            case (kind_text)
               values = [values, [(real(iachar(item%text(j:j)), wp), j=1, len(item%text))]]
            case default
               values = [values, real(item%ints, wp)]
            end select
         end associate
      end do
   end function scene_signature

   !> The keys of a scene that a restart must find unchanged (those of scene_signature), as
   !> namelist text: one `key = value` a line under its `&group` line.
   function signature_text(scene) result(text)
      !> Scene.
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      type(attribute_list) :: table
      integer :: i
      table = scene_table(scene)
      text = namelist_text(table, [(table%items(i)%signature, i=1, table%count)])
   end function signature_text

   !> Write the scene's signature_text to a checkpoint (datasets `scene_text_length` and
   !> `scene_text`, its character codes), so that a restart of another scene names the keys changed.
   subroutine write_scene_text(file, scene, ok)
      !> The checkpoint's temporary file (create_checkpoint).
      integer(hid_t), intent(in) :: file
      !> Scene of the run.
      type(scene_type), intent(in) :: scene
      !> Whether the writes succeeded.
      logical, intent(out) :: ok
      character(len=:), allocatable :: text
      integer :: j
      text = signature_text(scene)
      call write_vector(file, 'scene_text_length', [real(len(text), wp)], ok)
      if (ok) call write_vector(file, 'scene_text', [(real(iachar(text(j:j)), wp), j=1, len(text))], ok)
   end subroutine write_scene_text

   !> The keys whose values differ between the scene text of a checkpoint (write_scene_text) and
   !> `scene`, as `&group key = old in the checkpoint, new here; ...`; '' when the checkpoint has
   !> no scene text (written by an earlier version) or the same one.
   function changed_keys(file, scene) result(changed)
      integer(hid_t), intent(in) :: file
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: changed
      character(len=:), allocatable :: old
      real(wp) :: length(1)
      real(wp), allocatable :: codes(:)
      logical :: ok
      integer :: i
      changed = ''
      call read_vector(file, 'scene_text_length', length, ok)
      if (.not. ok) return
      if (.not. (length(1) >= 0 .and. length(1) < 1.0e8_wp)) return
      allocate (codes(nint(length(1))))
      call read_vector(file, 'scene_text', codes, ok)
      if (.not. ok) return
      if (any(codes < 0 .or. codes > 127)) return
      allocate (character(len=size(codes)) :: old)
      do i = 1, size(codes)
         old(i:i) = achar(nint(codes(i)))
      end do
      changed = key_changes(old, signature_text(scene), 'the checkpoint')
   end function changed_keys

   !> The keys whose values differ between two signature texts (signature_text), as `&group key =
   !> old in WHERE, new here; ...` ('' when the texts are the same), `where` naming the old one.
   function key_changes(old, new, where) result(changed)
      !> The old text, the new one, and where the old one comes from.
      character(len=*), intent(in) :: old, new, where
      character(len=:), allocatable :: changed
      character(len=:), allocatable :: old_keys(:), old_values(:), new_keys(:), new_values(:)
      integer :: i, j
      changed = ''
      if (old == new) return
      call key_lines(old, old_keys, old_values)
      call key_lines(new, new_keys, new_values)
      do i = 1, size(new_keys)
         j = position(old_keys, new_keys(i))
         if (j == 0) then
            call add(trim(new_keys(i))//' = '//trim(new_values(i))//' here, not in '//where)
         else if (old_values(j) /= new_values(i)) then
            call add(trim(new_keys(i))//' = '//trim(old_values(j))//' in '//where//', '//trim(new_values(i))// &
               & ' here')
         end if
      end do
      do j = 1, size(old_keys)
         if (position(new_keys, old_keys(j)) == 0) &
            & call add(trim(old_keys(j))//' = '//trim(old_values(j))//' in '//where//', not here')
      end do

   contains

      subroutine add(piece)
         character(len=*), intent(in) :: piece
         if (len(changed) > 0) changed = changed//'; '
         changed = changed//piece
      end subroutine add
   end function key_changes

   !> The `&group key` and value of each `key = value` line of a namelist_text.
   subroutine key_lines(text, keys, values)
      character(len=*), intent(in) :: text
      character(len=:), allocatable, intent(out) :: keys(:), values(:)
      integer :: pass, n, first, last, eq, group_start, group_end
      n = 0
      do pass = 1, 2
         if (pass == 2) allocate (character(len=max(1, len(text))) :: keys(n), values(n))
         n = 0
         group_start = 1
         group_end = 0
         first = 1
         do while (first <= len(text))
            last = index(text(first:), new_line('a'))
            if (last == 0) then
               last = len(text)
            else
               last = first + last - 2
            end if
            if (last >= first) then
               if (text(first:first) == '&') then
                  group_start = first
                  group_end = last
               else
                  eq = index(text(first:last), ' = ')
                  if (eq > 0) then
                     n = n + 1
                     if (pass == 2) then
                        keys(n) = text(group_start:group_end)//' '//adjustl(text(first:first + eq - 2))
                        values(n) = text(first + eq + 2:last)
                     end if
                  end if
               end if
            end if
            first = last + 2
         end do
      end do
   end subroutine key_lines

   !> Index of `item` in `list` (0 when absent).
   pure integer function position(list, item)
      character(len=*), intent(in) :: list(:), item
      do position = 1, size(list)
         if (list(position) == item) return
      end do
      position = 0
   end function position

   !> Whether `path` is a checkpoint file (HDF5 holding a scene signature), so that it may be
   !> replaced or removed.
   function is_checkpoint(path) result(yes)
      !> File.
      character(len=*), intent(in) :: path
      logical :: yes
      yes = checkpoint_state(path) == checkpoint_found
   end function is_checkpoint

   !> Why what is at the checkpoint `path` (or, `temporary`, at the checkpoint's temporary file)
   !> must not be replaced: '' when nothing is there or a checkpoint, and with `temporary` an
   !> empty file or an HDF5 file that cannot be opened too (what a run killed while it wrote a
   !> checkpoint leaves); else what it is ('is a symbolic link, ...', 'exists and is not a
   !> beamstops checkpoint', 'is the input file IN.nml'). Anything but a regular file is named,
   !> not opened.
   function foreign_checkpoint(path, input, temporary) result(why)
      !> Checkpoint file, or its temporary file.
      character(len=*), intent(in) :: path
      !> Input file of the run ('' for none).
      character(len=*), intent(in) :: input
      !> Whether `path` is the temporary file.
      logical, intent(in) :: temporary
      character(len=:), allocatable :: why
      integer :: state
      integer(ik) :: bytes
      why = not_writable_here(path, input)
      if (len(why) > 0 .or. .not. file_exists(path)) return
      state = checkpoint_state(path)
      if (state == checkpoint_found) return
      if (temporary) then
         if (state == checkpoint_unopened) return
         inquire (file=path, size=bytes)
         if (bytes == 0) return
      end if
      why = 'exists and is not a beamstops checkpoint'
   end function foreign_checkpoint

   !> What the regular file `path` is: not HDF5, an HDF5 file that cannot be opened, an HDF5 file
   !> without a scene signature, or a checkpoint.
   integer function checkpoint_state(path) result(state)
      character(len=*), intent(in) :: path
      integer(hid_t) :: file
      integer :: hdferr, closing
      logical :: hdf5_file, found
      state = checkpoint_other
      call h5open_f(hdferr)
      call h5eset_auto_f(0, hdferr)
      call h5fis_hdf5_f(path, hdf5_file, hdferr)
      if (hdferr /= 0 .or. .not. hdf5_file) return
      state = checkpoint_unopened
      call h5fopen_f(path, H5F_ACC_RDONLY_F, file, hdferr)
      if (hdferr /= 0) return
      state = checkpoint_other
      call h5lexists_f(file, 'signature', found, hdferr)
      if (found .and. hdferr == 0) state = checkpoint_found
      call h5fclose_f(file, closing)
   end function checkpoint_state

   !> Write the checkpoint `path` atomically.
   subroutine write_checkpoint(path, scene, state, records, snapshots, error)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      !> Scene of the run.
      type(scene_type), intent(in) :: scene
      !> State after the last step done.
      type(state_type), intent(in) :: state
      !> Records and snapshots already in the output file.
      integer(ik), intent(in) :: records, snapshots
      !> Set when the file cannot be written.
      type(error_type), allocatable, intent(out) :: error
      integer(hid_t) :: file
      logical :: ok(6)
      call create_checkpoint(path, file, error)
      if (allocated(error)) return
      call write_vector(file, 'signature', scene_signature(scene), ok(1))
      if (ok(1)) call write_scene_text(file, scene, ok(1))
      call write_vector(file, 'scalars', loop_scalars_vector(state%loop_scalars_type, records, snapshots), ok(2))
      call write_vector(file, 'u', state%u, ok(3))
      call write_vector(file, 'd', state%d, ok(4))
      call write_vector(file, 'su', state%su, ok(5))
      ok(6) = .true.
      if (allocated(state%stop_reaction)) call write_vector(file, 'stop_reaction', state%stop_reaction, ok(6))
      ! The energy the damping took (its other terms are rebuilt from d on resume).
      if (ok(6) .and. allocated(state%cd)) call write_vector(file, 'damped', [state%damped], ok(6))
      if (ok(6)) call write_observer(file, state%observer, ok(6))
      call commit_checkpoint(path, file, all(ok), error)
   end subroutine write_checkpoint

   !> Write an observer (when active) to a checkpoint: datasets `observer_length` and `observer`.
   subroutine write_observer(file, observer, ok)
      !> The checkpoint's temporary file (create_checkpoint).
      integer(hid_t), intent(in) :: file
      !> The loop's observer.
      type(observer_type), intent(in) :: observer
      !> Whether the writes succeeded (true when inactive).
      logical, intent(out) :: ok
      real(wp), allocatable :: values(:)
      ok = .true.
      if (.not. observer%active) return
      call observer%pack(values)
      call write_vector(file, 'observer_length', [real(size(values), wp)], ok)
      if (ok) call write_vector(file, 'observer', values, ok)
   end subroutine write_observer

   !> Read the observer that write_observer wrote (a run with &statistics enabled).
   subroutine read_observer(file, observer, ok)
      !> The checkpoint (open_checkpoint).
      integer(hid_t), intent(in) :: file
      !> The loop's observer, restored (active).
      type(observer_type), intent(inout) :: observer
      !> Whether the reads succeeded and gave an observer.
      logical, intent(out) :: ok
      real(wp), allocatable :: values(:)
      real(wp) :: length(1)
      type(error_type), allocatable :: failure
      call read_vector(file, 'observer_length', length, ok)
      if (.not. ok) return
      allocate (values(nint(length(1))))
      call read_vector(file, 'observer', values, ok)
      if (.not. ok) return
      call observer%unpack(values, failure)
      ok = .not. allocated(failure)
   end subroutine read_observer

   !> Create the temporary file of the checkpoint `path` (temporary_path), to be written and then
   !> moved in place by commit_checkpoint.
   subroutine create_checkpoint(path, file, error)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      !> The temporary file, open.
      integer(hid_t), intent(out) :: file
      !> Set when it cannot be created.
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: why
      integer :: hdferr
      file = -1
      ! checked when the run started, and again here: a file put there since is not written over
      why = foreign_checkpoint(temporary_path(path), '', temporary=.true.)
      if (len(why) > 0) then
         call fatal_error(error, path//': cannot create the checkpoint: '//temporary_path(path)//', where it is '// &
            & 'written before it is moved into place, '//why//'; refusing to write it (move it away)')
         return
      end if
      call h5open_f(hdferr)
      call h5eset_auto_f(0, hdferr)
      call h5fcreate_f(temporary_path(path), H5F_ACC_TRUNC_F, file, hdferr)
      if (hdferr /= 0) call fatal_error(error, path//': cannot create the checkpoint')
   end subroutine create_checkpoint

   !> Close the temporary file of create_checkpoint and, when every write went well (`ok`),
   !> rename it onto `path` (atomic); otherwise remove it.
   subroutine commit_checkpoint(path, file, ok, error)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      !> The temporary file.
      integer(hid_t), intent(in) :: file
      !> Whether every write succeeded.
      logical, intent(in) :: ok
      !> Set when the checkpoint could not be written or moved.
      type(error_type), allocatable, intent(out) :: error
      integer :: hdferr
      logical :: moved
      call h5fclose_f(file, hdferr)
      if (.not. ok .or. hdferr /= 0) then
         call remove_file(temporary_path(path))
         call fatal_error(error, path//': cannot write the checkpoint (disk full, or beyond the file-size limit?)')
         return
      end if
      call rename_file(temporary_path(path), path, moved)
      if (.not. moved) call fatal_error(error, path//': cannot move the new checkpoint in place')
   end subroutine commit_checkpoint

   !> Open the checkpoint `path` for reading.
   subroutine open_checkpoint(path, file, error)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      !> The file, open.
      integer(hid_t), intent(out) :: file
      !> Set when it cannot be read.
      type(error_type), allocatable, intent(out) :: error
      integer :: hdferr
      call h5open_f(hdferr)
      call h5eset_auto_f(0, hdferr)
      call h5fopen_f(path, H5F_ACC_RDONLY_F, file, hdferr)
      if (hdferr /= 0) call fatal_error(error, path//': cannot read the checkpoint')
   end subroutine open_checkpoint

   !> Close a checkpoint read with open_checkpoint: an error when a read failed (`ok` false) or
   !> when the `signature` read from it is not the scene's.
   subroutine close_checkpoint(path, file, ok, signature, scene, error)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      !> The file.
      integer(hid_t), intent(in) :: file
      !> Whether every read succeeded.
      logical, intent(in) :: ok
      !> The signature read from the file.
      real(wp), intent(in) :: signature(:)
      !> Scene of the run to resume.
      type(scene_type), intent(in) :: scene
      !> Set when the checkpoint cannot be used.
      type(error_type), allocatable, intent(out) :: error
      integer :: hdferr
      character(len=:), allocatable :: changed
      changed = changed_keys(file, scene)
      call h5fclose_f(file, hdferr)
      if (len(changed) > 0) then
         call fatal_error(error, path//': the checkpoint belongs to another scene: '//changed//'; allowed: the '// &
            & 'same namelist values as the interrupted run (or run without --restart)')
         return
      end if
      if (.not. ok) then
         call fatal_error(error, path//': the checkpoint is damaged or of another mesh')
         return
      end if
      if (any(signature /= scene_signature(scene))) then
         call fatal_error(error, path//': the checkpoint belongs to another scene; allowed: the same '// &
            & 'namelist values as the interrupted run (or run without --restart)')
      end if
   end subroutine close_checkpoint

   !> Read the checkpoint `path` of a run of `scene`: the state (with its work arrays) and
   !> the records and snapshots the output held at that moment.
   subroutine read_checkpoint(path, scene, model, state, records, snapshots, error)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      !> Scene of the run to resume (must be the checkpoint's).
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State restored.
      type(state_type), intent(out) :: state
      !> Records and snapshots the output held at the checkpoint.
      integer(ik), intent(out) :: records, snapshots
      !> Set when the file is unreadable or belongs to another scene.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: signature(:)
      real(wp) :: scalars(n_loop_scalars), damped(1)
      integer(hid_t) :: file
      integer :: n
      logical :: ok(6)
      records = 0
      snapshots = 0
      n = model%n
      signature = scene_signature(scene)
      allocate (state%u(n), state%d(n), state%su(n), state%rhs(n), state%scratch(n), state%shape(size(model%x)))
      if (stop_count(scene) > 0) allocate (state%stop_reaction(stop_count(scene)))
      call open_checkpoint(path, file, error)
      if (allocated(error)) return
      call read_vector(file, 'signature', signature, ok(1))
      call read_vector(file, 'scalars', scalars, ok(2))
      call read_vector(file, 'u', state%u, ok(3))
      call read_vector(file, 'd', state%d, ok(4))
      call read_vector(file, 'su', state%su, ok(5))
      ok(6) = .true.
      if (allocated(state%stop_reaction)) call read_vector(file, 'stop_reaction', state%stop_reaction, ok(6))
      if (ok(6) .and. model%damped) then
         call read_vector(file, 'damped', damped, ok(6))
         state%damped = damped(1)
      end if
      if (ok(6) .and. scene%statistics) call read_observer(file, state%observer, ok(6))
      call close_checkpoint(path, file, all(ok), signature, scene, error)
      if (allocated(error)) return
      call check_scalars(path, scene, scalars, [state%u, state%d, state%su, state%damped], error)
      if (allocated(error)) return
      call restore_loop_scalars(scalars, state%loop_scalars_type, records, snapshots)
   end subroutine read_checkpoint

   !> An error when the loop scalars read from a checkpoint (and the state's `values`) cannot be a
   !> checkpoint of a run of the scene (beamstops_loop_scalars' implausible_scalars).
   subroutine check_scalars(path, scene, scalars, values, error)
      !> Checkpoint file.
      character(len=*), intent(in) :: path
      !> Scene of the run to resume.
      type(scene_type), intent(in) :: scene
      !> The checkpoint's loop scalars and the state's other values.
      real(wp), intent(in) :: scalars(n_loop_scalars), values(:)
      !> Set when they cannot be.
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: why
      why = implausible_scalars(scalars, values, steps_of(scene), scene%record_every, scene%snapshot_every)
      if (len(why) > 0) call fatal_error(error, path//': the checkpoint is damaged: '//why// &
         & '; run without --restart to start over')
   end subroutine check_scalars
end module beamstops_checkpoint
