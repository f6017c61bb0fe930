!> Reduced (modal) models with exact contact (SPEC 11, issue 14): the Craig-Bampton basis
!> T = [Phi Psi] of a scene and its reduced operators, built once from the full model.
!>
!> The stop unknowns b (m of them: the tip value 2J-1 of the tip-only scene, each span stop's
!> node value 2i-1 with stops along the span) stay physical coordinates; the other unknowns
!> (the interior set i, n - m of them) are spanned by
!>  - Phi (n x r): the first r fixed-interface modes, (S_ii - omega^2 M_ii) phi_i = 0 with the
!>    b unknowns held at zero, mass-normalized (Phi^T M Phi = I), from the band matrices with
!>    the b rows and columns removed: eigenvalues by LAPACK dsbgvx (O(n^2)), eigenvectors by
!>    inverse iteration with the band LU of S_ii - lambda M_ii (O(n) a mode, and accurate
!>    relative to each mode's own scale, where dsbgvx's vectors are accurate only to
!>    eps lambda_max), then each eigenvalue replaced by its Rayleigh quotient with the band
!>    products. Removing rows and columns of a band matrix never widens it (the distance between
!>    two kept unknowns can only shrink), so S_ii and M_ii keep the half-bandwidth kd = 3 of S
!>    and M, whatever b: no reordering is needed;
!>  - Psi (n x m): the static constraint modes, Psi_b = I, Psi_i = -S_ii^{-1} S_ib.
!>
!> In q = (a, p) (a: r modal amplitudes, p: the m stop values), u = T q and
!>
!>     M_r = T^T M T = [ I    B   ]     S_r = T^T S T = [ Lambda  0   ]
!>                     [ B^T  M_pp ]                    [ 0       K_pp ]
!>
!> with Lambda = diag(omega_k^2), B = Phi^T M Psi, M_pp = Psi^T M Psi, K_pp = Psi^T S Psi (the
!> Schur complement S_bb - S_bi S_ii^{-1} S_ib): the modal-constraint stiffness coupling
!> Phi^T S Psi = Phi_i^T (S_ii Psi_i + S_ib) vanishes. These blocks are what the model stores
!> (Lambda the Rayleigh quotients, I and 0 exact, B, M_pp, K_pp computed): the reduced
!> operators are the T^T M T and T^T S T of the stored T to round-off (tests: 1e-12 of their
!> largest entry), so r = n - m gives the full model's results to round-off. So A_r = M_r + dt^2 beta S_r has a
!> diagonal modal block D = I + dt^2 beta Lambda and is solved through the m x m Schur
!> complement H = E - B^T D^{-1} B, E = M_pp + dt^2 beta K_pp (factored once by dpotrf):
!> O(r m + m^2) a solve instead of O((r + m)^2) with a dense factor.
!>
!> The stops see the physical coordinates p exactly: T^T e_b = e_{r+j} (the rows b of Phi are
!> exact zeros, those of Psi exact unit rows), so the tip projection (Lemma 4.1) with
!> z_r = A_r^{-1} e_{r+1} and the span stops' box QP on C_r = P_r^T A_r^{-1} P_r are exact for the
!> reduced model. The load is l_r = T^T l.
!>
!> The massless boundary (mass redistribution, SPEC 10; tip stops): T = [Phi e_tip] with Phi the
!> modes of (S_ii - S_ib S_bi/S_bb, M^rho_ii), the interior with the massless tip condensed, so
!> M_r = diag(I, 0), S_r = [[Lambda_c + G G^T/S_bb, G], [G^T, S_bb]] (G = Phi^T S e_tip, stored
!> in stiffness_coupling, Lambda_c in lambda), A_r solved in closed form (massless_solve); its
!> frequencies are the full redistributed model's r lowest. With m stops along the span the
!> same with E_b (S_bb diagonal: no two stop nodes on one element) and a condensed interior band
!> of kd + 1 (condense_stiffness); each stop row stepped as its equilibrium, the box QP on C_r
!> (advance_massless_span). See docs/reduced.md.
!>
!> Initial data: the stop values exactly, the rest M-orthogonally projected on the
!> fixed-interface modes: p0 = u0(b), a0 = Phi^T M (u0 - Psi p0) (and the same for v0). With
!> r = n - m, T is square and invertible, this is q0 = T^{-1} u0 exactly, and the reduced model is
!> the full one in another basis: the scheme gives the full model's results to round-off.
module beamstops_reduced
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf
   use beamstops_kinds, only: wp, ik
   use beamstops_error, only: error_type, fatal_error
   use beamstops_strings, only: fmt_int
   use beamstops_scene, only: scene_type, stop_count, law_compliance, fmt_real
   use beamstops_band, only: kd, band_matvec, cholesky_factor, cholesky_solve
   use beamstops_model, only: model_type, build_model
   use beamstops_contact_span_stops, only: span_stops_type
   use beamstops_contact_box_qp, only: box_qp_type, new_box_qp
   use beamstops_reduced_massless, only: condense_stiffness, massless_condensation
   use beamstops_lapack, only: dsbgvx, dgbtrf, dgbtrs, dpotrf, dsygv, dsbgvx_message, dgbtrf_message, &
      & dpotrf_message, dsygv_message
   implicit none
   private
   public :: reduced_model_type, block_solver_type, build_reduced, prepare_reduced, validate_reduced, reduce_model
   public :: check_stability_reduced, block_solve, reduced_stiffness_product, reduced_mass_product
   public :: reduced_matrices, expand, stop_unknowns, max_reduced_unknowns, reduced_damping_product, massless_solve

   !> Largest number of full unknowns n = 2J for which a reduced basis is built (the eigenvalues
   !> by dsbgvx cost O(n^2)).
   integer, parameter :: max_reduced_unknowns = 40000
   !> Largest number of interior unknowns for which dsbgvx may be asked for the eigenvectors too
   !> (it keeps an n x n orthogonal matrix, O(n^3) work).
   integer, parameter :: dense_modes_limit = 4000
   !> Largest number of entries of the basis T, n (r + m) (2 GB).
   real(wp), parameter :: max_basis_entries = 2.5e8_wp

   !> A symmetric positive definite matrix [D B; B^T E] with D diagonal (r), B (r x m), E (m x m),
   !> ready to solve: D^{-1}, W = D^{-1} B and the Cholesky factor R (upper, R^T R = H) of the Schur
   !> complement H = E - B^T D^{-1} B.
   type :: block_solver_type
      !> Sizes r (diagonal block) and m.
      integer :: r = 0, m = 0
      !> 1/D (r).
      real(wp), allocatable :: dinv(:)
      !> B (r, m).
      real(wp), allocatable :: b(:, :)
      !> W = D^{-1} B (r, m).
      real(wp), allocatable :: w(:, :)
      !> Upper Cholesky factor R of H (m, m), zero below the diagonal.
      real(wp), allocatable :: hfac(:, :)
      !> 1/R_jj (m): the time loop multiplies instead of dividing.
      real(wp), allocatable :: rdiag(:)
   end type block_solver_type

   !> The reduced model of a scene: the basis, the blocks of M_r and S_r, the solvers of A_r and
   !> M_r, the load, the initial data, the stop columns, and what the time loop records.
   type :: reduced_model_type
      !> Full unknowns n = 2J, fixed-interface modes r, stop unknowns m; size = r + m.
      integer :: n = 0, r = 0, m = 0, size = 0
      !> Index of the tip value among the full unknowns (2J - 1).
      integer :: tip = 0
      !> Which stop coordinate (1..m) is the tip value, 0 when the tip is not a stop unknown.
      integer :: tip_stop = 0
      !> Full indices of the stop unknowns b (m), in the order of the stops.
      integer, allocatable :: b(:)
      !> Time step, its square, Newmark beta.
      real(wp) :: dt = 0, dt2 = 0, beta = 0
      !> Rayleigh damping on (SPEC 8): C_r = T^T C T = a M_r + b S_r, a and b the full model's.
      logical :: damped = .false.
      !> The coefficients a (1/s) and b (s) of C_r (the full model's, from its own spectrum).
      real(wp) :: damping_a = 0, damping_b = 0
      !> Squared frequencies omega_k^2 of the fixed-interface modes, ascending (r) (1/s^2); with the
      !> massless boundary those of the condensed interior (Lambda_c).
      real(wp), allocatable :: lambda(:)
      !> Basis T = [Phi Psi] (n, r + m): u = T q.
      real(wp), allocatable :: basis(:, :)
      !> Modal-constraint mass coupling B = Phi^T M Psi (r, m).
      real(wp), allocatable :: coupling(:, :)
      !> Constraint blocks M_pp = Psi^T M Psi and K_pp = Psi^T S Psi (m, m).
      real(wp), allocatable :: mass_pp(:, :), stiffness_pp(:, :)
      !> Reduced load vector l_r = T^T l: G(t) = sin(omega t) l_r (r + m).
      real(wp), allocatable :: load(:)
      !> Reduced initial displacement and velocity (r + m).
      real(wp), allocatable :: q0(:), v0(:)
      !> Solver of A_r = M_r + dt/2 C_r + dt^2 beta S_r = (1 + dt a/2) M_r + (dt b/2 + dt^2 beta) S_r.
      type(block_solver_type) :: a_solver
      !> Solver of M_r (the Taylor start).
      type(block_solver_type) :: m_solver
      !> Columns A_r^{-1} e_{r+j} of the stop coordinates (r + m, m); column tip_stop is the z of
      !> the tip projection.
      real(wp), allocatable :: z(:, :)
      !> The stops along the span in reduced coordinates (unknown(j) = r + j, Z = z, C = P_r^T z);
      !> m = 0 for the tip-only scene.
      type(span_stops_type) :: stops
      !> Row of T at the tip value (r + m): u_tip = tip_row . q (exactly q(r + tip_stop) when the
      !> tip is a stop unknown).
      real(wp), allocatable :: tip_row(:)
      !> Node abscissae x_0..x_J and the lifting shape h there (J + 1).
      real(wp), allocatable :: x(:), lift(:)
      !> The massless boundary (mass redistribution, SPEC 10): T = [Phi E_b] (unit columns at the
      !> massless stop unknowns instead of Psi), M_r = diag(I, 0), the coupling in S_r.
      logical :: massless = .false.
      !> Modal-stop stiffness coupling G = Phi^T S E_b (r, m) of the massless boundary (zero in
      !> the Craig-Bampton basis, where Phi^T S Psi = 0; unallocated there).
      real(wp), allocatable :: stiffness_coupling(:, :)
      !> The rows of A_r of the massless stop coordinates over those of S_r: dt^2 beta.
      real(wp) :: row_scale = 0
      !> Largest generalized eigenvalue of (S_r, M_r) (with the compliance spring at the tip),
      !> computed only for beta < 1/4 (0 otherwise) (1/s^2).
      real(wp) :: kappa = 0
      !> Linear Newmark limit 2/sqrt((1 - 4 beta) kappa) for beta < 1/4, +Inf otherwise (s).
      real(wp) :: dt_newmark = 0
   end type reduced_model_type

contains

   !> Number m of stop unknowns of a scene: its stops along the span, or 1 (the tip value).
   pure function stop_unknowns(scene) result(m)
      !> Scene.
      type(scene_type), intent(in) :: scene
      integer :: m
      m = max(1, stop_count(scene))
   end function stop_unknowns

   !> Check &mesh modes of a scene with n = 2J unknowns and m stop unknowns: 0 (the full model)
   !> or 1 <= modes <= n - m; a reduced run also needs n <= max_reduced_unknowns and a basis of at
   !> most max_basis_entries values. `source` starts the message.
   pure subroutine validate_reduced(scene, n, m, source, error)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Full unknowns 2J.
      integer, intent(in) :: n
      !> Stop unknowns (stop_unknowns(scene)).
      integer, intent(in) :: m
      !> Where the scene came from (a file name or 'scene').
      character(len=*), intent(in) :: source
      !> Set when modes is out of range.
      type(error_type), allocatable, intent(out) :: error
      if (scene%modes == 0) return
      if (scene%modes < 0 .or. scene%modes > n - m) then
         allocate (error)
         error%message = source//': &mesh modes = '//fmt_int(int(scene%modes, ik))//' is out of range; allowed: '// &
            & '0 <= modes <= n - m = '//fmt_int(int(n - m, ik))//' (2*elements minus the stop unknowns; 0: the full model)'
         return
      end if
      if (n > max_reduced_unknowns) then
         allocate (error)
         error%message = source//': &mesh modes = '//fmt_int(int(scene%modes, ik))//' with elements = '// &
            & fmt_int(int(n/2, ik))//' is out of range; allowed: modes = 0, or elements <= '// &
            & fmt_int(int(max_reduced_unknowns/2, ik))//' for a reduced model (its frequencies are computed by dsbgvx, O(n^2))'
         return
      end if
      if (real(n, wp)*real(scene%modes + m, wp) > max_basis_entries) then
         allocate (error)
         error%message = source//': &mesh modes = '//fmt_int(int(scene%modes, ik))//' with elements = '// &
            & fmt_int(int(n/2, ik))//' is out of range; allowed: modes <= '// &
            & fmt_int(int(max_basis_entries/real(n, wp), ik) - m)//' for this mesh (the basis T keeps 2*elements x '// &
            & '(modes + stops) values, at most '//fmt_int(int(max_basis_entries, ik))//')'
      end if
   end subroutine validate_reduced

   !> Build the full model of a scene with modes > 0, its reduced model, and refuse an unstable
   !> explicit scheme (with the reduced model's own kappa).
   subroutine prepare_reduced(scene, source, reduced, error)
      !> Validated scene (modes > 0, validate_reduced passed).
      type(scene_type), intent(in) :: scene
      !> Where the scene came from, for messages.
      character(len=*), intent(in) :: source
      !> Reduced model built.
      type(reduced_model_type), intent(out) :: reduced
      !> Set when the scene cannot run.
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      call build_model(scene, model, error)
      if (allocated(error)) return
      call reduce_model(scene, model, source, reduced, error)
   end subroutine prepare_reduced

   !> The reduced model of a scene (modes > 0) from its full model, refused beyond its own linear
   !> stability limit: the model a run of the scene steps (prepare_run, prepare_reduced).
   subroutine reduce_model(scene, model, source, reduced, error)
      !> Validated scene (modes > 0).
      type(scene_type), intent(in) :: scene
      !> Its full model (build_model).
      type(model_type), intent(in) :: model
      !> Where the scene came from, for messages.
      character(len=*), intent(in) :: source
      !> Reduced model built.
      type(reduced_model_type), intent(out) :: reduced
      !> Set when the reduced model cannot be built or dt exceeds its limit.
      type(error_type), allocatable, intent(out) :: error
      call build_reduced(scene, model, reduced, error)
      if (allocated(error)) then
         error%message = source//': '//error%message
         return
      end if
      call check_stability_reduced(scene, reduced, source, error)
   end subroutine reduce_model

   !> Build the reduced model of a scene (scene%modes = r >= 1) from its full model.
   subroutine build_reduced(scene, model, reduced, error, inverse_iteration)
      !> Validated scene.
      type(scene_type), intent(in) :: scene
      !> Its full model (build_model).
      type(model_type), intent(in) :: model
      !> Reduced model.
      type(reduced_model_type), intent(out) :: reduced
      !> Set when r is out of range or LAPACK fails.
      type(error_type), allocatable, intent(out) :: error
      !> The eigenvectors by inverse iteration (.true., the default) or by dsbgvx (.false.; only
      !> up to dense_modes_limit interior unknowns).
      logical, intent(in), optional :: inverse_iteration
      real(wp), allocatable :: phi_i(:, :), psi_i(:, :), mt(:, :), st(:, :), col(:), w(:), sc(:, :)
      integer, allocatable :: interior(:)
      integer :: n, m, r, ni, j, k, kc, stat
      logical :: by_iteration

      n = model%n
      r = scene%modes
      if (model%stops%m > 0) then
         reduced%b = model%stops%unknown
      else
         reduced%b = [model%tip]
      end if
      m = size(reduced%b)
      ni = n - m
      if (r < 1 .or. r > ni) then
         call fatal_error(error, 'reduced model: modes = '//fmt_int(int(r, ik))//' is out of range; allowed: 1 <= modes <= '// &
            & fmt_int(int(ni, ik)))
         return
      end if
      reduced%n = n
      reduced%r = r
      reduced%m = m
      reduced%size = r + m
      reduced%tip = model%tip
      reduced%tip_stop = 0
      do j = 1, m
         if (reduced%b(j) == model%tip) reduced%tip_stop = j
      end do
      reduced%dt = model%dt
      reduced%dt2 = model%dt2
      reduced%beta = model%beta
      reduced%x = model%x
      reduced%lift = model%lift

      ! The massless boundary keeps unit vectors at the stop unknowns (no constraint modes) and
      ! takes the modes of the interior with the stop condensed (free, massless).
      reduced%massless = model%redistributed
      interior = interior_unknowns(n, reduced%b)
      ! Inverse iteration by default: its modes are accurate relative to their own scale (at
      ! J = 1000, phi_2^T S phi_1 = 5e-8 lambda_2), dsbgvx's only to eps lambda_max in absolute
      ! terms (7e-5 lambda_2), and the modal block of S_r is taken diagonal. It is also O(n) a mode.
      by_iteration = .true.
      if (present(inverse_iteration)) by_iteration = inverse_iteration .or. ni > dense_modes_limit
      if (reduced%massless) then
         ! The condensed band: kd for the tip value alone, kd + 1 with a value along the span.
         kc = kd + 1
         if (all(reduced%b == model%tip)) kc = kd
         allocate (sc(kc + 1, ni))
         sc = 0
         sc(kc - kd + 1:, :) = band_restriction(model%stiffness, interior)
         call condense_stiffness(model%stiffness, interior, reduced%b, sc)
         call fixed_interface_modes(model%stiffness, model%mass, interior, r, by_iteration, reduced%lambda, phi_i, &
            & error, sc)
      else
         call fixed_interface_modes(model%stiffness, model%mass, interior, r, by_iteration, reduced%lambda, phi_i, error)
      end if
      if (allocated(error)) return
      if (.not. reduced%massless) then
         call constraint_modes(model%stiffness, interior, reduced%b, psi_i, error)
         if (allocated(error)) return
      end if

      allocate (reduced%basis(n, r + m), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, 'reduced model: not enough memory for the basis T ('//fmt_int(int(n, ik))//' x '// &
            & fmt_int(int(r + m, ik))//')')
         return
      end if
      reduced%basis = 0
      do k = 1, r
         reduced%basis(interior, k) = phi_i(:, k)
      end do
      call rayleigh_quotients(model%stiffness, model%mass, reduced%basis(:, 1:r), reduced%lambda)
      do j = 1, m
         if (.not. reduced%massless) reduced%basis(interior, r + j) = psi_i(:, j)
         reduced%basis(reduced%b(j), r + j) = 1
      end do
      deallocate (phi_i)

      ! M Psi and S Psi, then the blocks.
      allocate (mt(n, m), st(n, m), col(n))
      do j = 1, m
         call band_matvec(model%mass, reduced%basis(:, r + j), mt(:, j))
         call band_matvec(model%stiffness, reduced%basis(:, r + j), st(:, j))
      end do
      allocate (reduced%coupling(r, m), reduced%mass_pp(m, m), reduced%stiffness_pp(m, m))
      do j = 1, m
         do k = 1, r
            reduced%coupling(k, j) = dot_product(reduced%basis(:, k), mt(:, j))
         end do
         do k = 1, m
            reduced%mass_pp(k, j) = dot_product(reduced%basis(:, r + k), mt(:, j))
            reduced%stiffness_pp(k, j) = dot_product(reduced%basis(:, r + k), st(:, j))
         end do
      end do
      reduced%mass_pp = 0.5_wp*(reduced%mass_pp + transpose(reduced%mass_pp))
      reduced%stiffness_pp = 0.5_wp*(reduced%stiffness_pp + transpose(reduced%stiffness_pp))
      if (reduced%massless) then
         ! M^rho E_b = 0: B and M_pp are exact zeros; G = Phi^T S E_b.
         reduced%coupling = 0
         reduced%mass_pp = 0
         allocate (reduced%stiffness_coupling(r, m))
         do j = 1, m
            do k = 1, r
               reduced%stiffness_coupling(k, j) = dot_product(reduced%basis(:, k), st(:, j))
            end do
         end do
         ! The condensed quotients phi^T (S_ii - S_ib S_bb^{-1} S_bi) phi (S_bb diagonal: no two
         ! stop nodes on one element).
         do j = 1, m
            reduced%lambda = reduced%lambda - reduced%stiffness_coupling(:, j)**2/reduced%stiffness_pp(j, j)
         end do
      end if

      reduced%load = matmul(model%load, reduced%basis)
      call project_initial(reduced, model%mass, model%u0, reduced%q0)
      call project_initial(reduced, model%mass, model%v0, reduced%v0)

      reduced%damped = model%damped
      reduced%damping_a = model%damping_a
      reduced%damping_b = model%damping_b
      if (reduced%massless) then
         ! A_r = (1 + dt a/2) M_r + dt^2 beta S_r (b = 0 with redistribution: build_model refuses
         ! it): [D, dt^2 beta G; dt^2 beta G^T, dt^2 beta S_bb], D = 1 + dt a/2 + dt^2 beta Lambda.
         ! M_r is singular: the Taylor start solves its modal block alone (unit E).
         reduced%row_scale = reduced%dt2*reduced%beta
         reduced%a_solver%r = r
         reduced%a_solver%m = m
         reduced%a_solver%dinv = 1/(1 + 0.5_wp*reduced%dt*reduced%damping_a + reduced%row_scale*reduced%lambda)
         allocate (reduced%a_solver%b(r, m))
         do j = 1, m
            reduced%a_solver%b(:, j) = reduced%stiffness_coupling(:, j)/reduced%stiffness_pp(j, j)
         end do
      else if (reduced%damped) then
         ! A_r = mass_scale M_r + stiffness_scale S_r: its modal block stays diagonal.
         associate (mass_scale => 1 + 0.5_wp*reduced%dt*reduced%damping_a, &
            & stiffness_scale => 0.5_wp*reduced%dt*reduced%damping_b + reduced%dt2*reduced%beta)
            call new_block_solver(reduced%a_solver, mass_scale + stiffness_scale*reduced%lambda, &
               & mass_scale*reduced%coupling, mass_scale*reduced%mass_pp + stiffness_scale*reduced%stiffness_pp, &
               & 'A_r = M_r + dt/2 C_r + dt^2 beta S_r', error)
         end associate
      else
         call new_block_solver(reduced%a_solver, 1 + reduced%dt2*reduced%beta*reduced%lambda, reduced%coupling, &
            & reduced%mass_pp + reduced%dt2*reduced%beta*reduced%stiffness_pp, 'A_r = M_r + dt^2 beta S_r', error)
      end if
      if (allocated(error)) return
      allocate (w(r))
      w = 1
      if (reduced%massless) then
         call new_block_solver(reduced%m_solver, w, reduced%coupling, identity(m), 'M_r', error)
      else
         call new_block_solver(reduced%m_solver, w, reduced%coupling, reduced%mass_pp, 'M_r', error)
      end if
      if (allocated(error)) return

      allocate (reduced%z(r + m, m))
      do j = 1, m
         reduced%z(:, j) = 0
         reduced%z(r + j, j) = 1
         if (reduced%massless) then
            call massless_solve(reduced, reduced%z(:, j))
         else
            call block_solve(reduced%a_solver, reduced%z(:, j))
         end if
      end do
      reduced%tip_row = reduced%basis(model%tip, :)
      if (model%stops%m > 0) then
         call reduced_stops(model%stops, reduced, error)
         if (allocated(error)) return
      end if
      call reduced_spectrum(scene, reduced, error)
   end subroutine build_reduced

   !> Solve A_r x = y in place for the massless boundary, O(r m), allocation-free:
   !> A_r = [D + s G S_bb^{-1} G^T, s G; s G^T, s S_bb] (s = dt^2 beta, D and S_bb diagonal) gives
   !> x_a = D^{-1} (y_a - G S_bb^{-1} y_p), x_p = S_bb^{-1} (y_p/s - G^T x_a).
   pure subroutine massless_solve(reduced, y)
      !> Reduced model (massless).
      type(reduced_model_type), intent(in) :: reduced
      !> Right-hand side on entry, solution on return (r + m).
      real(wp), intent(inout) :: y(:)
      integer :: r, i, j
      r = reduced%r
      do i = 1, r
         do j = 1, reduced%m
            y(i) = y(i) - reduced%a_solver%b(i, j)*y(r + j)
         end do
         y(i) = reduced%a_solver%dinv(i)*y(i)
      end do
      do j = 1, reduced%m
         y(r + j) = (y(r + j)/reduced%row_scale - dot_product(reduced%stiffness_coupling(:, j), y(1:r)))/ &
            & reduced%stiffness_pp(j, j)
      end do
   end subroutine massless_solve

   !> The m x m identity.
   pure function identity(m) result(e)
      integer, intent(in) :: m
      real(wp) :: e(m, m)
      integer :: j
      e = 0
      do j = 1, m
         e(j, j) = 1
      end do
   end function identity

   !> The unknowns 1..n not in b, ascending.
   pure function interior_unknowns(n, b) result(interior)
      integer, intent(in) :: n, b(:)
      integer, allocatable :: interior(:)
      logical :: keep(n)
      integer :: k
      keep = .true.
      keep(b) = .false.
      interior = pack([(k, k=1, n)], keep)
   end function interior_unknowns

   !> The rows and columns `kept` of a symmetric band matrix (kd+1, n), as a band matrix with the
   !> same kd (kept ascending: distances between kept unknowns only shrink).
   pure function band_restriction(ab, kept) result(sub)
      real(wp), intent(in) :: ab(:, :)
      integer, intent(in) :: kept(:)
      real(wp) :: sub(kd + 1, size(kept))
      integer :: ii, jj, i, j
      sub = 0
      do jj = 1, size(kept)
         j = kept(jj)
         do ii = max(1, jj - kd), jj
            i = kept(ii)
            if (j - i <= kd) sub(kd + 1 + ii - jj, jj) = ab(kd + 1 + i - j, j)
         end do
      end do
   end function band_restriction

   !> The first r eigenpairs of (S_ii, M_ii), eigenvectors M_ii-normalized (n - m, r): the
   !> eigenvalues by dsbgvx alone (O(n^2)) and each eigenvector by inverse iteration with the
   !> band LU factor of S_ii - lambda_k M_ii (O(n) a mode), or (on request) all by dsbgvx with
   !> its n x n orthogonal matrix (O(n^3)).
   subroutine fixed_interface_modes(stiffness, mass, interior, r, by_inverse_iteration, lambda, phi, error, &
      & stiffness_ii)
      real(wp), intent(in) :: stiffness(:, :), mass(:, :)
      integer, intent(in) :: interior(:), r
      logical, intent(in) :: by_inverse_iteration
      real(wp), allocatable, intent(out) :: lambda(:), phi(:, :)
      type(error_type), allocatable, intent(out) :: error
      !> The interior stiffness to use instead of S_ii (band, its half-bandwidth kd or kd + 1, by
      !> n - m): the massless boundary's condensed S_ii - S_ib S_bb^{-1} S_bi.
      real(wp), intent(in), optional :: stiffness_ii(:, :)
      real(wp), allocatable :: sa(:, :), ma(:, :), sb(:, :), mb(:, :), q(:, :), w(:), work(:)
      integer, allocatable :: iwork(:), ifail(:)
      integer :: ni, found, info, stat, ka, kb
      character :: range, jobz
      ni = size(interior)
      allocate (sa(kd + 1, ni), ma(kd + 1, ni))
      if (present(stiffness_ii)) then
         sa = stiffness_ii
      else
         sa = band_restriction(stiffness, interior)
      end if
      ma = band_restriction(mass, interior)
      jobz = 'V'
      if (by_inverse_iteration) then
         jobz = 'N'
         sb = sa
         mb = ma
         allocate (q(1, 1), stat=stat)
      else
         allocate (q(ni, ni), stat=stat)
      end if
      if (stat == 0) allocate (w(ni), phi(ni, r), work(7*ni), iwork(5*ni), ifail(ni), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, 'reduced model: not enough memory for the eigenvectors of '//fmt_int(int(ni, ik))// &
            & ' unknowns')
         return
      end if
      range = 'I'
      if (r == ni) range = 'A'
      ! LAPACK's band routines read beyond the last column when a half-bandwidth is not below the
      ! order (dpbstf's split index (n + kb)/2 exceeds n): with fewer interior unknowns than the
      ! band (one element), the bands are cut to ni - 1, the rows of the band storage kept.
      ka = min(size(sa, 1) - 1, ni - 1)
      kb = min(kd, ni - 1)
      sa = sa(size(sa, 1) - ka:, :)
      ma = ma(kd + 1 - kb:, :)
      call dsbgvx(jobz, range, 'U', ni, ka, kb, sa, ka + 1, ma, kb + 1, q, size(q, 1), 0.0_wp, 0.0_wp, 1, r, &
         & 2*tiny(1.0_wp), found, w, phi, ni, work, iwork, ifail, info)
      if (info /= 0) then
         call fatal_error(error, 'reduced model: '//dsbgvx_message(info, ni))
         return
      end if
      if (found /= r) then
         call fatal_error(error, 'reduced model: dsbgvx found '//fmt_int(int(found, ik))//' of '//fmt_int(int(r, ik))// &
            & ' fixed-interface modes')
         return
      end if
      lambda = w(1:r)
      if (by_inverse_iteration) call inverse_iteration(sb, mb, lambda, phi, error)
   end subroutine fixed_interface_modes

   !> Eigenvectors of (S, M) (band storage) for known eigenvalues, ascending: for each, three
   !> steps of inverse iteration x <- (S - lambda M)^{-1} M x with the band LU factor (dgbtrf),
   !> M-orthogonalized against the vectors already found for eigenvalues within 1e-6 of it
   !> (a safeguard for equal eigenvalues; the stops hold values, not slopes, so the segments
   !> between them stay coupled and the beam's are distinct), M-normalized.
   subroutine inverse_iteration(s, m, lambda, phi, error)
      real(wp), intent(in) :: s(:, :), m(:, :), lambda(:)
      real(wp), intent(out) :: phi(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: steps = 3
      real(wp), allocatable :: ab(:, :), x(:), y(:)
      integer, allocatable :: ipiv(:)
      real(wp) :: shift, golden
      integer :: n, i, j, k, it, info, attempt, ks, kl, ku, ldab
      n = size(s, 2)
      ! S's half-bandwidth (kd, or kd + 1 for the condensed stiffness with stops along the span).
      ks = size(s, 1) - 1
      kl = ks
      ku = ks
      ldab = 2*kl + ku + 1
      allocate (ab(ldab, n), x(n), y(n), ipiv(n))
      golden = (sqrt(5.0_wp) - 1)/2
      do k = 1, size(lambda)
         shift = lambda(k)
         do attempt = 1, 4
            ab = 0
            do j = 1, n
               do i = max(1, j - ks), j
                  ab(kl + ku + 1 + i - j, j) = s(ks + 1 + i - j, j)
                  if (j - i <= kd) ab(kl + ku + 1 + i - j, j) = ab(kl + ku + 1 + i - j, j) - &
                     & shift*m(kd + 1 + i - j, j)
                  ab(kl + ku + 1 + j - i, i) = ab(kl + ku + 1 + i - j, j)
               end do
            end do
            call dgbtrf(n, n, kl, ku, ab, ldab, ipiv, info)
            if (info == 0) exit
            ! An exactly singular shift: move it by a few ulps.
            shift = shift*(1 + 8*epsilon(1.0_wp)) + tiny(1.0_wp)
         end do
         if (info /= 0) then
            call fatal_error(error, 'reduced model: S - lambda M for mode '//fmt_int(int(k, ik))//': '// &
               & dgbtrf_message(info))
            return
         end if
         ! A start with components along every mode (a fixed pseudo-random sequence).
         x = [(modulo(golden*real(i + 7919*k, wp), 1.0_wp) - 0.5_wp, i=1, n)]
         do it = 1, steps
            call band_matvec(m, x, y)
            call dgbtrs('N', n, kl, ku, 1, ab, ldab, ipiv, y, n, info)
            x = y/maxval(abs(y))
            do j = 1, k - 1
               if (abs(lambda(j) - lambda(k)) > 1.0e-6_wp*abs(lambda(k))) cycle
               call band_matvec(m, phi(:, j), y)
               x = x - dot_product(x, y)*phi(:, j)
            end do
            call band_matvec(m, x, y)
            x = x/sqrt(dot_product(x, y))
         end do
         phi(:, k) = x
      end do
   end subroutine inverse_iteration

   !> Each mode phi M-normalized again and its eigenvalue replaced by the Rayleigh quotient
   !> phi^T S phi with the band products: dsbgvx's eigenvalues carry an absolute error of
   !> eps lambda_max (relative 5e-11 for the first mode at J = 19), the quotient an error of the
   !> order of the eigenvector's residual squared, so that the diagonal of S_r is T^T S T's.
   subroutine rayleigh_quotients(stiffness, mass, phi, lambda)
      real(wp), intent(in) :: stiffness(:, :), mass(:, :)
      real(wp), intent(inout) :: phi(:, :)
      real(wp), intent(inout) :: lambda(:)
      real(wp), allocatable :: y(:)
      integer :: k
      allocate (y(size(phi, 1)))
      do k = 1, size(phi, 2)
         call band_matvec(mass, phi(:, k), y)
         phi(:, k) = phi(:, k)/sqrt(dot_product(phi(:, k), y))
         call band_matvec(stiffness, phi(:, k), y)
         lambda(k) = dot_product(phi(:, k), y)
      end do
   end subroutine rayleigh_quotients

   !> Psi_i = -S_ii^{-1} S_ib (n - m, m) by the band Cholesky factor of S_ii.
   subroutine constraint_modes(stiffness, interior, b, psi, error)
      real(wp), intent(in) :: stiffness(:, :)
      integer, intent(in) :: interior(:), b(:)
      real(wp), allocatable, intent(out) :: psi(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: sfac(:, :), e(:), se(:)
      integer :: n, j
      n = size(stiffness, 2)
      allocate (sfac(kd + 1, size(interior)))
      sfac = band_restriction(stiffness, interior)
      call cholesky_factor(sfac, 'S_ii (the stiffness with the stop unknowns held)', error)
      if (allocated(error)) return
      allocate (psi(size(interior), size(b)), e(n), se(n))
      do j = 1, size(b)
         e = 0
         e(b(j)) = 1
         call band_matvec(stiffness, e, se)
         psi(:, j) = -se(interior)
         call cholesky_solve(sfac, psi(:, j))
      end do
   end subroutine constraint_modes

   !> q = (Phi^T M (u - Psi p), p) with p = u(b): the stop values exactly, the rest projected
   !> M-orthogonally on the fixed-interface modes (q = T^{-1} u when r = n - m).
   subroutine project_initial(reduced, mass, u, q)
      type(reduced_model_type), intent(in) :: reduced
      real(wp), intent(in) :: mass(:, :), u(:)
      real(wp), allocatable, intent(out) :: q(:)
      real(wp), allocatable :: rest(:), mrest(:)
      integer :: r, j
      r = reduced%r
      allocate (q(reduced%size), mrest(reduced%n))
      q(r + 1:) = u(reduced%b)
      rest = u
      do j = 1, reduced%m
         rest = rest - q(r + j)*reduced%basis(:, r + j)
      end do
      call band_matvec(mass, rest, mrest)
      q(1:r) = matmul(mrest, reduced%basis(:, 1:r))
   end subroutine project_initial

   !> The solver of [diag(d) B; B^T E]: W = D^{-1} B and the Cholesky factor of E - B^T W.
   subroutine new_block_solver(self, d, b, e, what, error)
      type(block_solver_type), intent(out) :: self
      real(wp), intent(in) :: d(:), b(:, :), e(:, :)
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      integer :: r, m, info, j
      r = size(d)
      m = size(e, 1)
      self%r = r
      self%m = m
      if (any(d <= 0)) then
         call fatal_error(error, 'reduced model: the modal block of '//what//' is not positive definite')
         return
      end if
      self%dinv = 1/d
      self%b = b
      allocate (self%w(r, m))
      do j = 1, m
         self%w(:, j) = self%dinv*b(:, j)
      end do
      self%hfac = e - matmul(transpose(b), self%w)
      self%hfac = 0.5_wp*(self%hfac + transpose(self%hfac))
      call dpotrf('U', m, self%hfac, m, info)
      if (info /= 0) then
         call fatal_error(error, 'reduced model: '//dpotrf_message(info, 'the Schur complement of '//what))
         return
      end if
      do j = 1, m
         self%hfac(j + 1:, j) = 0
      end do
      self%rdiag = [(1/self%hfac(j, j), j=1, m)]
   end subroutine new_block_solver

   !> Solve [D B; B^T E] x = y in place, O(r m + m^2), allocation-free:
   !> w = D^{-1} y_a, x_p = H^{-1} (y_p - B^T w), x_a = w - W x_p.
   pure subroutine block_solve(self, y)
      !> The solver.
      type(block_solver_type), intent(in) :: self
      !> Right-hand side on entry, solution on return (r + m).
      real(wp), intent(inout) :: y(:)
      integer :: r, m, i, j
      real(wp) :: acc
      r = self%r
      m = self%m
      y(1:r) = self%dinv*y(1:r)
      do j = 1, m
         y(r + j) = y(r + j) - dot_product(self%b(:, j), y(1:r))
      end do
      ! R^T R x_p = rhs: forward with R^T, then back with R.
      do j = 1, m
         acc = y(r + j)
         do i = 1, j - 1
            acc = acc - self%hfac(i, j)*y(r + i)
         end do
         y(r + j) = acc/self%hfac(j, j)
      end do
      do j = m, 1, -1
         acc = y(r + j)
         do i = j + 1, m
            acc = acc - self%hfac(j, i)*y(r + i)
         end do
         y(r + j) = acc/self%hfac(j, j)
      end do
      do j = 1, m
         acc = y(r + j)
         do i = 1, r
            y(i) = y(i) - self%w(i, j)*acc
         end do
      end do
   end subroutine block_solve

   !> y = S_r q = (Lambda a, K_pp p), O(r + m^2); with the massless boundary
   !> (Lambda a + G p, G^T a + S_bb p), O(r m + m^2).
   pure subroutine reduced_stiffness_product(reduced, q, y)
      !> Reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> Reduced vector (r + m).
      real(wp), intent(in) :: q(:)
      !> S_r q (r + m).
      real(wp), intent(out) :: y(:)
      integer :: r, i, j
      real(wp) :: acc
      r = reduced%r
      y(1:r) = reduced%lambda*q(1:r)
      do i = 1, reduced%m
         acc = 0
         do j = 1, reduced%m
            acc = acc + reduced%stiffness_pp(i, j)*q(r + j)
         end do
         y(r + i) = acc
      end do
      if (reduced%massless) then
         ! (Lambda_c a + G (S_bb^{-1} G^T a + p), G^T a + S_bb p), S_bb diagonal.
         do j = 1, reduced%m
            acc = dot_product(reduced%stiffness_coupling(:, j), q(1:r))
            y(1:r) = y(1:r) + reduced%stiffness_coupling(:, j)*(acc/reduced%stiffness_pp(j, j) + q(r + j))
            y(r + j) = y(r + j) + acc
         end do
      end if
   end subroutine reduced_stiffness_product

   !> d^T M_r d = a.a + 2 a.(B p) + p.(M_pp p), O(r m + m^2).
   pure function reduced_mass_product(reduced, d) result(dmd)
      !> Reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> Reduced vector (r + m).
      real(wp), intent(in) :: d(:)
      real(wp) :: dmd
      integer :: r, i, j
      real(wp) :: acc
      r = reduced%r
      dmd = dot_product(d(1:r), d(1:r))
      do j = 1, reduced%m
         dmd = dmd + 2*d(r + j)*dot_product(reduced%coupling(:, j), d(1:r))
         acc = 0
         do i = 1, reduced%m
            acc = acc + reduced%mass_pp(i, j)*d(r + i)
         end do
         dmd = dmd + d(r + j)*acc
      end do
   end function reduced_mass_product

   !> y = C_r d = a M_r d + b S_r d = (a (d_a + B d_p) + b Lambda d_a, a (B^T d_a + M_pp d_p) + b K_pp d_p),
   !> O(r m + m^2), allocation-free (the damped loop's product, once a step).
   pure subroutine reduced_damping_product(reduced, d, y)
      !> Reduced model (damped).
      type(reduced_model_type), intent(in) :: reduced
      !> Reduced vector (r + m).
      real(wp), intent(in) :: d(:)
      !> C_r d (r + m).
      real(wp), intent(out) :: y(:)
      integer :: r, i, j
      real(wp) :: a, b, acc, dp
      r = reduced%r
      a = reduced%damping_a
      b = reduced%damping_b
      do i = 1, r
         y(i) = a*d(i) + b*reduced%lambda(i)*d(i)
      end do
      do j = 1, reduced%m
         dp = d(r + j)
         acc = 0
         do i = 1, r
            y(i) = y(i) + a*reduced%coupling(i, j)*dp
            acc = acc + reduced%coupling(i, j)*d(i)
         end do
         do i = 1, reduced%m
            acc = acc + reduced%mass_pp(i, j)*d(r + i)
         end do
         y(r + j) = a*acc
         acc = 0
         do i = 1, reduced%m
            acc = acc + reduced%stiffness_pp(i, j)*d(r + i)
         end do
         y(r + j) = y(r + j) + b*acc
      end do
   end subroutine reduced_damping_product

   !> Dense M_r and S_r (r + m)^2 from the stored blocks (tests, spectra).
   pure subroutine reduced_matrices(reduced, mass, stiffness)
      !> Reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> M_r and S_r (r + m, r + m).
      real(wp), allocatable, intent(out) :: mass(:, :), stiffness(:, :)
      integer :: r, k, j
      r = reduced%r
      allocate (mass(reduced%size, reduced%size), stiffness(reduced%size, reduced%size))
      mass = 0
      stiffness = 0
      do k = 1, r
         mass(k, k) = 1
         stiffness(k, k) = reduced%lambda(k)
      end do
      mass(1:r, r + 1:) = reduced%coupling
      mass(r + 1:, 1:r) = transpose(reduced%coupling)
      mass(r + 1:, r + 1:) = reduced%mass_pp
      stiffness(r + 1:, r + 1:) = reduced%stiffness_pp
      if (reduced%massless) then
         do j = 1, reduced%m
            do k = 1, r
               stiffness(1:r, k) = stiffness(1:r, k) + reduced%stiffness_coupling(:, j)* &
                  & (reduced%stiffness_coupling(k, j)/reduced%stiffness_pp(j, j))
            end do
         end do
         stiffness(1:r, r + 1:) = reduced%stiffness_coupling
         stiffness(r + 1:, 1:r) = transpose(reduced%stiffness_coupling)
      end if
   end subroutine reduced_matrices

   !> u = T q (n) from a reduced vector.
   pure subroutine expand(reduced, q, u)
      !> Reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> Reduced vector (r + m).
      real(wp), intent(in) :: q(:)
      !> Full vector (n).
      real(wp), intent(out) :: u(:)
      integer :: k
      u = 0
      do k = 1, reduced%size
         u = u + reduced%basis(:, k)*q(k)
      end do
   end subroutine expand

   !> The stops along the span in reduced coordinates: unknown(j) = r + j, Z = z, C = P_r^T z.
   subroutine reduced_stops(full, reduced, error)
      type(span_stops_type), intent(in) :: full
      type(reduced_model_type), intent(inout) :: reduced
      type(error_type), allocatable, intent(out) :: error
      type(box_qp_type) :: check
      integer :: i, j, m
      m = full%m
      reduced%stops = full
      reduced%stops%unknown = [(reduced%r + j, j=1, m)]
      reduced%stops%z = reduced%z
      do j = 1, m
         do i = 1, m
            reduced%stops%c(i, j) = reduced%z(reduced%r + i, j)
         end do
      end do
      call new_box_qp(check, reduced%stops%c, error)
      if (allocated(error)) error%message = '&stops: the stops along the span of the reduced model: '//error%message
   end subroutine reduced_stops

   !> kappa of (S_r, M_r) (plus the compliance spring at the tip) and the Newmark limit, for
   !> beta < 1/4 only (a dense dsygv, O((r + m)^3)).
   subroutine reduced_spectrum(scene, reduced, error)
      type(scene_type), intent(in) :: scene
      type(reduced_model_type), intent(inout) :: reduced
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: mr(:, :), sr(:, :), w(:), work(:)
      integer :: s, info
      reduced%dt_newmark = ieee_value(1.0_wp, ieee_positive_inf)
      reduced%kappa = 0
      if (scene%beta >= 0.25_wp) return
      call reduced_matrices(reduced, mr, sr)
      if (scene%law == law_compliance .and. reduced%tip_stop > 0) then
         s = reduced%r + reduced%tip_stop
         sr(s, s) = sr(s, s) + scene%stiffness_per_mass
      end if
      if (reduced%massless) call massless_condensation(reduced%r, reduced%m, mr, sr, error)
      if (allocated(error)) return
      s = size(sr, 1)
      allocate (w(s), work(max(1, 3*s)))
      call dsygv(1, 'N', 'U', s, sr, s, mr, s, w, work, size(work), info)
      if (info /= 0) then
         call fatal_error(error, 'reduced model: (S_r, M_r): '//dsygv_message(info, s))
         return
      end if
      reduced%kappa = w(s)
      reduced%dt_newmark = 2/sqrt((1 - 4*scene%beta)*reduced%kappa)
   end subroutine reduced_spectrum

   !> Refuse a scheme with beta < 1/4 asked beyond the reduced model's linear stability limit,
   !> unless allowed (the reduced kappa is at most the full kappa_h: a reduced model may take a
   !> larger dt).
   subroutine check_stability_reduced(scene, reduced, source, error)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its reduced model.
      type(reduced_model_type), intent(in) :: reduced
      !> Where the scene came from, for the message.
      character(len=*), intent(in) :: source
      !> Set when dt exceeds the limit.
      type(error_type), allocatable, intent(out) :: error
      if (scene%allow_unstable .or. scene%beta >= 0.25_wp) return
      if (scene%dt < reduced%dt_newmark) return
      call fatal_error(error, source//': &time dt = '//fmt_real(scene%dt)//' is out of range; allowed: dt < '// &
         & fmt_real(reduced%dt_newmark, 6, 'down')//' s, the linear stability limit 2/sqrt((1-4 beta) kappa) of the '// &
         & 'reduced model with modes = '//fmt_int(int(reduced%r, ik))//' (kappa = '//fmt_real(reduced%kappa, 6)// &
         & ' 1/s^2); set &time allow_unstable=.true. to run it anyway')
   end subroutine check_stability_reduced
end module beamstops_reduced
