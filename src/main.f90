!> The `beamstops` command-line program:
!>   beamstops run FILE.nml [-o OUT.h5] [--restart]   run a scene (or resume it from its last
!>                                        checkpoint), write its HDF5 file, print a summary
!>   beamstops run A.nml B.nml ... [--restart]   run several scenes, the ones that share A in
!>                                        lockstep (beamstops_batch), each into its own file
!>   beamstops info FILE.nml              print the scene, its discretization and limits
!>   beamstops plot | sweep | converge | ... ARGS   the subcommands of `python -m beamstops`,
!>                                        handed (execv) to the Python of the program's environment
program beamstops_main
   use, intrinsic :: iso_c_binding, only: c_int, c_long, c_size_t, c_intptr_t, c_funptr, c_null_funptr, c_char, &
      & c_null_char, c_ptr, c_null_ptr, c_loc
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use beamstops
   use beamstops_checkpoint, only: checkpoint_path, temporary_path, read_checkpoint, foreign_checkpoint
   use beamstops_files, only: file_exists, remove_file, same_file, same_path, creation_error
   use beamstops_namelist, only: default_output
   use beamstops_recorder_hdf5, only: partial_path, check_output_path
   use beamstops_run, only: continue_run, continue_reduced
   use beamstops_stop_signals, only: caught_signal
   use beamstops_writer_thread, only: writer_thread, start_writer, stop_writer
   use beamstops_batch, only: lockstep_groups, simulate_group, min_group_members
   use beamstops_reduced, only: reduced_model_type, reduce_model
   use beamstops_reduced_scheme, only: reduced_state_type, start_reduced
   use beamstops_reduced_checkpoint, only: read_reduced_checkpoint
   use beamstops_restart_partial, only: check_partial_scene
   use beamstops_lapack, only: openblas_one_thread
   use beamstops_strings, only: fmt_real, fmt_int
   use beamstops_observe_statistics, only: statistics_table
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

   !> A file name of the command line.
   type :: path_type
      character(len=:), allocatable :: text
   end type path_type

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
      & 'plot the HDF5 output of a run (tip, energy, stops, impacts, pdf, psd, all, ...)', &
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
   !> SIGTERM (Linux and the BSDs).
   integer(c_int), parameter :: sigterm = 15_c_int
   integer(c_intptr_t), parameter :: sig_ign = 1_c_intptr_t

   integer, parameter :: exit_input = 1, exit_usage = 2, exit_diverged = 3, exit_output = 4, exit_signal = 128
   character(len=:), allocatable :: command, path, out
   type(path_type), allocatable :: paths(:)
   logical :: restart = .false.
   type(scene_type) :: scene
   type(model_type), target :: model
   !> With &mesh modes > 0, the reduced model the run steps (prepare_run).
   type(reduced_model_type) :: reduced
   type(error_type), allocatable :: error
   !> The HDF5 writes of every run on a thread of their own (beamstops_writer_thread).
   type(writer_thread) :: writer

   call ignore_file_size_signal()
   call parse_arguments(command, paths, out, restart)
   if (command == 'run') then
      call one_blas_thread()
      call start_writer(writer)
   end if
   if (size(paths) > 1) call run_several(paths, restart)
   path = paths(1)%text
   call read_scene(path, scene, error)
   call stop_on(error, exit_input)
   if (allocated(out)) scene%output_file = out
   call prepare_run(scene, path, model, error, reduced)
   call stop_on(error, exit_input)
   select case (command)
   case ('info')
      call print_info(scene, model, run_limit(scene, model, reduced))
   case ('run')
      call quit(run_to_file(scene, model, path, restart, c_isatty(2_c_int) == 1, reduced))
   end select

contains

   subroutine parse_arguments(command, paths, out, restart)
      character(len=:), allocatable, intent(out) :: command, out
      type(path_type), allocatable, intent(out) :: paths(:)
      type(path_type) :: item
      logical, intent(inout) :: restart
      character(len=4096) :: arg
      integer :: i, n
      allocate (paths(0))
      n = command_argument_count()
      if (n < 1) call usage('missing command')
      call get_command_argument(1, arg)
      command = trim(arg)
      select case (command)
      case ('-h', '--help', 'help')
         call no_more_arguments(command)
         call usage()
      case ('-V', '--version', 'version')
         call no_more_arguments(command)
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
            if (allocated(out)) call usage("'-o' is given twice (one output: the last would have won)")
            call get_command_argument(i + 1, arg)
            if (len_trim(arg) == 0) call usage("'-o' takes a file name; it was given an empty one")
            if (trim(arg) == '-') call usage("'-o -': beamstops cannot write its output to standard output (an "// &
               & "HDF5 file is written in place, and renamed when the run is done); name a file (-o ./- for a "// &
               & "file named -)")
            out = trim(arg)
            i = i + 1
         case ('-h', '--help')
            ! `beamstops run --help`, `beamstops info -h`: the help, as `beamstops --help` gives it
            call usage()
         case ('--restart')
            if (command /= 'run') call usage("'--restart' goes with 'run'")
            if (restart) call usage("'--restart' is given twice; allowed: once")
            restart = .true.
         case default
            if (arg(1:1) == '-' .or. (command /= 'run' .and. size(paths) > 0)) &
               & call usage("unexpected argument '"//trim(arg)//"'")
            item%text = trim(arg)
            paths = [paths, item]
         end select
         i = i + 1
      end do
      if (size(paths) == 0) call usage('missing namelist file')
      if (size(paths) > 1 .and. allocated(out)) call usage("'-o' names the output of one scene; with several "// &
         & 'namelist files each scene writes its own (&output file; default: the input''s name with .h5)')
   end subroutine parse_arguments

   !> Refuse arguments after `command`, which takes none (--help, --version).
   subroutine no_more_arguments(command)
      character(len=*), intent(in) :: command
      character(len=4096) :: arg
      if (command_argument_count() < 2) return
      call get_command_argument(2, arg)
      call usage("unexpected argument '"//trim(arg)//"' after '"//command//"', which takes none")
   end subroutine no_more_arguments

   !> The help (on stdout), or one line on stderr naming the problem, with exit status 2.
   subroutine usage(problem)
      character(len=*), intent(in), optional :: problem
      integer :: k
      if (present(problem)) then
         write (error_unit, '(a)') 'beamstops: '//problem//' (beamstops --help: the commands)'
         call quit(exit_usage)
      end if
      write (output_unit, '(a)') 'usage: beamstops COMMAND [ARGUMENTS]', '', &
         & 'commands of the engine:', &
         & '  run FILE.nml [-o OUT.h5] [--restart]', &
         & '                  run a scene, write its HDF5 output (OUT.h5.partial until the run is done);', &
         & '                  with --restart, continue from the last checkpoint (&output checkpoint_every)', &
         & '  run A.nml B.nml ... [--restart]', &
         & '                  run several scenes, those that share A = M + dt^2 beta S in lockstep, each', &
         & '                  into its own output (&output file); every file is checked before any runs', &
         & '  info FILE.nml   print the scene, kappa_h, stability limits and cost, without running', &
         & 'commands of the Python package (python -m beamstops of this environment; COMMAND --help):'
      do k = 1, n_python_commands
         write (output_unit, '(a)') '  '//python_commands(k)//'  '//trim(python_help(k))
      end do
      write (output_unit, '(a)') '  --version       print the version', &
         & 'exit statuses: 0 success, 1 bad input, 2 bad command line (or no Python for its commands),', &
         & '  3 the run diverged or failed, 4 the output could not be written or would destroy a file,', &
         & '  128 + N when SIGINT (N = 2) or SIGTERM (N = 15) stopped the run (records flushed, a checkpoint', &
         & '  saved: run again with --restart to continue)'
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

   !> One BLAS thread for `run`. A threaded OpenBLAS (Debian's default) starts its pool of threads
   !> when the program loads, and they spin on sched_yield for about 0.1 s of CPU before they
   !> sleep, whatever the program does (perf of a batch of eight 50,000-step sweep points: 0.22 s
   !> of CPU, 0.13 s with OPENBLAS_NUM_THREADS=1; the pool's spin the largest entry). The engine's
   !> LAPACK calls are small, and a sweep's processes share the cores, so unless the user chose
   !> (OPENBLAS_NUM_THREADS or OMP_NUM_THREADS set) the program puts OpenBLAS on one thread and
   !> stops its pool before any work (blas_threads.c; nothing with another BLAS).
   subroutine one_blas_thread()
      integer :: status
      call get_environment_variable('OPENBLAS_NUM_THREADS', status=status)
      if (status /= 1) return
      call get_environment_variable('OMP_NUM_THREADS', status=status)
      if (status /= 1) return
      status = openblas_one_thread()
   end subroutine one_blas_thread

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
      call stop_writer(writer)
      flush (output_unit)
      flush (error_unit)
      call c_exit(int(status, c_int))
   end subroutine quit

   !> Once a signal has stopped a run, a SIGTERM more (a batch system's second, a sweep worker's
   !> beside the one sent to the whole group) does not cut the files' end short.
   subroutine hold_terminate()
      type(c_funptr) :: previous
      previous = c_signal(sigterm, transfer(sig_ign, c_null_funptr))
   end subroutine hold_terminate

   !> A write beyond the file-size limit (ulimit -f) kills the process with SIGXFSZ; ignored, the
   !> write fails with EFBIG instead, and the run ends with a message like any failed write.
   subroutine ignore_file_size_signal()
      type(c_funptr) :: previous
      previous = c_signal(sigxfsz, transfer(sig_ign, c_null_funptr))
   end subroutine ignore_file_size_signal

   !> Run a scene into its HDF5 output; the exit status (0: complete), every problem told on
   !> stderr. The output path is checked before anything is written
   !> (not the input, not a file other than a beamstops output); the run writes OUT.partial
   !> and the recorder renames it onto OUT when the run went to its end (complete or diverged).
   !> With `restart`, the partial file continues from the checkpoint OUT.checkpoint.
   recursive integer function run_to_file(scene, model, input, restart, progress, reduced) result(status)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in), target :: model
      character(len=*), intent(in) :: input
      logical, intent(in) :: restart
      !> Print a progress line on stderr.
      logical, intent(in) :: progress
      !> With &mesh modes > 0, the reduced model the run steps (prepare_run); built here when absent
      !> (the scenes of `run A.nml B.nml ...`, prepared and checked up front without keeping it).
      type(reduced_model_type), intent(in), optional :: reduced
      type(hdf5_recorder), target :: recorder
      type(run_summary) :: summary
      type(state_type) :: state
      type(reduced_model_type) :: built
      type(reduced_state_type) :: reduced_state
      type(error_type), allocatable :: error, write_error, finish_error
      character(len=:), allocatable :: output, partial, checkpoint
      integer(ik) :: records, snapshots
      logical :: resume
      status = 0
      if (scene%modes > 0 .and. .not. present(reduced)) then
         call reduce_model(scene, model, input, built, error)
         if (reported(error, exit_input, status)) return
         status = run_to_file(scene, model, input, restart, progress, built)
         return
      end if
      recorder%writer = writer
      output = scene%output_file
      partial = partial_path(output)
      checkpoint = checkpoint_path(output)
      call check_outputs(scene, input, error)
      if (reported(error, exit_output, status)) return
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
         if (reported(error, exit_input, status)) return
         call check_partial_scene(partial, scene, error)
         if (reported(error, exit_input, status)) return
         call recorder%reopen(output, scene, model, records, snapshots, error)
         if (reported(error, exit_output, status)) return
      else
         ! the checkpoint of an earlier run goes once the recorder holds the partial file
         call recorder%open(output, scene, model, error)
         if (reported(error, exit_output, status)) return
         call remove_file(checkpoint)
      end if
      recorder%show_progress = progress
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
         call continue_reduced(scene, reduced, reduced_state, recorder, summary, write_error, checkpoint, .true.)
      else
         call continue_run(scene, model, state, recorder, summary, write_error, checkpoint, .true.)
      end if
      if (summary%status == status_interrupted) call hold_terminate()
      call recorder%finish(summary, finish_error)
      status = run_outcome(scene, input, summary, error, write_error, finish_error)
   end function run_to_file

   !> An error when `beamstops run --restart` could not resume a scene from its checkpoint and
   !> partial file (read_checkpoint's or read_reduced_checkpoint's, check_partial_scene's), so that
   !> `run A.nml B.nml ... --restart` refuses them all before any runs.
   subroutine check_resume(scene, model, input, error)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      character(len=*), intent(in) :: input
      type(error_type), allocatable, intent(out) :: error
      type(state_type) :: state
      type(reduced_model_type) :: reduced
      type(reduced_state_type) :: reduced_state
      integer(ik) :: records, snapshots
      if (scene%modes > 0) then
         call reduce_model(scene, model, input, reduced, error)
         if (.not. allocated(error)) call read_reduced_checkpoint(checkpoint_path(scene%output_file), scene, reduced, &
            & reduced_state, records, snapshots, error)
      else
         call read_checkpoint(checkpoint_path(scene%output_file), scene, model, state, records, snapshots, error)
      end if
      if (.not. allocated(error)) call check_partial_scene(partial_path(scene%output_file), scene, error)
   end subroutine check_resume

   !> Refuse, before anything is written, the output of a scene that the run cannot write or that
   !> would destroy data (check_output_path), what the run may not write at its checkpoint or the
   !> checkpoint's temporary file (the input file, a symbolic link, anything but a regular file, a
   !> file other than a beamstops checkpoint: foreign_checkpoint; a checkpoint is saved on SIGINT
   !> or SIGTERM even without checkpoint_every), and with checkpoint_every > 0 a checkpoint the
   !> system will not let the run create; the messages say where the output's name came from
   !> (output_origin).
   subroutine check_outputs(scene, input, error)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: input
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: origin, checkpoint, why, named
      origin = output_origin(scene, input)
      call check_output_path(scene%output_file, input, origin, error)
      if (allocated(error)) return
      named = scene%output_file//' ('//origin//'): '
      checkpoint = checkpoint_path(scene%output_file)
      why = foreign_checkpoint(checkpoint, input, temporary=.false.)
      if (len(why) > 0) then
         call fatal_error(error, named//checkpoint//', where the run saves its checkpoints, '//why// &
            & '; refusing to overwrite it (move it away)')
         return
      end if
      why = foreign_checkpoint(temporary_path(checkpoint), input, temporary=.true.)
      if (len(why) > 0) then
         call fatal_error(error, named//temporary_path(checkpoint)//', where the run writes a checkpoint before '// &
            & 'it moves it into place, '//why//'; refusing to overwrite it (move it away)')
         return
      end if
      if (scene%checkpoint_every == 0) return
      why = creation_error(temporary_path(checkpoint))
      if (len(why) > 0) call fatal_error(error, named//'cannot create '// &
         & temporary_path(checkpoint)//', where the run saves its checkpoints (&output checkpoint_every): '//why)
   end subroutine check_outputs

   !> Where the output name of a scene came from: -o, or the &output file of its input (whose
   !> default is the input's name with .h5).
   function output_origin(scene, input) result(origin)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: input
      character(len=:), allocatable :: origin
      if (allocated(out)) then
         origin = '-o'
      else if (scene%output_file == default_output(input)) then
         origin = '&output file of '//input//', by default the input''s name with .h5'
      else
         origin = '&output file of '//input
      end if
   end function output_origin

   !> The end of a run whose recorder is finished: the messages, the summary line and the exit
   !> status (0 complete, 1 the run could not start, 3 diverged or failed, 4 a write failed).
   integer function run_outcome(scene, input, summary, start_error, write_error, finish_error) result(status)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: input
      type(run_summary), intent(in) :: summary
      type(error_type), allocatable, intent(in) :: start_error, write_error, finish_error
      character(len=:), allocatable :: output, again
      status = 0
      output = scene%output_file
      if (reported(start_error, exit_input, status)) return
      if (allocated(write_error)) then
         status = write_failed(write_error, output)
         return
      end if
      if (allocated(finish_error)) then
         status = write_failed(finish_error, output)
         return
      end if
      if (summary%status == status_complete .or. summary%status == status_diverged) &
         & call remove_file(checkpoint_path(output))
      write (output_unit, '(a)') summary_line(scene, summary)
      if (summary%status == status_diverged) then
         write (error_unit, '(a)') 'beamstops: error: '//output//': run diverged: '//summary%message
         status = exit_diverged
      else if (summary%status == status_interrupted) then
         if (file_exists(checkpoint_path(output))) then
            again = 'beamstops run '//input//' --restart continues it'
         else
            again = 'beamstops run '//input//' runs it again'
         end if
         write (error_unit, '(a)') 'beamstops: '//output//': run interrupted: '//summary%message//'; '//output// &
            & ' is left as it was, the run so far is in '//partial_path(output)//'; '//again
         status = exit_signal + caught_signal()
      else if (summary%status /= status_complete) then
         write (error_unit, '(a)') 'beamstops: error: '//output//': run '//summary%status//': '// &
            & summary%message//'; '//output//' is left as it was, the run so far is in '//partial_path(output)
         status = exit_diverged
      end if
   end function run_outcome

   !> A write failed: one message, exit status 4; the output is untouched.
   integer function write_failed(failure, output) result(status)
      type(error_type), intent(in) :: failure
      character(len=*), intent(in) :: output
      write (error_unit, '(a)') 'beamstops: error: '//failure%message//'; '//output//' is left as it was'
      status = exit_output
   end function write_failed

   !> Whether there is an error; if so, it is told on stderr and `status` becomes `code`.
   logical function reported(error, code, status)
      type(error_type), allocatable, intent(in) :: error
      integer, intent(in) :: code
      integer, intent(inout) :: status
      reported = allocated(error)
      if (.not. reported) return
      write (error_unit, '(a)') 'beamstops: error: '//error%message
      status = code
   end function reported

   !> `beamstops run A.nml B.nml ...`: every file read, every scene prepared and every output
   !> path checked before anything runs (one bad file: its message, nothing runs, exit status 1
   !> or 4). The scenes are partitioned into lockstep groups by the engine's rule
   !> (lockstep_groups); a group of at least min_group_members runs in lockstep, the scenes of a
   !> smaller one (a scene that joins no other, too) run alone one after the other (as
   !> `beamstops run FILE.nml`), and each writes its own output exactly as it would alone, with
   !> its summary line. Exit status: 0 when every scene completed, else the largest of the
   !> scenes' statuses (3 diverged or failed, 4 an output could not be written).
   subroutine run_several(paths, restart)
      type(path_type), intent(in) :: paths(:)
      logical, intent(in) :: restart
      type(scene_type), allocatable :: scenes(:)
      type(model_type), allocatable, target :: models(:)
      type(error_type), allocatable :: error
      integer, allocatable :: group(:), status(:), members(:)
      logical, allocatable :: alone(:)
      character(len=:), allocatable :: output
      integer :: i, j, n, g
      logical :: progress
      n = size(paths)
      allocate (scenes(n), models(n), status(n), alone(n))
      do i = 1, n
         call read_scene(paths(i)%text, scenes(i), error)
         if (.not. allocated(error)) call prepare_run(scenes(i), paths(i)%text, models(i), error)
         call refuse_all(error, exit_input, n)
      end do
      do i = 1, n
         output = scenes(i)%output_file
         call check_outputs(scenes(i), paths(i)%text, error)
         do j = 1, n
            if (allocated(error)) exit
            if (j /= i .and. same_file(output, paths(j)%text)) call fatal_error(error, output//': is the input '// &
               & 'file '//paths(j)%text//'; writing the output of '//paths(i)%text//' there would destroy it')
            if (j < i) call check_shared_files(output, paths(i)%text, scenes(j)%output_file, paths(j)%text, error)
         end do
         call refuse_all(error, exit_output, n)
         alone(i) = restart .and. file_exists(checkpoint_path(output)) .and. file_exists(partial_path(output))
         ! the files a scene resumes from are checked before any scene runs, too
         if (alone(i)) call check_resume(scenes(i), models(i), paths(i)%text, error)
         call refuse_all(error, exit_input, n)
      end do
      call lockstep_groups(scenes, models, group, alone)
      block
         integer, allocatable :: sizes(:)
         sizes = [(count(group == g), g=1, maxval(group))]
         write (error_unit, '(a,i0,a,i0,a,i0,a,i0,a)') 'beamstops: ', n, ' scenes: ', &
            & sum(sizes, sizes >= min_group_members), ' in ', count(sizes >= min_group_members), &
            & ' lockstep group(s), ', sum(sizes, sizes < min_group_members), ' alone'
      end block
      progress = c_isatty(2_c_int) == 1
      status = 0
      do g = 1, maxval(group)
         members = pack([(i, i=1, n)], group == g)
         if (size(members) < min_group_members) then
            ! too few to gain from lockstep: one after the other, as alone
            do j = 1, size(members)
               i = members(j)
               status(i) = run_to_file(scenes(i), models(i), paths(i)%text, restart, progress)
               if (status(i) > exit_signal) then
                  ! stopped by SIGINT or SIGTERM: the scenes after it are not started
                  if (count(group > g) + size(members) > j) write (error_unit, '(a,i0,a,i0,a)') 'beamstops: ', &
                     & count(group > g) + size(members) - j, ' of the ', n, ' scenes were not started'
                  call quit(status(i))
               end if
            end do
         else
            call run_group_to_files(scenes, models, paths, members, progress, status)
            if (any(status(members) > exit_signal)) then
               ! a signal stopped the group: the scenes of the groups after it are not started
               if (count(group > g) > 0) write (error_unit, '(a,i0,a,i0,a)') 'beamstops: ', count(group > g), &
                  & ' of the ', n, ' scenes were not started'
               call quit(maxval(status))
            end if
         end if
      end do
      if (any(status /= 0)) write (error_unit, '(a,i0,a,i0,a)') 'beamstops: ', count(status /= 0), ' of ', n, &
         & ' scenes did not complete (messages above)'
      call quit(maxval(status))
   end subroutine run_several

   !> Refuse two scenes of one command whose files meet: the output, the partial output, the
   !> checkpoint or its temporary file of one is one of the other's, however spelt (`out.h5` and
   !> `./out.h5`; `a.h5.partial` as the output of one and the partial output of `a.h5`): one run
   !> would overwrite what the other writes.
   subroutine check_shared_files(output, path, other_output, other_path, error)
      character(len=*), intent(in) :: output, path, other_output, other_path
      type(error_type), allocatable, intent(inout) :: error
      character(len=*), parameter :: kinds(4) = [character(len=27) :: 'output', 'partial output', 'checkpoint', &
         & 'checkpoint''s temporary file']
      integer :: a, b
      do a = 1, size(kinds)
         do b = 1, size(kinds)
            if (allocated(error)) return
            if (.not. same_path(written_file(output, a), written_file(other_output, b))) cycle
            if (a == 1 .and. b == 1) then
               call fatal_error(error, output//': is the output of both '//other_path//' and '//path// &
                  & '; give each scene its own (&output file)')
            else
               call fatal_error(error, written_file(output, a)//': is the '//trim(kinds(a))//' of '//path// &
                  & ' and the '//trim(kinds(b))//' of '//other_path//'; give each scene its own (&output file)')
            end if
         end do
      end do
   end subroutine check_shared_files

   !> The files a run with this output writes: 1 the output, 2 its partial output, 3 its
   !> checkpoint, 4 the checkpoint's temporary file.
   pure function written_file(output, kind) result(path)
      character(len=*), intent(in) :: output
      integer, intent(in) :: kind
      character(len=:), allocatable :: path
      select case (kind)
      case (1)
         path = output
      case (2)
         path = partial_path(output)
      case (3)
         path = checkpoint_path(output)
      case default
         path = temporary_path(checkpoint_path(output))
      end select
   end function written_file

   !> One of n inputs cannot run: its message, and nothing runs.
   subroutine refuse_all(error, code, n)
      type(error_type), allocatable, intent(in) :: error
      integer, intent(in) :: code, n
      if (.not. allocated(error)) return
      write (error_unit, '(a)') 'beamstops: error: '//error%message
      write (error_unit, '(a,i0,a)') 'beamstops: none of the ', n, ' scenes was run'
      call quit(code)
   end subroutine refuse_all

   !> Run the scenes `members` (one lockstep group) into their outputs; status(i) gets scene i's
   !> exit status. A scene whose output cannot be opened fails (4) and the others run; a group
   !> that cannot start runs its scenes one at a time instead.
   subroutine run_group_to_files(scenes, models, paths, members, progress, status)
      type(scene_type), intent(in) :: scenes(:)
      type(model_type), intent(in), target :: models(:)
      type(path_type), intent(in) :: paths(:)
      integer, intent(in) :: members(:)
      logical, intent(in) :: progress
      integer, intent(inout) :: status(:)
      type(hdf5_recorder), allocatable, target :: recorders(:)
      type(run_summary), allocatable :: summaries(:)
      type(error_type), allocatable :: failures(:)
      type(error_type), allocatable :: error, start_error, write_error, finish_error
      logical, allocatable :: opened(:)
      integer, allocatable :: ids(:)
      integer :: k, i
      allocate (recorders(size(members)), opened(size(members)))
      do k = 1, size(members)
         i = members(k)
         recorders(k)%writer = writer
         call recorders(k)%open(scenes(i)%output_file, scenes(i), models(i), error)
         opened(k) = .not. reported(error, exit_output, status(i))
         if (opened(k)) call remove_file(checkpoint_path(scenes(i)%output_file))
      end do
      ids = pack(members, opened)
      if (size(ids) == 0) return
      if (.not. all(opened)) recorders = pack(recorders, opened)
      recorders(1)%show_progress = progress
      allocate (summaries(size(ids)), failures(size(ids)))
      call simulate_group(scenes(ids), models(ids), recorders, summaries, failures, error, stop_signals=.true.)
      if (allocated(error)) then
         write (error_unit, '(a)') 'beamstops: note: '//error%message//'; running these scenes one at a time'
         do k = 1, size(ids)
            summaries(k)%status = status_failed
            summaries(k)%message = error%message
            call recorders(k)%finish(summaries(k), finish_error)
            status(ids(k)) = run_to_file(scenes(ids(k)), models(ids(k)), paths(ids(k))%text, .false., progress)
         end do
         return
      end if
      do k = 1, size(ids)
         if (summaries(k)%status == status_interrupted) call hold_terminate()
      end do
      do k = 1, size(ids)
         i = ids(k)
         if (allocated(write_error)) deallocate (write_error)
         if (allocated(failures(k)%message)) call fatal_error(write_error, failures(k)%message)
         call recorders(k)%finish(summaries(k), finish_error)
         status(i) = run_outcome(scenes(i), paths(i)%text, summaries(k), start_error, write_error, finish_error)
      end do
   end subroutine run_group_to_files

   !> The summary line of a finished run; reals as the engine writes them (at most 4 digits here,
   !> exponents of any size: 1e-118 too).
   function summary_line(scene, summary) result(line)
      type(scene_type), intent(in) :: scene
      type(run_summary), intent(in) :: summary
      character(len=:), allocatable :: line
      character(len=24) :: cpu, per_step
      ! (f0.3 would drop the leading zero: ".003")
      write (cpu, '(f24.3)') summary%cpu_seconds
      write (per_step, '(f24.3)') 1.0e6_wp*summary%cpu_seconds/max(1_ik, summary%steps)
      line = scene%output_file//': '//fmt_int(summary%steps)//' steps, '//trim(adjustl(cpu))//' s CPU ('// &
         & trim(adjustl(per_step))//' us/step), '//fmt_int(summary%impacts)//' impacts ('// &
         & fmt_int(summary%contact_phases)//' contact phases), largest violation '//fmt_real(summary%max_violation, 4)// &
         & ' m; energy (J): support work '//fmt_real(summary%work, 4)//', stops '//fmt_real(summary%dissipated, 4)// &
         & ', damping '//fmt_real(summary%damped, 4)//', balance residual '//fmt_real(summary%energy_residual, 3)// &
         & '; status '//summary%status//headline(summary)
   end function summary_line

   !> The headline statistics after the transient, with their 95 % intervals: shocks per second,
   !> power the stops take, impulse rate (each stop's, in the order of /stops, when there are
   !> several), RMS tip displacement.
   function headline(summary) result(text)
      type(run_summary), intent(in) :: summary
      character(len=:), allocatable :: text
      text = ''
      if (.not. allocated(summary%statistics%quantity)) return
      text = new_line('a')//'statistics (95 % intervals):'//headline_values(summary%statistics)
      if (summary%ensemble_members < 2 .or. .not. allocated(summary%ensemble%quantity)) return
      text = text//new_line('a')//'across '//fmt_int(int(summary%ensemble_members, ik))//' members (95 %):'// &
         & headline_values(summary%ensemble)
   end function headline

   !> ' name value +- half-width unit;' for each headline statistic of a table.
   function headline_values(table) result(text)
      type(statistics_table), intent(in) :: table
      character(len=:), allocatable :: text
      character(len=*), parameter :: names(4) = [character(len=17) :: 'shocks_per_second', 'power', &
         & 'impulse_rate', 'tip_rms']
      integer :: i, j, k
      text = ''
      do i = 1, size(names)
         k = table%find(trim(names(i)))
         if (k == 0) cycle
         associate (q => table%quantity(k))
            text = text//' '//trim(names(i))
            if (size(q%value) > 1) text = text//' of stops 1..'//fmt_int(int(size(q%value), ik))
            do j = 1, size(q%value)
               text = text//trim(merge(' ', ',', j == 1))//' '//fmt_real(q%value(j), 5)//' +- '//fmt_real(q%half_width(j), 3)
            end do
            text = text//' '//q%unit//';'
         end associate
      end do
   end function headline_values

   !> `beamstops info`: the scene as read, its model and the stability limit of the model its run
   !> steps (prepare_run has applied the run's own check to it).
   subroutine print_info(scene, model, limit)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      type(run_limit_type), intent(in) :: limit
      character(len=*), parameter :: fi = '(a,t30,i0,1x,a)', fa = '(a,t30,a)'
      integer :: i
      write (output_unit, fa) 'file', path
      call show('&beam length', scene%length, 'm')
      call show('      k2', scene%k2, 'm^4/s^2')
      call show('      mass_per_length', scene%mass_per_length, 'kg/m')
      call show('&support amplitude', scene%amplitude, 'm')
      call show('      omega', scene%omega, 'rad/s')
      if (stop_count(scene) == 0) then
         call show('&stops lower', scene%lower, 'm')
         call show('      upper', scene%upper, 'm')
      else
         write (output_unit, fi) '&stops stops', stop_count(scene), 'along the span (node, x, lower, upper):'
         do i = 1, stop_count(scene)
            write (output_unit, '(t9,i8,3(1x,a))') scene%stop_nodes(i), fmt_real(model%stops%x(i), 7), &
               & fmt_real(scene%stop_lower(i), 7), fmt_real(scene%stop_upper(i), 7)
         end do
      end if
      write (output_unit, fa) '      law', law_name(scene%law)
      if (scene%law == law_compliance) call show('      stiffness_per_mass', scene%stiffness_per_mass, &
         & '1/s^2')
      call show('      restitution', scene%restitution, '')
      write (output_unit, fa) '      mass', trim(merge('redistributed', 'consistent   ', scene%redistributed_mass))
      if (scene%damping_by_ratio) then
         write (output_unit, '(a,t30,3(a,1x),2(1x,i0))') '&damping ratio', fmt_real(scene%damping_ratio(1), 7), &
            & fmt_real(scene%damping_ratio(2), 7), 'at modes', scene%damping_modes
         call show('      a (C = a M + b S)', model%damping_a, '1/s')
         call show('      b', model%damping_b, 's')
      else
         call show('&damping mass_coefficient', model%damping_a, '1/s (a of C = a M + b S)')
         call show('      stiffness_coefficient', model%damping_b, 's (b)')
      end if
      write (output_unit, fi) '&mesh elements', scene%elements, ''
      write (output_unit, fi) '      modes', scene%modes, trim(merge('(a reduced model: r modes)', &
         & '(0: the full model)       ', scene%modes > 0))
      call show('&time dt', scene%dt, 's')
      call show('      t_end', scene%t_end, 's')
      call show('      beta', scene%beta, '')
      write (output_unit, fa) '      load_rule', trim(merge('centered', 'paper   ', scene%centered_load))
      write (output_unit, fa) '      start', trim(merge('taylor', 'euler ', scene%taylor_start))
      write (output_unit, fa) '      allow_unstable', trim(merge('.true. ', '.false.', scene%allow_unstable))
      write (output_unit, fa) '&output file', scene%output_file
      write (output_unit, fi) '      record_every', scene%record_every, ''
      write (output_unit, fi) '      snapshot_every', scene%snapshot_every, '(0: none)'
      write (output_unit, fi) '      checkpoint_every', scene%checkpoint_every, '(0: none)'
      call show('      max_output_gb', scene%max_output_gb, 'GB')
      write (output_unit, fa) '&statistics enabled', trim(merge('.true. ', '.false.', scene%statistics))
      call show('      transient', scene%transient, 's')
      write (output_unit, fi) '      batches', scene%batches, ''
      write (output_unit, fi) '      bins', scene%bins, ''
      call show('      rest_time', scene%rest_time, 's')
      call show('      histogram_lower', scene%histogram_lower, 'm')
      call show('      histogram_upper', scene%histogram_upper, 'm')
      write (output_unit, fi) '&ensemble members', scene%members, ''
      call show('      perturbation', scene%perturbation, 'm')
      write (output_unit, fi) '      seed', scene%seed, ''
      if (scene%modes > 0) then
         write (output_unit, '(a,t30,i0,a,i0,a)') 'unknowns n', model%n, ' of the full model (the run: a reduced '// &
            & 'model of ', scene%modes, ' modes)'
      else
         write (output_unit, fi) 'unknowns n', model%n, ''
      end if
      call show('kappa_h', model%kappa_h, '1/s^2 ('//model%kappa_method//')')
      call show('kappa_bound (5.2)', model%kappa_bound, '1/s^2')
      if (scene%law == law_compliance) call show('kappa with spring', model%kappa_contact, '1/s^2')
      if (scene%modes > 0 .and. scene%beta < 0.25_wp) call show('kappa of the run', limit%kappa, &
         & '1/s^2 (the '//limit%model//', which the run steps)')
      call show('dt limit Newmark', limit%dt_newmark, 's (2/sqrt((1-4 beta) kappa) of the '// &
         & limit%model//', which the run steps; beta < 1/4)')
      call show('dt limit (3.1) exact', model%dt_paper_exact, 's (2/sqrt((1-2 beta) kappa_h))')
      call show('dt limit (3.1) bound', model%dt_paper_bound, 's (2/sqrt((1-2 beta) kappa_bound))')
      write (output_unit, fi) 'steps', steps_of(scene), ''
      write (output_unit, fi) 'records', record_count(scene), ''
      write (output_unit, fi) 'snapshots', snapshot_count(scene), ''
      call show('output size', output_bytes(scene)/1.0e6_wp, 'MB')
      write (output_unit, fa) 'energy ledger', 'support work /energy/work, stops /energy/dissipated, damping '// &
         & '/energy/damped (J, cumulative); balance residual E - E(0) - (work - stops - damping) in the summary'
   end subroutine print_info

   !> A line of `beamstops info`: the label, then from column 30 the value (at most 7 digits, as
   !> the engine writes reals: exponents of any size) and its unit.
   subroutine show(label, value, unit)
      character(len=*), intent(in) :: label, unit
      real(wp), intent(in) :: value
      write (output_unit, '(a,t30,a)') label, fmt_real(value, 7)//' '//unit
   end subroutine show
end program beamstops_main
