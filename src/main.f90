!> The `beamstops` command-line program:
!>   beamstops run FILE.nml [-o OUT.h5] [--restart]   run a scene (or resume it from its last
!>                                        checkpoint), write its HDF5 file, print a summary
!>   beamstops info FILE.nml              print the scene, its discretization and limits
program beamstops_main
   use, intrinsic :: iso_c_binding, only: c_int
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use beamstops
   use beamstops_checkpoint, only: checkpoint_path, read_checkpoint
   implicit none

   interface
      function c_isatty(fd) bind(c, name='isatty') result(r)
         import :: c_int
         integer(c_int), value :: fd
         integer(c_int) :: r
      end function c_isatty
      subroutine c_exit(status) bind(c, name='exit')
         import :: c_int
         integer(c_int), value :: status
      end subroutine c_exit
   end interface

   integer, parameter :: exit_input = 1, exit_usage = 2, exit_diverged = 3, exit_output = 4
   character(len=:), allocatable :: command, path, out
   logical :: restart = .false.
   type(scene_type) :: scene
   type(model_type) :: model
   type(error_type), allocatable :: error

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
      call run_to_file(scene, model, restart)
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

   subroutine usage(problem)
      character(len=*), intent(in), optional :: problem
      integer :: unit
      unit = output_unit
      if (present(problem)) then
         unit = error_unit
         write (unit, '(a)') 'beamstops: '//problem
      end if
      write (unit, '(a)') 'usage: beamstops run FILE.nml [-o OUT.h5] [--restart]', &
         & '           run a scene, write its HDF5 output; with --restart, continue from the last', &
         & '           checkpoint (&output checkpoint_every) if there is one', &
         & '       beamstops info FILE.nml              print the scene, kappa_h, stability limits, cost', &
         & '       beamstops --version'
      if (present(problem)) call quit(exit_usage)
      stop
   end subroutine usage

   subroutine stop_on(error, status)
      type(error_type), allocatable, intent(in) :: error
      integer, intent(in) :: status
      if (.not. allocated(error)) return
      write (error_unit, '(a)') 'beamstops: error: '//error%message
      call quit(status)
   end subroutine stop_on

   !> End the program with an exit status, without a runtime traceback.
   subroutine quit(status)
      integer, intent(in) :: status
      flush (output_unit)
      flush (error_unit)
      call c_exit(int(status, c_int))
   end subroutine quit

   subroutine run_to_file(scene, model, restart)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(in) :: model
      logical, intent(in) :: restart
      type(hdf5_recorder) :: recorder
      type(run_summary) :: summary
      type(state_type) :: state
      type(error_type), allocatable :: error, finish_error
      integer(ik) :: records, snapshots
      logical :: resume
      resume = .false.
      if (restart) then
         inquire (file=checkpoint_path(scene%output_file), exist=resume)
         if (.not. resume) write (error_unit, '(a)') 'beamstops: no checkpoint '// &
            & checkpoint_path(scene%output_file)//': starting from t = 0'
      end if
      if (resume) then
         call read_checkpoint(checkpoint_path(scene%output_file), scene, model, state, records, snapshots, error)
         call stop_on(error, exit_input)
         call recorder%reopen(scene%output_file, scene, model, records, snapshots, error)
         call stop_on(error, exit_output)
      else
         call recorder%open(scene%output_file, scene, model, error)
         call stop_on(error, exit_output)
      end if
      recorder%show_progress = c_isatty(2_c_int) == 1
      if (resume) then
         call run_scheme(scene, model, state, recorder, summary)
      else
         call simulate(scene, model, recorder, summary, error)
      end if
      if (allocated(error)) then
         summary%status = status_failed
         summary%message = error%message
      end if
      call recorder%finish(summary, finish_error)
      call stop_on(error, exit_input)
      call stop_on(finish_error, exit_output)
      write (output_unit, '(a)') summary_line(scene, summary)
      if (summary%status /= status_complete) then
         write (error_unit, '(a)') 'beamstops: error: '//scene%output_file//': run '//summary%status//': '// &
            & summary%message
         call quit(exit_diverged)
      end if
   end subroutine run_to_file

   function summary_line(scene, summary) result(line)
      type(scene_type), intent(in) :: scene
      type(run_summary), intent(in) :: summary
      character(len=:), allocatable :: line
      character(len=512) :: buf
      write (buf, '(a,": ",i0," steps, ",f0.3," s CPU (",f0.3," us/step), ",i0," impacts, largest violation ",' // &
         & 'es9.3," m, status ",a)') scene%output_file, summary%steps, summary%cpu_seconds, &
         & 1.0e6_wp*summary%cpu_seconds/max(1_ik, summary%steps), summary%impacts, summary%max_violation, &
         & summary%status
      line = trim(buf)
   end function summary_line

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
   end subroutine print_info
end program beamstops_main
