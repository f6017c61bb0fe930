!> The `beamstops` command-line program:
!>   beamstops run FILE.nml [-o OUT.h5] [--restart]   run a scene (or resume it from its last
!>                                        checkpoint), write its HDF5 file, print a summary
!>   beamstops info FILE.nml              print the scene, its discretization and limits
!>   beamstops plot | sweep | converge | ... ARGS   the subcommands of `python -m beamstops`,
!>                                        handed (execv) to the Python of the program's environment
program beamstops_main
   use, intrinsic :: iso_c_binding, only: c_int, c_long, c_size_t, c_intptr_t, c_funptr, c_null_funptr, c_char, &
      & c_null_char, c_ptr, c_null_ptr, c_loc
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use beamstops
   use beamstops_checkpoint, only: checkpoint_path, read_checkpoint, is_checkpoint
   use beamstops_files, only: file_exists, remove_file
   use beamstops_recorder_hdf5, only: partial_path, check_output_path
   use beamstops_run, only: continue_run, continue_reduced
   use beamstops_reduced, only: reduced_model_type, build_reduced, check_stability_reduced
   use beamstops_reduced_scheme, only: reduced_state_type, start_reduced
   use beamstops_reduced_checkpoint, only: read_reduced_checkpoint
   implicit none

   interface
      function c_isatty(fd) bind(c, name='isatty') result(r)
         import :: c_int
         integer(c_int), value :: fd
         integer(c_int) :: r
      end function c_isatty
      subroutine c_exit(status) bind(c, name='_exit')
         import :: c_int
         integer(c_int), value :: status
      end subroutine c_exit
      function c_signal(signum, handler) bind(c, name='signal') result(previous)
         import :: c_int, c_funptr
         integer(c_int), value :: signum
         type(c_funptr), value :: handler
         type(c_funptr) :: previous
      end function c_signal
   end interface

   interface
      function c_execv(path, argv) bind(c, name='execv') result(status)
         import :: c_char, c_ptr, c_int
         character(kind=c_char), intent(in) :: path(*)
         type(c_ptr), intent(in) :: argv(*)
         integer(c_int) :: status
      end function c_execv
      function c_execvp(file, argv) bind(c, name='execvp') result(status)
         import :: c_char, c_ptr, c_int
         character(kind=c_char), intent(in) :: file(*)
         type(c_ptr), intent(in) :: argv(*)
         integer(c_int) :: status
      end function c_execvp
      function c_readlink(path, buffer, size) bind(c, name='readlink') result(length)
         import :: c_char, c_size_t, c_long
         character(kind=c_char), intent(in) :: path(*)
         character(kind=c_char), intent(out) :: buffer(*)
         integer(c_size_t), value :: size
         integer(c_long) :: length
      end function c_readlink
   end interface

   !> A C string (NUL-terminated), for execv's argument vector.
   type :: c_string
      character(kind=c_char), allocatable :: text(:)
   end type c_string

   !> The subcommands of `python -m beamstops` (wrap/beamstops/cli.py) and their one-line help;
   !> tests/python/test_cli.py checks that they are exactly the Python parser's.
   integer, parameter :: n_python_commands = 8
   character(len=*), parameter :: python_commands(n_python_commands) = [character(len=14) :: 'plot', 'sweep', &
      & 'converge', 'work-precision', 'stability-map', 'compliance', 'contact-laws', 'plan']
   character(len=*), parameter :: python_help(n_python_commands) = [character(len=80) :: &
      & 'plot the HDF5 output of a run (tip, shape, energy, phase, reaction, stops)', &
      & 'run a parameter sweep (TOML specification) on local cores or MPI ranks', &
      & 'convergence tables in dt and h (markdown and CSV)', &
      & 'error against CPU time for every method (PNG, markdown, CSV)', &
      & 'stable/unstable maps in (beta, dt) and (J, dt) (PNG, markdown, CSV)', &
      & 'normal compliance: spurious oscillations and penetration', &
      & 'contact laws: energy, violation, chatter, convergence in dt', &
      & 'the cheapest model (law, mesh, dt) whose estimated error is under a tolerance']
   !> What the Python of the environment runs: beamstops.cli.main with the arguments, or one
   !> message and exit status 2 when the package cannot be imported.
   character(len=*), parameter :: bootstrap = &
      & 'import sys'//new_line('a')// &
      & 'try:'//new_line('a')// &
      & '    from beamstops.cli import main'//new_line('a')// &
      & 'except ImportError as exc:'//new_line('a')// &
      & '    sys.stderr.write(f"beamstops: error: {sys.argv[1]!r} needs the beamstops Python package, which "'// &
      & ' f"{sys.executable} cannot import ({exc}); install it with pip install . in this environment\n")'// &
      & new_line('a')// &
      & '    sys.exit(2)'//new_line('a')// &
      & 'sys.exit(main(sys.argv[1:], prog="beamstops"))'

   !> SIGXFSZ (Linux on x86, ARM, POWER, RISC-V, s390; BSD and macOS too) and SIG_IGN.
   integer(c_int), parameter :: sigxfsz = 25_c_int
   integer(c_intptr_t), parameter :: sig_ign = 1_c_intptr_t

   integer, parameter :: exit_input = 1, exit_usage = 2, exit_diverged = 3, exit_output = 4
   character(len=:), allocatable :: command, path, out
   logical :: restart = .false.
   type(scene_type) :: scene
   type(model_type) :: model
   type(error_type), allocatable :: error

   call ignore_file_size_signal()
   call parse_arguments(command, path, out, restart)
   call read_scene(path, scene, error)
   call stop_on(error, exit_input)
   if (allocated(out)) scene%output_file = out
   call prepare_run(scene, path, model, error)
   call stop_on(error, exit_input)
   select case (command)
   case ('info')
      call print_info(scene, model)
   case ('run')
      call run_to_file(scene, model, path, restart)
   end select

contains

   subroutine parse_arguments(command, path, out, restart)
      character(len=:), allocatable, intent(out) :: command, path, out
      logical, intent(inout) :: restart
      character(len=4096) :: arg
      integer :: i, n
      n = command_argument_count()
      if (n < 1) call usage('missing command')
      call get_command_argument(1, arg)
      command = trim(arg)
      select case (command)
      case ('-h', '--help', 'help')
         call usage()
      case ('-V', '--version', 'version')
         write (output_unit, '(a)') 'beamstops '//version
         stop
      case ('run', 'info')
      case default
         if (any(python_commands == command)) call hand_to_python()
         call usage("unknown command '"//command//"'")
      end select
      i = 2
      do while (i <= n)
         call get_command_argument(i, arg)
         select case (trim(arg))
         case ('-o', '--output')
            if (command /= 'run' .or. i == n) call usage("'-o' takes a file name, with 'run'")
            call get_command_argument(i + 1, arg)
            out = trim(arg)
            i = i + 1
         case ('--restart')
            if (command /= 'run') call usage("'--restart' goes with 'run'")
            restart = .true.
         case default
            if (arg(1:1) == '-' .or. allocated(path)) call usage("unexpected argument '"//trim(arg)//"'")
            path = trim(arg)
         end select
         i = i + 1
      end do
      if (.not. allocated(path)) call usage('missing namelist file')
   end subroutine parse_arguments

   !> The help (on stdout), or a problem and the help on stderr with exit status 2.
   subroutine usage(problem)
      character(len=*), intent(in), optional :: problem
      integer :: unit, k
      unit = output_unit
      if (present(problem)) then
         unit = error_unit
         write (unit, '(a)') 'beamstops: '//problem
      end if
      write (unit, '(a)') 'usage: beamstops COMMAND [ARGUMENTS]', '', &
         & 'commands of the engine:', &
         & '  run FILE.nml [-o OUT.h5] [--restart]', &
         & '                  run a scene, write its HDF5 output (OUT.h5.partial until the run is done);', &
         & '                  with --restart, continue from the last checkpoint (&output checkpoint_every)', &
         & '  info FILE.nml   print the scene, kappa_h, stability limits and cost, without running', &
         & 'commands of the Python package (python -m beamstops of this environment; COMMAND --help):'
      do k = 1, n_python_commands
         write (unit, '(a)') '  '//python_commands(k)//'  '//trim(python_help(k))
      end do
      write (unit, '(a)') '  --version       print the version', &
         & 'exit statuses: 0 success, 1 bad input, 2 bad command line (or no Python for its commands),', &
         & '  3 the run diverged or failed, 4 the output could not be written or would destroy a file'
      if (present(problem)) call quit(exit_usage)
      stop
   end subroutine usage

   !> Replace this process (execv) by the Python of the program's environment running the
   !> subcommand with its arguments, so that its exit status and signals are the command's:
   !> the `python` (or `python3`) beside the program's executable, else `python3` on PATH.
   subroutine hand_to_python()
      type(c_string), allocatable, target :: strings(:)
      type(c_ptr), allocatable :: argv(:)
      character(len=:), allocatable :: folder, python
      integer(c_int) :: status
      integer :: n, k, length
      n = command_argument_count()
      allocate (strings(n + 3), argv(n + 4))
      call set_string(strings(2), '-c')
      call set_string(strings(3), bootstrap)
      do k = 1, n
         call get_command_argument(k, length=length)
         block
            character(len=length) :: arg
            if (length > 0) call get_command_argument(k, arg)
            call set_string(strings(k + 3), arg)
         end block
      end do
      folder = program_folder()
      if (len(folder) > 0) then
         do k = 1, 2
            python = folder//'/'//trim(merge('python ', 'python3', k == 1))
            if (.not. file_exists(python)) cycle
            call set_string(strings(1), python)
            call set_argv(strings, argv)
            status = c_execv(python//c_null_char, argv)
         end do
      end if
      call set_string(strings(1), 'python3')
      call set_argv(strings, argv)
      status = c_execvp('python3'//c_null_char, argv)
      write (error_unit, '(a)') 'beamstops: error: '''//command//''' is a command of the beamstops Python '// &
         & 'package, and there is no Python to run it (no python beside '//folder//', no python3 on PATH); '// &
         & 'install the package with pip install . and use its beamstops program'
      call quit(exit_usage)

   end subroutine hand_to_python

   !> execv's argument vector: the addresses of `strings`, then a null pointer.
   subroutine set_argv(strings, argv)
      type(c_string), intent(in), target :: strings(:)
      type(c_ptr), intent(out) :: argv(:)
      integer :: j
      do j = 1, size(strings)
         argv(j) = c_loc(strings(j)%text)
      end do
      argv(size(argv)) = c_null_ptr
   end subroutine set_argv

   !> A NUL-terminated copy of `text`.
   subroutine set_string(string, text)
      type(c_string), intent(inout) :: string
      character(len=*), intent(in) :: text
      integer :: j
      if (allocated(string%text)) deallocate (string%text)
      allocate (string%text(len(text) + 1))
      do j = 1, len(text)
         string%text(j) = text(j:j)
      end do
      string%text(len(text) + 1) = c_null_char
   end subroutine set_string

   !> The folder of the program's executable (/proc/self/exe, else the command's own path);
   !> '' when unknown.
   function program_folder() result(folder)
      character(len=:), allocatable :: folder
      character(kind=c_char) :: buffer(4096)
      character(len=4096) :: path
      integer(c_long) :: length
      integer :: j, slash
      length = c_readlink('/proc/self/exe'//c_null_char, buffer, int(size(buffer), c_size_t))
      if (length > 0 .and. length < size(buffer)) then
         path = ''
         do j = 1, int(length)
            path(j:j) = buffer(j)
         end do
      else
         call get_command_argument(0, path)
      end if
      slash = index(path, '/', back=.true.)
      folder = path(:max(0, slash - 1))
      if (slash == 1) folder = '/'
   end function program_folder

   subroutine stop_on(error, status)
      type(error_type), allocatable, intent(in) :: error
      integer, intent(in) :: status
      if (.not. allocated(error)) return
      write (error_unit, '(a)') 'beamstops: error: '//error%message
      call quit(status)
   end subroutine stop_on

   !> End the program with an exit status, without a runtime traceback and without the HDF5
   !> library's exit handler (which must not touch a file whose writes failed; every file that
   !> was written correctly is closed by then).
   subroutine quit(status)
      integer, intent(in) :: status
      flush (output_unit)
      flush (error_unit)
      call c_exit(int(status, c_int))
   end subroutine quit

   !> A write beyond the file-size limit (ulimit -f) kills the process with SIGXFSZ; ignored, the
   !> write fails with EFBIG instead, and the run ends with a message like any failed write.
   subroutine ignore_file_size_signal()
      type(c_funptr) :: previous
      previous = c_signal(sigxfsz, transfer(sig_ign, c_null_funptr))
   end subroutine ignore_file_size_signal

   !> Run a scene into its HDF5 output. The output path is checked before anything is written
   !> (not the input, not a file other than a beamstops output); the run writes OUT.partial
   !> and the recorder renames it onto OUT when the run went to its end (complete or diverged).
   !> With `restart`, the partial file continues from the checkpoint OUT.checkpoint.
   subroutine run_to_file(scene, model, input, restart)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      character(len=*), intent(in) :: input
      logical, intent(in) :: restart
      type(hdf5_recorder) :: recorder
      type(run_summary) :: summary
      type(state_type) :: state
      type(reduced_model_type) :: reduced
      type(reduced_state_type) :: reduced_state
      type(error_type), allocatable :: error, write_error, finish_error
      character(len=:), allocatable :: output, partial, checkpoint
      integer(ik) :: records, snapshots
      logical :: resume
      if (scene%modes > 0) then
         ! The reduced (Craig-Bampton) model, before anything is written.
         call build_reduced(scene, model, reduced, error)
         call stop_on(error, exit_input)
         call check_stability_reduced(scene, reduced, input, error)
         call stop_on(error, exit_input)
      end if
      output = scene%output_file
      partial = partial_path(output)
      checkpoint = checkpoint_path(output)
      call check_output_path(output, input, error)
      call stop_on(error, exit_output)
      if (file_exists(checkpoint) .and. .not. is_checkpoint(checkpoint)) then
         call fatal_error(error, checkpoint//': exists and is not a beamstops checkpoint; refusing to overwrite it '// &
            & '(move it away)')
         call stop_on(error, exit_output)
      end if
      resume = .false.
      if (restart) then
         if (.not. file_exists(checkpoint)) then
            write (error_unit, '(a)') 'beamstops: no checkpoint '//checkpoint//': starting from t = 0'
         else if (.not. file_exists(partial)) then
            write (error_unit, '(a)') 'beamstops: no '//partial//' (the output of the interrupted run): '// &
               & 'starting from t = 0'
         else
            resume = .true.
         end if
      end if
      if (resume) then
         if (scene%modes > 0) then
            call read_reduced_checkpoint(checkpoint, scene, reduced, reduced_state, records, snapshots, error)
         else
            call read_checkpoint(checkpoint, scene, model, state, records, snapshots, error)
         end if
         call stop_on(error, exit_input)
         call recorder%reopen(output, scene, model, records, snapshots, error)
         call stop_on(error, exit_output)
      else
         call remove_file(checkpoint)
         call recorder%open(output, scene, model, error)
         call stop_on(error, exit_output)
      end if
      recorder%show_progress = c_isatty(2_c_int) == 1
      if (.not. resume) then
         if (scene%modes > 0) then
            call start_reduced(scene, reduced, reduced_state, recorder, error)
         else
            call start_state(scene, model, state, recorder, error)
         end if
      end if
      if (allocated(error)) then
         summary%status = status_failed
         summary%message = error%message
      else if (scene%modes > 0) then
         call continue_reduced(scene, reduced, reduced_state, recorder, summary, write_error, checkpoint)
      else
         call continue_run(scene, model, state, recorder, summary, write_error, checkpoint)
      end if
      call recorder%finish(summary, finish_error)
      call stop_on(error, exit_input)
      if (allocated(write_error)) call stop_on_write(write_error, output)
      if (allocated(finish_error)) call stop_on_write(finish_error, output)
      if (summary%status == status_complete .or. summary%status == status_diverged) call remove_file(checkpoint)
      write (output_unit, '(a)') summary_line(scene, summary)
      if (summary%status == status_diverged) then
         write (error_unit, '(a)') 'beamstops: error: '//output//': run diverged: '//summary%message
         call quit(exit_diverged)
      else if (summary%status /= status_complete) then
         write (error_unit, '(a)') 'beamstops: error: '//output//': run '//summary%status//': '// &
            & summary%message//'; '//output//' is left as it was, the run so far is in '//partial
         call quit(exit_diverged)
      end if
   end subroutine run_to_file

   !> A write failed: one message, exit status 4; the output is untouched.
   subroutine stop_on_write(failure, output)
      type(error_type), intent(in) :: failure
      character(len=*), intent(in) :: output
      write (error_unit, '(a)') 'beamstops: error: '//failure%message//'; '//output//' is left as it was'
      call quit(exit_output)
   end subroutine stop_on_write

   function summary_line(scene, summary) result(line)
      type(scene_type), intent(in) :: scene
      type(run_summary), intent(in) :: summary
      character(len=:), allocatable :: line
      character(len=768) :: buf
      write (buf, '(a,": ",i0," steps, ",f0.3," s CPU (",f0.3," us/step), ",i0," impacts (",i0,' // &
         & '" contact phases), largest violation ",' // &
         & 'es9.3," m; energy (J): support work ",es10.3,", stops ",es10.3,", damping ",es10.3,' // &
         & '", balance residual ",es9.2,"; status ",a)') scene%output_file, summary%steps, summary%cpu_seconds, &
         & 1.0e6_wp*summary%cpu_seconds/max(1_ik, summary%steps), summary%impacts, summary%contact_phases, &
         & summary%max_violation, summary%work, summary%dissipated, summary%damped, summary%energy_residual, &
         & summary%status
      line = trim(buf)//headline(summary)
   end function summary_line

   !> The headline statistics after the transient, with their 95 % intervals: shocks per second,
   !> power the stops take, impulse rate, RMS tip displacement (first stop).
   function headline(summary) result(text)
      type(run_summary), intent(in) :: summary
      character(len=:), allocatable :: text
      character(len=*), parameter :: names(4) = [character(len=17) :: 'shocks_per_second', 'power', &
         & 'impulse_rate', 'tip_rms']
      character(len=96) :: buf
      integer :: i, k
      text = ''
      if (.not. allocated(summary%statistics%quantity)) return
      text = new_line('a')//'statistics (95 % intervals):'
      do i = 1, size(names)
         k = summary%statistics%find(trim(names(i)))
         if (k == 0) cycle
         associate (q => summary%statistics%quantity(k))
            write (buf, '(1x,a,1x,es10.4," +- ",es8.2,1x,a)') trim(names(i)), q%value(1), q%half_width(1), q%unit
         end associate
         text = text//trim(buf)//';'
      end do
      if (summary%ensemble_members < 2 .or. .not. allocated(summary%ensemble%quantity)) return
      write (buf, '(i0)') summary%ensemble_members
      text = text//new_line('a')//'across '//trim(buf)//' members (95 %):'
      do i = 1, size(names)
         k = summary%ensemble%find(trim(names(i)))
         if (k == 0) cycle
         associate (q => summary%ensemble%quantity(k))
            write (buf, '(1x,a,1x,es10.4," +- ",es8.2,1x,a)') trim(names(i)), q%value(1), q%half_width(1), q%unit
         end associate
         text = text//trim(buf)//';'
      end do
   end function headline

   subroutine print_info(scene, model)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      character(len=*), parameter :: f = '(a,t24,es13.6,1x,a)', fi = '(a,t24,i0,1x,a)', fa = '(a,t24,a)'
      integer :: i
      write (output_unit, fa) 'file', path
      write (output_unit, f) '&beam length', scene%length, 'm'
      write (output_unit, f) '      k2', scene%k2, 'm^4/s^2'
      write (output_unit, f) '      mass_per_length', scene%mass_per_length, 'kg/m'
      write (output_unit, f) '&support amplitude', scene%amplitude, 'm'
      write (output_unit, f) '      omega', scene%omega, 'rad/s'
      if (stop_count(scene) == 0) then
         write (output_unit, f) '&stops lower', scene%lower, 'm'
         write (output_unit, f) '      upper', scene%upper, 'm'
      else
         write (output_unit, fi) '&stops stops', stop_count(scene), 'along the span (node, x, lower, upper):'
         do i = 1, stop_count(scene)
            write (output_unit, '(t9,i8,3(1x,es13.6))') scene%stop_nodes(i), model%stops%x(i), scene%stop_lower(i), &
               & scene%stop_upper(i)
         end do
      end if
      write (output_unit, fa) '      law', law_name(scene%law)
      if (scene%law == law_compliance) write (output_unit, f) '      stiffness_per_mass', scene%stiffness_per_mass, &
         & '1/s^2'
      write (output_unit, f) '      restitution', scene%restitution, ''
      write (output_unit, fa) '      mass', trim(merge('redistributed', 'consistent   ', scene%redistributed_mass))
      if (scene%damping_by_ratio) write (output_unit, '(a,t24,2(es13.6,1x),a,2(1x,i0))') '&damping ratio', &
         & scene%damping_ratio, 'at modes', scene%damping_modes
      write (output_unit, f) '      a (C = a M + b S)', model%damping_a, '1/s'
      write (output_unit, f) '      b', model%damping_b, 's'
      write (output_unit, fi) '&mesh elements', scene%elements, ''
      write (output_unit, f) '&time dt', scene%dt, 's'
      write (output_unit, f) '      t_end', scene%t_end, 's'
      write (output_unit, f) '      beta', scene%beta, ''
      write (output_unit, fa) '      load_rule', trim(merge('centered', 'paper   ', scene%centered_load))
      write (output_unit, fa) '      start', trim(merge('taylor', 'euler ', scene%taylor_start))
      write (output_unit, fa) '&output file', scene%output_file
      write (output_unit, fi) 'unknowns n', model%n, ''
      write (output_unit, f) 'kappa_h', model%kappa_h, '1/s^2 ('//model%kappa_method//')'
      write (output_unit, f) 'kappa_bound (5.2)', model%kappa_bound, '1/s^2'
      if (scene%law == law_compliance) write (output_unit, f) 'kappa with spring', model%kappa_contact, '1/s^2'
      write (output_unit, f) 'dt limit Newmark', model%dt_newmark, 's (2/sqrt((1-4 beta) kappa), beta < 1/4)'
      write (output_unit, f) 'dt limit (3.1) exact', model%dt_paper_exact, 's (2/sqrt((1-2 beta) kappa_h))'
      write (output_unit, f) 'dt limit (3.1) bound', model%dt_paper_bound, 's (2/sqrt((1-2 beta) kappa_bound))'
      write (output_unit, fi) 'steps', steps_of(scene), ''
      write (output_unit, fi) 'records', record_count(scene), ''
      write (output_unit, fi) 'snapshots', snapshot_count(scene), ''
      write (output_unit, f) 'output size', output_bytes(scene)/1.0e6_wp, 'MB'
      write (output_unit, fa) 'energy ledger', 'support work /energy/work, stops /energy/dissipated, damping '// &
         & '/energy/damped (J, cumulative); balance residual E - E(0) - (work - stops - damping) in the summary'
   end subroutine print_info
end program beamstops_main
