!> The scene: every input of a run as plain data, with the paper's scene as
!> default and one validation that names group, key and allowed range.
module beamstops_scene
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_strings, only: fmt_real, fmt_int
   use beamstops_attributes, only: attribute_list, namelist_text
   implicit none
   private
   public :: scene_type, validate_scene, steps_of, record_count, snapshot_count, output_bytes
   public :: shock_log_rows, shock_row_bytes
   public :: tube_section, tube_beam, fmt_real, fmt_int
   public :: law_none, law_signorini, law_compliance, law_name, law_code
   public :: max_elements, max_stops, max_members, stop_count, scene_table, canonical_text
   public :: min_stiffness_per_mass, max_stiffness_per_mass, k2_range, mass_per_length_range

   !> Contact law codes.
   integer, parameter :: law_none = 0, law_signorini = 1, law_compliance = 2
   !> Largest mesh accepted (memory stays below a few GB).
   integer, parameter :: max_elements = 1000000
   !> Most stops along the span (&stops nodes or x).
   integer, parameter :: max_stops = 1000
   !> Most members of an ensemble (&ensemble members).
   integer, parameter :: max_members = 10000
   !> Most memory an ensemble's members may take together (GB): each keeps its statistics (bins
   !> x batches values of its histograms), its state (about 16 values an unknown in lockstep) and
   !> its shock log (shock_log_rows rows of shock_row_bytes). Beyond it the allocations failed with
   !> a backtrace, or succeeded and filled the machine.
   real(wp), parameter :: max_ensemble_gb = 16
   !> Bytes of a row of the shock log (beamstops_observe_shocks' shock_row; the shocks suite of
   !> tests/fortran checks it against the type's storage_size).
   integer, parameter :: shock_row_bytes = 96
   !> Range of the compliance spring per unit mass (1/s^2); &stops stiffness (N/m) is told in it
   !> times mass_per_length.
   real(wp), parameter :: min_stiffness_per_mass = 1.0e-12_wp, max_stiffness_per_mass = 1.0e20_wp
   !> Ranges of k2 (m^4/s^2) and mass_per_length (kg/m), given or derived from a tube's material.
   real(wp), parameter :: k2_range(2) = [1.0e-12_wp, 1.0e15_wp], mass_per_length_range(2) = [1.0e-12_wp, 1.0e9_wp]
   !> Shortest time step and final time (s): a femtosecond, 1/50,000 of the first period of the
   !> stiffest real beam the lengths allow (E/rho <= 1e9 m^2/s^2 and a section narrower than
   !> the length give k2 <= 1e9 length^2: omega_1 <= 1.1e11 rad/s at length = 1e-6 m); far
   !> above the underflow of dt^2 (subnormal below 1.5e-154 s: runs diverged at t = 0).
   real(wp), parameter :: min_dt = 1.0e-15_wp

   !> Every input of a run. Defaults reproduce the paper's scene (Figure 2).
   type :: scene_type
      !> &beam: length L of the beam (m).
      real(wp) :: length = 1.501_wp
      !> &beam: k^2 = EI/(rho S) (m^4/s^2).
      real(wp) :: k2 = 282.84_wp
      !> &beam: mass per unit length rho S (kg/m); scales reactions and energies.
      real(wp) :: mass_per_length = 0.11938_wp
      !> &support: amplitude a of phi(t) = a sin(omega t) (m).
      real(wp) :: amplitude = 0.2_wp
      !> &support: angular frequency omega of the support (rad/s).
      real(wp) :: omega = 10.0_wp
      !> &stops: lower stop g1 < 0 (m).
      real(wp) :: lower = -0.1_wp
      !> &stops: upper stop g2 > 0 (m).
      real(wp) :: upper = 0.1_wp
      !> &stops: contact law (law_signorini, law_compliance or law_none).
      integer :: law = law_signorini
      !> &stops: normal-compliance stiffness per unit mass 1/epsilon (1/s^2).
      real(wp) :: stiffness_per_mass = 0.0_wp
      !> &stops: nodes (1..J) of the stops along the span (SPEC 7), the tip (J) possibly among
      !> them; unallocated or empty: the tip stops lower, upper only (stop_count).
      integer, allocatable :: stop_nodes(:)
      !> &stops: lower stop of each node of stop_nodes, < 0 (m): bounds the physical displacement.
      real(wp), allocatable :: stop_lower(:)
      !> &stops: upper stop of each node of stop_nodes, > 0 (m).
      real(wp), allocatable :: stop_upper(:)
      !> &mesh: number of elements J.
      integer :: elements = 19
      !> &time: time step (s).
      real(wp) :: dt = 5.0e-5_wp
      !> &time: final time (s).
      real(wp) :: t_end = 2.0_wp
      !> &time: Newmark beta in [0, 1/2].
      real(wp) :: beta = 0.5_wp
      !> &time: .true. for the centred load rule (second order), .false. for the paper's.
      logical :: centered_load = .true.
      !> &time: .true. for the second-order Taylor start, .false. for the Euler start.
      logical :: taylor_start = .true.
      !> &time: run even beyond the linear stability limit of beta < 1/4.
      logical :: allow_unstable = .false.
      !> &output: HDF5 file written by the program (not used by the in-memory path); '' when the
      !> namelist came from a pipe or a device, which gives the file no default name.
      character(len=:), allocatable :: output_file
      !> &output: refuse a run whose output would exceed this many gigabytes (1e9 bytes).
      real(wp) :: max_output_gb = 4.0_wp
      !> &output: save a checkpoint every this many steps (0: never).
      integer(ik) :: checkpoint_every = 0
      !> &output: record the tip and the energy every this many steps.
      integer :: record_every = 1
      !> &output: record the beam's shape every this many steps (0: never).
      integer :: snapshot_every = 0
      ! ---- physics of issue 12 (SPEC 8-10): damping, restitution, mass redistribution ----
      ! Checked by beamstops_physics_checks' validate_physics; the model derives what it uses.
      !> &damping: Rayleigh coefficient a of C = a M + b S (1/s), >= 0.
      real(wp) :: damping_mass = 0
      !> &damping: Rayleigh coefficient b of C = a M + b S (s), >= 0.
      real(wp) :: damping_stiffness = 0
      !> &damping: damping ratios zeta at the two modes damping_modes, in [0, 1) (ratio form:
      !> a and b solve zeta(omega) = a/(2 omega) + b omega/2 at those modes; one ratio given
      !> means both equal).
      real(wp) :: damping_ratio(2) = 0
      !> &damping: the two cantilever modes (1-based, distinct, <= 2J) of the ratio form.
      integer :: damping_modes(2) = [1, 2]
      !> &damping: .true. when a and b come from damping_ratio (the ratio form).
      logical :: damping_by_ratio = .false.
      !> &stops: Paoli-Schatzman restitution coefficient e in [0, 1] (law 'signorini'; 0: the
      !> paper's scheme).
      real(wp) :: restitution = 0
      !> &stops: .true. to give the constrained displacement unknowns no mass (SPEC 10; beta > 0).
      logical :: redistributed_mass = .false.
      ! ---- end of issue 12 ----
      ! ---- shocks and statistics (issue 13, SPEC 12), ensembles ----
      !> &statistics enabled: keep the shock log and the running statistics.
      logical :: statistics = .true.
      !> &statistics: start of the statistics' window (s), 0 <= transient < t_end.
      real(wp) :: transient = 0
      !> &statistics: batches of the batch-means intervals (>= 2) and bins of the tip histogram.
      integer :: batches = 20, bins = 40
      !> &statistics: contact phases closer than this are one shock (s; code_aster's DUREE_REPOS).
      real(wp) :: rest_time = 1.0e-2_wp
      !> &statistics: range of the tip histogram (m); the reader fills in the stops' range.
      real(wp) :: histogram_lower = -0.1_wp, histogram_upper = 0.1_wp
      !> &ensemble: members (1: the scene alone), the size of their initial perturbation (m) and the
      !> seed of its random numbers.
      integer :: members = 1
      real(wp) :: perturbation = 0
      integer :: seed = 1
      ! ---- end of issue 13 ----
      ! ---- reduced (modal) models (SPEC 11, issue 14; beamstops_reduced) ----
      !> &mesh: fixed-interface modes r of a reduced (Craig-Bampton) model; 0: the full model.
      integer :: modes = 0
      ! ---- end reduced ----
   end type scene_type

contains

   !> Number of time steps N = nint(t_end/dt) of a scene.
   pure function steps_of(scene) result(n)
      !> The scene.
      type(scene_type), intent(in) :: scene
      integer(ik) :: n
      n = max(1_ik, nint(scene%t_end/scene%dt, ik))
   end function steps_of

   !> Number m of stops along the span (0: the tip-only form, stops lower and upper at the tip).
   pure function stop_count(scene) result(m)
      !> Scene.
      type(scene_type), intent(in) :: scene
      integer :: m
      m = 0
      if (allocated(scene%stop_nodes)) m = size(scene%stop_nodes)
   end function stop_count

   !> Records a complete run writes (t = 0 included).
   pure function record_count(scene) result(n)
      !> Scene.
      type(scene_type), intent(in) :: scene
      integer(ik) :: n
      n = steps_of(scene)/scene%record_every + 1
   end function record_count

   !> Rows of the shock log of a scene with m stops (the tip alone: 1): drained every block of
   !> 8192 steps, in which at most m (4096 + 1) shocks can close (beamstops_observe_observer).
   pure integer function shock_log_rows(m)
      !> Stops.
      integer, intent(in) :: m
      shock_log_rows = m*4097 + 16
   end function shock_log_rows

   !> Snapshots a complete run writes (t = 0 included; 0 when snapshot_every = 0).
   pure function snapshot_count(scene) result(n)
      !> Scene.
      type(scene_type), intent(in) :: scene
      integer(ik) :: n
      n = 0
      if (scene%snapshot_every > 0) n = steps_of(scene)/scene%snapshot_every + 1
   end function snapshot_count

   !> Bytes of recorded data of a complete run: 9 series of records, 2 per stop along the span,
   !> and the snapshots.
   pure function output_bytes(scene) result(bytes)
      !> Scene.
      type(scene_type), intent(in) :: scene
      real(wp) :: bytes
      bytes = row_bytes(scene)*real(record_count(scene), wp) + shape_bytes(scene)*real(snapshot_count(scene), wp)
   end function output_bytes

   !> Bytes of one record: its 9 series (tip and energy) and, with stops along the span, each
   !> stop's displacement and reaction.
   pure real(wp) function row_bytes(scene)
      !> Scene.
      type(scene_type), intent(in) :: scene
      row_bytes = 8*real(9 + 2*stop_count(scene), wp)
   end function row_bytes

   !> Bytes of one snapshot: the time and the J + 1 nodal displacements.
   pure real(wp) function shape_bytes(scene)
      !> Scene.
      type(scene_type), intent(in) :: scene
      shape_bytes = 8*real(scene%elements + 2, wp)
   end function shape_bytes

   !> Cross-section area and second moment of a tube.
   pure subroutine tube_section(outer_diameter, wall_thickness, area, inertia)
      !> Outer diameter (m).
      real(wp), intent(in) :: outer_diameter
      !> Wall thickness (m).
      real(wp), intent(in) :: wall_thickness
      !> Cross-section area (m^2).
      real(wp), intent(out) :: area
      !> Second moment of area (m^4).
      real(wp), intent(out) :: inertia
      real(wp), parameter :: pi = acos(-1.0_wp)
      real(wp) :: d_in
      d_in = outer_diameter - 2*wall_thickness
      area = pi/4*(outer_diameter**2 - d_in**2)
      inertia = pi/64*(outer_diameter**4 - d_in**4)
   end subroutine tube_section

   !> k^2 = E I/(rho S) and the mass per length rho S of a tube.
   pure subroutine tube_beam(youngs_modulus, density, outer_diameter, wall_thickness, k2, mass_per_length)
      !> Young's modulus E (Pa).
      real(wp), intent(in) :: youngs_modulus
      !> Density rho (kg/m^3).
      real(wp), intent(in) :: density
      !> Outer diameter (m).
      real(wp), intent(in) :: outer_diameter
      !> Wall thickness (m).
      real(wp), intent(in) :: wall_thickness
      !> k^2 (m^4/s^2).
      real(wp), intent(out) :: k2
      !> rho S (kg/m).
      real(wp), intent(out) :: mass_per_length
      real(wp) :: area, inertia
      call tube_section(outer_diameter, wall_thickness, area, inertia)
      k2 = youngs_modulus*inertia/(density*area)
      mass_per_length = density*area
   end subroutine tube_beam

   !> Name of a contact-law code, as written in a namelist.
   pure function law_name(law) result(name)
      !> Law code.
      integer, intent(in) :: law
      character(len=:), allocatable :: name
      select case (law)
      case (law_signorini); name = 'signorini'
      case (law_compliance); name = 'compliance'
      case default; name = 'none'
      end select
   end function law_name

   !> Code of a contact-law name; -1 when unknown.
   pure function law_code(name) result(law)
      !> Law name (case-sensitive, lower case).
      character(len=*), intent(in) :: name
      integer :: law
      select case (trim(adjustl(name)))
      case ('signorini'); law = law_signorini
      case ('compliance'); law = law_compliance
      case ('none'); law = law_none
      case default; law = -1
      end select
   end function law_code

   !> The one table of a scene's keys: every namelist key with its value (defaults filled in,
   !> the material route resolved into k2 and mass_per_length, x into nodes, stiffness into
   !> stiffness_per_mass), and whether each is a root attribute of the output and part of a
   !> checkpoint's signature. The canonical text, the output's attributes, Python's scene and
   !> the restart check all read it. A new scene key is one line here.
   function scene_table(scene) result(list)
      !> Scene.
      type(scene_type), intent(in) :: scene
      type(attribute_list) :: list
      integer :: m
      m = stop_count(scene)
      call list%add_real('beam', 'length', scene%length)
      call list%add_real('beam', 'k2', scene%k2)
      call list%add_real('beam', 'mass_per_length', scene%mass_per_length)
      call list%add_real('support', 'amplitude', scene%amplitude)
      call list%add_real('support', 'omega', scene%omega)
      if (m == 0) then
         call list%add_real('stops', 'lower', scene%lower)
         call list%add_real('stops', 'upper', scene%upper)
      else
         call list%add_int('stops', 'nodes', 0_ik, values=int(scene%stop_nodes, ik), attribute=.false.)
         call list%add_real('stops', 'lower', 0.0_wp, values=scene%stop_lower, attribute=.false.)
         call list%add_real('stops', 'upper', 0.0_wp, values=scene%stop_upper, attribute=.false.)
         call list%add_int('', 'stops', int(m, ik))
      end if
      call list%add_text('stops', 'law', law_name(scene%law))
      if (scene%law == law_compliance) call list%add_real('stops', 'stiffness_per_mass', scene%stiffness_per_mass)
      call list%add_real('stops', 'restitution', scene%restitution)
      call list%add_text('stops', 'mass', trim(merge('redistributed', 'consistent   ', scene%redistributed_mass)))
      if (scene%damping_by_ratio) then
         call list%add_real('damping', 'ratio', 0.0_wp, values=scene%damping_ratio, attribute=.false.)
      else
         call list%add_real('damping', 'mass_coefficient', scene%damping_mass)
         call list%add_real('damping', 'stiffness_coefficient', scene%damping_stiffness)
      end if
      if (scene%damping_by_ratio) call list%add_int('damping', 'modes', 0_ik, values=int(scene%damping_modes, ik), &
         & attribute=.false.)
      call list%add_logical('statistics', 'enabled', scene%statistics)
      call list%add_real('statistics', 'transient', scene%transient)
      call list%add_int('statistics', 'batches', int(scene%batches, ik))
      call list%add_int('statistics', 'bins', int(scene%bins, ik))
      call list%add_real('statistics', 'rest_time', scene%rest_time)
      call list%add_real('statistics', 'histogram_lower', scene%histogram_lower)
      call list%add_real('statistics', 'histogram_upper', scene%histogram_upper)
      call list%add_int('ensemble', 'members', int(scene%members, ik))
      call list%add_real('ensemble', 'perturbation', scene%perturbation)
      call list%add_int('ensemble', 'seed', int(scene%seed, ik))
      call list%add_int('mesh', 'elements', int(scene%elements, ik))
      call list%add_int('mesh', 'modes', int(scene%modes, ik))
      call list%add_real('time', 'dt', scene%dt)
      call list%add_real('time', 't_end', scene%t_end)
      call list%add_real('time', 'beta', scene%beta)
      call list%add_text('time', 'load_rule', trim(merge('centered', 'paper   ', scene%centered_load)))
      call list%add_text('time', 'start', trim(merge('taylor', 'euler ', scene%taylor_start)))
      call list%add_logical('time', 'allow_unstable', scene%allow_unstable, signature=.false.)
      ! ('' when the input, a pipe or /dev/fd/N, gave no name: none to write)
      if (allocated(scene%output_file)) then
         if (len(scene%output_file) > 0) call list%add_text('output', 'file', scene%output_file, attribute=.false., &
            & signature=.false.)
      end if
      call list%add_int('output', 'record_every', int(scene%record_every, ik))
      call list%add_int('output', 'snapshot_every', int(scene%snapshot_every, ik))
      call list%add_int('output', 'checkpoint_every', scene%checkpoint_every, attribute=.false.)
      call list%add_real('output', 'max_output_gb', scene%max_output_gb, signature=.false.)
   end function scene_table

   !> The scene as namelist text: every key, defaults filled in, values that read back exactly
   !> (reading it gives the same scene); the output file only when `with_file` (default .true.).
   function canonical_text(scene, with_file) result(text)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Include &output file.
      logical, intent(in), optional :: with_file
      character(len=:), allocatable :: text
      type(attribute_list) :: list
      logical, allocatable :: keep(:)
      integer :: i
      list = scene_table(scene)
      allocate (keep(list%count))
      keep = .true.
      if (present(with_file)) then
         if (.not. with_file) then
            do i = 1, list%count
               if (list%items(i)%name == 'file') keep(i) = .false.
            end do
         end if
      end if
      text = namelist_text(list, keep)
   end function canonical_text

   !> Check every value of a scene; `source` (a file name or 'scene') starts the message.
   subroutine validate_scene(scene, source, error)
      !> Scene to check.
      type(scene_type), intent(in) :: scene
      !> Where the scene came from, for messages.
      character(len=*), intent(in) :: source
      !> Set on the first value out of range.
      type(error_type), allocatable, intent(out) :: error

      call within('beam', 'length', scene%length, 1.0e-6_wp, 1.0e6_wp); if (allocated(error)) return
      call within('beam', 'k2', scene%k2, k2_range(1), k2_range(2)); if (allocated(error)) return
      call within('beam', 'mass_per_length', scene%mass_per_length, mass_per_length_range(1), mass_per_length_range(2))
      if (allocated(error)) return
      call within('support', 'amplitude', scene%amplitude, -1.0e3_wp, 1.0e3_wp); if (allocated(error)) return
      call within('support', 'omega', scene%omega, 0.0_wp, 1.0e9_wp); if (allocated(error)) return
      if (.not. (scene%lower >= -1.0e6_wp .and. scene%lower < 0)) then
         call say('stops', 'lower', fmt_real(scene%lower), '-1e+06 <= lower < 0 (the beam starts at rest at 0)'); return
      end if
      if (.not. (scene%upper > 0 .and. scene%upper <= 1.0e6_wp)) then
         call say('stops', 'upper', fmt_real(scene%upper), '0 < upper <= 1e+06 (the beam starts at rest at 0)'); return
      end if
      if (scene%law < law_none .or. scene%law > law_compliance) then
         call say('stops', 'law', '?', "'signorini', 'compliance' or 'none'"); return
      end if
      if (scene%law == law_compliance) then
         call within('stops', 'stiffness_per_mass', scene%stiffness_per_mass, min_stiffness_per_mass, &
            & max_stiffness_per_mass)
         if (allocated(error)) return
      end if
      if (scene%elements < 1 .or. scene%elements > max_elements) then
         call say('mesh', 'elements', fmt_int(int(scene%elements, ik)), '1 <= elements <= '//fmt_int(int(max_elements, ik)))
         return
      end if
      call span_stops_valid(); if (allocated(error)) return
      call within('time', 't_end', scene%t_end, min_dt, 1.0e9_wp, fmt_real(min_dt)//' <= t_end <= 1e+09 s')
      if (allocated(error)) return
      call within('time', 'dt', scene%dt, min_dt, scene%t_end, fmt_real(min_dt)//' <= dt <= t_end = '// &
         & fmt_real(scene%t_end)//' s')
      if (allocated(error)) return
      if (scene%t_end/scene%dt > 1.0e13_wp) then
         call say('time', 'dt', fmt_real(scene%dt), 't_end/dt <= 1e13 steps'); return
      end if
      call within('time', 'beta', scene%beta, 0.0_wp, 0.5_wp); if (allocated(error)) return
      if (scene%record_every < 1) then
         call say('output', 'record_every', fmt_int(int(scene%record_every, ik)), 'record_every >= 1'); return
      end if
      if (scene%snapshot_every < 0) then
         call say('output', 'snapshot_every', fmt_int(int(scene%snapshot_every, ik)), 'snapshot_every >= 0 (0: none)')
         return
      end if
      if (scene%checkpoint_every < 0) then
         call say('output', 'checkpoint_every', fmt_int(scene%checkpoint_every), 'checkpoint_every >= 0 (0: none)')
         return
      end if
      if (.not. (scene%max_output_gb > 0 .and. scene%max_output_gb <= 1.0e6_wp)) then
         call say('output', 'max_output_gb', fmt_real(scene%max_output_gb), '0 < max_output_gb <= 1e+06 (GB)'); return
      end if
      call output_fits(); if (allocated(error)) return
      call ensemble_fits(); if (allocated(error)) return

   contains

      !> Refuse an ensemble whose members' tables would not fit in max_ensemble_gb of memory,
      !> saying how many members would.
      subroutine ensemble_fits()
         real(wp) :: member_bytes
         if (scene%members < 2 .or. scene%members > max_members) return
         member_bytes = 8*(real(scene%bins, wp)*real(scene%batches, wp) + 16*2*real(scene%elements, wp)) + &
            & real(shock_row_bytes, wp)*shock_log_rows(max(1, stop_count(scene)))
         if (member_bytes*scene%members <= max_ensemble_gb*1.0e9_wp) return
         call say('ensemble', 'members', fmt_int(int(scene%members, ik)), 'members <= '// &
            & fmt_int(int(max_ensemble_gb*1.0e9_wp/member_bytes, ik))//' for this scene: the members take '// &
            & fmt_real(member_bytes*scene%members/1.0e9_wp, 5)//' GB of memory together, members x (8 bytes x '// &
            & '(bins x batches + 16 x 2 elements) + '//fmt_int(int(shock_row_bytes, ik))//' bytes x (4097 stops + 16) '// &
            & 'for the shock log) with bins = '//fmt_int(int(scene%bins, ik))//', batches = '// &
            & fmt_int(int(scene%batches, ik))//', elements = '//fmt_int(int(scene%elements, ik))//', stops = '// &
            & fmt_int(int(max(1, stop_count(scene)), ik))//'; at most '// &
            & fmt_real(max_ensemble_gb)//' GB')
      end subroutine ensemble_fits

      !> The stops along the span: as many bounds as nodes, nodes distinct in 1..J, lower < 0 < upper,
      !> and the Signorini law (or none); the compliance spring is at the tip only.
      subroutine span_stops_valid()
         integer :: m, i, j
         m = stop_count(scene)
         if (m == 0) return
         if (m > max_stops) then
            call say('stops', 'nodes', fmt_int(int(m, ik))//' stops', 'at most '//fmt_int(int(max_stops, ik))//' stops')
            return
         end if
         if (.not. allocated(scene%stop_lower)) then
            call say('stops', 'lower', 'missing', 'one value per stop'); return
         end if
         if (.not. allocated(scene%stop_upper)) then
            call say('stops', 'upper', 'missing', 'one value per stop'); return
         end if
         if (size(scene%stop_lower) /= m) then
            call say('stops', 'lower', fmt_int(int(size(scene%stop_lower), ik))//' values', &
               & 'one value per stop ('//fmt_int(int(m, ik))//')'); return
         end if
         if (size(scene%stop_upper) /= m) then
            call say('stops', 'upper', fmt_int(int(size(scene%stop_upper), ik))//' values', &
               & 'one value per stop ('//fmt_int(int(m, ik))//')'); return
         end if
         if (scene%law == law_compliance) then
            call fatal_error(error, source//": &stops law = 'compliance' with stops along the span (nodes or x) is "// &
               & "out of range; allowed: law = 'signorini' or 'none' with nodes or x (the compliance spring acts "// &
               & 'at the tip only: give lower and upper alone)')
            return
         end if
         do i = 1, m
            if (scene%stop_nodes(i) < 1 .or. scene%stop_nodes(i) > scene%elements) then
               call say('stops', 'nodes('//fmt_int(int(i, ik))//')', fmt_int(int(scene%stop_nodes(i), ik)), &
                  & '1 <= nodes <= elements = '//fmt_int(int(scene%elements, ik))//' (node 0 is clamped)'); return
            end if
            do j = 1, i - 1
               if (scene%stop_nodes(j) == scene%stop_nodes(i)) then
                  call say('stops', 'nodes('//fmt_int(int(i, ik))//')', fmt_int(int(scene%stop_nodes(i), ik)), &
                     & 'each node once (node '//fmt_int(int(scene%stop_nodes(i), ik))//' is given twice, as nodes('// &
                     & fmt_int(int(j, ik))//') too)'); return
               end if
            end do
            if (.not. (scene%stop_lower(i) >= -1.0e6_wp .and. scene%stop_lower(i) < 0)) then
               call say('stops', 'lower('//fmt_int(int(i, ik))//')', fmt_real(scene%stop_lower(i)), &
                  & '-1e+06 <= lower < 0 (the beam starts at rest at 0)'); return
            end if
            if (.not. (scene%stop_upper(i) > 0 .and. scene%stop_upper(i) <= 1.0e6_wp)) then
               call say('stops', 'upper('//fmt_int(int(i, ik))//')', fmt_real(scene%stop_upper(i)), &
                  & '0 < upper <= 1e+06 (the beam starts at rest at 0)'); return
            end if
         end do
      end subroutine span_stops_valid

      !> Refuse an output larger than max_output_gb, saying which record_every (or snapshot_every)
      !> fits, or, when none does, that the fixed part of the output alone exceeds it.
      subroutine output_fits()
         real(wp) :: limit, row, snapshot, records, snaps, fixed
         integer(ik) :: steps
         character(len=:), allocatable :: given
         limit = scene%max_output_gb*1.0e9_wp
         if (output_bytes(scene) <= limit) return
         steps = steps_of(scene)
         row = row_bytes(scene)
         snapshot = shape_bytes(scene)
         records = row*real(record_count(scene), wp)
         snaps = snapshot*real(snapshot_count(scene), wp)
         ! The least any record_every (at most huge(1)) gives, without snapshots.
         fixed = row*real(steps/huge(1) + 1, wp)
         given = ' gives '//fmt_real(output_bytes(scene)/1.0e9_wp, 3)//' GB of output, more than max_output_gb = '// &
            & fmt_real(scene%max_output_gb)
         if (fixed > limit) then
            call fatal_error(error, source//': &output max_output_gb = '//fmt_real(scene%max_output_gb)// &
               & ' is too small: the fixed part of the output alone (its records with the largest record_every, '// &
               & 'no snapshots) is '//fmt_real(fixed/1.0e9_wp, 3)//' GB; allowed: max_output_gb >= '// &
               & fmt_real(fixed/1.0e9_wp, 3)//' (raise max_output_gb)')
         else if (snaps > 0 .and. records + snapshot <= limit) then
            call fatal_error(error, source//': &output snapshot_every = '//fmt_int(int(scene%snapshot_every, ik))// &
               & given//'; allowed: snapshot_every >= '//fmt_int(least_every(snapshot, limit - records))// &
               & ' or snapshot_every = 0 (or raise max_output_gb)')
         else if (snaps + fixed <= limit) then
            call fatal_error(error, source//': &output record_every = '//fmt_int(int(scene%record_every, ik))// &
               & given//'; allowed: record_every >= '//fmt_int(least_every(row, limit - snaps))// &
               & ' (or raise max_output_gb)')
         else
            call fatal_error(error, source//': &output record_every = '//fmt_int(int(scene%record_every, ik))// &
               & ' and snapshot_every = '//fmt_int(int(scene%snapshot_every, ik))//given// &
               & '; allowed: snapshot_every = 0 and record_every >= '//fmt_int(least_every(row, limit))// &
               & ' (or raise max_output_gb)')
         end if
      end subroutine output_fits

      !> The least `every` whose steps/every + 1 rows of `bytes` each fit in `room` bytes (room >= bytes).
      pure function least_every(bytes, room) result(every)
         real(wp), intent(in) :: bytes, room
         integer(ik) :: every, rows, steps
         steps = steps_of(scene)
         ! rows - 1 = floor(steps/every) must be <= floor(room/bytes) - 1
         rows = int(min(room/bytes, real(steps + 1, wp)), ik)
         every = steps/rows + 1
      end function least_every

      subroutine say(group, key, value, allowed)
         character(len=*), intent(in) :: group, key, value, allowed
         call fatal_error(error, source//': &'//group//' '//key//' = '//value// &
            & ' is out of range; allowed: '//allowed)
      end subroutine say

      subroutine within(group, key, x, lo, hi, allowed)
         character(len=*), intent(in) :: group, key
         real(wp), intent(in) :: x, lo, hi
         character(len=*), intent(in), optional :: allowed
         if (ieee_is_finite(x) .and. x >= lo .and. x <= hi) return
         if (present(allowed)) then
            call say(group, key, fmt_real(x), allowed)
         else
            call say(group, key, fmt_real(x), fmt_real(lo)//' <= '//key//' <= '//fmt_real(hi))
         end if
      end subroutine within

   end subroutine validate_scene
end module beamstops_scene
