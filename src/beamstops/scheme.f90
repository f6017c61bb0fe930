!> The time loop of the paper's scheme in increment form (SPEC 4):
!>   A (d^n - d^{n-1}) = dt^2 (G^n - S u^n),  u^{n+1} = u^n + d^n,
!> followed by the contact law at the tip, with the energy bookkeeping of SPEC 6.
!> The loop allocates nothing and writes nothing: records go to a recorder.
module beamstops_scheme
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use beamstops_kinds, only: wp, ik
   use beamstops_scene, only: scene_type, steps_of, law_none, law_signorini, law_compliance
   use beamstops_model, only: model_type
   use beamstops_error, only: error_type
   use beamstops_band, only: band_matvec, cholesky_factor, cholesky_solve
   use beamstops_forcing, only: load_average, support_position
   use beamstops_contact_tip_projection, only: project_tip
   use beamstops_contact_compliance, only: spring_force, solve_spring_tip
   use beamstops_recorder, only: recorder_type, n_columns, col_t, col_u, col_v, col_reaction, col_energy, &
      & col_work, col_dissipated
   use beamstops_summary, only: run_summary, status_complete, status_diverged, status_failed, status_running
   implicit none
   private
   public :: state_type, start_state, advance, run_scheme, block_steps

   !> Steps between progress reports and divergence checks.
   integer(ik), parameter :: block_steps = 8192_ik

   !> Everything the loop carries from step n to step n+1: with it, a run can be resumed.
   type :: state_type
      !> Index n of the next step (the step that computes u^{n+1}).
      integer(ik) :: step = 1
      !> u^n (n).
      real(wp), allocatable :: u(:)
      !> d^{n-1} = u^n - u^{n-1} (n).
      real(wp), allocatable :: d(:)
      !> S u^n (n).
      real(wp), allocatable :: su(:)
      !> Scratch vectors (n) and the snapshot buffer (J+1).
      real(wp), allocatable :: rhs(:), scratch(:), shape(:)
      !> Load averages sigma_{n-1}, sigma_n.
      real(wp) :: sigma_prev = 0, sigma_now = 0
      !> g . d^{n-1}.
      real(wp) :: gd_prev = 0
      !> Spring forces p(u^{n-1}), p(u^n) at the tip (compliance).
      real(wp) :: p_prev = 0, p_now = 0
      !> Work of the load W_{n-1} and energy taken by the stops D_{n-1}, per unit mass.
      real(wp) :: work = 0, dissipated = 0
      !> Discrete energy E^{1/2} per unit mass (reference for the divergence check).
      real(wp) :: energy0 = 0
      !> Whether the previous step was in contact.
      logical :: in_contact = .false.
      !> Impacts so far.
      integer(ik) :: impacts = 0
      !> Largest violation of the stops so far (m).
      real(wp) :: max_violation = 0
   end type state_type

contains

   !> Start a run: u^0 = u0 and u^1 by the Taylor (or Euler) start, projected into K;
   !> hands the record (and snapshot) of step 0 to the recorder.
   subroutine start_state(scene, model, state, recorder, error)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State at n = 1 on return.
      type(state_type), intent(out) :: state
      !> Receives the record of t = 0.
      class(recorder_type), intent(inout) :: recorder
      !> Set when M cannot be factored.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: mfac(:, :), a0(:), su0(:)
      real(wp) :: c, tip_value, r(n_columns)
      integer :: n, tip

      n = model%n
      tip = model%tip
      allocate (state%u(n), state%d(n), state%su(n), state%rhs(n), state%scratch(n), state%shape(size(model%x)))
      state%u = model%u0 + model%dt*model%v0
      if (scene%taylor_start) then
         ! M a0 = G(0) - S u0 + p(u0) e_tip
         allocate (a0(n), su0(n))
         call band_matvec(model%stiffness, model%u0, su0)
         a0 = support_position(0.0_wp, 1.0_wp, scene%omega)*model%load - su0
         if (scene%law == law_compliance) a0(tip) = a0(tip) + &
            & spring_force(model%u0(tip), scene%lower, scene%upper, scene%stiffness_per_mass)
         mfac = model%mass
         call cholesky_factor(mfac, 'M', error)
         if (allocated(error)) return
         call cholesky_solve(mfac, a0)
         state%u = state%u + 0.5_wp*model%dt2*a0
      end if
      if (scene%law == law_signorini) then
         call project_tip(state%u(tip), scene%lower, scene%upper, model%z(tip), c, tip_value)
         state%u = state%u + c*model%z
         state%u(tip) = tip_value
      end if
      state%d = state%u - model%u0
      call band_matvec(model%stiffness, state%u, state%su)
      state%sigma_prev = load_average(0_ik, model%dt, scene%omega, scene%centered_load)
      state%sigma_now = load_average(1_ik, model%dt, scene%omega, scene%centered_load)
      state%gd_prev = dot_product(model%load, state%d)
      if (scene%law == law_compliance) then
         state%p_prev = spring_force(model%u0(tip), scene%lower, scene%upper, scene%stiffness_per_mass)
         state%p_now = spring_force(state%u(tip), scene%lower, scene%upper, scene%stiffness_per_mass)
      end if
      if (scene%law /= law_none) state%max_violation = violation(state%u(tip), scene)
      state%energy0 = energy(model, state%u, state%d, state%su, state%scratch, &
         & dot_product(model%u0, matmul_band(model, model%u0)))
      r = 0
      r(col_u) = model%u0(tip)
      r(col_v) = model%v0(tip)
      r(col_energy) = scene%mass_per_length*state%energy0
      call recorder%record(r)
      if (scene%snapshot_every > 0) then
         call physical_shape(model, model%u0, 0.0_wp, scene, state%shape)
         call recorder%snapshot(0.0_wp, state%shape)
      end if
      state%step = 1
   end subroutine start_state

   !> S x as a new array (start-up only).
   function matmul_band(model, x) result(y)
      type(model_type), intent(in) :: model
      real(wp), intent(in) :: x(:)
      real(wp) :: y(size(x))
      call band_matvec(model%stiffness, x, y)
   end function matmul_band

   !> Run from the state's step to the scene's last step, in blocks; fills the summary.
   subroutine run_scheme(scene, model, state, recorder, summary)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State (from start_state or a checkpoint), advanced to the end.
      type(state_type), intent(inout) :: state
      !> Receives the records.
      class(recorder_type), intent(inout) :: recorder
      !> Outcome of the run.
      type(run_summary), intent(inout) :: summary
      integer(ik) :: steps, last
      real(wp) :: t0, t1, kinetic, cap
      steps = steps_of(scene)
      summary%status = status_running
      call cpu_time(t0)
      do while (state%step <= steps)
         last = min(steps, state%step + block_steps - 1)
         call advance(scene, model, state, recorder, last)
         if (recorder%failed) then
            summary%status = status_failed
            summary%message = 'the recorder could not write'
            exit
         end if
         call band_matvec(model%mass, state%d, state%scratch)
         kinetic = 0.5_wp*dot_product(state%d, state%scratch)/model%dt2
         cap = 1.0e8_wp*(0.5_wp*scene%length*(scene%amplitude*scene%omega)**2 + abs(state%energy0) &
            & + abs(state%work) + abs(state%dissipated))
         if (.not. ieee_is_finite(kinetic) .or. kinetic > cap) then
            summary%status = status_diverged
            summary%message = 'the solution blew up (kinetic energy beyond 1e8 times the energy supplied) '// &
               & 'before t = '//trim(real_text(real(state%step - 1, wp)*model%dt))//' s'
            exit
         end if
         call recorder%progress(state%step - 1, steps)
      end do
      call cpu_time(t1)
      summary%cpu_seconds = summary%cpu_seconds + (t1 - t0)
      summary%steps = state%step - 1
      summary%t_final = real(summary%steps, wp)*model%dt
      summary%impacts = state%impacts
      summary%max_violation = state%max_violation
      if (summary%status == status_running) summary%status = status_complete
   end subroutine run_scheme

   !> Text of a real for messages.
   function real_text(x) result(s)
      real(wp), intent(in) :: x
      character(len=32) :: s
      write (s, '(g0.6)') x
   end function real_text

   !> Advance from state%step through step `last` (computing u^{last+1}), recording on the way.
   subroutine advance(scene, model, state, recorder, last)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> State, advanced.
      type(state_type), intent(inout) :: state
      !> Receives the records.
      class(recorder_type), intent(inout) :: recorder
      !> Last step to do.
      integer(ik), intent(in) :: last
      integer(ik) :: step
      integer :: tip
      real(wp) :: dt2, beta, sigma_next, weight, c, tip_value, r_step, gd, d_tip_prev, u_tip_prev
      real(wp) :: u_old_su, p_next, row(n_columns)
      logical :: contact

      tip = model%tip
      dt2 = model%dt2
      beta = model%beta
      do step = state%step, last
         sigma_next = load_average(step + 1, model%dt, scene%omega, scene%centered_load)
         weight = beta*sigma_next + (1 - 2*beta)*state%sigma_now + beta*state%sigma_prev
         state%rhs = dt2*(weight*model%load - state%su)
         if (scene%law == law_compliance) state%rhs(tip) = state%rhs(tip) + &
            & dt2*((1 - 2*beta)*state%p_now + beta*state%p_prev)
         call cholesky_solve(model%factor, state%rhs)
         d_tip_prev = state%d(tip)
         u_tip_prev = state%u(tip)
         state%d = state%d + state%rhs
         select case (scene%law)
         case (law_signorini)
            call project_tip(u_tip_prev + state%d(tip), scene%lower, scene%upper, model%z(tip), c, tip_value)
            contact = c /= 0
            if (contact) state%d = state%d + c*model%z
            r_step = c/dt2
            state%u = state%u + state%d
            if (contact) state%u(tip) = tip_value
         case (law_compliance)
            tip_value = solve_spring_tip(u_tip_prev + state%d(tip), scene%lower, scene%upper, &
               & scene%stiffness_per_mass, dt2*beta*model%z(tip))
            p_next = spring_force(tip_value, scene%lower, scene%upper, scene%stiffness_per_mass)
            c = dt2*beta*p_next
            if (c /= 0) state%d = state%d + c*model%z
            r_step = beta*p_next + (1 - 2*beta)*state%p_now + beta*state%p_prev
            state%p_prev = state%p_now
            state%p_now = p_next
            contact = r_step /= 0
            state%u = state%u + state%d
            state%max_violation = max(state%max_violation, violation(state%u(tip), scene))
         case default
            r_step = 0
            contact = .false.
            state%u = state%u + state%d
         end select
         if (contact .and. .not. state%in_contact) state%impacts = state%impacts + 1
         state%in_contact = contact

         gd = dot_product(model%load, state%d)
         state%work = state%work + 0.5_wp*weight*(gd + state%gd_prev)
         state%dissipated = state%dissipated - 0.5_wp*r_step*(state%d(tip) + d_tip_prev)
         state%gd_prev = gd
         state%sigma_prev = state%sigma_now
         state%sigma_now = sigma_next

         if (mod(step, int(scene%record_every, ik)) == 0) then
            u_old_su = dot_product(state%u, state%su) - dot_product(state%d, state%su)
            call band_matvec(model%stiffness, state%u, state%su)
            row(col_t) = real(step, wp)*model%dt
            row(col_u) = u_tip_prev
            row(col_v) = (state%d(tip) + d_tip_prev)/(2*model%dt)
            row(col_reaction) = scene%mass_per_length*r_step
            row(col_energy) = scene%mass_per_length*energy(model, state%u, state%d, state%su, state%scratch, u_old_su)
            row(col_work) = scene%mass_per_length*state%work
            row(col_dissipated) = scene%mass_per_length*state%dissipated
            call recorder%record(row)
         else
            call band_matvec(model%stiffness, state%u, state%su)
         end if
         if (scene%snapshot_every > 0) then
            if (mod(step, int(scene%snapshot_every, ik)) == 0) then
               state%scratch = state%u - state%d
               call physical_shape(model, state%scratch, real(step, wp)*model%dt, scene, state%shape)
               call recorder%snapshot(real(step, wp)*model%dt, state%shape)
            end if
         end if
      end do
      state%step = last + 1
   end subroutine advance

   !> Discrete energy E^{n+1/2} per unit mass from u^{n+1}, d^n = u^{n+1} - u^n, S u^{n+1}
   !> and u^n.S u^n (SPEC 6); `scratch` receives M d.
   function energy(model, u, d, su, scratch, u_old_s_u_old) result(e)
      type(model_type), intent(in) :: model
      real(wp), intent(in) :: u(:), d(:), su(:), u_old_s_u_old
      real(wp), intent(inout) :: scratch(:)
      real(wp) :: e, usu, u_old_su
      call band_matvec(model%mass, d, scratch)
      usu = dot_product(u, su)
      u_old_su = usu - dot_product(d, su)
      e = 0.5_wp*dot_product(d, scratch)/model%dt2 + 0.5_wp*(model%beta*usu + model%beta*u_old_s_u_old &
         & + (1 - 2*model%beta)*u_old_su)
   end function energy

   !> Violation of the stops by a tip value (m).
   pure function violation(u_tip, scene) result(v)
      real(wp), intent(in) :: u_tip
      type(scene_type), intent(in) :: scene
      real(wp) :: v
      v = max(u_tip - scene%upper, scene%lower - u_tip, 0.0_wp)
   end function violation

   !> Physical displacement u + h(x) phi(t) at the nodes x_0..x_J from the homogeneous unknown u.
   subroutine physical_shape(model, u, t, scene, shape)
      type(model_type), intent(in) :: model
      real(wp), intent(in) :: u(:), t
      type(scene_type), intent(in) :: scene
      real(wp), intent(out) :: shape(:)
      real(wp) :: phi
      phi = support_position(t, scene%amplitude, scene%omega)
      shape = model%lift*phi
      shape(2:) = shape(2:) + u(1::2)
   end subroutine physical_shape
end module beamstops_scheme
