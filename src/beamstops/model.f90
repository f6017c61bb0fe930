!> What a scene implies before time runs: assembled M and S, the load vector,
!> the factor of A = M + dt/2 C + dt^2 beta S (C the Rayleigh damping, M possibly with the
!> constrained unknowns massless, SPEC 8, 10), the tip column z = A^{-1} e_tip, the stops along
!> the span (their columns A^{-1} P and C = P^T A^{-1} P), the initial data, kappa_h and
!> the stability limits. Built once.
module beamstops_model
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf
   use beamstops_kinds, only: wp
   use beamstops_error, only: error_type, fatal_error
   use beamstops_scene, only: scene_type, law_compliance, fmt_real, stop_count
   use beamstops_hermite, only: element_mass, element_stiffness, hermite_basis, gauss_points, gauss_weights
   use beamstops_band, only: kd, assemble_band, cholesky_factor, cholesky_solve, &
      & largest_eigenvalue_exact, largest_eigenvalue_iterative, generalized_eigenvalues
   use beamstops_contact_mass_redistribution, only: assemble_redistributed_mass
   use beamstops_band_solve, only: band_solver, prepare_solver, band_diagonals, prepare_diagonals
   use beamstops_forcing, only: lift_shape, lift_slope
   use beamstops_contact_span_stops, only: span_stops_type, new_span_stops
   use beamstops_contact_box_qp, only: box_qp_type, new_box_qp
   implicit none
   private
   public :: model_type, build_model, check_stability, kappa_bound_constant, exact_eigen_limit

   !> Constant C of the paper's bound (5.2): kappa_tilde = C k^2/dx^4, C = 24*420*19^2/37.
   real(wp), parameter :: kappa_bound_constant = 24.0_wp*420.0_wp*19.0_wp**2/37.0_wp
   !> Largest number of unknowns for which kappa_h is computed by dsbgv (O(n^2) work).
   integer, parameter :: exact_eigen_limit = 6000

   !> Matrices, vectors and constants of a discretized scene.
   type :: model_type
      !> Number of unknowns n = 2J.
      integer :: n = 0
      !> Index of the tip value (2J - 1).
      integer :: tip = 0
      !> Element length (m).
      real(wp) :: h = 0
      !> Time step and its square (s, s^2).
      real(wp) :: dt = 0, dt2 = 0
      !> Newmark beta.
      real(wp) :: beta = 0
      !> Mass matrix M, band storage (kd+1, n).
      real(wp), allocatable :: mass(:, :)
      !> Stiffness matrix S, band storage (kd+1, n).
      real(wp), allocatable :: stiffness(:, :)
      !> Cholesky factor U of A = M + dt/2 C + dt^2 beta S, band storage (kd+1, n).
      real(wp), allocatable :: factor(:, :)
      !> The factor of A in the form of the fused substitutions (from factor).
      type(band_solver) :: solver
      !> S and M by diagonals (the vectorized products of the time loop).
      type(band_diagonals) :: stiffness_diagonals, mass_diagonals
      !> Load vector g: G(t) = sin(omega t) g (n).
      real(wp), allocatable :: load(:)
      !> Tip column z = A^{-1} e_tip (n).
      real(wp), allocatable :: z(:)
      !> Stops along the span (SPEC 7): nodes, bounds, Z = A^{-1} P, C = P^T Z (m = 0: none).
      type(span_stops_type) :: stops
      !> Initial displacement u0 and velocity v0 of the homogeneous unknown (n).
      real(wp), allocatable :: u0(:), v0(:)
      !> Node abscissae x_0 = 0, ..., x_J = L (J+1).
      real(wp), allocatable :: x(:)
      !> Lifting shape h(x) at the nodes (J+1): physical displacement = u + h phi(t).
      real(wp), allocatable :: lift(:)
      !> Largest generalized eigenvalue of (S, M) (1/s^2).
      real(wp) :: kappa_h = 0
      !> How kappa_h was computed: 'dsbgv' (exact) or 'inverse iteration'.
      character(len=:), allocatable :: kappa_method
      !> The paper's upper bound kappa_tilde of kappa_h (1/s^2).
      real(wp) :: kappa_bound = 0
      !> Largest eigenvalue with the compliance spring at the tip (= kappa_h without it).
      real(wp) :: kappa_contact = 0
      !> Linear Newmark limit 2/sqrt((1-4 beta) kappa) for beta < 1/4 (+Inf otherwise) (s).
      real(wp) :: dt_newmark = 0
      !> Paper's condition (3.1) with the exact kappa_h, alpha -> 0 (+Inf for beta = 1/2) (s).
      real(wp) :: dt_paper_exact = 0
      !> Paper's condition (3.1) with its bound kappa_tilde (s).
      real(wp) :: dt_paper_bound = 0
      ! ---- physics of issue 12 (SPEC 8-10) ----
      !> Rayleigh damping on: C = a M + b S with a or b nonzero (SPEC 8).
      logical :: damped = .false.
      !> The coefficients a (1/s) and b (s) used: the scene's, or solved from its ratios.
      real(wp) :: damping_a = 0, damping_b = 0
      !> Angular frequencies of the two modes of the ratio form (rad/s; 0 otherwise).
      real(wp) :: damping_omega(2) = 0
      !> C = a M + b S, band storage (kd+1, n) (allocated when damped).
      real(wp), allocatable :: damping(:, :)
      !> C by diagonals (the loop's product C d^n; filled when damped).
      type(band_diagonals) :: damping_diagonals
      !> Mass redistribution (SPEC 10): the constrained unknowns carry no mass.
      logical :: redistributed = .false.
      !> The massless unknowns (the tip value, or the value of each stop node); empty otherwise.
      integer, allocatable :: massless(:)
      !> The rows of A of the massless unknowns are row_scale times those of S:
      !> row_scale = dt^2 beta + dt b/2.
      real(wp) :: row_scale = 0
   end type model_type

contains

   !> Build the model of a validated scene.
   subroutine build_model(scene, model, error)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Model to build.
      type(model_type), intent(out) :: model
      !> Set when a factorization fails.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: bh(:), b1(:)
      real(wp) :: me(4, 4), se(4, 4), forcing_scale
      integer :: n, j

      n = 2*scene%elements
      model%n = n
      model%tip = n - 1
      model%h = scene%length/scene%elements
      model%dt = scene%dt
      model%dt2 = scene%dt**2
      model%beta = scene%beta
      me = element_mass(model%h)
      se = element_stiffness(model%h, scene%k2)
      allocate (model%mass(kd + 1, n), model%stiffness(kd + 1, n))
      call assemble_band(scene%elements, se, model%stiffness)
      model%redistributed = scene%redistributed_mass
      if (model%redistributed) then
         if (stop_count(scene) > 0) then
            model%massless = 2*scene%stop_nodes - 1
            call assemble_redistributed_mass(scene%elements, model%h, scene%stop_nodes, model%mass)
         else
            model%massless = [model%tip]
            call assemble_redistributed_mass(scene%elements, model%h, [scene%elements], model%mass)
         end if
      else
         allocate (model%massless(0))
         call assemble_band(scene%elements, me, model%mass)
      end if

      model%x = [(scene%length*j/scene%elements, j=0, scene%elements)]
      model%lift = lift_shape(model%x, scene%length)
      call load_shapes(scene%elements, model%h, scene%length, bh, b1)
      forcing_scale = 8*scene%k2/scene%length**4
      model%load = scene%amplitude*(scene%omega**2*bh + forcing_scale*b1)
      allocate (model%u0(n), model%v0(n))
      model%u0 = 0
      model%v0(1::2) = -scene%amplitude*scene%omega*lift_shape(model%x(2:), scene%length)
      model%v0(2::2) = -scene%amplitude*scene%omega*lift_slope(model%x(2:), scene%length)

      call build_damping(scene, model, error)
      if (allocated(error)) return
      if (model%damped) then
         model%factor = model%mass + 0.5_wp*model%dt*model%damping + model%dt2*model%beta*model%stiffness
      else
         model%factor = model%mass + model%dt2*model%beta*model%stiffness
      end if
      model%row_scale = model%dt2*model%beta + 0.5_wp*model%dt*model%damping_b
      call cholesky_factor(model%factor, 'A = M + dt/2 C + dt^2 beta S', error)
      if (allocated(error)) return
      call prepare_solver(model%factor, model%solver)
      call prepare_diagonals(model%stiffness, model%stiffness_diagonals)
      call prepare_diagonals(model%mass, model%mass_diagonals)
      allocate (model%z(n))
      model%z = 0
      model%z(model%tip) = 1
      call cholesky_solve(model%factor, model%z)
      if (stop_count(scene) > 0) then
         call build_stops(scene, model, error)
         if (allocated(error)) return
      end if

      call spectrum(scene, model, error)
   end subroutine build_model

   !> Rayleigh damping (SPEC 8): a and b, given or solved from the ratios at two modes,
   !> zeta(omega) = a/(2 omega) + b omega/2 (the reader gives both modes one ratio when one is given), the
   !> frequencies those of the model's own pencil (S, M) (M^rho with mass redistribution);
   !> then C = a M + b S.
   subroutine build_damping(scene, model, error)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(inout) :: model
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: kappa(:)
      real(wp) :: zeta(2), w1, w2, det
      model%damping_a = scene%damping_mass
      model%damping_b = scene%damping_stiffness
      if (scene%damping_by_ratio) then
         zeta = scene%damping_ratio
         if (model%n > exact_eigen_limit) then
            call fatal_error(error, '&damping ratio: the ratio form needs the frequencies of the mesh, '// &
               & 'computed for 2 elements <= '//fmt_real(real(exact_eigen_limit, wp))//' only; give '// &
               & 'mass_coefficient and stiffness_coefficient instead')
            return
         end if
         call generalized_eigenvalues(model%stiffness, model%mass, size(model%massless), kappa, error)
         if (allocated(error)) return
         if (any(scene%damping_modes > size(kappa))) then
            call fatal_error(error, '&damping modes: the model has '//fmt_real(real(size(kappa), wp))// &
               & ' modes only')
            return
         end if
         w1 = sqrt(kappa(scene%damping_modes(1)))
         w2 = sqrt(kappa(scene%damping_modes(2)))
         model%damping_omega = [w1, w2]
         ! [1/(2 w1), w1/2; 1/(2 w2), w2/2] [a; b] = zeta
         det = (w2**2 - w1**2)/(4*w1*w2)
         model%damping_a = (zeta(1)*w2/2 - zeta(2)*w1/2)/det
         model%damping_b = (zeta(2)/(2*w1) - zeta(1)/(2*w2))/det
         if (model%damping_a < 0 .or. model%damping_b < 0) then
            call fatal_error(error, '&damping ratio = '//fmt_real(zeta(1))//', '//fmt_real(zeta(2))// &
               & ' at modes of '//fmt_real(w1, 6)//' and '//fmt_real(w2, 6)//' rad/s gives a = '// &
               & fmt_real(model%damping_a, 6)//' 1/s, b = '//fmt_real(model%damping_b, 6)// &
               & ' s; allowed: ratios giving a >= 0 and b >= 0')
            return
         end if
      end if
      if (model%redistributed .and. model%damping_b /= 0) then
         call fatal_error(error, '&stops mass = ''redistributed'' with stiffness-proportional damping (b = '// &
            & fmt_real(model%damping_b, 6)//' s) is not supported; allowed: &damping mass_coefficient alone')
         return
      end if
      model%damped = model%damping_a /= 0 .or. model%damping_b /= 0
      if (.not. model%damped) return
      model%damping = model%damping_a*model%mass + model%damping_b*model%stiffness
      call prepare_diagonals(model%damping, model%damping_diagonals)
   end subroutine build_damping

   !> The stops along the span: Z = A^{-1} P by m solves, C = P^T Z, and C checked positive
   !> definite (stops on distinct nodes make it so; round-off could not for nodes too close).
   subroutine build_stops(scene, model, error)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(inout) :: model
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: check
      call new_span_stops(model%stops, scene%stop_nodes, scene%stop_lower, scene%stop_upper, model%x, model%lift, &
         & model%factor, error)
      if (allocated(error)) return
      call new_box_qp(check, model%stops%c, error)
      if (allocated(error)) error%message = '&stops: the stops along the span: '//error%message// &
         & ' (stops too close together for this mesh and time step?)'
   end subroutine build_stops

   !> Load shapes (h, phi_i) and (1, phi_i) by 4-point Gauss quadrature per element.
   pure subroutine load_shapes(elements, h, length, bh, b1)
      integer, intent(in) :: elements
      real(wp), intent(in) :: h, length
      real(wp), allocatable, intent(out) :: bh(:), b1(:)
      real(wp) :: full_h(2*elements + 2), full_1(2*elements + 2), nq(4), xq
      integer :: e, q
      full_h = 0
      full_1 = 0
      do e = 1, elements
         do q = 1, 4
            nq = hermite_basis(gauss_points(q), h)*gauss_weights(q)*h
            xq = (e - 1 + gauss_points(q))*h
            full_h(2*e - 1:2*e + 2) = full_h(2*e - 1:2*e + 2) + nq*lift_shape(xq, length)
            full_1(2*e - 1:2*e + 2) = full_1(2*e - 1:2*e + 2) + nq
         end do
      end do
      bh = full_h(3:)
      b1 = full_1(3:)
   end subroutine load_shapes

   !> kappa_h (exact for small meshes, inverse iteration beyond), the paper's bound and the limits.
   subroutine spectrum(scene, model, error)
      type(scene_type), intent(in) :: scene
      type(model_type), intent(inout) :: model
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: sc(:, :), mfac(:, :), e_tip(:), kappas(:)
      real(wp) :: inf, spring, upper
      inf = ieee_value(1.0_wp, ieee_positive_inf)
      model%kappa_bound = kappa_bound_constant*scene%k2/model%h**4
      spring = 0
      if (scene%law == law_compliance) spring = scene%stiffness_per_mass
      allocate (sc, source=model%stiffness)
      sc(kd + 1, model%tip) = sc(kd + 1, model%tip) + spring
      if (model%redistributed) then
         ! M^rho is singular: the finite spectrum from the pencil taken the other way round.
         if (model%n > exact_eigen_limit) then
            call fatal_error(error, '&stops mass = ''redistributed'': the spectrum of M^rho is computed for '// &
               & '2 elements <= '//fmt_real(real(exact_eigen_limit, wp))//' only')
            return
         end if
         model%kappa_method = 'dsbgv (S, M^rho)'
         call generalized_eigenvalues(model%stiffness, model%mass, size(model%massless), kappas, error)
         if (allocated(error)) return
         model%kappa_h = kappas(size(kappas))
         model%kappa_contact = model%kappa_h
      else if (model%n <= exact_eigen_limit) then
         model%kappa_method = 'dsbgv'
         call largest_eigenvalue_exact(model%stiffness, model%mass, model%kappa_h, error)
         if (allocated(error)) return
         model%kappa_contact = model%kappa_h
         if (spring > 0) call largest_eigenvalue_exact(sc, model%mass, model%kappa_contact, error)
      else
         model%kappa_method = 'inverse iteration'
         ! (M^-1)_tip,tip bounds the Rayleigh quotient of the spring term.
         mfac = model%mass
         call cholesky_factor(mfac, 'M', error)
         if (allocated(error)) return
         allocate (e_tip(model%n))
         e_tip = 0
         e_tip(model%tip) = 1
         call cholesky_solve(mfac, e_tip)
         upper = element_bound(model%h, scene%k2)
         call largest_eigenvalue_iterative(model%stiffness, model%mass, upper, model%kappa_h, error)
         if (allocated(error)) return
         model%kappa_contact = model%kappa_h
         if (spring > 0) call largest_eigenvalue_iterative(sc, model%mass, &
            & upper + spring*e_tip(model%tip), model%kappa_contact, error)
      end if
      if (allocated(error)) return
      model%dt_newmark = inf
      if (scene%beta < 0.25_wp) model%dt_newmark = 2/sqrt((1 - 4*scene%beta)*model%kappa_contact)
      model%dt_paper_exact = inf
      model%dt_paper_bound = inf
      if (scene%beta < 0.5_wp) then
         model%dt_paper_exact = 2/sqrt((1 - 2*scene%beta)*model%kappa_h)
         model%dt_paper_bound = 2/sqrt((1 - 2*scene%beta)*model%kappa_bound)
      end if
   end subroutine spectrum

   !> Upper bound of kappa_h: the largest eigenvalue of one element, slightly enlarged.
   function element_bound(h, k2) result(bound)
      real(wp), intent(in) :: h, k2
      real(wp) :: bound
      real(wp) :: mb(kd + 1, 4), sb(kd + 1, 4)
      type(error_type), allocatable :: error
      integer :: i, j
      mb = 0
      sb = 0
      associate (me => element_mass(h), se => element_stiffness(h, k2))
         do j = 1, 4
            do i = max(1, j - kd), j
               mb(kd + 1 + i - j, j) = me(i, j)
               sb(kd + 1 + i - j, j) = se(i, j)
            end do
         end do
      end associate
      call largest_eigenvalue_exact(sb, mb, bound, error)
      bound = bound*(1 + 1.0e-6_wp)
   end function element_bound

   !> Refuse a scheme with beta < 1/4 asked beyond its linear stability limit, unless allowed.
   subroutine check_stability(scene, model, source, error)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      !> Where the scene came from, for the message.
      character(len=*), intent(in) :: source
      !> Set when dt exceeds the limit.
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: kappa, what
      if (scene%allow_unstable .or. scene%beta >= 0.25_wp) return
      if (scene%dt < model%dt_newmark) return
      if (model%kappa_contact == model%kappa_h) then
         kappa = 'kappa_h'
         what = ''
      else  ! normal compliance: the stops' spring stiffens the tip's row
         kappa = 'kappa'
         what = ', the largest eigenvalue of S with the stops'' spring at the tip, against M'
      end if
      call fatal_error(error, source//': &time dt = '//fmt_real(scene%dt)//' is out of range; allowed: dt < '// &
         & fmt_real(model%dt_newmark, 6, 'down')//' s, the linear stability limit 2/sqrt((1-4 beta) '//kappa//') for '// &
         & 'beta = '//fmt_real(scene%beta)//' ('//kappa//' = '//fmt_real(model%kappa_contact, 6)//' 1/s^2'//what// &
         & '); set &time allow_unstable=.true. to run it anyway')
   end subroutine check_stability
end module beamstops_model
