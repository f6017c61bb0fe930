!> read_scene on namelist files written by the test into a temporary directory:
!> values of a valid file (the material route included) and one message per bad input,
!> naming the file, the group and the key.
module test_namelist
   use testing
   use beamstops, only: scene_type, read_scene, law_signorini, law_compliance, scene_from_text, canonical_text, &
      & model_type, build_model, check_stability
   implicit none
   private
   public :: collect_namelist

   !> Length of a line of a test file.
   integer, parameter :: ll = 120

contains

   !> Tests of the suite.
   subroutine collect_namelist(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('valid file: every value, material route', test_valid), &
         & new_unittest('groups left out keep the paper''s values', test_defaults), &
         & new_unittest('missing file', test_missing_file), &
         & new_unittest('unknown group', test_unknown_group), &
         & new_unittest('unknown key', test_unknown_key), &
         & new_unittest('malformed value dt=abc', test_malformed), &
         & new_unittest('repeated group', test_repeated), &
         & new_unittest('dt = -1 out of range', test_dt), &
         & new_unittest('beta = 0.7 out of range', test_beta), &
         & new_unittest('lower = 0.1 out of range', test_lower), &
         & new_unittest('upper = -0.1 out of range', test_upper), &
         & new_unittest('elements = 0 out of range', test_elements), &
         & new_unittest('law = ''glue'' unknown', test_law), &
         & new_unittest('compliance without stiffness', test_compliance_stiffness), &
         & new_unittest('a stiffness (N/m) out of range is told in its own key and unit', test_stiffness_range), &
         & new_unittest('a material giving k2 or mass_per_length out of range is told in its keys', test_material_range), &
         & new_unittest('record_every = 0 out of range', test_record_every), &
         & new_unittest('text outside any group is refused, quoted', test_outside_group), &
         & new_unittest('a file without any group is refused', test_no_group), &
         & new_unittest('an HDF5 file given for the namelist: binary characters, not its start quoted', test_hdf5_signature), &
         & new_unittest('a malformed value names its key and kind', test_malformed_kind), &
         & new_unittest('canonical text reads back the same scene', test_canonical_round_trip), &
         & new_unittest('max_output_gb: 0 refused, the fixed part too big named, no snapshots suggested', &
         & test_max_output_gb), &
         & new_unittest('a spring with a law other than compliance is refused', test_spring_other_law), &
         & new_unittest('&damping modes: one value, or without ratio, is refused', test_damping_modes), &
         & new_unittest('an ensemble without statistics is refused', test_ensemble_without_statistics), &
         & new_unittest('two x at one node are told in x', test_x_twice), &
         & new_unittest('a bad logical followed by other keys names the key', test_bad_logical), &
         & new_unittest('a group not closed by / is told so', test_unclosed_group), &
         & new_unittest('more values than a list holds are out of range', test_too_many_values), &
         & new_unittest('a bad value leaves no state: the next text is read whole', test_reader_state_after_bad_logical), &
         & new_unittest('a carried key that does nothing is dropped, one given anew refused', test_carried_keys), &
         & new_unittest('every real key refuses infinity and huge values, naming its range', test_real_keys_bounded), &
         & new_unittest('a material beyond any real one is told in its own key', test_material_bounds), &
         & new_unittest('dt and t_end below 1e-15 s refused; each message states a range the value violates', &
         & test_tiny_time_step), &
         & new_unittest('a dt refused for stability is beyond the limit as shown', test_stability_limit_shown), &
         & new_unittest('both springs of the compliance law are told as both given', test_two_springs), &
         & new_unittest('a FIFO is read to its end and gives no output name', test_fifo), &
         & new_unittest('a path or a word longer than its key holds is out of range, not cut short', test_long_texts), &
         & new_unittest('a text of 16 MB: 2,000,000 assignments or list values, each told at once', test_huge_texts), &
         & new_unittest('a logical is one of the forms a user means, not any word by its first letter', &
         & test_logical_forms), &
         & new_unittest('a null value (r* alone, nothing before a comma) is refused, not read as not given', &
         & test_null_values), &
         & new_unittest('an element of a list given twice is refused; distinct elements are read', test_elements_twice), &
         & new_unittest('a subscript or a substring on a key of one value is malformed', test_scalar_subscript), &
         & new_unittest('an element outside a list is out of range, with the list''s bounds', test_element_outside), &
         & new_unittest('&ensemble seed: the range a refused seed names is the range read', test_seed_range), &
         & new_unittest('lines ending in several carriage returns are read', test_carriage_returns) &
         & ]
   end subroutine collect_namelist

   ! ---------------------------------------------------------------- helpers

   !> A directory of this process under $TMPDIR (or /tmp), created if needed.
   function temp_dir() result(dir)
      character(len=:), allocatable :: dir
      character(len=4096) :: base
      character(len=16) :: pid
      integer :: length, stat
      call get_environment_variable('TMPDIR', base, length, stat)
      if (stat /= 0 .or. length == 0) base = '/tmp'
      write (pid, '(i0)') getpid()
      dir = trim(base)//'/beamstops-fortran-tests-'//trim(pid)
      call execute_command_line('mkdir -p "'//dir//'"', exitstat=stat)
   end function temp_dir

   !> Write `lines` to a file `name` in the temporary directory; its path.
   function write_file(name, lines) result(path)
      character(len=*), intent(in) :: name
      character(len=*), intent(in) :: lines(:)
      character(len=:), allocatable :: path
      integer :: unit, i
      path = temp_dir()//'/'//name
      open (newunit=unit, file=path, status='replace', action='write')
      do i = 1, size(lines)
         write (unit, '(a)') trim(lines(i))
      end do
      close (unit)
   end function write_file

   !> Delete a test file and, once empty, the temporary directory.
   subroutine remove(path)
      character(len=*), intent(in) :: path
      integer :: unit, stat
      logical :: exists
      inquire (file=path, exist=exists)
      if (exists) then
         open (newunit=unit, file=path, status='old', iostat=stat)
         if (stat == 0) close (unit, status='delete')
      end if
      call execute_command_line('rmdir "'//path(:index(path, '/', back=.true.) - 1)//'" 2>/dev/null', exitstat=stat)
   end subroutine remove

   !> Whether `word` occurs in `text` not preceded or followed by a name character.
   pure logical function has_word(text, word)
      character(len=*), intent(in) :: text, word
      character(len=*), parameter :: name_chars = 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_'
      integer :: start, at
      logical :: before, after
      has_word = .false.
      start = 1
      do
         at = index(text(start:), word)
         if (at == 0) return
         at = at + start - 1
         before = .true.
         if (at > 1) before = index(name_chars, text(at - 1:at - 1)) == 0
         after = .true.
         if (at + len(word) <= len(text)) after = index(name_chars, text(at + len(word):at + len(word))) == 0
         if (before .and. after) then
            has_word = .true.
            return
         end if
         start = at + 1
      end do
   end function has_word

   !> read_scene on a file must fail with a message holding the path and each of `needles`.
   subroutine expect_error(name, lines, needles, error)
      character(len=*), intent(in) :: name
      character(len=*), intent(in) :: lines(:)
      character(len=*), intent(in) :: needles(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: path
      path = write_file(name, lines)
      call expect_error_at(path, needles, error)
      call remove(path)
   end subroutine expect_error

   !> read_scene on `path` must fail with a message holding the path and each of `needles`.
   subroutine expect_error_at(path, needles, error)
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: needles(:)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(error_type), allocatable :: read_error
      integer :: i
      call read_scene(path, scene, read_error)
      if (.not. allocated(read_error)) then
         call test_failed(error, 'read_scene accepted '//path)
         return
      end if
      call note('message: '//read_error%message)
      call check(error, index(read_error%message, path) > 0, 'the message names the file '//path//': '// &
         & read_error%message)
      if (allocated(error)) return
      do i = 1, size(needles)
         call check(error, has_word(read_error%message, trim(needles(i))), 'the message names '//trim(needles(i))// &
            & ': '//read_error%message)
         if (allocated(error)) return
      end do
   end subroutine expect_error_at

   ! ---------------------------------------------------------------- tests

   subroutine test_valid(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: pi = acos(-1.0_wp), e = 2e11_wp, rho = 8e3_wp, d_out = 0.01_wp, wall = 5e-4_wp
      type(scene_type) :: scene
      character(len=:), allocatable :: path
      real(wp) :: d_in, area, inertia
      path = write_file('valid.nml', [character(len=ll) :: &
         & '! a scene with every group', &
         & '&beam length = 1.2, youngs_modulus = 2e11, density = 8e3,', &
         & '      outer_diameter = 0.01, wall_thickness = 5e-4 /', &
         & '&support amplitude = 0.15, omega = 12.5 /', &
         & '&stops lower = -0.05, upper = 0.08, law = ''compliance'', stiffness = 2.0e7 /', &
         & '&mesh elements = 23 /', &
         & '&time dt = 1e-5, t_end = 0.75, beta = 0.25, load_rule = ''paper'', start = ''euler'',', &
         & '      allow_unstable = .true. /', &
         & '&output record_every = 10, snapshot_every = 100 /'])
      call read_scene(path, scene, error)
      call remove(path)
      if (allocated(error)) return
      ! thin-walled tube: S = pi/4 (D^2 - d^2), I = pi/64 (D^4 - d^4), k2 = E I/(rho S)
      d_in = d_out - 2*wall
      area = pi/4*(d_out**2 - d_in**2)
      inertia = pi/64*(d_out**4 - d_in**4)
      call note('material route: k2 = '//real_text(scene%k2)//', mass_per_length = '//real_text(scene%mass_per_length))
      call check(error, scene%k2, 282.8_wp, 'k2 (SPEC 2: 282.84)', thr=1e-3_wp, rel=.true.); if (allocated(error)) return
      call check(error, scene%k2, e*(d_out**2 + d_in**2)/(16*rho), 'k2 = E (D^2 + d^2)/(16 rho)', thr=1e-12_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, scene%mass_per_length, 0.11938_wp, 'mass_per_length (SPEC 2)', thr=1e-4_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, scene%mass_per_length, rho*area, 'mass_per_length = rho S', thr=1e-12_wp, rel=.true.)
      if (allocated(error)) return
      call check(error, scene%length, 1.2_wp, 'length'); if (allocated(error)) return
      call check(error, scene%amplitude, 0.15_wp, 'amplitude'); if (allocated(error)) return
      call check(error, scene%omega, 12.5_wp, 'omega'); if (allocated(error)) return
      call check(error, scene%lower, -0.05_wp, 'lower'); if (allocated(error)) return
      call check(error, scene%upper, 0.08_wp, 'upper'); if (allocated(error)) return
      call check(error, scene%law, law_compliance, 'law'); if (allocated(error)) return
      call check(error, scene%stiffness_per_mass, 2.0e7_wp/(rho*area), 'stiffness_per_mass = stiffness/(rho S)', &
         & thr=1e-12_wp, rel=.true.); if (allocated(error)) return
      call check(error, scene%elements, 23, 'elements'); if (allocated(error)) return
      call check(error, scene%dt, 1e-5_wp, 'dt'); if (allocated(error)) return
      call check(error, scene%t_end, 0.75_wp, 't_end'); if (allocated(error)) return
      call check(error, scene%beta, 0.25_wp, 'beta'); if (allocated(error)) return
      call check(error, scene%centered_load, .false., 'centered_load (load_rule = ''paper'')'); if (allocated(error)) return
      call check(error, scene%taylor_start, .false., 'taylor_start (start = ''euler'')'); if (allocated(error)) return
      call check(error, scene%allow_unstable, .true., 'allow_unstable'); if (allocated(error)) return
      call check(error, scene%record_every, 10, 'record_every'); if (allocated(error)) return
      call check(error, scene%snapshot_every, 100, 'snapshot_every'); if (allocated(error)) return
      call check(error, allocated(scene%output_file), 'an output file name is set'); if (allocated(error)) return
      call check(error, scene%output_file == 'valid.h5', 'default output file valid.h5, got '//scene%output_file)
   end subroutine test_valid

   subroutine test_defaults(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene, paper
      character(len=:), allocatable :: path
      path = write_file('mesh_only.nml', [character(len=ll) :: '&mesh elements = 7 /', '&output file = ''x.h5'' /'])
      call read_scene(path, scene, error)
      call remove(path)
      if (allocated(error)) return
      call check(error, scene%elements, 7, 'elements'); if (allocated(error)) return
      call check(error, scene%output_file == 'x.h5', 'output file x.h5, got '//scene%output_file); if (allocated(error)) return
      call check(error, scene%length, paper%length, 'length'); if (allocated(error)) return
      call check(error, scene%k2, paper%k2, 'k2'); if (allocated(error)) return
      call check(error, scene%mass_per_length, paper%mass_per_length, 'mass_per_length'); if (allocated(error)) return
      call check(error, scene%amplitude, paper%amplitude, 'amplitude'); if (allocated(error)) return
      call check(error, scene%omega, paper%omega, 'omega'); if (allocated(error)) return
      call check(error, scene%lower, paper%lower, 'lower'); if (allocated(error)) return
      call check(error, scene%upper, paper%upper, 'upper'); if (allocated(error)) return
      call check(error, scene%law, law_signorini, 'law'); if (allocated(error)) return
      call check(error, scene%dt, paper%dt, 'dt'); if (allocated(error)) return
      call check(error, scene%t_end, paper%t_end, 't_end'); if (allocated(error)) return
      call check(error, scene%beta, paper%beta, 'beta'); if (allocated(error)) return
      call check(error, scene%centered_load, paper%centered_load, 'centered_load'); if (allocated(error)) return
      call check(error, scene%taylor_start, paper%taylor_start, 'taylor_start'); if (allocated(error)) return
      call check(error, scene%record_every, paper%record_every, 'record_every')
   end subroutine test_defaults

   subroutine test_missing_file(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: path
      path = temp_dir()//'/no_such_file.nml'
      call expect_error_at(path, [character(len=8) :: 'cannot'], error)
      call remove(path)
   end subroutine test_missing_file

   subroutine test_unknown_group(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('unknown_group.nml', [character(len=ll) :: '&mesh elements = 7 /', '&velocity v = 1 /'], &
         & [character(len=16) :: '&velocity'], error)
   end subroutine test_unknown_group

   subroutine test_unknown_key(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('unknown_key.nml', [character(len=ll) :: '&time dtt = 1e-5 /'], &
         & [character(len=16) :: '&time', 'dtt'], error)
   end subroutine test_unknown_key

   subroutine test_malformed(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('malformed.nml', [character(len=ll) :: '&time dt=abc /'], &
         & [character(len=16) :: '&time', 'dt', 'abc'], error)
   end subroutine test_malformed

   subroutine test_repeated(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('repeated.nml', [character(len=ll) :: '&time dt = 1e-5 /', '&mesh elements = 3 /', &
         & '&time beta = 0.25 /'], [character(len=16) :: '&time'], error)
   end subroutine test_repeated

   subroutine test_dt(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('dt.nml', [character(len=ll) :: '&time dt = -1 /'], [character(len=16) :: '&time', 'dt'], error)
   end subroutine test_dt

   subroutine test_beta(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('beta.nml', [character(len=ll) :: '&time beta = 0.7 /'], [character(len=16) :: '&time', 'beta'], error)
   end subroutine test_beta

   subroutine test_lower(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('lower.nml', [character(len=ll) :: '&stops lower = 0.1 /'], &
         & [character(len=16) :: '&stops', 'lower'], error)
   end subroutine test_lower

   subroutine test_upper(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('upper.nml', [character(len=ll) :: '&stops upper = -0.1 /'], &
         & [character(len=16) :: '&stops', 'upper'], error)
   end subroutine test_upper

   subroutine test_elements(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('elements.nml', [character(len=ll) :: '&mesh elements = 0 /'], &
         & [character(len=16) :: '&mesh', 'elements'], error)
   end subroutine test_elements

   subroutine test_law(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('law.nml', [character(len=ll) :: '&stops law = ''glue'' /'], &
         & [character(len=16) :: '&stops', 'law', 'glue'], error)
   end subroutine test_law

   subroutine test_compliance_stiffness(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('compliance.nml', [character(len=ll) :: '&stops law = ''compliance'' /'], &
         & [character(len=24) :: '&stops', 'stiffness', 'stiffness_per_mass'], error)
   end subroutine test_compliance_stiffness

   subroutine test_record_every(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('record_every.nml', [character(len=ll) :: '&output record_every = 0 /'], &
         & [character(len=16) :: '&output', 'record_every'], error)
   end subroutine test_record_every

   subroutine test_outside_group(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('outside.nml', [character(len=ll) :: '&beam length = 2 /', 'time dt = 1e-5 /'], &
         & [character(len=32) :: 'line 2', 'text outside any group', '`time dt = 1e-5 /`'], error)
   end subroutine test_outside_group

   subroutine test_no_group(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('no_group.nml', [character(len=ll) :: '! only a comment'], &
         & [character(len=32) :: 'no namelist group'], error)
   end subroutine test_no_group

   !> An HDF5 output begins with the line \x89HDF\r and only its second line holds control
   !> characters: the first line was quoted as text outside any group, its byte 0x89 (not
   !> UTF-8) written raw into the message.
   subroutine test_hdf5_signature(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('output.h5', [character(len=ll) :: achar(137)//'HDF'//achar(13), achar(26)//'x'//achar(0)//'y'], &
         & [character(len=32) :: 'line 2', 'holds binary characters'], error)
   end subroutine test_hdf5_signature

   !> stiffness = 1e300 was refused as 'stiffness_per_mass = 8.4e+300', a key the file does not
   !> hold, with the range in 1/s^2.
   subroutine test_stiffness_range(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('stiffness.nml', [character(len=ll) :: '&stops law = ''compliance'', stiffness = 1e300 /'], &
         & [character(len=48) :: '&stops stiffness = 1e+300 is out of range', &
         & '1.1938e-13 <= stiffness <= 1.1938e+19 N/m'], error)
   end subroutine test_stiffness_range

   !> youngs_modulus = 1e13 with density = 0.01 was refused as 'k2 = 1e+16', a key the file does not hold.
   subroutine test_material_range(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('material.nml', [character(len=ll) :: '&beam youngs_modulus = 1e13, density = 0.01,', &
         & '      outer_diameter = 10, wall_thickness = 1 /'], &
         & [character(len=48) :: '&beam youngs_modulus = 1e+13', 'give k2 = EI/(rho S)', &
         & '1e-12 <= k2 <= 1e+15 m^4/s^2'], error)
      if (allocated(error)) return
      call expect_error('material.nml', [character(len=ll) :: '&beam youngs_modulus = 2e11, density = 1e5,', &
         & '      outer_diameter = 1000, wall_thickness = 500 /'], &
         & [character(len=48) :: '&beam density = 100000', 'give mass_per_length = rho S', &
         & '1e-12 <= mass_per_length <= 1e+09 kg/m'], error)
   end subroutine test_material_range

   subroutine test_malformed_kind(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('kind.nml', [character(len=ll) :: '&time beta = 0.25 /', '&mesh elements = 19.5 /'], &
         & [character(len=32) :: '&mesh elements = 19.5', 'is malformed', 'a whole number'], error)
      if (allocated(error)) return
      ! a whole number beyond the integer kind is out of range, with the key's own range
      call expect_error('huge.nml', [character(len=ll) :: '&mesh elements = 99999999999999999999 /'], &
         & [character(len=48) :: '&mesh elements = 99999999999999999999', 'is out of range', &
         & 'allowed: 1 <= elements <= 1000000'], error)
      if (allocated(error)) return
      call expect_error('huge.nml', [character(len=ll) :: '&output checkpoint_every = 99999999999999999999 /'], &
         & [character(len=48) :: 'is out of range', 'checkpoint_every >= 0 (0: none)', &
         & 'and at most 9223372036854775807'], error)
      if (allocated(error)) return
      call expect_error('huge.nml', [character(len=ll) :: '&stops nodes = 5, 99999999999999999999,', &
         & '  lower = -0.1, upper = 0.1 /'], [character(len=48) :: 'nodes = 5, 99999999999999999999', &
         & 'is out of range', '1 <= nodes <= elements = 19'], error)
      if (allocated(error)) return
      ! the sentinel of an element not given, given: out of range (it had passed for not given)
      call expect_error('sentinel.nml', [character(len=ll) :: '&stops nodes = -2147483647, lower = -0.1, upper = 0.1 /'], &
         & [character(len=48) :: '&stops nodes(1) = -2147483647', 'is out of range'], error)
   end subroutine test_malformed_kind

   !> Reading the canonical text of a scene gives the same canonical text (so the same values:
   !> every real is written so that it reads back exactly), for texts using every form of input.
   subroutine test_canonical_round_trip(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: nl = new_line('a')
      character(len=200), parameter :: texts(5) = [character(len=200) :: &
         & '&time dt = 1e-5 /', &
         & '&beam length = 0.30000000000000004, k2 = 0.3333333333333333 /'//nl//'&support omega = 0 /', &
         & '&stops law = ''compliance'', stiffness = 1e8 /'//nl//'&time beta = 0.25, dt = 5e-6 /', &
         & '&beam length = 1.5 /'//nl//'&mesh elements = 30 /'//nl//'&stops x = 0.5, 1.0, 1.5, lower = -0.002, upper = 0.1, 0.2, 0.3 /', &
         & '&beam youngs_modulus = 2e11, density = 8e3, outer_diameter = 0.01, wall_thickness = 5e-4 /'//nl// &
         & '&output file = ''it''''s.h5'', checkpoint_every = 9, max_output_gb = 0.01 /']
      type(scene_type) :: first, second
      type(error_type), allocatable :: failure
      character(len=:), allocatable :: canonical
      integer :: i
      do i = 1, size(texts)
         call scene_from_text(trim(texts(i)), 'test', first, failure)
         call check(error, .not. allocated(failure), 'text '//trim(texts(i))//' is read')
         if (allocated(error)) return
         canonical = canonical_text(first)
         call scene_from_text(canonical, 'canonical', second, failure)
         call check(error, .not. allocated(failure), 'canonical text is read: '//canonical)
         if (allocated(error)) return
         call check(error, canonical_text(second) == canonical, 'canonical text reads back the same: '//canonical)
         if (allocated(error)) return
         call check(error, second%dt == first%dt .and. second%k2 == first%k2 .and. &
            & second%stiffness_per_mass == first%stiffness_per_mass .and. second%length == first%length, &
            & 'values read back bit for bit')
         if (allocated(error)) return
      end do
      call check(error, first%output_file == 'it''s.h5', 'quotes in texts survive')
   end subroutine test_canonical_round_trip

   !> max_output_gb = 0 was accepted (and refused every run naming snapshot_every, with an
   !> overflowed bound); 1e-9 suggested turning snapshots on.
   subroutine test_max_output_gb(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('gb0.nml', [character(len=ll) :: '&output max_output_gb = 0 /'], &
         & [character(len=48) :: '&output max_output_gb = 0 is out of range', '0 < max_output_gb <= 1e+06'], error)
      if (allocated(error)) return
      call expect_error('gb_tiny.nml', [character(len=ll) :: '&output max_output_gb = 1e-9 /'], &
         & [character(len=48) :: '&output max_output_gb = 1e-09', 'the fixed part of the output alone', &
         & '7.2e-08 GB', 'raise max_output_gb'], error)
      if (allocated(error)) return
      call expect_error('gb_records.nml', [character(len=ll) :: '&output max_output_gb = 1e-5 /'], &
         & [character(len=48) :: '&output record_every = 1', 'record_every >= 290'], error)
      if (allocated(error)) return
      call expect_error('gb_snapshots.nml', [character(len=ll) :: '&output max_output_gb = 0.003, snapshot_every = 1 /'], &
         & [character(len=48) :: '&output snapshot_every = 1', 'snapshot_every = 0'], error)
      if (allocated(error)) return
      call expect_error('gb_both.nml', [character(len=ll) :: '&output max_output_gb = 1e-4, snapshot_every = 1 /'], &
         & [character(len=48) :: 'snapshot_every = 0 and record_every >= 29'], error)
   end subroutine test_max_output_gb

   !> A spring given with law 'signorini' or 'none' was dropped silently.
   subroutine test_spring_other_law(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('spring.nml', [character(len=ll) :: '&stops stiffness = 1e5 /'], &
         & [character(len=48) :: '&stops stiffness = 100000', 'law = ''signorini''', 'law = ''compliance'''], error)
      if (allocated(error)) return
      call expect_error('spring.nml', [character(len=ll) :: '&stops law = ''none'', stiffness_per_mass = 1e5 /'], &
         & [character(len=48) :: '&stops stiffness_per_mass = 100000', 'law = ''none'''], error)
   end subroutine test_spring_other_law

   !> modes = 2 became (2, 2); modes without ratio did nothing.
   subroutine test_damping_modes(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('modes.nml', [character(len=ll) :: '&damping ratio = 0.01, modes = 2 /'], &
         & [character(len=48) :: '&damping modes = 2 (one value)', 'two distinct mode numbers'], error)
      if (allocated(error)) return
      call expect_error('modes.nml', [character(len=ll) :: '&damping modes = 2, 3 /'], &
         & [character(len=48) :: '&damping modes = 2, 3 is given without ratio', 'modes only with ratio'], error)
      if (allocated(error)) return
      ! the second alone was told as one value, 3, as if modes = 3
      call expect_error('modes.nml', [character(len=ll) :: '&damping ratio = 0.01, modes(2) = 3 /'], &
         & [character(len=48) :: '&damping modes(2) = 3 is given but modes(1)', 'two distinct mode numbers'], error)
   end subroutine test_damping_modes

   !> members = 3 with the statistics off ran three members and wrote no /ensemble.
   subroutine test_ensemble_without_statistics(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('ensemble.nml', [character(len=ll) :: '&ensemble members = 3 /', '&statistics enabled = .false. /'], &
         & [character(len=48) :: '&ensemble members = 3', 'enabled = .false.', 'members = 1'], error)
   end subroutine test_ensemble_without_statistics

   !> x = 0.079, 0.079 was told as nodes(2) = 1, a key the file does not hold.
   subroutine test_x_twice(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('x.nml', [character(len=ll) :: '&stops x = 0.079, 0.079 /'], &
         & [character(len=48) :: '&stops x(2) = 0.079 is out of range', 'each stop at its own node', 'node 1'], error)
   end subroutine test_x_twice

   !> allow_unstable = 3 followed by another key gave gfortran's 'Bad repeat count'.
   subroutine test_bad_logical(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('logical.nml', [character(len=ll) :: '&time allow_unstable = 3, dt = 1e-5 /'], &
         & [character(len=64) :: '&time allow_unstable = 3 is malformed', 'allowed: allow_unstable = .true. or .false.'], &
         & error)
      if (allocated(error)) return
      call expect_error('logical.nml', [character(len=ll) :: '&statistics enabled = 2 bins = 3 /'], &
         & [character(len=64) :: '&statistics enabled = 2 is malformed', 'allowed: enabled = .true. or .false.'], error)
   end subroutine test_bad_logical

   !> A group without its / at the end of the file was told as a malformed value.
   subroutine test_unclosed_group(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('open.nml', [character(len=ll) :: '&time t_end=0.01'], &
         & [character(len=48) :: 'group &time is not closed by /'], error)
      if (allocated(error)) return
      call expect_error('open.nml', [character(len=ll) :: '&time t_end=0.01', '&mesh elements = 3 /'], &
         & [character(len=48) :: 'line 2', 'group &time is not closed by / before &mesh'], error)
   end subroutine test_unclosed_group

   !> 1001 stops were told as a malformed value.
   subroutine test_too_many_values(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_error('many.nml', [character(len=ll) :: '&stops nodes = 1001*19, lower = -0.01, upper = 0.01 /'], &
         & [character(len=64) :: '&stops nodes has 1001 values, out of range', 'at most 1000 stops'], error)
      if (allocated(error)) return
      call expect_error('many.nml', [character(len=ll) :: '&damping ratio = 0.1, 0.2, 0.3 /'], &
         & [character(len=64) :: '&damping ratio has 3 values, out of range', 'at most two values'], error)
   end subroutine test_too_many_values

   !> gfortran keeps the start of a text longer than its variable without a word: a path of
   !> 5,000 characters was read as its first 4,096, a word padded past 64 characters as the word.
   subroutine test_long_texts(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(error_type), allocatable :: failure
      call scene_from_text("&output file = '"//repeat('b', 5000)//".h5' /", 'long', scene, failure)
      call check(error, allocated(failure), 'a path of 5,003 characters refused')
      if (allocated(error)) return
      call check(error, index(failure%message, '&output file is 5003 characters long, out of range; allowed: at most '// &
         & '4095 characters') > 0, failure%message(:min(200, len(failure%message))))
      if (allocated(error)) return
      deallocate (failure)
      call scene_from_text("&time load_rule = 'paper"//repeat(' ', 70)//"x' /", 'padded', scene, failure)
      call check(error, allocated(failure), 'a word padded past its 64 characters refused')
      if (allocated(error)) return
      call check(error, index(failure%message, '&time load_rule is 76 characters long, out of range; allowed: at most '// &
         & '63 characters') > 0, failure%message)
      if (allocated(error)) return
      deallocate (failure)
      ! blanks at the end of a word do not count (the reader drops them)
      call scene_from_text("&time load_rule = 'centered"//repeat(' ', 70)//"' /", 'blanks', scene, failure)
      call check(error, .not. allocated(failure), 'a word with 70 blanks after it read')
      if (allocated(error)) return
      ! at the limit: read whole (a quote doubled inside counts one)
      call scene_from_text("&output file = '"//repeat('c', 4090)//"''s.h5' /", 'limit', scene, failure)
      call check(error, .not. allocated(failure), 'a path of 4,095 characters read')
      if (allocated(error)) return
      call check(error, len(scene%output_file), 4095, 'the whole path kept')
   end subroutine test_long_texts

   !> A file converted to \r\n twice ends its lines in \r\r\n: its groups were told as text
   !> outside any group.
   subroutine test_carriage_returns(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: ends = achar(13)//achar(13)//new_line('a')
      type(scene_type) :: scene
      type(error_type), allocatable :: failure
      call scene_from_text('&time dt = 1e-4 /'//ends//ends//'&mesh elements = 5 /'//ends, 'crcr', scene, failure)
      call check(error, .not. allocated(failure), 'read')
      if (allocated(error)) return
      call check(error, scene%elements, 5, 'elements of the group after the blank line')
   end subroutine test_carriage_returns

   !> Texts far larger than any scene (the reader takes up to 64 MB): each is refused with its
   !> message rather than a crash (a line of 16 MB overflowed the stack) or minutes of copying
   !> (the lines and the assignments were gathered one by one into growing strings).
   subroutine test_huge_texts(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: many = 2000000
      type(scene_type) :: scene
      type(error_type), allocatable :: failure
      character(len=:), allocatable :: text
      text = '&time '//repeat('dt=1e-5 ', many)//'/'
      call scene_from_text(text, 'keys', scene, failure)
      call check(error, allocated(failure), 'dt given 2,000,000 times refused')
      if (allocated(error)) return
      call check(error, index(failure%message, '&time dt is given twice') > 0, failure%message)
      if (allocated(error)) return
      deallocate (failure)
      text = '&stops nodes = '//repeat('5,'//new_line('a'), many)//'/'
      call scene_from_text(text, 'lines', scene, failure)
      call check(error, allocated(failure), '2,000,000 nodes on as many lines refused')
      if (allocated(error)) return
      call check(error, index(failure%message, '&stops nodes has 2000000 values, out of range') > 0, failure%message)
      if (allocated(error)) return
      deallocate (failure)
      text = '&time '//repeat('dt0=1e-5 ', many/10)//'/'
      call scene_from_text(text, 'unknown', scene, failure)
      call check(error, allocated(failure), '200,000 unknown keys refused')
      if (allocated(error)) return
      call check(error, index(failure%message, '&time: unknown key dt0') > 0, failure%message)
   end subroutine test_huge_texts

   !> A malformed logical left gfortran's reader in a state where the next text's &stops was
   !> not read: law = 'glue' was then accepted as 'signorini'.
   subroutine test_reader_state_after_bad_logical(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: bad(4) = [character(len=40) :: '&time allow_unstable = 1 /', &
         & '&time allow_unstable = 3, dt = 1e-5 /', '&statistics enabled = 2 /', '&mesh elements = 19.5 /']
      type(scene_type) :: scene
      type(error_type), allocatable :: failure
      integer :: i
      do i = 1, size(bad)
         call scene_from_text(trim(bad(i)), 'first', scene, failure)
         call check(error, allocated(failure), 'refused: '//trim(bad(i)))
         if (allocated(error)) return
         deallocate (failure)
         call scene_from_text('&stops law = ''glue'' /', 'second', scene, failure)
         call check(error, allocated(failure), 'law = ''glue'' refused after '//trim(bad(i)))
         if (allocated(error)) return
         deallocate (failure)
         call scene_from_text('&mesh elements = 7 /', 'third', scene, failure)
         call check(error, .not. allocated(failure), 'a good text read after '//trim(bad(i)))
         if (allocated(error)) return
         call check(error, scene%elements, 7, 'elements read after '//trim(bad(i)))
         if (allocated(error)) return
      end do
   end subroutine test_reader_state_after_bad_logical

   !> Keys carried over from a scene being changed (Scene.replace): dropped where they do
   !> nothing (a spring without the compliance law, &damping modes without ratio), kept where
   !> they act, and refused when not carried.
   subroutine test_carried_keys(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: spring = '&stops law = ''signorini'', stiffness_per_mass = 1e8 /', &
         & compliance = '&stops law = ''compliance'', stiffness_per_mass = 1e8 / &time beta = 0.25, dt = 5e-6 /', &
         & modes = '&damping modes = 1, 3 /', with_ratio = '&damping ratio = 0.01, modes = 1, 3 /'
      type(scene_type) :: scene
      type(error_type), allocatable :: failure
      call scene_from_text(spring, 'scene', scene, failure)
      call check(error, allocated(failure), 'a spring with law signorini, given anew, refused')
      if (allocated(error)) return
      deallocate (failure)
      call scene_from_text(spring, 'scene', scene, failure, carried='stops:stiffness_per_mass')
      call check(error, .not. allocated(failure), 'the same spring carried over, dropped')
      if (allocated(error)) return
      call check(error, scene%law == law_signorini, 'law signorini')
      if (allocated(error)) return
      call scene_from_text(compliance, 'scene', scene, failure, carried='stops:stiffness_per_mass')
      call check(error, .not. allocated(failure), 'a carried spring with the compliance law')
      if (allocated(error)) return
      call check(error, scene%stiffness_per_mass, 1.0e8_wp, 'the carried spring acts')
      if (allocated(error)) return
      call scene_from_text(modes, 'scene', scene, failure, carried='stops:stiffness_per_mass')
      call check(error, allocated(failure), 'modes without ratio, not carried, refused')
      if (allocated(error)) return
      deallocate (failure)
      call scene_from_text(modes, 'scene', scene, failure, carried='stops:stiffness_per_mass damping:modes')
      call check(error, .not. allocated(failure) .and. .not. scene%damping_by_ratio, 'carried modes without ratio dropped')
      if (allocated(error)) return
      call scene_from_text(with_ratio, 'scene', scene, failure, carried='damping:modes')
      call check(error, .not. allocated(failure), 'carried modes with ratio')
      if (allocated(error)) return
      call check(error, scene%damping_modes(2), 3, 'the carried modes act with ratio')
   end subroutine test_carried_keys

   !> The text `text` must be refused with a message holding each of `needles` (as words).
   subroutine expect_text_error(text, needles, error)
      character(len=*), intent(in) :: text
      character(len=*), intent(in) :: needles(:)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(error_type), allocatable :: failure
      integer :: i
      call scene_from_text(text, 'in.nml', scene, failure)
      if (.not. allocated(failure)) then
         call test_failed(error, 'accepted: '//text)
         return
      end if
      call note('message: '//failure%message)
      do i = 1, size(needles)
         call check(error, has_word(failure%message, trim(needles(i))), 'the message names '//trim(needles(i))// &
            & ': '//failure%message)
         if (allocated(error)) return
      end do
   end subroutine expect_text_error

   !> The text must be read.
   subroutine expect_read(text, error)
      character(len=*), intent(in) :: text
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      call scene_from_text(text, 'in.nml', scene, error)
   end subroutine expect_read

   !> &damping mass_coefficient and stiffness_coefficient took Inf and 1e300 (the run diverged
   !> at t = 0 and replaced an earlier output), &statistics rest_time and the histogram's range
   !> any finite value; every real key of every group is finite and bounded.
   subroutine test_real_keys_bounded(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 27
      character(len=100), parameter :: texts(n) = [character(len=100) :: &
         & '&beam length = inf /', '&beam k2 = 1e300 /', '&beam mass_per_length = inf /', &
         & '&support amplitude = -inf /', '&support omega = 1e300 /', '&stops lower = -inf /', '&stops upper = inf /', &
         & '&stops x = inf /', '&stops law = ''compliance'', stiffness = inf /', &
         & '&stops law = ''compliance'', stiffness_per_mass = 1e300 /', '&stops restitution = inf /', &
         & '&damping mass_coefficient = inf /', '&damping mass_coefficient = 1e150 /', &
         & '&damping stiffness_coefficient = inf /', '&damping stiffness_coefficient = 1e300 /', &
         & '&damping ratio = inf /', '&time dt = inf /', '&time t_end = inf /', '&time beta = inf /', &
         & '&output max_output_gb = inf /', '&statistics transient = inf /', '&statistics rest_time = inf /', &
         & '&statistics rest_time = 1e300 /', '&statistics histogram_lower = -1e300 /', &
         & '&statistics histogram_upper = inf /', '&ensemble perturbation = inf /', '&beam youngs_modulus = inf, '// &
         & 'density = 8e3, outer_diameter = 0.01, wall_thickness = 5e-4 /']
      character(len=32), parameter :: keys(n) = [character(len=32) :: 'length', 'k2', 'mass_per_length', 'amplitude', &
         & 'omega', 'lower', 'upper', 'x(1)', 'stiffness', 'stiffness_per_mass', 'restitution', 'mass_coefficient', &
         & 'mass_coefficient', 'stiffness_coefficient', 'stiffness_coefficient', 'ratio', 'dt', 't_end', 'beta', &
         & 'max_output_gb', 'transient', 'rest_time', 'rest_time', 'histogram_lower', 'histogram_upper', 'perturbation', &
         & 'youngs_modulus']
      integer :: i
      do i = 1, n
         call expect_text_error(trim(texts(i)), [character(len=32) :: keys(i), 'is out of range'], error)
         if (allocated(error)) return
      end do
      call expect_text_error('&damping mass_coefficient = 1e150 /', [character(len=64) :: &
         & '&damping mass_coefficient = 1e+150 is out of range', 'allowed: 0 <= mass_coefficient <= 1.69e+08 1/s'], error)
      if (allocated(error)) return
      call expect_text_error('&damping stiffness_coefficient = inf /', [character(len=64) :: &
         & '&damping stiffness_coefficient = Inf is out of range', 'allowed: 0 <= stiffness_coefficient <= 7.62 s'], &
         & error)
      if (allocated(error)) return
      ! Within the bounds: read.
      call expect_read('&damping mass_coefficient = 1e8, stiffness_coefficient = 7 /', error)
      if (allocated(error)) return
      call expect_read('&statistics rest_time = 1e9, histogram_lower = -1e9, histogram_upper = 1e9 /', error)
   end subroutine test_real_keys_bounded

   !> A tube's material and section: each key bounded beyond any real material and section (a
   !> diameter of 1e100 gave k2 = -Inf, a wall of 1e-17 on a diameter of 1 k2 = NaN).
   subroutine test_material_bounds(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: rest = ', density = 8e3, outer_diameter = 0.01, wall_thickness = 5e-4 /'
      call expect_text_error('&beam youngs_modulus = 1e14'//rest, [character(len=64) :: &
         & '&beam youngs_modulus = 1e+14 is out of range', 'allowed: 0 < youngs_modulus <= 1e+13 Pa'], error)
      if (allocated(error)) return
      call expect_text_error('&beam youngs_modulus = 2e11, density = 1e6, outer_diameter = 0.01, wall_thickness = 5e-4 /', &
         & [character(len=64) :: '&beam density = 1e+06', 'allowed: 0.001 <= density <= 100000 kg/m^3'], error)
      if (allocated(error)) return
      call expect_text_error('&beam youngs_modulus = 2e11, density = 8e3, outer_diameter = 1e100, wall_thickness = 1e99 /', &
         & [character(len=64) :: '&beam outer_diameter = 1e+100', 'allowed: 1e-09 <= outer_diameter <= 1000 m'], error)
      if (allocated(error)) return
      call expect_text_error('&beam youngs_modulus = 2e11, density = 8e3, outer_diameter = 1, wall_thickness = 1e-17 /', &
         & [character(len=96) :: '&beam wall_thickness = 1e-17', &
         & 'allowed: 1e-06*outer_diameter = 1e-06 <= wall_thickness <= outer_diameter/2 = 0.5 m'], error)
   end subroutine test_material_bounds

   !> dt = t_end = 1e-170 was accepted and diverged at t = 0 (dt^2 underflows); dt = 1e-310 with
   !> t_end = 1e-300 was refused as out of 0 < dt <= t_end = 1e-300 s, a range it is in.
   subroutine test_tiny_time_step(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_text_error('&time dt = 1e-170, t_end = 1e-170 /', [character(len=64) :: &
         & '&time t_end = 1e-170 is out of range', 'allowed: 1e-15 <= t_end <= 1e+09 s'], error)
      if (allocated(error)) return
      call expect_text_error('&time dt = 1e-310, t_end = 1e-300 /', [character(len=64) :: &
         & '&time t_end = 1e-300 is out of range', 'allowed: 1e-15 <= t_end <= 1e+09 s'], error)
      if (allocated(error)) return
      call expect_text_error('&time dt = 1e-310, t_end = 1e-3 /', [character(len=64) :: &
         & '&time dt = 1e-310 is out of range', 'allowed: 1e-15 <= dt <= t_end = 0.001 s'], error)
      if (allocated(error)) return
      call expect_text_error('&time dt = 0.1, t_end = 1e-3 /', [character(len=64) :: &
         & '&time dt = 0.1 is out of range', 'allowed: 1e-15 <= dt <= t_end = 0.001 s'], error)
      if (allocated(error)) return
      call expect_read('&time dt = 1e-15, t_end = 1e-15 /', error)
   end subroutine test_tiny_time_step

   !> The stability limit was shown rounded to the nearest: dt = the limit, refused, read as
   !> within `dt < 1.23951e-05` (the limit is 1.2395061e-05).
   subroutine test_stability_limit_shown(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(model_type) :: model
      type(error_type), allocatable :: failure
      real(wp) :: shown_limit
      integer :: at, stat
      call scene_from_text('&time dt = 1e-6, t_end = 1e-3, beta = 0 /', 'in.nml', scene, error)
      if (allocated(error)) return
      call build_model(scene, model, error)
      if (allocated(error)) return
      scene%dt = model%dt_newmark
      call check_stability(scene, model, 'in.nml', failure)
      call check(error, allocated(failure), 'dt at the limit refused')
      if (allocated(error)) return
      call note(failure%message)
      at = index(failure%message, 'allowed: dt < ') + len('allowed: dt < ')
      read (failure%message(at:index(failure%message(at:), ' ') + at - 2), *, iostat=stat) shown_limit
      call check(error, stat == 0 .and. scene%dt >= shown_limit, 'dt = '//real_text(scene%dt)// &
         & ' is beyond the limit shown: '//failure%message)
   end subroutine test_stability_limit_shown

   !> Both springs given with the compliance law was told as `needs a spring`.
   subroutine test_two_springs(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_text_error('&stops law = ''compliance'', stiffness = 1e5, stiffness_per_mass = 1e6 /', &
         & [character(len=64) :: '&stops stiffness and stiffness_per_mass are both given', 'allowed: one of them'], error)
   end subroutine test_two_springs

   !> A FIFO (as a pipe, bash's `<(...)`) reports size 0: it was read as an empty text, 'no
   !> namelist group'. It is read to its end, and gives no output name (its name, like /dev/fd/63,
   !> says nothing of the scene); a regular file gives its own.
   subroutine test_fifo(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      character(len=:), allocatable :: path
      integer :: stat
      path = temp_dir()//'/scene.fifo'
      call execute_command_line('rm -f "'//path//'" && mkfifo "'//path//'" && '// &
         & '(printf ''&time dt = 2e-5 /\n&mesh elements = 7 /\n'' > "'//path//'" &)', exitstat=stat)
      call check(error, stat == 0, 'a FIFO with a writer')
      if (allocated(error)) return
      call read_scene(path, scene, error)
      call remove(path)
      if (allocated(error)) return
      call check(error, scene%elements, 7, 'elements read from the FIFO')
      if (allocated(error)) return
      call check(error, scene%output_file == '', 'a FIFO gives no output name, got '//scene%output_file)
      if (allocated(error)) return
      path = write_file('named.nml', [character(len=ll) :: '&time dt = 1e-5 /'])
      call read_scene(path, scene, error)
      call remove(path)
      if (allocated(error)) return
      call check(error, scene%output_file == 'named.h5', 'named.nml gives named.h5, got '//scene%output_file)
   end subroutine test_fifo
   !> gfortran reads a logical by the first letter of any word: `allow_unstable = trash` was
   !> .true. (the stability refusal turned off), `enabled = fish` .false.. Only .true., .false.,
   !> T, F, .t., .f., true and false (any case) are read; every other word is malformed.
   subroutine test_logical_forms(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: bad(6) = [character(len=48) :: '&time allow_unstable=trash /', &
         & '&statistics enabled=Tuesday /', '&statistics enabled=fish /', '&statistics enabled=.frobnicate. /', &
         & '&statistics enabled=.false.xyz /', '&time allow_unstable = .t, dt = 1e-5 /']
      character(len=*), parameter :: shown(6) = [character(len=32) :: 'allow_unstable=trash', 'enabled=Tuesday', &
         & 'enabled=fish', 'enabled=.frobnicate.', 'enabled=.false.xyz', 'allow_unstable = .t']
      character(len=*), parameter :: keys(6) = [character(len=14) :: 'allow_unstable', 'enabled', 'enabled', &
         & 'enabled', 'enabled', 'allow_unstable']
      character(len=*), parameter :: good(8) = [character(len=8) :: '.true.', '.FALSE.', 'T', 'f', '.t.', '.F.', &
         & 'True', 'false']
      type(scene_type) :: scene
      character(len=64) :: needles(3)
      integer :: i
      do i = 1, size(bad)
         needles(1) = trim(shown(i))//' is malformed'
         needles(2) = 'allowed: '//trim(keys(i))//' ='
         needles(3) = '.true. or .false.'
         call expect_text_error(trim(bad(i)), needles, error)
         if (allocated(error)) return
      end do
      do i = 1, size(good)
         call scene_from_text('&statistics enabled = '//trim(good(i))//' /', 'in.nml', scene, error)
         if (allocated(error)) return
         call check(error, scene%statistics .eqv. scan(good(i)(1:2), 'tT') > 0, 'enabled = '//trim(good(i)))
         if (allocated(error)) return
      end do
      if (allocated(error)) return
      ! a repeat count before a logical, as before any value
      call expect_read('&statistics enabled = 1*T /', error)
      if (allocated(error)) return
      call expect_read('&time allow_unstable = 1*.false. /', error)
   end subroutine test_logical_forms

   !> A null value leaves its element as it was: `nodes = 2*` was read as no stops along the
   !> span (where `nodes = /` is refused), `modes = , 3` as one mode. Every null is refused.
   subroutine test_null_values(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: bad(7) = [character(len=64) :: '&stops nodes=2* /', &
         & '&stops nodes=5, 10, 5*, lower=-0.1, upper=0.1 /', '&damping ratio=0.01, modes=, 3 /', &
         & '&stops nodes=5,,10 /', '&stops nodes=5, 10, , lower=-0.1 /', '&time dt=1*, beta=0.25 /', &
         & '&damping ratio(1)=2* /']
      character(len=*), parameter :: shown(7) = [character(len=32) :: '&stops nodes=2*', '&stops nodes=5, 10, 5*', &
         & '&damping modes=, 3', '&stops nodes=5,,10', '&stops nodes=5, 10, ,', '&time dt=1*', '&damping ratio(1)=2*']
      character(len=*), parameter :: allowed(7) = [character(len=48) :: 'allowed: nodes = whole numbers', &
         & 'allowed: nodes = whole numbers', 'allowed: modes = whole numbers', 'allowed: nodes = whole numbers', &
         & 'allowed: nodes = whole numbers', 'allowed: dt = a real number', 'allowed: ratio = one or two real']
      character(len=64) :: needles(3)
      integer :: i
      do i = 1, size(bad)
         needles(1) = shown(i)
         needles(2) = 'has an empty value'
         needles(3) = allowed(i)
         call expect_text_error(trim(bad(i)), needles, error)
         if (allocated(error)) return
      end do
      ! a comma after the last value separates it from the next key or the /; a quoted comma is text
      call expect_read('&stops nodes = 5 , 10 , lower = -0.1, upper = 0.1, / &output file = ''a,,b.h5'', /', error)
      if (allocated(error)) return
      call expect_read('&stops nodes = 5, 10, lower = 2*-0.1 /', error)
   end subroutine test_null_values
   !> A key given twice is refused, but an element of a list given twice was overwritten unsaid:
   !> `ratio = 0.01, 0.03, ratio(2) = 0.02` was read as 0.01, 0.02. Each element is given at most
   !> once, by the whole list or by its subscript; distinct elements are read.
   subroutine test_elements_twice(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: bad(6) = [character(len=64) :: '&damping ratio(1)=0.01, ratio(1)=0.02 /', &
         & '&damping ratio=0.01, 0.03, ratio(2)=0.02 /', '&stops nodes=5,10, nodes(2)=12 /', &
         & '&stops nodes=5,10, lower=-0.1,-0.2, lower(2)=-0.3 /', '&stops nodes(2:3)=5,10, nodes(3)=12 /', &
         & '&stops nodes(2)=10, nodes=5, 12 /']
      character(len=*), parameter :: shown(6) = [character(len=32) :: '&damping ratio(1)', '&damping ratio(2)', &
         & '&stops nodes(2)', '&stops lower(2)', '&stops nodes(3)', '&stops nodes(2)']
      character(len=64) :: needles(3)
      type(scene_type) :: scene
      integer :: i
      do i = 1, size(bad)
         needles(1) = trim(shown(i))//' is given twice'
         needles(2) = 'allowed: each key once in a group'
         needles(3) = 'each element of a list at most once'
         call expect_text_error(trim(bad(i)), needles, error)
         if (allocated(error)) return
      end do
      ! the whole key twice keeps its message
      call expect_text_error('&stops nodes=5, nodes=10 /', [character(len=48) :: '&stops nodes is given twice'], error)
      if (allocated(error)) return
      ! distinct elements, in any order, are read
      call scene_from_text('&stops nodes(2) = 10, nodes(1) = 5, lower(1:2) = -0.1, -0.2 / &damping ratio(2) = '// &
         & '0.02, ratio(1) = 0.01 /', 'in.nml', scene, error)
      if (allocated(error)) return
      call check(error, all(scene%stop_nodes == [5, 10]), 'nodes 5, 10')
      if (allocated(error)) return
      call check(error, scene%stop_lower(2), -0.2_wp, 'lower(2)')
      if (allocated(error)) return
      call check(error, scene%damping_ratio(1), 0.01_wp, 'ratio(1)')
      if (allocated(error)) return
      call check(error, scene%damping_ratio(2), 0.02_wp, 'ratio(2)')
   end subroutine test_elements_twice

   !> `nodes(1001) = 1001` or `ratio(0) = 0.1` failed gfortran's read and was told as malformed:
   !> it is out of range, and the message gives the list's first and last elements. Elements
   !> inside the list, and empty sections, are not refused for their subscript.
   subroutine test_element_outside(error)
      type(error_type), allocatable, intent(out) :: error
      ! subscripts beyond the integer kind too (they were malformed): a whole number is out of range
      character(len=*), parameter :: bad(8) = [character(len=64) :: '&stops nodes(1001) = 1001 /', &
         & '&stops nodes(0) = 3 /', '&stops lower(999) = -0.1, -0.1, -0.1 /', '&damping ratio(3) = 0.1 /', &
         & '&damping ratio(1:3:2) = 0.1, 0.2 /', '&damping modes(2:0:-1) = 1, 2 /', &
         & '&stops nodes(99999999999999999999) = 2 /', '&damping ratio(-99999999999999999999:2) = 0.1 /']
      character(len=*), parameter :: shown(8) = [character(len=56) :: '&stops nodes(1001) = 1001', &
         & '&stops nodes(0) = 3', '&stops lower(999) = -0.1, -0.1, -0.1', '&damping ratio(3) = 0.1', &
         & '&damping ratio(1:3:2) = 0.1, 0.2', '&damping modes(2:0:-1) = 1, 2', &
         & '&stops nodes(99999999999999999999) = 2', '&damping ratio(-99999999999999999999:2) = 0.1']
      character(len=*), parameter :: bounds(8) = [character(len=40) :: 'nodes(1) to nodes(1000)', &
         & 'nodes(1) to nodes(1000)', 'lower(1) to lower(1000)', 'ratio(1) to ratio(2)', 'ratio(1) to ratio(2)', &
         & 'modes(1) to modes(2)', 'nodes(1) to nodes(1000)', 'ratio(1) to ratio(2)']
      character(len=80) :: needles(2)
      type(scene_type) :: scene
      integer :: i
      do i = 1, size(bad)
         needles(1) = trim(shown(i))//' is out of range'
         needles(2) = 'allowed: elements '//trim(bounds(i))
         call expect_text_error(trim(bad(i)), needles, error)
         if (allocated(error)) return
      end do
      ! the last elements of a list, and a section backwards inside it, are read
      call scene_from_text('&damping ratio(2:1:-1) = 0.02, 0.01, modes(2) = 3, modes(1) = 1 / &mesh elements = 4 /', &
         & 'in.nml', scene, error)
      if (allocated(error)) return
      call check(error, scene%damping_ratio(1), 0.01_wp, 'ratio(1)')
      if (allocated(error)) return
      call check(error, scene%damping_ratio(2), 0.02_wp, 'ratio(2)')
   end subroutine test_element_outside

   !> `load_rule(1:2) = 'pa'` was read as a substring of the default: load_rule = 'pantered'.
   !> A key of one value takes no subscript or substring.
   subroutine test_scalar_subscript(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: bad(5) = [character(len=48) :: "&time load_rule(1:2)='pa' /", &
         & "&stops law(1:4) = 'none' /", '&time dt(1)=1e-5 /', '&mesh modes(1) = 2 /', '&statistics enabled(1)=T /']
      character(len=*), parameter :: shown(5) = [character(len=32) :: "&time load_rule(1:2)='pa'", &
         & "&stops law(1:4) = 'none'", '&time dt(1)=1e-5', '&mesh modes(1) = 2', '&statistics enabled(1)=T']
      character(len=*), parameter :: allowed(5) = [character(len=48) :: 'allowed: load_rule = a quoted text', &
         & 'allowed: law = a quoted text', 'allowed: dt = a real number', 'allowed: modes = a whole number', &
         & 'allowed: enabled = .true. or .false.']
      character(len=64) :: needles(2)
      integer :: i
      do i = 1, size(bad)
         needles(1) = trim(shown(i))//' is malformed'
         needles(2) = allowed(i)
         call expect_text_error(trim(bad(i)), needles, error)
         if (allocated(error)) return
      end do
   end subroutine test_scalar_subscript
   !> seed = -2147483648 was read, while a seed beyond the integer was told "from -2147483647 to
   !> 2147483647": the message names the integer's whole range, both ends read.
   subroutine test_seed_range(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: beyond(2) = [character(len=40) :: '&ensemble seed=2147483648 /', &
         & '&ensemble seed=-2147483649 /']
      character(len=64) :: needles(2)
      type(scene_type) :: scene
      integer :: i
      do i = 1, size(beyond)
         needles(1) = trim(beyond(i)(:index(beyond(i), ' /') - 1))//' is out of range'
         needles(2) = 'seed = a whole number from -2147483648 to 2147483647'
         call expect_text_error(trim(beyond(i)), needles, error)
         if (allocated(error)) return
      end do
      call scene_from_text('&ensemble seed=-2147483648 /', 'in.nml', scene, error)
      if (allocated(error)) return
      call check(error, scene%seed == -huge(1) - 1, 'seed -2147483648 read')
      if (allocated(error)) return
      call scene_from_text('&ensemble seed=2147483647 /', 'in.nml', scene, error)
      if (allocated(error)) return
      call check(error, scene%seed, huge(1), 'seed 2147483647 read')
   end subroutine test_seed_range
end module test_namelist
