!> The discrete energy balance of SPEC 6: E^{n+1/2} - E^{1/2} = W_n - D_n, with D_n the
!> energy taken by the stops, nondecreasing for the Signorini scheme.
module test_energy
   use testing
   use test_support, only: run_recorded, base_scene
   use beamstops, only: ik, scene_type, array_recorder, run_summary, law_none, law_signorini, law_compliance
   use beamstops_recorder, only: col_t, col_energy, col_work, col_dissipated
   implicit none
   private
   public :: collect_energy

contains

   !> Tests of the suite.
   subroutine collect_energy(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('no stops, beta = 1/4, J = 8: E_n - E_0 = W_n within 1e-12', test_free_8), &
         & new_unittest('no stops, beta = 1/4, J = 19: E_n - E_0 = W_n within 1e-10', test_free_19), &
         & new_unittest('Signorini, beta = 1/2, J = 19: dissipated >= 0, nondecreasing', test_signorini_dissipation), &
         & new_unittest('Signorini, beta = 1/2: balance, J = 8 within 1e-12, J = 19 within 1e-10', test_signorini_balance), &
         & new_unittest('compliance 1e8, beta = 1/4, dt = 5e-6: balance, J = 8 within 1e-12, J = 19 within 1e-10', &
         &              test_compliance) &
         & ]
   end subroutine collect_energy

   ! The balance E^{n+1/2} - E^{1/2} = W_n - D_n is an identity of the scheme for every beta,
   ! mesh and contact law; what is left is the round-off of E = 1/2 d.M d/dt^2 + ... u.S u,
   ! evaluated afresh at each record (it does not accumulate). S has entries ~ k2/h^3, so the
   ! round-off grows like J^3: 5e-14 (J = 4), 4e-13 (J = 8), 2e-12 (J = 12) and 1.2e-11 (J = 19)
   ! of max |E| measured on the free run. Hence 1e-12 at J = 8 and 1e-10 at J = 19.

   !> max over the records of |(E_n - E_0) - (W_n - D_n)| / max |E| must be <= thr.
   subroutine check_balance(rec, what, thr, error)
      type(array_recorder), intent(in) :: rec
      character(len=*), intent(in) :: what
      real(wp), intent(in) :: thr
      type(error_type), allocatable, intent(inout) :: error
      real(wp) :: scale, worst, defect
      integer(ik) :: j, at
      scale = maxval(abs(rec%rows(col_energy, 1:rec%filled)))
      worst = 0
      at = 1
      do j = 1, rec%filled
         defect = abs((rec%rows(col_energy, j) - rec%rows(col_energy, 1)) &
            & - (rec%rows(col_work, j) - rec%rows(col_dissipated, j)))
         if (defect > worst) then
            worst = defect
            at = j
         end if
      end do
      call note(what//': max |E| = '//real_text(scale)//' J, worst balance defect '//real_text(worst)// &
         & ' J (relative '//real_text(worst/scale)//') at t = '//real_text(rec%rows(col_t, at)))
      call check(error, worst/scale, 0.0_wp, what//': balance defect / max |E| at t = '//real_text(rec%rows(col_t, at)), &
         & thr=thr)
   end subroutine check_balance

   !> Run a scene and check its balance.
   subroutine balance_case(scene, what, thr, error)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: what
      real(wp), intent(in) :: thr
      type(error_type), allocatable, intent(out) :: error
      type(array_recorder) :: rec
      type(run_summary) :: summary
      call run_recorded(scene, rec, summary, error)
      if (allocated(error)) return
      if (scene%law == law_none) then
         call check(error, maxval(abs(rec%rows(col_dissipated, 1:rec%filled))), 0.0_wp, what//': nothing dissipated')
         if (allocated(error)) return
      else
         call check(error, summary%impacts > 0, what//': the stops are reached')
         if (allocated(error)) return
      end if
      call check(error, maxval(abs(rec%rows(col_work, 1:rec%filled))) > 0, what//': the support does work')
      if (allocated(error)) return
      call check_balance(rec, what, thr, error)
   end subroutine balance_case

   !> Run a scene on J = 8 and on J = 19 and check its balance within the round-off bound of
   !> each mesh (1e-12 and 1e-10, above).
   subroutine balance_on_both_meshes(law, beta, dt, t_end, what, error)
      integer, intent(in) :: law
      real(wp), intent(in) :: beta, dt, t_end
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      call balance_case(base_scene(8, dt, beta, law, t_end), what//', J = 8', 1e-12_wp, error)
      if (allocated(error)) return
      call balance_case(base_scene(19, dt, beta, law, t_end), what//', J = 19', 1e-10_wp, error)
   end subroutine balance_on_both_meshes

   subroutine test_free_8(error)
      type(error_type), allocatable, intent(out) :: error
      call balance_case(base_scene(8, 5e-5_wp, 0.25_wp, law_none, 2.0_wp), 'law none, J = 8', 1e-12_wp, error)
   end subroutine test_free_8

   subroutine test_free_19(error)
      type(error_type), allocatable, intent(out) :: error
      call balance_case(base_scene(19, 5e-5_wp, 0.25_wp, law_none, 2.0_wp), 'law none, J = 19', 1e-10_wp, error)
   end subroutine test_free_19

   subroutine test_signorini_dissipation(error)
      type(error_type), allocatable, intent(out) :: error
      type(array_recorder) :: rec
      type(run_summary) :: summary
      real(wp) :: increment, smallest
      integer(ik) :: j
      call run_recorded(base_scene(19, 5e-5_wp, 0.5_wp, law_signorini, 2.0_wp), rec, summary, error)
      if (allocated(error)) return
      call check(error, summary%impacts > 0, 'impacts > 0'); if (allocated(error)) return
      smallest = huge(1.0_wp)
      do j = 2, rec%filled
         increment = rec%rows(col_dissipated, j) - rec%rows(col_dissipated, j - 1)
         smallest = min(smallest, increment)
         call check(error, increment >= -1e-13_wp, 'dissipated decreases by '//real_text(-increment)// &
            & ' J at t = '//real_text(rec%rows(col_t, j)))
         if (allocated(error)) return
         call check(error, rec%rows(col_dissipated, j) >= 0, 'dissipated '//real_text(rec%rows(col_dissipated, j))// &
            & ' < 0 at t = '//real_text(rec%rows(col_t, j)))
         if (allocated(error)) return
      end do
      call note('Signorini: impacts '//int_text(summary%impacts)//', dissipated at T '// &
         & real_text(rec%rows(col_dissipated, rec%filled))//' J, smallest increment '//real_text(smallest)//' J')
      call check(error, rec%rows(col_dissipated, rec%filled) > 0, 'the stops take energy')
   end subroutine test_signorini_dissipation

   subroutine test_signorini_balance(error)
      type(error_type), allocatable, intent(out) :: error
      call balance_on_both_meshes(law_signorini, 0.5_wp, 5e-5_wp, 2.0_wp, 'Signorini', error)
   end subroutine test_signorini_balance

   subroutine test_compliance(error)
      type(error_type), allocatable, intent(out) :: error
      call balance_on_both_meshes(law_compliance, 0.25_wp, 5e-6_wp, 0.3_wp, 'compliance', error)
   end subroutine test_compliance
end module test_energy
