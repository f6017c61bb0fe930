!> The engine's time loop against the scheme of SPEC 4 written out by the test itself:
!> dense matrices from exact integration of the Hermite basis, the load from an
!> independent quadrature and exact time averages, the increment form of SPEC 4
!>   A (d^n - d^{n-1}) = dt^2 (G^n - S u^n),  u^{n+1} = u^n + d^n,
!> Lemma 4.1 for the stops (or the Newmark-weighted spring), and the energy of SPEC 6.
!> J = 2 (four unknowns): the engine's band storage and solves must give the same tip,
!> reaction and energy at every step, to round-off. (The three-level form, algebraically
!> the same, drifts from it by 2e-11 to 7e-11 m over these 1e4 steps: the round-off SPEC 4
!> warns of.)
module test_scheme
   use testing
   use test_support, only: base_scene, run_recorded, exact_element, dense_assembly, lift, lift_prime, simpson_load, solve_spd
   use beamstops, only: ik, scene_type, array_recorder, run_summary, law_none, law_signorini, law_compliance, steps_of
   use beamstops_recorder, only: col_t, col_u, col_v, col_reaction, col_energy
   implicit none
   private
   public :: collect_scheme

contains

   !> Tests of the suite.
   subroutine collect_scheme(tests)
      !> The suite's tests.
      type(unittest_type), allocatable, intent(out) :: tests(:)
      tests = [ &
         & new_unittest('no stops, beta = 1/4, centred load', test_free_centered), &
         & new_unittest('no stops, beta = 0.3, paper''s load', test_free_paper), &
         & new_unittest('Signorini, beta = 1/2, centred load', test_signorini_half), &
         & new_unittest('Signorini, beta = 1/4, paper''s load', test_signorini_quarter), &
         & new_unittest('compliance 1e8, beta = 1/4, centred load, first two contacts', test_compliance) &
         & ]
   end subroutine collect_scheme

   !> Exact time average of sin(omega t) over step k's interval: [(k-1/2) dt, (k+1/2) dt]
   !> (centred) or [k dt, (k+1) dt] (paper's rule).
   pure function average(k, dt, omega, centered) result(s)
      integer(ik), intent(in) :: k
      real(wp), intent(in) :: dt, omega
      logical, intent(in) :: centered
      real(wp) :: s, a
      a = real(k, wp)*dt
      if (centered) a = a - dt/2
      s = (cos(omega*a) - cos(omega*(a + dt)))/(omega*dt)
   end function average

   !> Spring force per unit mass beyond the stops, p(u) = -k [max(u - g2, 0) - max(g1 - u, 0)].
   pure function spring(u, scene) result(p)
      real(wp), intent(in) :: u
      type(scene_type), intent(in) :: scene
      real(wp) :: p
      p = -scene%stiffness_per_mass*(max(u - scene%upper, 0.0_wp) - max(scene%lower - u, 0.0_wp))
   end function spring

   !> Run the scene in the engine and by the dense three-level scheme; compare every record.
   subroutine compare(scene, error)
      type(scene_type), intent(in) :: scene
      type(error_type), allocatable, intent(out) :: error
      type(array_recorder) :: rec
      type(run_summary) :: summary
      real(wp), allocatable :: mm(:, :), ss(:, :), aa(:, :), g(:), bh(:), b1(:), z(:), &
         & u_old(:), u(:), u_new(:), d(:), d_new(:), f(:), a0(:), v0(:), e_tip(:)
      real(wp) :: me(4, 4), se(4, 4), h, dt, beta, weight, y, c, r, energy, x
      real(wp) :: du_max, dv_max, dr_max, de_max, r_scale, r_prev, e_scale, u_scale, v_scale
      integer(ik) :: k, steps, contacts
      integer :: n, tip, i

      call run_recorded(scene, rec, summary, error)
      if (allocated(error)) return
      n = 2*scene%elements
      tip = n - 1
      h = scene%length/scene%elements
      dt = scene%dt
      beta = scene%beta
      call exact_element(h, scene%k2, me, se)
      mm = dense_assembly(scene%elements, me)
      ss = dense_assembly(scene%elements, se)
      aa = mm + dt**2*beta*ss
      call simpson_load(scene%elements, scene%length, bh, b1)
      g = scene%amplitude*(scene%omega**2*bh + 8*scene%k2/scene%length**4*b1)
      allocate (e_tip(n), v0(n))
      e_tip = 0
      e_tip(tip) = 1
      z = solve_spd(aa, e_tip)
      do i = 1, scene%elements
         x = i*h
         v0(2*i - 1) = -scene%amplitude*scene%omega*lift(x, scene%length)
         v0(2*i) = -scene%amplitude*scene%omega*lift_prime(x, scene%length)
      end do
      ! u^0 = 0, u^1 = dt v0 + dt^2/2 a0, M a0 = G(0) - S u^0 + p(u^0) e_tip = 0 for this scene
      allocate (u_old(n))
      u_old = 0
      a0 = solve_spd(mm, sin(0.0_wp)*g - matmul(ss, u_old) + spring(u_old(tip), scene)*e_tip)
      u = u_old + dt*v0 + dt**2/2*a0

      steps = steps_of(scene)
      du_max = 0
      dv_max = abs(rec%rows(col_v, 1) - v0(tip))
      dr_max = 0
      de_max = 0
      contacts = 0
      u_scale = maxval(abs(rec%rows(col_u, :rec%filled)))
      r_scale = max(maxval(abs(rec%rows(col_reaction, :rec%filled))), tiny(1.0_wp))
      r_prev = 0
      e_scale = maxval(abs(rec%rows(col_energy, :rec%filled)))
      v_scale = maxval(abs(rec%rows(col_v, :rec%filled)))
      ! E^{1/2} at the record of t = 0
      energy = scene%mass_per_length*discrete_energy(u_old, u)
      de_max = abs(rec%rows(col_energy, 1) - energy)
      d = u - u_old
      do k = 1, steps
         weight = beta*average(k + 1, dt, scene%omega, scene%centered_load) &
            & + (1 - 2*beta)*average(k, dt, scene%omega, scene%centered_load) &
            & + beta*average(k - 1, dt, scene%omega, scene%centered_load)
         ! increment form: A (d^n - d^{n-1}) = dt^2 (G^n - S u^n) [+ dt^2 explicit spring part]
         f = dt**2*(weight*g - matmul(ss, u))
         if (scene%law == law_compliance) f(tip) = f(tip) + dt**2*((1 - 2*beta)*spring(u(tip), scene) &
            & + beta*spring(u_old(tip), scene))
         d_new = d + solve_spd(aa, f)
         r = 0
         select case (scene%law)
         case (law_signorini)
            ! Lemma 4.1: u = u' + (P(u'_tip) - u'_tip)/z_tip z, reaction (A u - F)_tip/dt^2
            y = min(max(u(tip) + d_new(tip), scene%lower), scene%upper)
            if (y /= u(tip) + d_new(tip)) then
               d_new = d_new + (y - (u(tip) + d_new(tip)))/z(tip)*z
               contacts = contacts + 1
            end if
            u_new = u + d_new
            u_new(tip) = y
            r = (dot_product(aa(tip, :), d_new - d) - f(tip))/dt**2
         case (law_compliance)
            ! y = u'_tip + dt^2 beta z_tip p(y), piecewise linear in y
            c = dt**2*beta*z(tip)*scene%stiffness_per_mass
            y = u(tip) + d_new(tip)
            if (y > scene%upper) y = (y + c*scene%upper)/(1 + c)
            if (y < scene%lower) y = (y + c*scene%lower)/(1 + c)
            d_new = d_new + dt**2*beta*spring(y, scene)*z
            u_new = u + d_new
            r = beta*spring(u_new(tip), scene) + (1 - 2*beta)*spring(u(tip), scene) + beta*spring(u_old(tip), scene)
            if (r /= 0) contacts = contacts + 1
         case default
            u_new = u + d_new
         end select
         ! the engine's row of step k: t_k, u^k, the reaction r^{k-1} that gave u^k, E^{k+1/2}
         if (abs(rec%rows(col_t, k + 1) - k*dt) > 1e-9_wp*dt) then
            call test_failed(error, 'the record of step '//int_text(k)//' is at t = '//real_text(rec%rows(col_t, k + 1)))
            return
         end if
         du_max = max(du_max, abs(rec%rows(col_u, k + 1) - u(tip)))
         dv_max = max(dv_max, abs(rec%rows(col_v, k + 1) - (u_new(tip) - u_old(tip))/(2*dt)))
         dr_max = max(dr_max, abs(rec%rows(col_reaction, k + 1) - scene%mass_per_length*r_prev))
         r_prev = r
         de_max = max(de_max, abs(rec%rows(col_energy, k + 1) - scene%mass_per_length*discrete_energy(u, u_new)))
         u_old = u
         u = u_new
         d = d_new
      end do
      call note('steps '//int_text(steps)//', contact steps '//int_text(contacts)// &
         & ': max |tip u - written out| '//real_text(du_max)//' m, velocity '//real_text(dv_max/v_scale)// &
         & ' of max, reaction '//real_text(dr_max/r_scale)// &
         & ' of max, energy '//real_text(de_max/e_scale)//' of max')
      if (scene%law /= law_none) then
         call check(error, contacts > 0, 'the written-out scheme reaches the stops'); if (allocated(error)) return
      end if
      call check(error, du_max, 0.0_wp, 'max |tip u, engine - written out| (m)', thr=1e-11_wp*max(u_scale, 1.0_wp))
      if (allocated(error)) return
      call check(error, dv_max/v_scale, 0.0_wp, 'max |tip velocity (u^{n+1} - u^{n-1})/(2 dt), engine - written out| '// &
         & '/ max |v|', thr=1e-7_wp)
      if (allocated(error)) return
      call check(error, dr_max/r_scale, 0.0_wp, 'max |reaction, engine - written out| / max |reaction|', thr=1e-7_wp)
      if (allocated(error)) return
      ! At an impact step, d^n depends on the position through the stop: a 1e-13 m difference of the
      ! two computations of u^n moves E^{n+1/2} by ~ (M d)/dt^2 1e-13, 1e-10 of max |E| (measured 2e-10).
      call check(error, de_max/e_scale, 0.0_wp, 'max |energy, engine - written out| / max |E|', thr=1e-8_wp)

   contains

      !> E^{n+1/2} per unit mass from u^n and u^{n+1} (SPEC 6).
      function discrete_energy(un, unp) result(e)
         real(wp), intent(in) :: un(:), unp(:)
         real(wp) :: e
         real(wp) :: delta(size(un))
         delta = unp - un
         e = 0.5_wp*dot_product(delta, matmul(mm, delta))/dt**2 + 0.5_wp*(beta*dot_product(unp, matmul(ss, unp)) &
            & + beta*dot_product(un, matmul(ss, un)) + (1 - 2*beta)*dot_product(un, matmul(ss, unp)))
      end function discrete_energy
   end subroutine compare

   !> The scene of the suite: two elements, the paper's beam and support.
   function scheme_scene(law, beta, centered, dt, t_end) result(scene)
      integer, intent(in) :: law
      real(wp), intent(in) :: beta, dt, t_end
      logical, intent(in) :: centered
      type(scene_type) :: scene
      scene = base_scene(2, dt, beta, law, t_end)
      scene%centered_load = centered
   end function scheme_scene

   subroutine test_free_centered(error)
      type(error_type), allocatable, intent(out) :: error
      call compare(scheme_scene(law_none, 0.25_wp, .true., 5e-5_wp, 0.5_wp), error)
   end subroutine test_free_centered

   subroutine test_free_paper(error)
      type(error_type), allocatable, intent(out) :: error
      call compare(scheme_scene(law_none, 0.3_wp, .false., 5e-5_wp, 0.5_wp), error)
   end subroutine test_free_paper

   subroutine test_signorini_half(error)
      type(error_type), allocatable, intent(out) :: error
      call compare(scheme_scene(law_signorini, 0.5_wp, .true., 5e-5_wp, 0.5_wp), error)
   end subroutine test_signorini_half

   subroutine test_signorini_quarter(error)
      type(error_type), allocatable, intent(out) :: error
      call compare(scheme_scene(law_signorini, 0.25_wp, .false., 5e-5_wp, 0.5_wp), error)
   end subroutine test_signorini_quarter

   subroutine test_compliance(error)
      type(error_type), allocatable, intent(out) :: error
      ! Up to t = 0.1 s only: each grazing contact with the stiff spring amplifies a round-off
      ! difference about a hundredfold (1e-14 m before the first contact, 1e-6 m at t = 0.3 s),
      ! the sensitivity to data that the paper reports.
      call compare(scheme_scene(law_compliance, 0.25_wp, .true., 5e-6_wp, 0.1_wp), error)
   end subroutine test_compliance
end module test_scheme
