!> Flat subroutines over the beamstops engine, the only file f2py parses.
!>
!> Every routine takes the scene as flat scalars (integers as integer(8), logicals
!> as integers 0/1, the contact law as its code) and reports errors as
!> `status` (0: none) and a fixed-length `message`; nothing here stops the process.
!> Arrays are explicit-shape, sized by the caller from bs_sizes. The engine's
!> modules are used inside the routines; f2py never sees them.
!>
!> Scene arguments, in this order everywhere:
!>   length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass,
!>   elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable,
!>   record_every, snapshot_every, max_output_gb,
!>   stop_count, stop_nodes(stop_count+1), stop_lower(stop_count+1), stop_upper(stop_count+1)
!> (the stops along the span; stop_count = 0 for the tip-only form, lower and upper). The
!> stops' arrays carry one padding value at the end: f2py refuses input arrays of size 0;
!> from Python, stop_count is optional (the arrays' length minus one).

!> Version of the engine.
subroutine bs_version(text)
   use beamstops, only: version
   implicit none
   !> Version text.
   character(len=64), intent(out) :: text
   text = version
end subroutine bs_version

!> Validate a scene; `source` (a file name or 'scene') starts the message.
subroutine bs_validate(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
   & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
   & max_output_gb, stop_count, stop_nodes, stop_lower, stop_upper, source, status, message)
   use beamstops, only: error_type, scene_type, validate_scene
   use beamstops_wrap_support, only: make_scene, report
   implicit none
   real(8), intent(in) :: length, k2, mass_per_length, amplitude, omega, lower, upper, stiffness_per_mass
   real(8), intent(in) :: dt, t_end, beta, max_output_gb
   integer(8), intent(in) :: stop_count
   integer(8), intent(in) :: stop_nodes(stop_count + 1)
   real(8), intent(in) :: stop_lower(stop_count + 1), stop_upper(stop_count + 1)
   integer(8), intent(in) :: law, elements, centered_load, taylor_start, allow_unstable, record_every, snapshot_every
   character(len=*), intent(in) :: source
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(error_type), allocatable :: error
   call make_scene(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
      & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
      & max_output_gb, stop_nodes(:stop_count), stop_lower(:stop_count), stop_upper(:stop_count), &
      & trim(source), scene, error)
   if (.not. allocated(error)) call validate_scene(scene, trim(source), error)
   call report(error, status, message)
end subroutine bs_validate

!> Sizes of the arrays of a run: records and snapshots of a complete run, nodes J+1.
subroutine bs_sizes(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
   & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
   & max_output_gb, stop_count, stop_nodes, stop_lower, stop_upper, records, snapshots, nodes, status, message)
   use beamstops, only: error_type, scene_type, validate_scene, record_count, snapshot_count
   use beamstops_wrap_support, only: make_scene, report
   implicit none
   real(8), intent(in) :: length, k2, mass_per_length, amplitude, omega, lower, upper, stiffness_per_mass
   real(8), intent(in) :: dt, t_end, beta, max_output_gb
   integer(8), intent(in) :: stop_count
   integer(8), intent(in) :: stop_nodes(stop_count + 1)
   real(8), intent(in) :: stop_lower(stop_count + 1), stop_upper(stop_count + 1)
   integer(8), intent(in) :: law, elements, centered_load, taylor_start, allow_unstable, record_every, snapshot_every
   integer(8), intent(out) :: records, snapshots, nodes
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(error_type), allocatable :: error
   records = 0
   snapshots = 0
   nodes = 0
   call make_scene(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
      & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
      & max_output_gb, stop_nodes(:stop_count), stop_lower(:stop_count), stop_upper(:stop_count), &
      & 'scene', scene, error)
   if (.not. allocated(error)) call validate_scene(scene, 'scene', error)
   if (.not. allocated(error)) then
      records = record_count(scene)
      snapshots = snapshot_count(scene)
      nodes = scene%elements + 1
   end if
   call report(error, status, message)
end subroutine bs_sizes

!> kappa_h, the paper's bound kappa_tilde and the time-step limits of a scene, and
!> whether the engine would refuse to run it (`refused` = 1, with its reason).
subroutine bs_stability(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
   & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
   & max_output_gb, stop_count, stop_nodes, stop_lower, stop_upper, kappa_h, kappa_bound, kappa_contact, dt_limit_newmark, dt_limit_paper, dt_limit_paper_bound, &
   & kappa_method, refused, refusal, status, message)
   use beamstops, only: error_type, scene_type, validate_scene, model_type, build_model, check_stability
   use beamstops_wrap_support, only: make_scene, report
   implicit none
   !f2py threadsafe
   real(8), intent(in) :: length, k2, mass_per_length, amplitude, omega, lower, upper, stiffness_per_mass
   real(8), intent(in) :: dt, t_end, beta, max_output_gb
   integer(8), intent(in) :: stop_count
   integer(8), intent(in) :: stop_nodes(stop_count + 1)
   real(8), intent(in) :: stop_lower(stop_count + 1), stop_upper(stop_count + 1)
   integer(8), intent(in) :: law, elements, centered_load, taylor_start, allow_unstable, record_every, snapshot_every
   real(8), intent(out) :: kappa_h, kappa_bound, kappa_contact, dt_limit_newmark, dt_limit_paper, dt_limit_paper_bound
   character(len=32), intent(out) :: kappa_method
   integer, intent(out) :: refused
   character(len=1024), intent(out) :: refusal
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(model_type) :: model
   type(error_type), allocatable :: error, refusal_error
   kappa_h = 0; kappa_bound = 0; kappa_contact = 0
   dt_limit_newmark = 0; dt_limit_paper = 0; dt_limit_paper_bound = 0
   kappa_method = ''
   refused = 0
   refusal = ''
   call make_scene(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
      & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
      & max_output_gb, stop_nodes(:stop_count), stop_lower(:stop_count), stop_upper(:stop_count), &
      & 'scene', scene, error)
   if (.not. allocated(error)) call validate_scene(scene, 'scene', error)
   if (.not. allocated(error)) call build_model(scene, model, error)
   if (.not. allocated(error)) then
      kappa_h = model%kappa_h
      kappa_bound = model%kappa_bound
      kappa_contact = model%kappa_contact
      dt_limit_newmark = model%dt_newmark
      dt_limit_paper = model%dt_paper_exact
      dt_limit_paper_bound = model%dt_paper_bound
      kappa_method = model%kappa_method
      call check_stability(scene, model, 'scene', refusal_error)
      call report(refusal_error, refused, refusal)
   end if
   call report(error, status, message)
end subroutine bs_stability

!> Run a scene in memory (the array recorder) and copy the records into the caller's arrays.
!> `records`, `snapshots`, `nodes` must be those of bs_sizes; `filled` and `snaps` say how many
!> were written (fewer when the run did not complete). run_status: 0 complete, 1 diverged,
!> 2 failed (the recorder), with run_message; status/message report errors that prevent the run.
subroutine bs_run(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
   & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
   & max_output_gb, stop_count, stop_nodes, stop_lower, stop_upper, records, snapshots, nodes, t, tip_u, tip_v, reaction, energy, work, dissipated, &
   & snapshot_t, snapshot_x, snapshot_u, stops_u, stops_reaction, filled, snaps, kappa_h, kappa_bound, &
   & dt_limit_newmark, dt_limit_paper, &
   & dt_limit_paper_bound, steps, t_final, cpu_seconds, impacts, max_violation, run_status, run_message, &
   & status, message)
   use beamstops, only: error_type, fatal_error, scene_type, validate_scene, record_count, snapshot_count, &
      & model_type, prepare_run, simulate, array_recorder, n_columns, run_summary, status_complete, &
      & status_diverged
   use beamstops_recorder, only: col_t, col_u, col_v, col_reaction, col_energy, col_work, col_dissipated
   use beamstops_wrap_support, only: make_scene, report
   implicit none
   !f2py threadsafe
   real(8), intent(in) :: length, k2, mass_per_length, amplitude, omega, lower, upper, stiffness_per_mass
   real(8), intent(in) :: dt, t_end, beta, max_output_gb
   integer(8), intent(in) :: stop_count
   integer(8), intent(in) :: stop_nodes(stop_count + 1)
   real(8), intent(in) :: stop_lower(stop_count + 1), stop_upper(stop_count + 1)
   integer(8), intent(in) :: law, elements, centered_load, taylor_start, allow_unstable, record_every, snapshot_every
   integer(8), intent(in) :: records, snapshots, nodes
   real(8), intent(out) :: t(records), tip_u(records), tip_v(records), reaction(records)
   real(8), intent(out) :: energy(records), work(records), dissipated(records)
   real(8), intent(out) :: snapshot_t(snapshots), snapshot_x(nodes), snapshot_u(nodes, snapshots)
   real(8), intent(out) :: stops_u(stop_count, records), stops_reaction(stop_count, records)
   integer(8), intent(out) :: filled, snaps, steps, impacts
   real(8), intent(out) :: kappa_h, kappa_bound, dt_limit_newmark, dt_limit_paper, dt_limit_paper_bound
   real(8), intent(out) :: t_final, cpu_seconds, max_violation
   integer, intent(out) :: run_status
   character(len=1024), intent(out) :: run_message
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(model_type) :: model
   type(array_recorder) :: recorder
   type(run_summary) :: summary
   type(error_type), allocatable :: error
   integer :: stat
   integer(8) :: k

   t = 0; tip_u = 0; tip_v = 0; reaction = 0; energy = 0; work = 0; dissipated = 0
   snapshot_t = 0; snapshot_x = 0; snapshot_u = 0
   stops_u = 0; stops_reaction = 0
   filled = 0; snaps = 0; steps = 0; impacts = 0
   kappa_h = 0; kappa_bound = 0; dt_limit_newmark = 0; dt_limit_paper = 0; dt_limit_paper_bound = 0
   t_final = 0; cpu_seconds = 0; max_violation = 0
   run_status = 2
   run_message = ''

   call make_scene(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
      & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
      & max_output_gb, stop_nodes(:stop_count), stop_lower(:stop_count), stop_upper(:stop_count), &
      & 'scene', scene, error)
   if (.not. allocated(error)) call validate_scene(scene, 'scene', error)
   if (.not. allocated(error)) then
      if (records /= record_count(scene) .or. snapshots /= snapshot_count(scene) .or. &
         & nodes /= scene%elements + 1) call fatal_error(error, 'scene: the arrays given to bs_run do not have '// &
         & 'the sizes bs_sizes returns for this scene')
   end if
   if (.not. allocated(error)) call prepare_run(scene, 'scene', model, error)
   if (.not. allocated(error)) then
      ! The array recorder's buffers, sized as its `reserve` would, but allocated with a status.
      allocate (recorder%rows(n_columns, records), recorder%snap_t(snapshots), recorder%snap_u(nodes, snapshots), &
         & recorder%stops_u(stop_count, records), recorder%stops_reaction(stop_count, records), stat=stat)
      if (stat /= 0) call fatal_error(error, 'scene: not enough memory for the records of this run')
      recorder%filled = 0
      recorder%snaps = 0
      recorder%stops_filled = 0
   end if
   if (.not. allocated(error)) call simulate(scene, model, recorder, summary, error)
   if (allocated(error)) then
      call report(error, status, message)
      return
   end if

   kappa_h = model%kappa_h
   kappa_bound = model%kappa_bound
   dt_limit_newmark = model%dt_newmark
   dt_limit_paper = model%dt_paper_exact
   dt_limit_paper_bound = model%dt_paper_bound
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
   end do
   stops_u(:, :recorder%stops_filled) = recorder%stops_u(:, :recorder%stops_filled)
   stops_reaction(:, :recorder%stops_filled) = recorder%stops_reaction(:, :recorder%stops_filled)
   snapshot_t(:snaps) = recorder%snap_t(:snaps)
   snapshot_u(:, :snaps) = recorder%snap_u(:, :snaps)
   snapshot_x = model%x
   steps = summary%steps
   t_final = summary%t_final
   cpu_seconds = summary%cpu_seconds
   impacts = summary%impacts
   max_violation = summary%max_violation
   if (summary%status == status_complete) then
      run_status = 0
   else if (summary%status == status_diverged) then
      run_status = 1
   else
      run_status = 2
   end if
   if (allocated(summary%message)) run_message = summary%message
   status = 0
   message = ''
end subroutine bs_run

!> The scene the program reads from a namelist file (the engine's own reader), flat.
subroutine bs_read_scene(path, length, k2, mass_per_length, amplitude, omega, lower, upper, law, &
   & stiffness_per_mass, elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, &
   & snapshot_every, max_output_gb, stop_count, file, status, message)
   use beamstops, only: error_type, scene_type, read_scene, stop_count_of => stop_count
   use beamstops_wrap_support, only: report
   implicit none
   character(len=*), intent(in) :: path
   real(8), intent(out) :: length, k2, mass_per_length, amplitude, omega, lower, upper, stiffness_per_mass
   real(8), intent(out) :: dt, t_end, beta, max_output_gb
   integer(8), intent(out) :: law, elements, centered_load, taylor_start, allow_unstable, record_every, snapshot_every
   integer(8), intent(out) :: stop_count
   character(len=4096), intent(out) :: file
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(error_type), allocatable :: error
   call read_scene(trim(path), scene, error)
   length = scene%length
   k2 = scene%k2
   mass_per_length = scene%mass_per_length
   amplitude = scene%amplitude
   omega = scene%omega
   lower = scene%lower
   upper = scene%upper
   law = scene%law
   stiffness_per_mass = scene%stiffness_per_mass
   elements = scene%elements
   dt = scene%dt
   t_end = scene%t_end
   beta = scene%beta
   centered_load = merge(1, 0, scene%centered_load)
   taylor_start = merge(1, 0, scene%taylor_start)
   allow_unstable = merge(1, 0, scene%allow_unstable)
   record_every = scene%record_every
   snapshot_every = scene%snapshot_every
   max_output_gb = scene%max_output_gb
   stop_count = stop_count_of(scene)
   file = ''
   if (allocated(scene%output_file)) file = scene%output_file
   call report(error, status, message)
end subroutine bs_read_scene

!> The stops along the span the program reads from a namelist file: `stop_count` from
!> bs_read_scene; nodes (1..J), lower and upper stops (m).
subroutine bs_read_stops(path, stop_count, stop_nodes, stop_lower, stop_upper, status, message)
   use beamstops, only: error_type, fatal_error, scene_type, read_scene, stop_count_of => stop_count
   use beamstops_wrap_support, only: report
   implicit none
   character(len=*), intent(in) :: path
   integer(8), intent(in) :: stop_count
   integer(8), intent(out) :: stop_nodes(stop_count)
   real(8), intent(out) :: stop_lower(stop_count), stop_upper(stop_count)
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(error_type), allocatable :: error
   stop_nodes = 0
   stop_lower = 0
   stop_upper = 0
   call read_scene(trim(path), scene, error)
   if (.not. allocated(error)) then
      if (stop_count_of(scene) /= stop_count) then
         call fatal_error(error, trim(path)//': bs_read_stops needs the stop_count of bs_read_scene')
      else if (stop_count > 0) then
         stop_nodes = scene%stop_nodes
         stop_lower = scene%stop_lower
         stop_upper = scene%stop_upper
      end if
   end if
   call report(error, status, message)
end subroutine bs_read_stops

!> k2 = E I/(rho S) and the mass per length rho S of a tube, as the namelist reader derives them.
subroutine bs_tube(youngs_modulus, density, outer_diameter, wall_thickness, k2, mass_per_length)
   use beamstops_scene, only: tube_beam
   implicit none
   real(8), intent(in) :: youngs_modulus, density, outer_diameter, wall_thickness
   real(8), intent(out) :: k2, mass_per_length
   call tube_beam(youngs_modulus, density, outer_diameter, wall_thickness, k2, mass_per_length)
end subroutine bs_tube

!> Studies: a scene without stops run in the paper's three-level form (module
!> beamstops_three_level), recording the tip every record_every steps; `records` from bs_sizes.
!> Only to measure the round-off floor that the engine's increment form removes (SPEC 4).
subroutine bs_run_three_level(length, k2, mass_per_length, amplitude, omega, lower, upper, law, &
   & stiffness_per_mass, elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, &
   & snapshot_every, max_output_gb, stop_count, stop_nodes, stop_lower, stop_upper, records, t, tip_u, cpu_seconds, status, message)
   use beamstops, only: error_type, fatal_error, scene_type, validate_scene, record_count, model_type, &
      & prepare_run, run_three_level
   use beamstops_wrap_support, only: make_scene, report
   implicit none
   !f2py threadsafe
   real(8), intent(in) :: length, k2, mass_per_length, amplitude, omega, lower, upper, stiffness_per_mass
   real(8), intent(in) :: dt, t_end, beta, max_output_gb
   integer(8), intent(in) :: stop_count
   integer(8), intent(in) :: stop_nodes(stop_count + 1)
   real(8), intent(in) :: stop_lower(stop_count + 1), stop_upper(stop_count + 1)
   integer(8), intent(in) :: law, elements, centered_load, taylor_start, allow_unstable, record_every, snapshot_every
   integer(8), intent(in) :: records
   real(8), intent(out) :: t(records), tip_u(records), cpu_seconds
   integer, intent(out) :: status
   character(len=1024), intent(out) :: message
   type(scene_type) :: scene
   type(model_type) :: model
   type(error_type), allocatable :: error
   real(8), allocatable :: tt(:), uu(:)
   t = 0; tip_u = 0; cpu_seconds = 0
   call make_scene(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
      & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
      & max_output_gb, stop_nodes(:stop_count), stop_lower(:stop_count), stop_upper(:stop_count), &
      & 'scene', scene, error)
   if (.not. allocated(error)) call validate_scene(scene, 'scene', error)
   if (.not. allocated(error)) then
      if (records /= record_count(scene)) call fatal_error(error, 'scene: the arrays given to '// &
         & 'bs_run_three_level do not have the size bs_sizes returns for this scene')
   end if
   if (.not. allocated(error)) call prepare_run(scene, 'scene', model, error)
   if (.not. allocated(error)) call run_three_level(scene, model, tt, uu, cpu_seconds, error)
   if (.not. allocated(error)) then
      t = tt
      tip_u = uu
   end if
   call report(error, status, message)
end subroutine bs_run_three_level

!> Studies: the full state of the engine's own loop (start_state, advance) at chosen steps,
!> u^n (the homogeneous unknown, 2J values and slopes) and v^n = (u^{n+1} - u^{n-1})/(2 dt),
!> with M and S (band storage, per unit mass). Rationale: the energy norm of an error,
!> 1/2 e'.M e' + 1/2 e.S e, needs slopes and velocities, which the records (tip) and the
!> snapshots (nodal values) do not hold. `steps` ascending in 0..steps_of(scene); n = 2J.
subroutine bs_states(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
   & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
   & max_output_gb, stop_count, stop_nodes, stop_lower, stop_upper, count, steps, n, u, v, mass, stiffness, cpu_seconds, status, message)
   use beamstops, only: error_type, fatal_error, scene_type, validate_scene, steps_of, model_type, prepare_run, &
      & state_type, start_state, array_recorder
   use beamstops_scheme, only: advance
   use beamstops_wrap_support, only: make_scene, report
   implicit none
   !f2py threadsafe
   real(8), intent(in) :: length, k2, mass_per_length, amplitude, omega, lower, upper, stiffness_per_mass
   real(8), intent(in) :: dt, t_end, beta, max_output_gb
   integer(8), intent(in) :: stop_count
   integer(8), intent(in) :: stop_nodes(stop_count + 1)
   real(8), intent(in) :: stop_lower(stop_count + 1), stop_upper(stop_count + 1)
   integer(8), intent(in) :: law, elements, centered_load, taylor_start, allow_unstable, record_every, snapshot_every
   integer(8), intent(in) :: count, n
   integer(8), intent(in) :: steps(count)
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
   u = 0; v = 0; mass = 0; stiffness = 0; cpu_seconds = 0
   call make_scene(length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, &
      & elements, dt, t_end, beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, &
      & max_output_gb, stop_nodes(:stop_count), stop_lower(:stop_count), stop_upper(:stop_count), &
      & 'scene', scene, error)
   if (.not. allocated(error)) call validate_scene(scene, 'scene', error)
   if (.not. allocated(error)) then
      if (n /= 2*scene%elements) call fatal_error(error, 'scene: bs_states needs n = 2*elements')
   end if
   if (.not. allocated(error)) then
      do k = 1, count
         if (steps(k) < 0 .or. steps(k) > steps_of(scene) .or. (k > 1 .and. steps(max(k - 1, 1_8)) >= steps(k))) &
            & call fatal_error(error, 'scene: bs_states needs ascending steps in 0..steps of the scene')
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
   call prepare_run(scene, 'scene', model, error)
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
   call cpu_time(t0)
   do k = 1, count
      step = steps(k)
      if (step == 0) then
         u(:, k) = model%u0
         v(:, k) = model%v0
         cycle
      end if
      if (state%step <= step - 1) call advance(scene, model, state, recorder, step - 1)
      d_prev = state%d
      call advance(scene, model, state, recorder, step)
      u(:, k) = state%u - state%d
      v(:, k) = (state%d + d_prev)/(2*dt)
   end do
   call cpu_time(t1)
   cpu_seconds = t1 - t0
   call report(error, status, message)
end subroutine bs_states
