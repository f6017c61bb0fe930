!> The Fortran unit tests: `tester SUITE [TEST]` runs one suite (or one test of it, by its
!> full name) and prints TAP; the exit status is non-zero when a test fails. `tester --list`
!> lists the suites, `tester SUITE --list` the tests of a suite.
!> The suites are named in the table `suites` below; tests/meson.build holds the same list
!> (it derives the sources `test_SUITE.f90` and one `meson test` per suite from it) and
!> registers `tester --check NAME...` with that list, which fails when the two differ.
program tester
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use testing, only: unittest_type, run_suite
   use test_harness, only: collect_harness
   use test_hermite, only: collect_hermite
   use test_eigen, only: collect_eigen
   use test_projection, only: collect_projection
   use test_energy, only: collect_energy
   use test_order, only: collect_order
   use test_namelist, only: collect_namelist
   use test_scheme, only: collect_scheme
   use test_box_qp, only: collect_box_qp
   use test_stops, only: collect_stops
   use test_run, only: collect_run
   use test_shocks, only: collect_shocks
   use test_statistics, only: collect_statistics
   use test_damping, only: collect_damping
   use test_restitution, only: collect_restitution
   use test_redistribution, only: collect_redistribution
   use test_physics_checks, only: collect_physics_checks
   use test_lockstep, only: collect_lockstep
   use test_batch, only: collect_batch
   use test_lockstep_general, only: collect_lockstep_general
   use test_lockstep_span, only: collect_lockstep_span
   use test_reduced, only: collect_reduced
   use test_reduced_physics, only: collect_reduced_physics
   use test_writer, only: collect_writer
   use test_strings, only: collect_strings
   implicit none

   abstract interface
      !> Fills a suite's tests.
      subroutine collect_interface(tests)
         import :: unittest_type
         !> The suite's tests.
         type(unittest_type), allocatable, intent(out) :: tests(:)
      end subroutine collect_interface
   end interface

   !> A named suite and the procedure collecting its tests.
   type :: testsuite_type
      !> Name given on the command line (and to `meson test`).
      character(len=:), allocatable :: name
      !> Collects the suite's tests.
      procedure(collect_interface), pointer, nopass :: collect => null()
   end type testsuite_type

   type(testsuite_type), allocatable :: suites(:)
   type(unittest_type), allocatable :: tests(:)
   character(len=:), allocatable :: suite, test
   integer :: failures, k

   suites = [ &
      & new_testsuite('harness', collect_harness), &
      & new_testsuite('hermite', collect_hermite), &
      & new_testsuite('eigen', collect_eigen), &
      & new_testsuite('projection', collect_projection), &
      & new_testsuite('energy', collect_energy), &
      & new_testsuite('order', collect_order), &
      & new_testsuite('scheme', collect_scheme), &
      & new_testsuite('namelist', collect_namelist), &
      & new_testsuite('strings', collect_strings), &
      & new_testsuite('box_qp', collect_box_qp), &
      & new_testsuite('stops', collect_stops), &
      & new_testsuite('run', collect_run), &
      & new_testsuite('shocks', collect_shocks), &
      & new_testsuite('statistics', collect_statistics), &
      & new_testsuite('damping', collect_damping), &
      & new_testsuite('restitution', collect_restitution), &
      & new_testsuite('redistribution', collect_redistribution), &
      & new_testsuite('physics_checks', collect_physics_checks), &
      & new_testsuite('reduced', collect_reduced), &
      & new_testsuite('reduced_physics', collect_reduced_physics), &
      & new_testsuite('lockstep', collect_lockstep), &
      & new_testsuite('lockstep_general', collect_lockstep_general), &
      & new_testsuite('lockstep_span', collect_lockstep_span), &
      & new_testsuite('batch', collect_batch), &
      & new_testsuite('writer', collect_writer) &
      & ]

   if (command_argument_count() < 1) call usage()
   suite = argument(1)
   if (suite == '--list') then
      do k = 1, size(suites)
         write (output_unit, '(a)') suites(k)%name
      end do
      stop
   end if
   if (suite == '--check') call check_table()
   if (command_argument_count() > 2) call usage()
   k = findloc([(suites(k)%name == suite, k=1, size(suites))], .true., dim=1)
   if (k == 0) then
      write (error_unit, '(a)') 'tester: unknown suite '''//suite//''''
      call usage()
   end if
   call suites(k)%collect(tests)
   if (command_argument_count() == 2) then
      test = argument(2)
      if (test == '--list') then
         do k = 1, size(tests)
            write (output_unit, '(a)') tests(k)%name
         end do
         stop
      end if
      k = findloc([(tests(k)%name == test, k=1, size(tests))], .true., dim=1)
      if (k == 0) then
         write (error_unit, '(a)') 'tester: suite '''//suite//''' has no test '''//test// &
            & ''' (tester '//suite//' --list shows its tests)'
         stop 2
      end if
      tests = tests(k:k)
   end if
   failures = run_suite(suite, tests)
   if (failures > 0) error stop 1

contains

   !> A suite from its name and collector.
   function new_testsuite(name, collect) result(self)
      character(len=*), intent(in) :: name
      procedure(collect_interface) :: collect
      type(testsuite_type) :: self
      self%name = name
      self%collect => collect
   end function new_testsuite

   !> The command-line argument `i`, trimmed.
   function argument(i) result(arg)
      integer, intent(in) :: i
      character(len=:), allocatable :: arg
      integer :: length
      call get_command_argument(i, length=length)
      allocate (character(len=length) :: arg)
      if (length > 0) call get_command_argument(i, arg)
   end function argument

   !> `tester --check NAME...`: the names given (tests/meson.build's list) must be the table's,
   !> in the same order; prints one TAP test.
   subroutine check_table()
      integer :: j
      logical :: same
      same = command_argument_count() - 1 == size(suites)
      if (same) same = all([(argument(j + 1) == suites(j)%name, j=1, size(suites))])
      write (output_unit, '(a)') '1..1'
      if (same) then
         write (output_unit, '(a)') 'ok 1 - tests/meson.build lists the suites of tests/fortran/main.f90'
         stop
      end if
      write (output_unit, '(a)', advance='no') 'not ok 1 - tests/meson.build and tests/fortran/main.f90 list '// &
         & 'different suites; main.f90:'
      do j = 1, size(suites)
         write (output_unit, '(a)', advance='no') ' '//suites(j)%name
      end do
      write (output_unit, '(a)') ''
      stop 1
   end subroutine check_table

   subroutine usage()
      integer :: j
      write (error_unit, '(a)', advance='no') 'usage: tester SUITE [TEST | --list], tester --list; suites:'
      do j = 1, size(suites)
         write (error_unit, '(a)', advance='no') ' '//suites(j)%name
      end do
      write (error_unit, '(a)') ''
      stop 2
   end subroutine usage
end program tester
