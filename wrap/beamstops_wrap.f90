!> Plain subroutines over the beamstops engine, the only file f2py parses.
!>
!> Every routine takes a scene as namelist text and a source for messages, `(text, source)`:
!> Python passes the exact text of Scene.to_namelist, and the engine's one reader reads,
!> derives and validates it (beamstops_namelist). Errors come back as `status` (0: none) and a
!> fixed-length `message`; nothing here stops the process. Arrays are explicit-shape, sized by
!> the caller from bs_sizes. Text outputs (canonical scenes, attribute lines) are blank-padded.

!> Version of the engine.
subroutine bs_version(text)
   use beamstops, only: version
   implicit none
   !> Version text.
   character(len=64), intent(out) :: text
   text = version
end subroutine bs_version

!> The signal that stopped the last run of bs_run with interruptible = 1 (0: none).
subroutine bs_stop_signal(signum)
   use beamstops_stop_signals, only: caught_signal
   implicit none
   integer, intent(out) :: signum
   signum = caught_signal()
end subroutine bs_stop_signal

!> Raise the end of allocation an HDF5 file's superblock records to the file's size (a run killed
!> while HDF5 flushed its file; beamstops_files' raise_hdf5_eoa): raised = 1 when it was.
subroutine bs_raise_hdf5_eoa(path, raised)
   use beamstops_files, only: raise_hdf5_eoa
   implicit none
   character(len=*), intent(in) :: path
   integer, intent(out) :: raised
   raised = merge(1, 0, raise_hdf5_eoa(path))
end subroutine bs_raise_hdf5_eoa

!> Groups and keys the reader accepts, one group a line: `group: key key ...`.
subroutine bs_keys(text)
   use beamstops_namelist, only: group_names, group_keys
   implicit none
   !> The groups and their keys.
   character(len=4096), intent(out) :: text
   integer :: g
   text = ''
   do g = 1, size(group_names)
      text = trim(text)//trim(group_names(g))//': '//trim(group_keys(g))//new_line('a')
   end do
end subroutine bs_keys

!> The canonical text of a scene (every key, defaults filled in, values that read back
!> exactly) from namelist text; `carried`: the keys it carries over from a scene being changed
!> ('group:key' words; such a key that does nothing is dropped rather than refused).
subroutine bs_scene(text, source, carried, canonical, status, message)
   use beamstops, only: error_type, scene_type, canonical_text
   use beamstops_wrap_support, only: scene_of, report
   implicit none
   !f2py threadsafe
   !> Namelist text.
   character(len=*), intent(in) :: text
   !> Source for messages.
   character(len=*), intent(in) :: source
   !> Keys carried over ('group:key' words, blank-separated; blank: none).
   character(len=*), intent(in) :: carried
   !> Canonical namelist text.
   character(len=131072), intent(out) :: canonical
   !> 0, or 1 with `message`.
   integer, intent(out) :: status
   !> Error message.
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(error_type), allocatable :: error
   canonical = ''
   call scene_of(text, source, scene, error, carried)
   if (.not. allocated(error)) canonical = canonical_text(scene)
   call report(error, status, message)
end subroutine bs_scene

!> The canonical text of the scene of a namelist file, read as the program reads it (the
!> output file defaults to the file's base name with '.h5').
subroutine bs_read_file(path, canonical, status, message)
   use beamstops, only: error_type, scene_type, canonical_text, read_scene
   use beamstops_wrap_support, only: report
   implicit none
   !> Namelist file.
   character(len=*), intent(in) :: path
   !> Canonical namelist text.
   character(len=131072), intent(out) :: canonical
   !> 0, or 1 with `message`.
   integer, intent(out) :: status
   !> Error message.
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(error_type), allocatable :: error
   canonical = ''
   call read_scene(trim(path), scene, error)
   if (.not. allocated(error)) canonical = canonical_text(scene)
   call report(error, status, message)
end subroutine bs_read_file

!> Sizes of the arrays of a run: records and snapshots of a complete run, nodes J+1, stops m.
subroutine bs_sizes(text, source, records, snapshots, nodes, stops, status, message)
   use beamstops, only: error_type, scene_type, record_count, snapshot_count, stop_count
   use beamstops_wrap_support, only: scene_of, report
   implicit none
   character(len=*), intent(in) :: text, source
   integer(8), intent(out) :: records, snapshots, nodes, stops
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(error_type), allocatable :: error
   records = 0; snapshots = 0; nodes = 0; stops = 0
   call scene_of(text, source, scene, error)
   if (.not. allocated(error)) then
      records = record_count(scene)
      snapshots = snapshot_count(scene)
      nodes = scene%elements + 1
      stops = stop_count(scene)
   end if
   call report(error, status, message)
end subroutine bs_sizes

!> kappa_h, the paper's bound kappa_tilde and the time-step limits of a scene, the linear limit of
!> the model its run steps (`run_model`: the full model, or the reduced one of &mesh modes > 0),
!> and whether the engine would refuse to run it (`refused` = 1, with its reason): check_run,
!> the check of `beamstops run` and `beamstops info`.
subroutine bs_stability(text, source, kappa_h, kappa_bound, kappa_contact, dt_limit_newmark, dt_limit_paper, &
   & dt_limit_paper_bound, kappa_method, kappa_run, dt_limit_run, run_model, refused, refusal, status, message)
   use beamstops, only: error_type, scene_type, model_type, build_model, check_run, run_limit_type, run_limit, &
      & reduced_model_type
   use beamstops_wrap_support, only: scene_of, report
   implicit none
   !f2py threadsafe
   character(len=*), intent(in) :: text, source
   real(8), intent(out) :: kappa_h, kappa_bound, kappa_contact, dt_limit_newmark, dt_limit_paper, dt_limit_paper_bound
   character(len=32), intent(out) :: kappa_method
   !> The largest eigenvalue (0: not computed) and the linear limit of the model the run steps.
   real(8), intent(out) :: kappa_run, dt_limit_run
   !> Which model the run steps: 'full model' or 'reduced model of r modes'.
   character(len=64), intent(out) :: run_model
   integer, intent(out) :: refused
   character(len=1024), intent(out) :: refusal
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(model_type) :: model
   type(reduced_model_type) :: reduced
   type(run_limit_type) :: limit
   type(error_type), allocatable :: error, refusal_error
   kappa_h = 0; kappa_bound = 0; kappa_contact = 0
   dt_limit_newmark = 0; dt_limit_paper = 0; dt_limit_paper_bound = 0
   kappa_method = ''
   kappa_run = 0; dt_limit_run = 0; run_model = ''
   refused = 0
   refusal = ''
   call scene_of(text, source, scene, error)
   if (.not. allocated(error)) call build_model(scene, model, error)
   if (.not. allocated(error)) then
      kappa_h = model%kappa_h
      kappa_bound = model%kappa_bound
      kappa_contact = model%kappa_contact
      dt_limit_newmark = model%dt_newmark
      dt_limit_paper = model%dt_paper_exact
      dt_limit_paper_bound = model%dt_paper_bound
      kappa_method = model%kappa_method
      call check_run(scene, trim(source), model, refusal_error, reduced)
      limit = run_limit(scene, model, reduced)
      kappa_run = limit%kappa
      dt_limit_run = limit%dt_newmark
      run_model = limit%model
      call report(refusal_error, refused, refusal)
   end if
   call report(error, status, message)
end subroutine bs_stability

!> Run a scene in memory (the array recorder) and copy the records into the caller's arrays.
!> `records`, `snapshots`, `nodes`, `stops` must be those of bs_sizes; `filled` and `snaps`
!> say how many were written (fewer when the run did not complete). `attributes` holds the
!> output file's root attributes as lines `name = value` (the same list the HDF5 writer writes,
!> status last; the quoted `scene` text spans lines); status/message report errors that
!> prevent the run.
subroutine bs_run(text, source, records, snapshots, nodes, stops, shock_capacity, stat_width, interruptible, t, tip_u, tip_v, &
   & reaction, energy, work, dissipated, damped, snapshot_t, snapshot_x, snapshot_u, stops_x, stops_u, &
   & stops_reaction, filled, snaps, shocks, shock_count, shock_labels, stat_value, stat_half, stat_entries, stat_labels, &
   & attributes, status, message)
   use beamstops, only: error_type, fatal_error, scene_type, record_count, snapshot_count, stop_count, &
      & model_type, prepare_run, simulate, array_recorder, n_columns, run_summary, reduced_model_type
   use beamstops_recorder, only: col_t, col_u, col_v, col_reaction, col_energy, col_work, col_dissipated, col_damped
   use beamstops_attributes, only: attribute_list, attribute_lines
   use beamstops_output_attributes, only: run_attributes, summary_attributes
   use beamstops_observe_shocks, only: n_shock_columns, shock_column_names
   use beamstops_observe_statistics, only: statistics_table
   use beamstops_wrap_support, only: scene_of, report
   implicit none
   !f2py threadsafe
   character(len=*), intent(in) :: text, source
   integer(8), intent(in) :: records, snapshots, nodes, stops
   !> Columns of `shocks` (shock_count may exceed it: then call again with shock_count) and entries
   !> per quantity of the statistics (max(stops, bins + 1) from bs_sizes).
   integer(8), intent(in) :: shock_capacity, stat_width
   !> 1: SIGINT and SIGTERM stop the time loop between two blocks (status 'interrupted'; the
   !> caller raises the signal again, bs_stop_signal); 0: they keep their handlers meanwhile.
   integer, intent(in) :: interruptible
   real(8), intent(out) :: t(records), tip_u(records), tip_v(records), reaction(records)
   real(8), intent(out) :: energy(records), work(records), dissipated(records), damped(records)
   real(8), intent(out) :: snapshot_t(snapshots), snapshot_x(nodes), snapshot_u(nodes, snapshots)
   real(8), intent(out) :: stops_x(stops), stops_u(stops, records), stops_reaction(stops, records)
   integer(8), intent(out) :: filled, snaps
   !> The shocks (13 fields each, the order of /impacts: shock_column_names) and their number.
   real(8), intent(out) :: shocks(13, shock_capacity)
   integer(8), intent(out) :: shock_count
   !> The names of the 13 fields, separated by blanks.
   character(len=1024), intent(out) :: shock_labels
   !> The statistics and (members > 1) the ensemble's: up to 128 quantities, value and half-width of
   !> each entry, entries per quantity, and a line `name unit axis table` per quantity (table:
   !> statistics or ensemble).
   real(8), intent(out) :: stat_value(stat_width, 128), stat_half(stat_width, 128)
   integer(8), intent(out) :: stat_entries(128)
   character(len=8192), intent(out) :: stat_labels
   character(len=262144), intent(out) :: attributes
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(model_type) :: model
   type(reduced_model_type) :: reduced
   type(array_recorder) :: recorder
   type(run_summary) :: summary
   type(attribute_list) :: list
   type(error_type), allocatable :: error
   integer :: stat, i, n, j
   integer(8) :: k

   t = 0; tip_u = 0; tip_v = 0; reaction = 0; energy = 0; work = 0; dissipated = 0; damped = 0
   snapshot_t = 0; snapshot_x = 0; snapshot_u = 0
   stops_x = 0; stops_u = 0; stops_reaction = 0
   filled = 0; snaps = 0
   shock_labels = ''
   do i = 1, n_shock_columns
      shock_labels = trim(shock_labels)//' '//trim(shock_column_names(i))
   end do
   shocks = 0; shock_count = 0; stat_value = 0; stat_half = 0; stat_entries = 0; stat_labels = ''
   attributes = ''

   call scene_of(text, source, scene, error)
   if (.not. allocated(error)) then
      if (records /= record_count(scene) .or. snapshots /= snapshot_count(scene) .or. &
         & nodes /= scene%elements + 1 .or. stops /= stop_count(scene)) call fatal_error(error, &
         & trim(source)//': the arrays given to bs_run do not have the sizes bs_sizes returns for this scene')
   end if
   if (.not. allocated(error)) call prepare_run(scene, trim(source), model, error, reduced)
   if (.not. allocated(error)) then
      ! The array recorder's buffers, sized as its `reserve` would, but allocated with a status.
      allocate (recorder%rows(n_columns, records), recorder%snap_t(snapshots), recorder%snap_u(nodes, snapshots), &
         & recorder%stops_u(stops, records), recorder%stops_reaction(stops, records), stat=stat)
      if (stat /= 0) call fatal_error(error, trim(source)//': not enough memory for the records of this run')
      recorder%filled = 0
      recorder%snaps = 0
      recorder%stops_filled = 0
   end if
   if (.not. allocated(error)) call simulate(scene, model, recorder, summary, error, reduced, interruptible /= 0)
   if (allocated(error)) then
      call report(error, status, message)
      return
   end if

   filled = recorder%filled
   snaps = recorder%snaps
   do k = 1, filled
      t(k) = recorder%rows(col_t, k)
      tip_u(k) = recorder%rows(col_u, k)
      tip_v(k) = recorder%rows(col_v, k)
      reaction(k) = recorder%rows(col_reaction, k)
      energy(k) = recorder%rows(col_energy, k)
      work(k) = recorder%rows(col_work, k)
      dissipated(k) = recorder%rows(col_dissipated, k)
      damped(k) = recorder%rows(col_damped, k)
   end do
   stops_u(:, :recorder%stops_filled) = recorder%stops_u(:, :recorder%stops_filled)
   stops_reaction(:, :recorder%stops_filled) = recorder%stops_reaction(:, :recorder%stops_filled)
   snapshot_t(:snaps) = recorder%snap_t(:snaps)
   snapshot_u(:, :snaps) = recorder%snap_u(:, :snaps)
   snapshot_x = model%x
   if (stops > 0) stops_x = model%x(scene%stop_nodes + 1)
   if (allocated(summary%shocks)) then
      shock_count = size(summary%shocks, 2)
      k = min(shock_count, shock_capacity)
      shocks(:, :k) = summary%shocks(:, :k)
   end if
   j = 0
   if (allocated(summary%statistics%quantity)) call hand_table(summary%statistics, 'statistics')
   if (summary%ensemble_members > 1 .and. allocated(summary%ensemble%quantity)) &
      & call hand_table(summary%ensemble, 'ensemble')
   list = run_attributes(scene, model)
   call list%extend(summary_attributes(summary))
   call list%add_text('', 'status', summary%status)
   attributes = attribute_lines(list)
   status = 0
   message = ''

contains

   !> The quantities of a table into the statistics' arrays, after the j already there.
   subroutine hand_table(table, label)
      type(statistics_table), intent(in) :: table
      character(len=*), intent(in) :: label
      do i = 1, size(table%quantity)
         if (j == size(stat_entries)) return
         j = j + 1
         associate (q => table%quantity(i))
            n = int(min(size(q%value, kind=8), stat_width))
            stat_entries(j) = n
            stat_value(:n, j) = q%value(:n)
            stat_half(:n, j) = q%half_width(:n)
            stat_labels = trim(stat_labels)//q%name//' '//q%unit//' '//q%axis//' '//label//new_line('a')
         end associate
      end do
   end subroutine hand_table
end subroutine bs_run

!> Studies: a scene without stops run in the paper's three-level form (module
!> beamstops_three_level), recording the tip every record_every steps; `records` from bs_sizes.
!> Only to measure the round-off floor that the engine's increment form removes (SPEC 4).
!> `interruptible` as bs_run's; status 2: a stop signal ended the loop (bs_stop_signal says which).
subroutine bs_run_three_level(text, source, records, interruptible, t, tip_u, cpu_seconds, status, message)
   use beamstops, only: error_type, fatal_error, scene_type, record_count, model_type, prepare_run, run_three_level
   use beamstops_wrap_support, only: scene_of, report
   implicit none
   !f2py threadsafe
   character(len=*), intent(in) :: text, source
   integer(8), intent(in) :: records
   integer, intent(in) :: interruptible
   real(8), intent(out) :: t(records), tip_u(records), cpu_seconds
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(model_type) :: model
   type(error_type), allocatable :: error
   real(8), allocatable :: tt(:), uu(:)
   integer :: signum
   t = 0; tip_u = 0; cpu_seconds = 0
   signum = 0
   call scene_of(text, source, scene, error)
   if (.not. allocated(error)) then
      if (records /= record_count(scene)) call fatal_error(error, trim(source)//': the arrays given to '// &
         & 'bs_run_three_level do not have the size bs_sizes returns for this scene')
   end if
   if (.not. allocated(error)) call prepare_run(scene, trim(source), model, error)
   if (.not. allocated(error)) call run_three_level(scene, model, tt, uu, cpu_seconds, error, interruptible /= 0, signum)
   if (.not. allocated(error)) then
      t = tt
      tip_u = uu
   end if
   call report(error, status, message)
   if (signum /= 0) status = 2
end subroutine bs_run_three_level

!> Studies: the full state of the engine's own loop (start_state, advance) at chosen steps,
!> u^n (the homogeneous unknown, 2J values and slopes) and v^n = (u^{n+1} - u^{n-1})/(2 dt),
!> with M and S (band storage, per unit mass). Rationale: the energy norm of an error,
!> 1/2 e'.M e' + 1/2 e.S e, needs slopes and velocities, which the records (tip) and the
!> snapshots (nodal values) do not hold. `steps` ascending in 0..steps_of(scene); n = 2J.
!> `interruptible` as bs_run's (the loop looks for a signal every block_steps steps); status 2:
!> a stop signal ended it (bs_stop_signal says which).
subroutine bs_states(text, source, count, steps, n, interruptible, u, v, mass, stiffness, cpu_seconds, status, message)
   use beamstops, only: error_type, fatal_error, scene_type, steps_of, model_type, prepare_run, &
      & state_type, start_state, array_recorder
   use beamstops_scheme, only: advance, block_steps
   use beamstops_stop_signals, only: catch_stop_signals, release_stop_signals, stop_signal, interrupted_at
   use beamstops_wrap_support, only: scene_of, report
   implicit none
   !f2py threadsafe
   character(len=*), intent(in) :: text, source
   integer(8), intent(in) :: count, n
   integer(8), intent(in) :: steps(count)
   integer, intent(in) :: interruptible
   real(8), intent(out) :: u(n, count), v(n, count), mass(4, n), stiffness(4, n), cpu_seconds
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(model_type) :: model
   type(state_type) :: state
   type(array_recorder) :: recorder
   type(error_type), allocatable :: error
   real(8), allocatable :: d_prev(:)
   real(8) :: t0, t1
   integer(8) :: k, step
   integer :: signum
   u = 0; v = 0; mass = 0; stiffness = 0; cpu_seconds = 0
   call scene_of(text, source, scene, error)
   if (.not. allocated(error)) then
      if (n /= 2*scene%elements) call fatal_error(error, trim(source)//': bs_states needs n = 2*elements')
   end if
   if (.not. allocated(error)) then
      do k = 1, count
         if (steps(k) < 0 .or. steps(k) > steps_of(scene) .or. (k > 1 .and. steps(max(k - 1, 1_8)) >= steps(k))) &
            & call fatal_error(error, trim(source)//': bs_states needs ascending steps in 0..steps of the scene')
         if (allocated(error)) exit
      end do
   end if
   if (allocated(error)) then
      call report(error, status, message)
      return
   end if
   ! Records are not wanted here: one row (t = 0), no snapshots.
   scene%record_every = huge(scene%record_every)
   scene%snapshot_every = 0
   call prepare_run(scene, trim(source), model, error)
   if (.not. allocated(error)) then
      call recorder%reserve(2_8, 0_8, scene%elements + 1)
      call start_state(scene, model, state, recorder, error)
   end if
   if (allocated(error)) then
      call report(error, status, message)
      return
   end if
   mass = model%mass
   stiffness = model%stiffness
   signum = 0
   if (interruptible /= 0) call catch_stop_signals()
   call cpu_time(t0)
   do k = 1, count
      step = steps(k)
      if (step == 0) then
         u(:, k) = model%u0
         v(:, k) = model%v0
         cycle
      end if
      call advance_to(step - 1)
      if (signum /= 0) exit
      d_prev = state%d
      call advance(scene, model, state, recorder, step)
      u(:, k) = state%u - state%d
      v(:, k) = (state%d + d_prev)/(2*scene%dt)
   end do
   call cpu_time(t1)
   if (interruptible /= 0) call release_stop_signals()
   cpu_seconds = t1 - t0
   call report(error, status, message)
   if (signum /= 0) then
      status = 2
      message = interrupted_at(signum, real(state%step - 1, 8)*scene%dt)
   end if

contains

   !> Advance the state to step `last` (done), in blocks of block_steps steps with a look for a
   !> stop signal after each when interruptible (the same steps as one call: advance's blocks).
   subroutine advance_to(last)
      integer(8), intent(in) :: last
      do while (state%step <= last)
         call advance(scene, model, state, recorder, min(last, state%step + block_steps - 1))
         if (interruptible /= 0) then
            signum = stop_signal()
            if (signum /= 0) return
         end if
      end do
   end subroutine advance_to
end subroutine bs_states
