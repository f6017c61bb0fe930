!> The convergence study of SPEC 10 on the paper's scene (J = 19, beta = 1/4, Signorini,
!> t <= 0.125 s, the first contact period): the tip against a reference run at dt = 3.90625e-8 s,
!> largest error on [0.08, 0.125] s at dt = 6.25e-7, 1.5625e-7, 7.8125e-8 s, for the consistent
!> mass and for the redistributed one (the massless tip); the observed orders, the stops' energy
!> and the contact phases. Built with -Dbench=true; run as
!>   build/bench/convergence_redistribution [paper]
!> ('paper': the paper's load rule and Euler start, as input/paper_fig8.nml; default: the centred
!> load and the Taylor start). About 5 s.
program convergence_redistribution
   use beamstops, only: wp, ik, scene_type, model_type, error_type, array_recorder, run_summary, validate_scene, &
      & prepare_run, simulate, record_count
   use beamstops_recorder, only: col_t, col_u, col_dissipated
   implicit none
   real(wp), parameter :: dts(4) = [6.25e-7_wp, 1.5625e-7_wp, 7.8125e-8_wp, 3.90625e-8_wp]
   character(len=16) :: arg
   type(array_recorder) :: ref, rec
   real(wp) :: err(3), stops(4), cpu(4)
   integer(ik) :: phases(4)
   integer :: mode, i
   logical :: centered

   call get_command_argument(1, arg)
   centered = trim(arg) /= 'paper'
   write (*, '(a)') 'paper''s scene, J = 19, beta = 1/4, t <= 0.125 s, '// &
      & merge('centred load, Taylor start    ', 'paper''s load rule, Euler start', centered)
   write (*, '(a)') 'mass           error on [0.08, 0.125] s at dt = 6.25e-7, 1.5625e-7, 7.8125e-8 (ref 3.90625e-8)' // &
      & '   order(6.25e-7 -> 7.8125e-8)'
   do mode = 0, 1
      call one(dts(4), mode == 1, ref, stops(4), phases(4), cpu(4))
      do i = 1, 3
         call one(dts(i), mode == 1, rec, stops(i), phases(i), cpu(i))
         err(i) = maxval(abs(rec%rows(col_u, 1:rec%filled) - ref%rows(col_u, 1:ref%filled)), &
            & mask=rec%rows(col_t, 1:rec%filled) >= 0.08_wp - 1.0e-12_wp)
      end do
      write (*, '(a14, 3es12.3, f10.2)') merge('redistributed', 'consistent   ', mode == 1), err, &
         & log(err(1)/err(3))/log(8.0_wp)
      write (*, '(a14, 4es12.3, a)') '  stops (J)', stops, '   (dt = 6.25e-7 ... 3.90625e-8)'
      write (*, '(a14, 4i12)') '  phases', phases
      write (*, '(a14, 4f12.1)') '  ns/step', cpu/(0.125_wp/dts)*1.0e9_wp
   end do

contains

   subroutine one(dt, redistributed, rec, stops, phases, cpu)
      real(wp), intent(in) :: dt
      logical, intent(in) :: redistributed
      type(array_recorder), intent(out) :: rec
      real(wp), intent(out) :: stops, cpu
      integer(ik), intent(out) :: phases
      type(scene_type) :: scene
      type(model_type) :: model
      type(run_summary) :: summary
      type(error_type), allocatable :: error
      scene%beta = 0.25_wp
      scene%dt = dt
      scene%t_end = 0.125_wp
      scene%record_every = nint(1.0e-5_wp/dt)
      scene%redistributed_mass = redistributed
      scene%centered_load = centered
      scene%taylor_start = centered
      call validate_scene(scene, 'convergence_redistribution', error)
      if (allocated(error)) error stop error%message
      call prepare_run(scene, 'convergence_redistribution', model, error)
      if (allocated(error)) error stop error%message
      call rec%reserve(record_count(scene), 0_ik, scene%elements + 1)
      call simulate(scene, model, rec, summary, error)
      if (allocated(error)) error stop error%message
      stops = rec%rows(col_dissipated, rec%filled)
      phases = summary%impacts
      cpu = summary%cpu_seconds
   end subroutine one
end program convergence_redistribution
