!> The Fortran unit tests: `tester SUITE` runs one suite and prints TAP;
!> the exit status is non-zero when a test fails.
program tester
   use, intrinsic :: iso_fortran_env, only: error_unit
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
   use test_lockstep, only: collect_lockstep
   implicit none
   character(len=64) :: suite
   type(unittest_type), allocatable :: tests(:)
   integer :: failures

   if (command_argument_count() /= 1) then
      write (error_unit, '(a)') 'usage: tester SUITE (harness, hermite, eigen, projection, energy, order, scheme, namelist, box_qp, stops, lockstep)'
      error stop 2
   end if
   call get_command_argument(1, suite)
   select case (trim(suite))
   case ('harness'); call collect_harness(tests)
   case ('hermite'); call collect_hermite(tests)
   case ('eigen'); call collect_eigen(tests)
   case ('projection'); call collect_projection(tests)
   case ('energy'); call collect_energy(tests)
   case ('order'); call collect_order(tests)
   case ('scheme'); call collect_scheme(tests)
   case ('namelist'); call collect_namelist(tests)
   case ('box_qp'); call collect_box_qp(tests)
   case ('stops'); call collect_stops(tests)
   case ('lockstep'); call collect_lockstep(tests)
   case default
      write (error_unit, '(a)') 'tester: unknown suite '''//trim(suite)//''''
      error stop 2
   end select
   failures = run_suite(trim(suite), tests)
   if (failures > 0) error stop 1
end program tester
