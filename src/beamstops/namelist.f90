!> Scene from namelist text: groups &beam, &support, &stops, &mesh, &time, &output.
!> The one reader of every input: the program reads a file into text (read_scene), Python
!> hands the text it wrote (scene_from_text). Unknown or repeated groups, text outside any
!> group, unknown keys, malformed and out-of-range values all end in one message naming the
!> source, the group and the key.
module beamstops_namelist
   use, intrinsic :: iso_fortran_env, only: iostat_end, int64
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_files, only: read_whole_file, read_missing, read_folder, read_too_big, read_unopened, read_failed
   use beamstops_scene, only: scene_type, validate_scene, tube_beam, law_code, law_compliance, max_stops, stop_count, &
      & steps_of, min_stiffness_per_mass, max_stiffness_per_mass, k2_range, mass_per_length_range
   use beamstops_strings, only: fmt_real, fmt_int, itoa, lower, squeeze
   use beamstops_physics_checks, only: validate_physics
   use beamstops_observe_statistics, only: validate_statistics, validate_ensemble
   use beamstops_reduced, only: validate_reduced, stop_unknowns
   use beamstops_namelist_text
   implicit none
   private
   public :: read_scene, scene_from_text, read_text_file, default_output, group_names, group_keys

   real(wp), parameter :: unset = -huge(1.0_wp)
   integer, parameter :: unset_node = -huge(1)

contains

   !> Read, derive and validate a scene from a namelist file; missing groups and keys keep
   !> the paper's values. The output file defaults to the file's base name with '.h5'; a file
   !> named by an open descriptor (/dev/stdin, /dev/fd/N, /proc/.../fd/N: a pipe, `<(...)`) or that
   !> is not a regular file gives no name (the output file is then '', refused by the program's
   !> check_output_path unless named by -o or &output file).
   subroutine read_scene(path, scene, error)
      !> Namelist file.
      character(len=*), intent(in) :: path
      !> Scene read.
      type(scene_type), intent(out) :: scene
      !> Set on any bad input.
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      logical :: regular
      call read_text_file(path, text, error, regular)
      if (allocated(error)) return
      if (regular .and. .not. descriptor_path(path)) then
         call scene_from_text(text, path, scene, error, default_output(path))
      else
         call scene_from_text(text, path, scene, error, '')
      end if
   end subroutine read_scene

   !> Whether a path names an open file descriptor rather than a file: /dev/stdin, /dev/fd/N,
   !> /proc/self/fd/N or /proc/PID/fd/N (what a shell's `<(...)` gives).
   pure logical function descriptor_path(path)
      !> Path.
      character(len=*), intent(in) :: path
      descriptor_path = path == '/dev/stdin' .or. index(path, '/dev/fd/') == 1 .or. &
         & (index(path, '/proc/') == 1 .and. index(path, '/fd/') > 0)
   end function descriptor_path

   !> The whole of a text file (lines separated by new_line('a')), at most 64 MB: a regular file,
   !> or a pipe, a FIFO or a device read to its end.
   subroutine read_text_file(path, text, error, regular)
      !> File.
      character(len=*), intent(in) :: path
      !> Its content.
      character(len=:), allocatable, intent(out) :: text
      !> Set when the file cannot be read.
      type(error_type), allocatable, intent(out) :: error
      !> Whether it is a regular file (not a pipe, a FIFO or a device).
      logical, intent(out), optional :: regular
      integer(int64), parameter :: max_bytes = 64*1024*1024_int64
      character(len=:), allocatable :: why
      integer(int64) :: bytes
      integer :: outcome
      logical :: is_regular
      call read_whole_file(path, max_bytes, text, outcome, bytes, is_regular, why)
      if (present(regular)) regular = is_regular
      select case (outcome)
      case (read_missing)
         call fatal_error(error, path//': cannot open: no such file')
      case (read_folder)
         call fatal_error(error, path//': cannot open: a directory, not a namelist file')
      case (read_too_big)
         if (bytes >= 0) then
            call fatal_error(error, path//': '//fmt_int(bytes)//' bytes; allowed: a namelist file of at most 64 MB')
         else
            call fatal_error(error, path//': more than 64 MB read (a pipe or a device); allowed: a namelist file of '// &
               & 'at most 64 MB')
         end if
      case (read_unopened)
         call fatal_error(error, path//': cannot open: '//why)
      case (read_failed)
         call fatal_error(error, path//': cannot read: '//why)
      end select
   end subroutine read_text_file

   !> Read, derive and validate a scene from namelist text; `source` (a file name, or 'scene'
   !> for Python's text) starts every message. Missing groups and keys keep the paper's values;
   !> the output file is `default_file` when the text names none (unset when not given either).
   !> `carried` names keys the text carries over from a scene being changed rather than gives
   !> anew (Python's Scene.replace), as 'group:key' words: such a key that does nothing under
   !> the other keys (a spring without the compliance law, &damping modes without ratio) is
   !> dropped where a key given anew is refused.
   recursive subroutine scene_from_text(text, source, scene, error, default_file, carried)
      !> Namelist text.
      character(len=*), intent(in) :: text
      !> Where the text came from, for messages.
      character(len=*), intent(in) :: source
      !> Scene read.
      type(scene_type), intent(out) :: scene
      !> Set on any bad input.
      type(error_type), allocatable, intent(out) :: error
      !> Output file when the text names none.
      character(len=*), intent(in), optional :: default_file
      !> Keys carried over from a scene being changed ('group:key' words, blank-separated).
      character(len=*), intent(in), optional :: carried
      ! &beam
      real(wp) :: length, k2, mass_per_length, youngs_modulus, density, outer_diameter, wall_thickness
      ! &support
      real(wp) :: amplitude, omega
      ! &stops: lower, upper one value (the tip) or one per stop along the span (nodes or x)
      real(wp) :: lower(max_stops), upper(max_stops), x(max_stops), stiffness, stiffness_per_mass
      integer :: nodes(max_stops)
      character(len=word_len) :: law, mass
      real(wp) :: restitution
      ! &damping: Rayleigh coefficients, or ratios at two modes
      real(wp) :: mass_coefficient, stiffness_coefficient, ratio(2)
      integer :: modes(2)
      ! &statistics, &ensemble
      logical :: enabled
      real(wp) :: transient, rest_time, histogram_lower, histogram_upper, perturbation
      integer :: batches, bins, members, seed
      ! &mesh
      integer :: elements, mesh_modes
      ! &time
      real(wp) :: dt, t_end, beta
      character(len=word_len) :: load_rule, start
      logical :: allow_unstable
      ! &output
      character(len=text_len) :: file
      integer :: record_every, snapshot_every
      real(wp) :: max_output_gb
      integer(ik) :: checkpoint_every
      namelist /beam/ length, k2, mass_per_length, youngs_modulus, density, outer_diameter, wall_thickness
      namelist /support/ amplitude, omega
      namelist /stops/ lower, upper, nodes, x, law, stiffness, stiffness_per_mass, restitution, mass
      namelist /damping/ mass_coefficient, stiffness_coefficient, ratio, modes
      namelist /statistics/ enabled, transient, batches, bins, rest_time, histogram_lower, histogram_upper
      namelist /ensemble/ members, perturbation, seed
      namelist /time/ dt, t_end, beta, load_rule, start, allow_unstable
      namelist /output/ file, record_every, snapshot_every, checkpoint_every, max_output_gb
      character(len=text_len) :: groups_text(size(group_names))
      logical :: has_group(size(group_names))
      character(len=512) :: msg
      character(len=:), allocatable :: cleaned, spring_key
      character(len=*), parameter :: no_file = achar(1)
      integer :: stat, g

      call scan_groups(without_bom(text), source, has_group, groups_text, cleaned, error)
      if (allocated(error)) return

      length = scene%length; k2 = unset; mass_per_length = unset
      youngs_modulus = unset; density = unset; outer_diameter = unset; wall_thickness = unset
      amplitude = scene%amplitude; omega = scene%omega
      lower = unset; upper = unset; nodes = unset_node; x = unset
      law = 'signorini'; stiffness = unset; stiffness_per_mass = unset
      restitution = scene%restitution; mass = 'consistent'
      mass_coefficient = unset; stiffness_coefficient = unset; ratio = unset; modes = unset_node
      enabled = scene%statistics; transient = scene%transient; batches = scene%batches; bins = scene%bins
      rest_time = scene%rest_time; histogram_lower = unset; histogram_upper = unset
      members = scene%members; perturbation = scene%perturbation; seed = scene%seed
      elements = scene%elements; mesh_modes = scene%modes
      dt = scene%dt; t_end = scene%t_end; beta = scene%beta; load_rule = 'centered'; start = 'taylor'
      allow_unstable = .false.
      file = no_file; record_every = scene%record_every; snapshot_every = scene%snapshot_every
      max_output_gb = scene%max_output_gb
      checkpoint_every = scene%checkpoint_every

      do g = 1, size(group_names)
         if (.not. has_group(g)) cycle
         call check_assignments(g)
         if (allocated(error)) return
      end do
      do g = 1, size(group_names)
         if (.not. has_group(g)) cycle
         call read_group(g, group_text(g), stat, msg)
         if (stat /= 0) then
            call malformed_key(g, stat, msg)
            return
         end if
      end do
      call sentinel_given(); if (allocated(error)) return

      call derive_beam(source, length, k2, mass_per_length, youngs_modulus, density, outer_diameter, &
         & wall_thickness, scene, error)
      if (allocated(error)) return
      scene%amplitude = amplitude
      scene%omega = omega
      scene%law = law_code(law)
      if (scene%law < 0) then
         call fatal_error(error, source//": &stops law = '"//trim(law)//"' is out of range; allowed: "// &
            & "'signorini', 'compliance' or 'none'")
         return
      end if
      if (scene%law /= law_compliance) then
         if (is_carried('stops:stiffness')) stiffness = unset
         if (is_carried('stops:stiffness_per_mass')) stiffness_per_mass = unset
      end if
      if (scene%law /= law_compliance .and. (stiffness /= unset .or. stiffness_per_mass /= unset)) then
         spring_key = trim(merge('stiffness         ', 'stiffness_per_mass', stiffness /= unset))
         call fatal_error(error, source//': &stops '//spring_key//' = '// &
            & fmt_real(merge(stiffness, stiffness_per_mass, stiffness /= unset))//" is out of range for law = '"// &
            & trim(law)//"'; allowed: "//spring_key//" only with law = 'compliance' (the spring of the compliance "// &
            & 'law; other laws have none)')
         return
      end if
      if (scene%law == law_compliance) then
         if (stiffness /= unset .and. stiffness_per_mass /= unset) then
            call fatal_error(error, source//": &stops stiffness and stiffness_per_mass are both given; allowed: "// &
               & "one of them, the spring of law = 'compliance' (stiffness in N/m or stiffness_per_mass in 1/s^2)")
            return
         end if
         if (stiffness == unset .and. stiffness_per_mass == unset) then
            call fatal_error(error, source//": &stops law = 'compliance' needs a spring; allowed: exactly one "// &
               & 'of stiffness (N/m) or stiffness_per_mass (1/s^2), > 0')
            return
         end if
         if (stiffness /= unset) then
            if (.not. stiffness > 0) then
               call fatal_error(error, source//': &stops stiffness = '//fmt_real(stiffness)// &
                  & ' is out of range; allowed: stiffness > 0 (N/m)')
               return
            end if
            scene%stiffness_per_mass = stiffness/scene%mass_per_length
            ! The range is stiffness_per_mass's (validate_scene), told here in the key given.
            if (scene%mass_per_length > 0 .and. .not. (scene%stiffness_per_mass >= min_stiffness_per_mass .and. &
               & scene%stiffness_per_mass <= max_stiffness_per_mass)) then
               call fatal_error(error, source//': &stops stiffness = '//fmt_real(stiffness)//' is out of range; '// &
                  & 'allowed: '//fmt_real(min_stiffness_per_mass*scene%mass_per_length)//' <= stiffness <= '// &
                  & fmt_real(max_stiffness_per_mass*scene%mass_per_length)//' N/m (stiffness_per_mass '// &
                  & fmt_real(min_stiffness_per_mass)//' ... '//fmt_real(max_stiffness_per_mass)// &
                  & ' 1/s^2 times mass_per_length = '//fmt_real(scene%mass_per_length)//' kg/m)')
               return
            end if
         else
            scene%stiffness_per_mass = stiffness_per_mass
         end if
      end if
      scene%elements = elements
      scene%modes = mesh_modes
      scene%dt = dt
      scene%t_end = t_end
      scene%beta = beta
      select case (trim(load_rule))
      case ('centered'); scene%centered_load = .true.
      case ('paper'); scene%centered_load = .false.
      case default
         call fatal_error(error, source//": &time load_rule = '"//trim(load_rule)//"' is out of range; "// &
            & "allowed: 'centered' or 'paper'")
         return
      end select
      select case (trim(start))
      case ('taylor'); scene%taylor_start = .true.
      case ('euler'); scene%taylor_start = .false.
      case default
         call fatal_error(error, source//": &time start = '"//trim(start)//"' is out of range; "// &
            & "allowed: 'taylor' or 'euler'")
         return
      end select
      scene%allow_unstable = allow_unstable
      if (file == no_file) then
         if (present(default_file)) scene%output_file = default_file
      else if (len_trim(file) == 0) then
         call fatal_error(error, source//": &output file = '' is out of range; allowed: a file name")
         return
      else
         scene%output_file = trim(file)
      end if
      scene%record_every = record_every
      scene%snapshot_every = snapshot_every
      scene%max_output_gb = max_output_gb
      scene%checkpoint_every = checkpoint_every
      call stops_from_lists(source, lower, upper, nodes, x, scene, error)
      if (allocated(error)) return
      scene%restitution = restitution
      select case (trim(mass))
      case ('consistent'); scene%redistributed_mass = .false.
      case ('redistributed'); scene%redistributed_mass = .true.
      case default
         call fatal_error(error, source//": &stops mass = '"//trim(mass)//"' is out of range; allowed: "// &
            & "'consistent' or 'redistributed'")
         return
      end select
      call damping_forms(); if (allocated(error)) return
      call statistics_keys()
      call validate_scene(scene, source, error)
      if (allocated(error)) return
      call validate_physics(scene, source, error)
      if (allocated(error)) return
      call validate_statistics(scene%transient, real(steps_of(scene), wp)*scene%dt, scene%batches, scene%bins, &
         & scene%rest_time, scene%histogram_lower, scene%histogram_upper, source, error)
      if (allocated(error)) return
      call validate_ensemble(scene%members, source, error)
      if (allocated(error)) return
      if (scene%members > 1 .and. .not. scene%statistics) then
         call fatal_error(error, source//': &ensemble members = '//itoa(scene%members)//' with &statistics '// &
            & 'enabled = .false. is out of range; allowed: members = 1 when enabled = .false., or enabled = '// &
            & '.true. (an ensemble gives nothing but its statistics, in /ensemble)')
         return
      end if
      call validate_reduced(scene, 2*scene%elements, stop_unknowns(scene), source, error)
      if (allocated(error)) return
      if (scene%modes > 0 .and. scene%members > 1) then
         call fatal_error(error, source//': &mesh modes = '//itoa(scene%modes)//' with an ensemble (&ensemble '// &
            & 'members > 1) is not supported; allowed: modes = 0 (the full model) for ensembles')
         return
      end if
      if (.not. (ieee_is_finite(scene%perturbation) .and. scene%perturbation >= 0 .and. &
         & scene%perturbation <= 1.0e-3_wp*min(-scene%lower, scene%upper))) then
         call fatal_error(error, source//': &ensemble perturbation = '//fmt_real(scene%perturbation)// &
            & ' is out of range; allowed: 0 <= perturbation <= 1e-3 times the smallest gap to a stop = '// &
            & fmt_real(1.0e-3_wp*min(-scene%lower, scene%upper))//' m')
         return
      end if

   contains

      !> &statistics and &ensemble into the scene; the histogram's range defaults to the stops'.
      subroutine statistics_keys()
         scene%statistics = enabled
         scene%transient = transient
         scene%batches = batches
         scene%bins = bins
         scene%rest_time = rest_time
         if (allocated(scene%stop_lower)) then
            scene%histogram_lower = minval(scene%stop_lower)
            scene%histogram_upper = maxval(scene%stop_upper)
            if (any(scene%stop_nodes == scene%elements)) then
               scene%histogram_lower = scene%stop_lower(findloc(scene%stop_nodes, scene%elements, dim=1))
               scene%histogram_upper = scene%stop_upper(findloc(scene%stop_nodes, scene%elements, dim=1))
            end if
         else
            scene%histogram_lower = scene%lower
            scene%histogram_upper = scene%upper
         end if
         if (histogram_lower /= unset) scene%histogram_lower = histogram_lower
         if (histogram_upper /= unset) scene%histogram_upper = histogram_upper
         scene%members = members
         scene%perturbation = perturbation
         scene%seed = seed
      end subroutine statistics_keys

      !> &damping: the coefficients a and b, or the ratios (one value: both) at `modes`; not both.
      subroutine damping_forms()
         if (ratio(1) == unset .and. ratio(2) == unset .and. is_carried('damping:modes')) modes = unset_node
         if (modes(1) /= unset_node .or. modes(2) /= unset_node) then
            if (modes(1) == unset_node) then  ! modes(2) = j alone
               call fatal_error(error, source//': &damping modes(2) = '//itoa(modes(2))//' is given but modes(1) '// &
                  & 'is not; allowed: modes = i, j, two distinct mode numbers (1 <= mode <= 2*elements)')
               return
            end if
            if (modes(2) == unset_node) then
               call fatal_error(error, source//': &damping modes = '//itoa(modes(1))//' (one value) is out of '// &
                  & 'range; allowed: modes = i, j, two distinct mode numbers (1 <= mode <= 2*elements)')
               return
            end if
            if (ratio(1) == unset .and. ratio(2) == unset) then
               call fatal_error(error, source//': &damping modes = '//itoa(modes(1))//', '//itoa(modes(2))// &
                  & ' is given without ratio; allowed: modes only with ratio (the modes at which the damping '// &
                  & 'ratios are given)')
               return
            end if
         else
            modes = scene%damping_modes
         end if
         if (ratio(1) == unset) then
            if (ratio(2) /= unset) then
               call fatal_error(error, source//': &damping ratio(2) is given but ratio(1) is not; allowed: '// &
                  & 'ratio = zeta (both modes) or ratio = zeta1, zeta2')
               return
            end if
            if (mass_coefficient /= unset) scene%damping_mass = mass_coefficient
            if (stiffness_coefficient /= unset) scene%damping_stiffness = stiffness_coefficient
            scene%damping_modes = modes
            return
         end if
         if (mass_coefficient /= unset .or. stiffness_coefficient /= unset) then
            call fatal_error(error, source//': &damping gives ratio together with mass_coefficient or '// &
               & 'stiffness_coefficient; allowed: either the Rayleigh coefficients (mass_coefficient, '// &
               & 'stiffness_coefficient) or the ratios (ratio, with modes)')
            return
         end if
         scene%damping_by_ratio = .true.
         scene%damping_ratio = ratio(1)
         if (ratio(2) /= unset) scene%damping_ratio(2) = ratio(2)
         scene%damping_modes = modes
      end subroutine damping_forms

      !> Whether `key` ('group:key') is among the keys carried over.
      logical function is_carried(key)
         character(len=*), intent(in) :: key
         is_carried = .false.
         if (present(carried)) is_carried = index(' '//carried//' ', ' '//key//' ') > 0
      end function is_carried

      !> Group g alone, `&name body /`, from `cleaned` (the groups' text): what read_group hands
      !> gfortran. Handed every group, gfortran looked for the group through the others as through
      !> comments: a `!` in another group's quoted value (`file = 'a!b.h5'`) hid every group after
      !> it, which kept its defaults unsaid.
      function group_text(g) result(text)
         integer, intent(in) :: g
         character(len=:), allocatable :: text
         text = '&'//trim(group_names(g))//' '//group_body(cleaned, trim(group_names(g)))//' /'
      end function group_text

      !> Read group g from `text`, the group alone (group_text, or one assignment of it), into the
      !> namelist variables.
      subroutine read_group(g, text, stat, msg)
         integer, intent(in) :: g
         character(len=*), intent(in) :: text
         integer, intent(out) :: stat
         character(len=*), intent(out) :: msg
         msg = ''
         select case (g)
         case (1); read (text, nml=beam, iostat=stat, iomsg=msg)
         case (2); read (text, nml=support, iostat=stat, iomsg=msg)
         case (3); read (text, nml=stops, iostat=stat, iomsg=msg)
         case (4); read (text, nml=damping, iostat=stat, iomsg=msg)
         case (5); call read_mesh(text, elements, mesh_modes, stat, msg)
         case (6); read (text, nml=time, iostat=stat, iomsg=msg)
         case (7); read (text, nml=output, iostat=stat, iomsg=msg)
         case (8); read (text, nml=statistics, iostat=stat, iomsg=msg)
         case (9); read (text, nml=ensemble, iostat=stat, iomsg=msg)
         end select
      end subroutine read_group

      !> The assignments of group g, before gfortran reads it; refused are: a key given twice, or an
      !> element of a list (`key = a, b`, `key(i) = a`, `key(i:j) = a, b`) given twice, where gfortran
      !> would let the last one win unsaid (distinct elements are fine); a key given no value (`dt =
      !> /`, `dt = , beta = 0.5`) or a null value (`nodes = 2*`, `5,, 10`), where gfortran would keep
      !> the default unsaid; a subscript or substring on a key of one value (`load_rule(1:2) =
      !> 'pa'` was read into the default, 'pantered'); and a logical other than the forms
      !> logical_text names, which gfortran reads by its first letter.
      subroutine check_assignments(g)
         integer, intent(in) :: g
         character(len=:), allocatable :: body, key, seen, subscript
         integer, allocatable :: starts(:)
         integer :: i, j, last, paren, slot, capacity, first, final, step, k, n, values
         ! how each element of the group's lists was given: 0 not, 1 by `key =`, 2 by `key(...) =`
         integer :: given_by(max_stops, 4)
         logical :: ok
         body = group_body(cleaned, trim(group_names(g)))
         starts = assignment_starts(body)
         seen = ' '
         given_by = 0
         do i = 1, size(starts)
            key = key_at(body, starts(i))
            last = len(body)
            if (i < size(starts)) last = starts(i + 1) - 1
            ! a value with no key name before its = (`&time = 1e-5 /`, `&time (1) = 2 /`): the
            ! messages below would name an empty key (`allowed:  = a real number`, `unknown key `)
            if (len(key) == 0) then
               call fatal_error(error, source//': &'//trim(group_names(g))//' '// &
                  & assignment_text(body(starts(i):min(last, starts(i) + 120)))//' is malformed: no key name '// &
                  & 'before =; allowed: key = value, the keys of &'//trim(group_names(g))//': '// &
                  & trim(group_keys(g)))
               return
            end if
            ! a key is a whole word: `d-t = 2` (read as the key t), `dt = 1e-5 = 2` (as 5 = 2, the
            ! message quoting `dt=1e-`) and `dt%x = 2` have none
            if (starts(i) > 1) then
               if (scan(body(starts(i) - 1:starts(i) - 1), ' ,;"'''//achar(9)//new_line('a')) == 0) then
                  j = scan(body(:starts(i) - 1), ' ,;="'''//achar(9)//new_line('a'), back=.true.) + 1
                  call fatal_error(error, source//': &'//trim(group_names(g))//' '// &
                     & assignment_text(body(merge(starts(max(i - 1, 1)), j, i > 1):min(last, j + 120)))// &
                     & ' is malformed: `'//body(j:starts(i) + len(key) - 1)//'` before = is not a key name; '// &
                     & 'allowed: key = value, the keys of &'//trim(group_names(g))//': '//trim(group_keys(g)))
                  return
               end if
            end if
            j = starts(i) + len(key)
            if (verify(body(j:), ' ') == 0) cycle
            j = j - 1 + verify(body(j:), ' ')
            ! an element or a section, `key(i) =`, `key(i:j) =`
            subscript = ''
            if (body(j:j) == '(') then
               paren = index(body(j:), ')')
               if (paren == 0) cycle
               subscript = body(j:j + paren - 1)
               j = j + paren
               if (verify(body(j:), ' ') == 0) cycle
               j = j - 1 + verify(body(j:), ' ')
            end if
            if (body(j:j) /= '=') cycle
            last = len(body)
            if (i < size(starts)) last = starts(i + 1) - 1
            if (verify(body(j + 1:last), ' ,'//new_line('a')//achar(9)) == 0) then
               call fatal_error(error, source//': &'//trim(group_names(g))//' '//key//subscript//' has no value; '// &
                  & 'allowed: '//key//' = '//value_kind(key, g))
               return
            end if
            ! (an unknown key is told by the read)
            if (.not. known_key(g, key)) cycle
            call list_key(trim(group_names(g)), key, slot, capacity)
            ! a subscript on a key of one value: gfortran would read `load_rule(1:2) = 'pa'` into
            ! the default, 'pantered'
            if (len(subscript) > 0 .and. capacity == 0) then
               call fatal_error(error, source//': &'//trim(group_names(g))//' '// &
                  & assignment_text(body(starts(i):min(last, starts(i) + 120)))//' is malformed; allowed: '// &
                  & key//' = '//value_kind(key, g))
               return
            end if
            ! a null value (`nodes = 2*`, `5,, 10`, `modes = , 3`): gfortran would leave the element
            ! as it was, without a word (`nodes = 2*` read as no stops along the span)
            if (has_null(body(j + 1:last))) then
               call fatal_error(error, source//': &'//trim(group_names(g))//' '// &
                  & trim(adjustl(body(starts(i):min(last, starts(i) + 120))))//' has an empty value (r* with no '// &
                  & 'value after it, or nothing before a comma); allowed: '//key//' = '//value_kind(key, g))
               return
            end if
            ! a text longer than its variable: gfortran would keep its start without a word (a
            ! path of 5,000 characters became another one of 4,096)
            if (value_kind(key) == "a quoted text, e.g. 'name'") then
               if (text_length(body(j + 1:last)) > text_capacity(key)) then
                  call fatal_error(error, source//': &'//trim(group_names(g))//' '//key//' is '// &
                     & itoa(text_length(body(j + 1:last)))//' characters long, out of range; allowed: at most '// &
                     & itoa(text_capacity(key))//' characters')
                  return
               end if
            end if
            ! a logical is one of the forms a user means: gfortran reads the first letter of any
            ! word (`allow_unstable = trash` was .true., `enabled = fish` .false.)
            if (value_kind(key) == '.true. or .false.') then
               if (.not. logical_text(body(j + 1:last))) then
                  call fatal_error(error, source//': &'//trim(group_names(g))//' '// &
                     & assignment_text(body(starts(i):min(last, starts(i) + 120)))//' is malformed; allowed: '// &
                     & key//' = '//value_kind(key))
                  return
               end if
            end if
            if (capacity == 0) then
               if (index(seen, ' '//key//' ') > 0) then
                  call fatal_error(error, source//': &'//trim(group_names(g))//' '//key// &
                     & ' is given twice; allowed: each key once in a group')
                  return
               end if
               seen = seen//key//' '
               cycle
            end if
            ! the elements of a list the assignment gives: `key =` from the first, `key(i) =` from
            ! i on, `key(i:j:s) =` along its section; each may be given once (gfortran would let
            ! the last win: `ratio = 0.01, 0.03, ratio(2) = 0.02` was 0.01, 0.02)
            first = 1; final = capacity; step = 1; ok = .true.
            if (len(subscript) > 0) call section_of(subscript, capacity, first, final, step, ok)
            if (.not. ok) cycle
            values = value_count(body(j + 1:last))
            ! an element outside the list (`nodes(1001) =`, `ratio(0) =`, `nodes(999) = 1, 2, 3`):
            ! gfortran's read fails on it, which would be told as malformed
            if (values > capacity) then
               call fatal_error(error, too_many_values(g, key, values, capacity))
               return
            end if
            if (len(subscript) > 0 .and. outside_list(first, final, step, values, capacity, &
               & index(subscript, ':') > 0)) then
               call fatal_error(error, source//': &'//trim(group_names(g))//' '// &
                  & assignment_text(body(starts(i):min(last, starts(i) + 120)))//' is out of range; allowed: '// &
                  & 'elements '//key//'(1) to '//key//'('//itoa(capacity)//')')
               return
            end if
            k = first
            n = 0
            do while (n < values .and. k >= 1 .and. k <= capacity)
               if ((step > 0 .and. k > final) .or. (step < 0 .and. k < final)) exit
               if (given_by(k, slot) /= 0) then
                  if (given_by(k, slot) == 1 .and. len(subscript) == 0) then
                     call fatal_error(error, source//': &'//trim(group_names(g))//' '//key// &
                        & ' is given twice; allowed: each key once in a group')
                  else
                     call fatal_error(error, source//': &'//trim(group_names(g))//' '//key//'('//itoa(k)// &
                        & ') is given twice; allowed: each key once in a group, each element of a list at most '// &
                        & 'once (e.g. '//key//' = a, b or '//key//'(1) = a, '//key//'(2) = b)')
                  end if
                  return
               end if
               given_by(k, slot) = merge(1, 2, len(subscript) == 0)
               k = k + step
               n = n + 1
            end do
         end do
      end subroutine check_assignments

      !> Keys not given keep a sentinel (unset for reals, unset_node for &stops nodes and &damping
      !> modes); a value given equal to it would pass for not given. The groups are read again with
      !> other sentinels (huge): a key that holds the sentinel both times was given so. A real is
      !> then taken as given, one step toward zero (its range check follows); a node or mode is out
      !> of range.
      subroutine sentinel_given()
         real(wp) :: first(12), first_lower(max_stops), first_upper(max_stops), first_x(max_stops), first_ratio(2)
         integer :: first_nodes(max_stops), first_modes(2), i, g
         first = [k2, mass_per_length, youngs_modulus, density, outer_diameter, wall_thickness, stiffness, &
            & stiffness_per_mass, mass_coefficient, stiffness_coefficient, histogram_lower, histogram_upper]
         first_lower = lower; first_upper = upper; first_x = x; first_ratio = ratio
         first_nodes = nodes; first_modes = modes
         k2 = huge(1.0_wp); mass_per_length = huge(1.0_wp); youngs_modulus = huge(1.0_wp); density = huge(1.0_wp)
         outer_diameter = huge(1.0_wp); wall_thickness = huge(1.0_wp); stiffness = huge(1.0_wp)
         stiffness_per_mass = huge(1.0_wp); mass_coefficient = huge(1.0_wp); stiffness_coefficient = huge(1.0_wp)
         histogram_lower = huge(1.0_wp); histogram_upper = huge(1.0_wp)
         lower = huge(1.0_wp); upper = huge(1.0_wp); x = huge(1.0_wp); ratio = huge(1.0_wp)
         nodes = huge(1); modes = huge(1)
         do g = 1, size(group_names)
            if (.not. has_group(g)) cycle
            if (all(trim(group_names(g)) /= [character(len=10) :: 'beam', 'stops', 'damping', 'statistics'])) cycle
            call read_group(g, group_text(g), stat, msg)
         end do
         do i = 1, max_stops
            if (nodes(i) == unset_node) then
               call fatal_error(error, source//': &stops nodes('//itoa(i)//') = '//itoa(unset_node)// &
                  & ' is out of range; allowed: 1 <= nodes <= elements = '//itoa(elements))
               return
            end if
         end do
         if (any(modes == unset_node)) then
            call fatal_error(error, source//': &damping modes = '//itoa(first_modes(1))//', '// &
               & itoa(first_modes(2))//' is out of range; allowed: two distinct modes, 1 <= mode <= 2 elements = '// &
               & itoa(2*elements))
            return
         end if
         nodes = first_nodes; modes = first_modes
         k2 = again(first(1), k2); mass_per_length = again(first(2), mass_per_length)
         youngs_modulus = again(first(3), youngs_modulus); density = again(first(4), density)
         outer_diameter = again(first(5), outer_diameter); wall_thickness = again(first(6), wall_thickness)
         stiffness = again(first(7), stiffness); stiffness_per_mass = again(first(8), stiffness_per_mass)
         mass_coefficient = again(first(9), mass_coefficient)
         stiffness_coefficient = again(first(10), stiffness_coefficient)
         histogram_lower = again(first(11), histogram_lower); histogram_upper = again(first(12), histogram_upper)
         lower = again(first_lower, lower); upper = again(first_upper, upper); x = again(first_x, x)
         ratio = again(first_ratio, ratio)
      end subroutine sentinel_given

      !> A real key after both reads: its first value, or (the sentinel given) the next one toward zero.
      elemental real(wp) function again(first_read, second_read)
         real(wp), intent(in) :: first_read, second_read
         again = first_read
         if (second_read == unset) again = unset + spacing(unset)
      end function again

      !> The message for a list key given more values than it holds.
      function too_many_values(g, key, count, capacity) result(message)
         integer, intent(in) :: g, count, capacity
         character(len=*), intent(in) :: key
         character(len=:), allocatable :: message
         message = source//': &'//trim(group_names(g))//' '//key//' has '//itoa(count)//' values, out of range; '// &
            & 'allowed: at most '
         if (capacity == max_stops) then
            message = message//itoa(max_stops)//' stops (one value per stop)'
         else
            message = message//'two values'
         end if
      end function too_many_values

      !> The message of a group gfortran could not read: each `key = value` of the group is read
      !> alone to find the first one that fails, and the message names it with the kind of value
      !> the key takes; gfortran's own words when no single assignment fails.
      subroutine malformed_key(g, stat, msg)
         integer, intent(in) :: g, stat
         character(len=*), intent(in) :: msg
         character(len=:), allocatable :: body, key, value
         integer, allocatable :: starts(:)
         integer :: i, one_stat, last, slot, capacity, count
         character(len=512) :: one_msg
         body = group_body(cleaned, trim(group_names(g)))
         starts = assignment_starts(body)
         do i = 1, size(starts)
            last = len(body)
            if (i < size(starts)) last = starts(i + 1) - 1
            key = key_at(body, starts(i))
            value = body(starts(i):last)
            value = value(index(value, '=') + 1:)
            ! More values than a list key holds: out of range, not malformed.
            call list_key(trim(group_names(g)), key, slot, capacity)
            if (capacity > 0) then
               count = value_count(value)
               if (count > capacity) then
                  call fatal_error(error, too_many_values(g, key, count, capacity))
                  return
               end if
            end if
            call read_group(g, '&'//trim(group_names(g))//' '//body(starts(i):last)//' /', one_stat, one_msg)
            ! (gfortran may read alone what it refuses in the group: then a lone assignment is the culprit)
            if (one_stat == 0 .and. size(starts) > 1) cycle
            if (index(one_msg, 'Cannot match namelist object name') > 0 .and. .not. known_key(g, key)) then
               call fatal_error(error, source//': &'//trim(group_names(g))//': unknown key '//key// &
                  & '; keys of &'//trim(group_names(g))//': '//trim(group_keys(g)))
            else if ((key == 'nodes' .or. key == 'modes') .and. whole_numbers_text(value)) then
               ! whole numbers, one of them too large for an integer: out of range, not malformed
               call fatal_error(error, source//': &'//trim(group_names(g))//' '// &
                  & assignment_text(body(starts(i):min(last, starts(i) + 120)))//' is out of range; allowed: '// &
                  & list_range(trim(group_names(g)), key, index(cleaned, body) + starts(i) - 1, &
                  & index(cleaned, body) + last - 1, value))
            else if (value_kind(key, g) == 'a whole number' .and. whole_number_text(value)) then
               ! a whole number too large for the key's integer kind: out of range, not malformed
               call fatal_error(error, source//': &'//trim(group_names(g))//' '// &
                  & assignment_text(body(starts(i):min(last, starts(i) + 120)))//' is out of range; allowed: '// &
                  & whole_range(trim(group_names(g)), key, adjustl(value)))
            else
               call fatal_error(error, source//': &'//trim(group_names(g))//' '// &
                  & assignment_text(body(starts(i):min(last, starts(i) + 120)))//' is malformed; allowed: '//key// &
                  & ' = '//value_kind(key, g))
            end if
            return
         end do
         call fatal_error(error, source//': &'//trim(group_names(g))//': '//trim(explain(stat, msg, groups_text(g)))// &
            & ' in `'//trim(groups_text(g))//'`; keys of &'//trim(group_names(g))//': '//trim(group_keys(g)))
      end subroutine malformed_key

      !> The allowed range of a whole-number key given `value`, a whole number beyond its integer
      !> kind: the range validate_scene names for the kind's extreme of the value's sign given alone,
      !> else the one it names for the other extreme with the kind's limit added, else the kind's range.
      function whole_range(group, key, value) result(allowed)
         character(len=*), intent(in) :: group, key, value
         character(len=:), allocatable :: allowed, largest, smallest, beyond, other
         ! (the kind's range is not symmetric: -2147483648 is read, and a key without a range of
         ! its own, &ensemble seed, takes it)
         if (key == 'checkpoint_every') then
            largest = fmt_int(huge(1_ik))
            smallest = fmt_int(-huge(1_ik) - 1_ik)
         else
            largest = itoa(huge(1))
            smallest = itoa(-huge(1) - 1)
         end if
         if (value(1:1) == '-') then
            beyond = smallest; other = largest
         else
            beyond = largest; other = smallest
         end if
         allowed = range_named(group, key, '&'//group//' '//key//' = '//beyond//' /')
         if (len(allowed) > 0) return
         allowed = range_named(group, key, '&'//group//' '//key//' = '//other//' /')
         if (len(allowed) > 0) then
            if (value(1:1) == '-') then
               allowed = allowed//', and at least '//beyond
            else
               allowed = allowed//', and at most '//beyond
            end if
         else
            allowed = key//' = a whole number from '//smallest//' to '//largest
         end if
      end function whole_range

      !> The allowed range of a list of whole numbers (&stops nodes, &damping modes), one of them
      !> beyond the integer kind: the range validate_scene names when the scene is read again with
      !> such values at the kind's extreme (cleaned(first:final) is the key's assignment), else the
      !> kind's range.
      function list_range(group, key, first, final, value) result(allowed)
         character(len=*), intent(in) :: group, key, value
         integer, intent(in) :: first, final
         character(len=:), allocatable :: allowed, largest
         allowed = range_named(group, key, cleaned(:first - 1)//key//' = '//clamped_list(value)//' '// &
            & cleaned(final + 1:))
         if (len(allowed) > 0) return
         largest = itoa(huge(1))
         allowed = key//' = whole numbers from '//itoa(-huge(1) - 1)//' to '//largest
      end function list_range

      !> What validate_scene allows of the key when it refuses the key in `probe`, a scene's text
      !> ('' when it does not: the text is read, or another key is refused first).
      function range_named(group, key, probe) result(range)
         character(len=*), intent(in) :: group, key, probe
         character(len=:), allocatable :: range
         type(scene_type) :: scene
         type(error_type), allocatable :: probe_error
         integer :: at
         range = ''
         call scene_from_text(probe, source, scene, probe_error)
         if (.not. allocated(probe_error)) return
         at = index(probe_error%message, '; allowed: ')
         if (at == 0) return
         if (index(probe_error%message, '&'//group//' '//key//' ') > 0 .or. &
            & index(probe_error%message, '&'//group//' '//key//'(') > 0) &
            & range = probe_error%message(at + len('; allowed: '):)
      end function range_named
   end subroutine scene_from_text

   !> &mesh: elements and modes (a scope of its own: &damping has a key `modes` too).
   subroutine read_mesh(text, elements, modes, stat, msg)
      character(len=*), intent(in) :: text
      integer, intent(inout) :: elements, modes
      integer, intent(out) :: stat
      character(len=*), intent(inout) :: msg
      namelist /mesh/ elements, modes
      read (text, nml=mesh, iostat=stat, iomsg=msg)
   end subroutine read_mesh

   !> The stops of &stops: without nodes or x, lower and upper (one value each) are the tip stops;
   !> with nodes (indices 1..J) or x (abscissae, each at a node to 1e-9 length), the stops along
   !> the span, lower and upper one value for all or one per stop. Needs the scene's length and
   !> elements.
   subroutine stops_from_lists(path, lower, upper, nodes, x, scene, error)
      character(len=*), intent(in) :: path
      real(wp), intent(in) :: lower(:), upper(:), x(:)
      integer, intent(in) :: nodes(:)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      integer :: n_lower, n_upper, n_nodes, n_x, m, i, j, node
      real(wp) :: h, at
      n_lower = given(lower == unset, 'lower'); if (allocated(error)) return
      n_upper = given(upper == unset, 'upper'); if (allocated(error)) return
      n_nodes = given(nodes == unset_node, 'nodes'); if (allocated(error)) return
      n_x = given(x == unset, 'x'); if (allocated(error)) return
      if (n_nodes > 0 .and. n_x > 0) then
         call fatal_error(error, path//': &stops gives both nodes and x; allowed: one of them (node indices '// &
            & '1..elements, or abscissae x = i*length/elements)')
         return
      end if
      m = max(n_nodes, n_x)
      if (m == 0) then
         if (n_lower > 1 .or. n_upper > 1) then
            call fatal_error(error, path//': &stops lower or upper has several values but no stops along the span '// &
               & 'are given (nodes or x); allowed: one value each (the tip stops), or nodes or x with one value '// &
               & 'per stop')
            return
         end if
         if (n_lower == 1) scene%lower = lower(1)
         if (n_upper == 1) scene%upper = upper(1)
         return
      end if
      call per_stop(lower, n_lower, 'lower', scene%lower, scene%stop_lower); if (allocated(error)) return
      call per_stop(upper, n_upper, 'upper', scene%upper, scene%stop_upper); if (allocated(error)) return
      if (n_nodes > 0) then
         scene%stop_nodes = nodes(:m)
         return
      end if
      allocate (scene%stop_nodes(m))
      h = scene%length/scene%elements
      do i = 1, m
         if (.not. (x(i) > 0 .and. x(i) <= scene%length*(1 + 1.0e-9_wp))) then
            call fatal_error(error, path//': &stops x('//itoa(i)//') = '//fmt_real(x(i))//' is out of range; '// &
               & 'allowed: 0 < x <= length = '//fmt_real(scene%length)//' (x = 0 is the clamp)')
            return
         end if
         node = max(1, min(scene%elements, nint(x(i)/h)))
         at = scene%length*node/scene%elements
         if (abs(x(i) - at) > 1.0e-9_wp*scene%length) then
            node = min(scene%elements - 1, int(x(i)/h))
            call fatal_error(error, path//': &stops x('//itoa(i)//') = '//fmt_real(x(i))//' is not at a node; '// &
               & 'allowed: x = i*length/elements to 1e-9*length (length = '//fmt_real(scene%length)// &
               & ', elements = '//itoa(scene%elements)//'); the nearest nodes are '//node_text(node)//' and '// &
               & node_text(node + 1))
            return
         end if
         if (any(scene%stop_nodes(:i - 1) == node)) then
            j = findloc(scene%stop_nodes(:i - 1), node, dim=1)
            call fatal_error(error, path//': &stops x('//itoa(i)//') = '//fmt_real(x(i))//' is out of range; '// &
               & 'allowed: each stop at its own node (x('//itoa(i)//') and x('//itoa(j)//') = '//fmt_real(x(j))// &
               & ' are both node '//node_text(node)//')')
            return
         end if
         scene%stop_nodes(i) = node
      end do

   contains

      !> Number of values given to a list key; a value after a missing one is an error.
      integer function given(missing, key)
         logical, intent(in) :: missing(:)
         character(len=*), intent(in) :: key
         integer :: j
         given = size(missing)
         do j = 1, size(missing)
            if (missing(j)) then
               given = j - 1
               exit
            end if
         end do
         do j = given + 1, size(missing)
            if (.not. missing(j)) then
               call fatal_error(error, path//': &stops '//key//'('//itoa(j)//') is given but '//key//'('// &
                  & itoa(given + 1)//') is not; allowed: the values one after the other from '//key//'(1)')
               return
            end if
         end do
      end function given

      !> Bounds of the m stops from a list with `count` values: none (the default), one for all, or m.
      subroutine per_stop(values, count, key, default, bounds)
         real(wp), intent(in) :: values(:)
         integer, intent(in) :: count
         character(len=*), intent(in) :: key
         real(wp), intent(in) :: default
         real(wp), allocatable, intent(out) :: bounds(:)
         allocate (bounds(m))
         select case (count)
         case (0)
            bounds = default
         case (1)
            bounds = values(1)
         case default
            if (count /= m) then
               if (m == 1) then
                  call fatal_error(error, path//': &stops '//key//' has '//itoa(count)//' values for 1 stop; '// &
                     & 'allowed: one value')
               else
                  call fatal_error(error, path//': &stops '//key//' has '//itoa(count)//' values for '//itoa(m)// &
                     & ' stops; allowed: one value (the same for every stop) or '//itoa(m)//', one per stop')
               end if
               return
            end if
            bounds = values(:m)
         end select
      end subroutine per_stop

      !> "i (x = ...)" for a node.
      function node_text(i) result(t)
         integer, intent(in) :: i
         character(len=:), allocatable :: t
         t = itoa(i)//' (x = '//fmt_real(scene%length*i/scene%elements)//')'
      end function node_text
   end subroutine stops_from_lists

   !> k2 and the mass per length, given directly or derived from the tube's material and geometry.
   subroutine derive_beam(path, length, k2, mass_per_length, youngs_modulus, density, outer_diameter, &
      & wall_thickness, scene, error)
      character(len=*), intent(in) :: path
      real(wp), intent(in) :: length, k2, mass_per_length, youngs_modulus, density, outer_diameter, wall_thickness
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: material(4), low(4), high(4)
      character(len=*), parameter :: names(4) = ['youngs_modulus', 'density       ', 'outer_diameter', &
         & 'wall_thickness'], units(4) = ['Pa    ', 'kg/m^3', 'm     ', 'm     ']
      character(len=:), allocatable :: low_text, high_text
      integer :: i
      scene%length = length
      material = [youngs_modulus, density, outer_diameter, wall_thickness]
      if (all(material == unset)) then
         if (k2 /= unset) scene%k2 = k2
         if (mass_per_length /= unset) scene%mass_per_length = mass_per_length
         return
      end if
      do i = 1, 4
         if (material(i) == unset) then
            call fatal_error(error, path//': &beam '//trim(names(i))//' is missing; allowed: give all of '// &
               & 'youngs_modulus, density, outer_diameter, wall_thickness, or none of them (then k2)')
            return
         end if
      end do
      if (k2 /= unset .or. mass_per_length /= unset) then
         call fatal_error(error, path//': &beam gives k2 or mass_per_length together with the material; '// &
            & 'allowed: either k2 (and mass_per_length) or youngs_modulus, density, outer_diameter, wall_thickness')
         return
      end if
      ! Beyond any real material (Young's modulus ten times diamond's, density four times
      ! osmium's, lighter than air), and sections whose area and second moment are computed
      ! without underflow or cancellation (k2 came out 0, NaN or -Inf).
      low = [0.0_wp, 1.0e-3_wp, 1.0e-9_wp, 1.0e-6_wp*outer_diameter]
      high = [1.0e13_wp, 1.0e5_wp, 1.0e3_wp, outer_diameter/2]
      do i = 1, 4
         if (material(i) > low(i) .or. (i > 1 .and. material(i) == low(i))) then
            if (material(i) <= high(i)) cycle
         end if
         low_text = fmt_real(low(i))//' <= '
         if (i == 1) low_text = '0 < '
         if (i == 4) low_text = '1e-06*outer_diameter = '//low_text
         high_text = fmt_real(high(i))
         if (i == 4) high_text = 'outer_diameter/2 = '//high_text
         call fatal_error(error, path//': &beam '//trim(names(i))//' = '//fmt_real(material(i))// &
            & ' is out of range; allowed: '//low_text//trim(names(i))//' <= '//high_text//' '//trim(units(i)))
         return
      end do
      call tube_beam(youngs_modulus, density, outer_diameter, wall_thickness, scene%k2, scene%mass_per_length)
      ! What the material gives is told in the keys given (the file holds no k2 or mass_per_length).
      if (.not. (scene%k2 >= k2_range(1) .and. scene%k2 <= k2_range(2))) then
         call fatal_error(error, path//': &beam youngs_modulus = '//fmt_real(youngs_modulus)//', density = '// &
            & fmt_real(density)//', outer_diameter = '//fmt_real(outer_diameter)//', wall_thickness = '// &
            & fmt_real(wall_thickness)//' give k2 = EI/(rho S) = '//fmt_real(scene%k2)//' m^4/s^2, out of range; '// &
            & 'allowed: '//fmt_real(k2_range(1))//' <= k2 <= '//fmt_real(k2_range(2))//' m^4/s^2')
         return
      end if
      if (.not. (scene%mass_per_length >= mass_per_length_range(1) .and. &
         & scene%mass_per_length <= mass_per_length_range(2))) then
         call fatal_error(error, path//': &beam density = '//fmt_real(density)//', outer_diameter = '// &
            & fmt_real(outer_diameter)//', wall_thickness = '//fmt_real(wall_thickness)// &
            & ' give mass_per_length = rho S = '//fmt_real(scene%mass_per_length)//' kg/m, out of range; allowed: '// &
            & fmt_real(mass_per_length_range(1))//' <= mass_per_length <= '//fmt_real(mass_per_length_range(2))//' kg/m')
         return
      end if
   end subroutine derive_beam

   !> Which groups the text holds (and their text, for messages); unknown or repeated groups,
   !> binary characters, text outside any group that is not a comment (a forgotten `&`) and a
   !> text without any group are errors. `cleaned` is the whole text without comments, its lines
   !> joined: gfortran reads namelists from it whatever the last line ends with.
   subroutine scan_groups(text, source, present, texts, cleaned, error)
      character(len=*), intent(in) :: text, source
      logical, intent(out) :: present(:)
      character(len=*), intent(out) :: texts(:)
      character(len=:), allocatable, intent(out) :: cleaned
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: line, name, joined
      integer :: i, j, g, current, line_no, used(size(present)), first, last, filled
      logical :: quoted
      character :: quote
      present = .false.
      texts = ''
      used = 0
      ! the lines joined into one buffer (a line and its blank take no more than the line and its
      ! newline): appended line after line to a growing string, a text of 200,000 short lines
      ! took 31 s
      allocate (character(len=len(text) + 1) :: joined)
      filled = 0
      cleaned = ''
      current = 0
      ! Binary characters anywhere (an HDF5 output or an image given for the namelist) are told
      ! first: the start of such a file was otherwise quoted as text outside any group.
      line_no = first_binary_line(text)
      if (line_no > 0) then
         call fatal_error(error, source//': line '//itoa(line_no)//' holds binary characters; '// &
            & 'allowed: a namelist text file')
         return
      end if
      line_no = 0
      first = 1
      do while (first <= len(text))
         last = index(text(first:), new_line('a'))
         if (last == 0) then
            last = len(text)
            line = text(first:last)
         else
            last = first + last - 1
            line = text(first:last - 1)
         end if
         first = last + 1
         line_no = line_no + 1
         ! a line's end may carry carriage returns (\r\n, or \r\r\n from a file converted twice)
         do while (len(line) > 0)
            if (line(len(line):) /= achar(13)) exit
            line = line(:len(line) - 1)
         end do
         quoted = .false.
         quote = ' '
         i = 1
         do while (i <= len_trim(line))
            if (quoted) then
               if (line(i:i) == quote) quoted = .false.
            else if (line(i:i) == '"' .or. line(i:i) == "'") then
               if (current == 0) call outside(); if (allocated(error)) return
               quoted = .true.
               quote = line(i:i)
            else if (line(i:i) == '!') then
               call join(line(:i - 1))
               exit
            else if (line(i:i) == '/' .and. current > 0) then
               call append_text(current, '/')
               current = 0
            else if (line(i:i) == '&' .or. line(i:i) == '$') then
               j = i + 1
               do while (j <= len(line))
                  if (scan(line(j:j), 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_') == 0) exit
                  j = j + 1
               end do
               name = lower(line(i + 1:j - 1))
               if (name == 'end') then
                  current = 0
                  i = j
                  cycle
               end if
               if (current > 0) then
                  call fatal_error(error, source//': line '//itoa(line_no)//': group &'// &
                     & trim(group_names(current))//' is not closed by / before &'//name// &
                     & '; allowed: each group ends with / (e.g. `&time dt = 1e-5 /`)')
                  return
               end if
               g = group_index(name)
               if (g == 0) then
                  call fatal_error(error, source//': line '//itoa(line_no)//': unknown group &'//name// &
                     & '; allowed groups: '//all_groups())
                  return
               end if
               if (present(g)) then
                  call fatal_error(error, source//': line '//itoa(line_no)//': group &'//name// &
                     & ' appears twice; allowed: each group once')
                  return
               end if
               ! the name ends at a blank, a comma, the group's / or a comment: gfortran did not
               ! find `&time=1e-5, beta=0.3 /` as the group &time and kept every default unsaid
               if (j <= len(line)) then
                  if (scan(line(j:j), ' ,/!'//achar(9)//achar(13)) == 0) then
                     call fatal_error(error, source//': line '//itoa(line_no)//': group &'//name// &
                        & ' is followed by `'//trim(line(j:min(len(line), j + 40)))//'` with no blank; allowed: '// &
                        & 'a blank after the group name (e.g. `&'//name//' key = value /`)')
                     return
                  end if
               end if
               present(g) = .true.
               current = g
               texts(g) = ''
               used(g) = 0
               call append_text(g, '&'//name)
               i = j
               cycle
            else if (current == 0 .and. line(i:i) /= ' ' .and. line(i:i) /= achar(9)) then
               call outside()
               return
            end if
            if (current > 0) call append_text(current, line(i:i))
            i = i + 1
         end do
         if (i > len_trim(line)) call join(trim(line))
         if (current > 0) call append_text(current, ' ')
      end do
      cleaned = joined(:filled)
      if (current > 0) then
         call fatal_error(error, source//': group &'//trim(group_names(current))//' is not closed by / '// &
            & '(the text ends inside it); allowed: each group ends with / (e.g. `&time dt = 1e-5 /`)')
         return
      end if
      if (.not. any(present)) then
         call fatal_error(error, source//': no namelist group; allowed: groups '//all_groups()// &
            & ' (e.g. `&time dt = 1e-5 /`), each at most once, and comments after !')
      end if

   contains

      !> Text outside any group: a forgotten `&` or a stray word, quoted with its line.
      subroutine outside()
         call fatal_error(error, source//': line '//itoa(line_no)//': text outside any group: `'// &
            & trim(adjustl(line(:min(len(line), 200))))//'`; allowed outside groups: blanks and comments '// &
            & 'after ! (a group starts with &name, e.g. `&time dt = 1e-5 /`)')
      end subroutine outside

      !> Append a line (without its comment) and a blank to the joined text.
      subroutine join(piece)
         character(len=*), intent(in) :: piece
         joined(filled + 1:filled + len(piece) + 1) = piece//' '
         filled = filled + len(piece) + 1
      end subroutine join

      !> Append to a group's text (kept short for messages; runs of blanks folded).
      subroutine append_text(g, piece)
         integer, intent(in) :: g
         character(len=*), intent(in) :: piece
         character(len=len(piece)) :: text
         text = piece
         if (text == achar(9) .or. text == achar(13)) text = ' '
         if (used(g) + len(text) > 200) return
         if (text == ' ' .and. used(g) > 0) then
            if (texts(g)(used(g):used(g)) == ' ') return
         end if
         texts(g)(used(g) + 1:used(g) + len(text)) = text
         used(g) = used(g) + len(text)
      end subroutine append_text
   end subroutine scan_groups

   !> Clearer text for gfortran's namelist messages: gfortran reports a malformed value
   !> as an unknown object name, so a name not followed by '=' in the group is a bad value.
   function explain(stat, msg, text) result(what)
      integer, intent(in) :: stat
      character(len=*), intent(in) :: msg, text
      character(len=:), allocatable :: what, name
      if (stat == iostat_end) then
         what = 'a value is malformed or the group is not closed by /'
      else if (index(msg, 'Cannot match namelist object name') > 0) then
         name = trim(adjustl(msg(index(msg, 'object name') + 11:)))
         if (index(squeeze(lower(text)), squeeze(lower(name))//'=') > 0) then
            what = 'unknown key '//name
         else
            what = "malformed value '"//name//"'"
         end if
      else
         what = 'malformed value ('//trim(msg)//')'
      end if
   end function explain


   !> Index of a group name in group_names (0 when unknown).
   pure integer function group_index(name)
      character(len=*), intent(in) :: name
      do group_index = size(group_names), 1, -1
         if (trim(group_names(group_index)) == name) return
      end do
   end function group_index

   !> The first line (1, 2, ...) of a text holding control characters other than tab, carriage
   !> return and the line ends; 0 when none does.
   pure integer function first_binary_line(s)
      character(len=*), intent(in) :: s
      integer :: i, code, line_no
      first_binary_line = 0
      line_no = 1
      do i = 1, len(s)
         code = iachar(s(i:i))
         if (code == 10) then
            line_no = line_no + 1
         else if ((code < 32 .and. code /= 9 .and. code /= 13) .or. code == 127) then
            first_binary_line = line_no
            return
         end if
      end do
   end function first_binary_line





   !> Base name of the input with '.h5' in place of its extension.
   pure function default_output(path) result(file)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: file
      integer :: slash, dot
      slash = index(path, '/', back=.true.)
      file = path(slash + 1:)
      dot = index(file, '.', back=.true.)
      if (dot > 1) file = file(:dot - 1)
      file = file//'.h5'
   end function default_output
end module beamstops_namelist
