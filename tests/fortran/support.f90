!> Helpers shared by the suites: LAPACK eigenvalues computed by the tests themselves,
!> a whole run of a scene into an array recorder, and two runs' records compared bit for bit.
module test_support
   use testing, only: int_text   ! public here too, for the suites that take it from this module
   use beamstops, only: wp, ik, error_type, fatal_error, scene_type, validate_scene, model_type, &
      & prepare_run, simulate, record_count, array_recorder, run_summary, status_complete, stop_count, &
      & law_signorini, law_compliance
   use beamstops_lapack, only: dsbgv, dsygv, dsbgv_message, dsygv_message
   use beamstops_recorder, only: n_columns, col_energy, col_work, col_dissipated, col_damped
   implicit none
   private
   public :: band_eigenvalues, dense_eigenvalues, run_recorded, same_columns, int_text
   public :: basis_coefficients, product_integral, poly, exact_element, dense_assembly, lift, lift_prime
   public :: simpson_load, solve_spd
   public :: base_scene, tube, balance_defect, validated_model


contains

   !> Coefficients c(0:3) in xi of the four Hermite functions on [0, 1] (element length h),
   !> ordered (value left, slope left, value right, slope right).
   pure function basis_coefficients(h) result(c)
      !> Element length.
      real(wp), intent(in) :: h
      real(wp) :: c(0:3, 4)
      c(:, 1) = [1.0_wp, 0.0_wp, -3.0_wp, 2.0_wp]   ! 1 - 3 xi^2 + 2 xi^3
      c(:, 2) = h*[0.0_wp, 1.0_wp, -2.0_wp, 1.0_wp] ! h (xi - 2 xi^2 + xi^3)
      c(:, 3) = [0.0_wp, 0.0_wp, 3.0_wp, -2.0_wp]   ! 3 xi^2 - 2 xi^3
      c(:, 4) = h*[0.0_wp, 0.0_wp, -1.0_wp, 1.0_wp] ! h (xi^3 - xi^2)
   end function basis_coefficients

   !> Exact integral over [0, 1] of the product of two polynomials given by coefficients.
   pure function product_integral(p, q) result(s)
      !> Coefficients of the first polynomial.
      real(wp), intent(in) :: p(0:)
      !> Coefficients of the second polynomial.
      real(wp), intent(in) :: q(0:)
      real(wp) :: s
      integer :: a, b
      s = 0
      do a = 0, ubound(p, 1)
         do b = 0, ubound(q, 1)
            s = s + p(a)*q(b)/(a + b + 1)
         end do
      end do
   end function product_integral

   !> Value of a polynomial with coefficients c(0:) at xi (Horner).
   pure function poly(c, xi) result(y)
      !> Coefficients.
      real(wp), intent(in) :: c(0:)
      !> Abscissa.
      real(wp), intent(in) :: xi
      real(wp) :: y
      integer :: k
      y = 0
      do k = ubound(c, 1), 0, -1
         y = y*xi + c(k)
      end do
   end function poly

   !> Mass int(phi_i phi_j) and stiffness k2 int(phi_i'' phi_j'') of one element, by exact
   !> integration of the polynomials of basis_coefficients.
   subroutine exact_element(h, k2, me, se)
      !> Element length.
      real(wp), intent(in) :: h
      !> k^2.
      real(wp), intent(in) :: k2
      !> Mass matrix.
      real(wp), intent(out) :: me(4, 4)
      !> Stiffness matrix.
      real(wp), intent(out) :: se(4, 4)
      real(wp) :: c(0:3, 4), d2(0:1, 4)
      integer :: i, j
      c = basis_coefficients(h)
      do i = 1, 4
         d2(:, i) = [2*c(2, i), 6*c(3, i)]/h**2   ! d^2/dx^2 = (1/h^2) d^2/dxi^2
      end do
      do j = 1, 4
         do i = 1, 4
            me(i, j) = h*product_integral(c(:, i), c(:, j))
            se(i, j) = k2*h*product_integral(d2(:, i), d2(:, j))
         end do
      end do
   end subroutine exact_element

   !> Dense assembly of J equal elements into a (2J+2) matrix, then node 0 (clamped) removed.
   function dense_assembly(elements, e) result(a)
      !> Number of elements J.
      integer, intent(in) :: elements
      !> Element matrix.
      real(wp), intent(in) :: e(4, 4)
      real(wp) :: a(2*elements, 2*elements)
      real(wp) :: full(2*elements + 2, 2*elements + 2)
      integer :: k
      full = 0
      do k = 1, elements
         full(2*k - 1:2*k + 2, 2*k - 1:2*k + 2) = full(2*k - 1:2*k + 2, 2*k - 1:2*k + 2) + e
      end do
      a = full(3:, 3:)
   end function dense_assembly

   !> Lifting shape h(x) = 1 - 2 s^2 + 4/3 s^3 - 1/3 s^4, s = x/L (SPEC 1).
   elemental function lift(x, length) result(y)
      !> Abscissa.
      real(wp), intent(in) :: x
      !> Beam length.
      real(wp), intent(in) :: length
      real(wp) :: y, s
      s = x/length
      y = 1 - 2*s**2 + 4*s**3/3 - s**4/3
   end function lift

   !> Its derivative h'(x).
   elemental function lift_prime(x, length) result(y)
      !> Abscissa.
      real(wp), intent(in) :: x
      !> Beam length.
      real(wp), intent(in) :: length
      real(wp) :: y, s
      s = x/length
      y = (-4*s + 4*s**2 - 4*s**3/3)/length
   end function lift_prime

   !> (h, phi_i) and (1, phi_i) for the unknowns of J elements, by composite Simpson
   !> (400 panels per element; the integrands are polynomials of degree <= 7).
   subroutine simpson_load(elements, length, bh, b1)
      !> Number of elements J.
      integer, intent(in) :: elements
      !> Beam length.
      real(wp), intent(in) :: length
      !> (h, phi_i), node 0 removed (2J).
      real(wp), allocatable, intent(out) :: bh(:)
      !> (1, phi_i), node 0 removed (2J).
      real(wp), allocatable, intent(out) :: b1(:)
      integer, parameter :: panels = 400
      real(wp) :: full_h(2*elements + 2), full_1(2*elements + 2), c(0:3, 4), h, xi, w, x
      integer :: e, q, i
      h = length/elements
      c = basis_coefficients(h)
      full_h = 0
      full_1 = 0
      do e = 1, elements
         do q = 0, 2*panels
            xi = real(q, wp)/(2*panels)
            if (q == 0 .or. q == 2*panels) then
               w = 1
            else if (mod(q, 2) == 1) then
               w = 4
            else
               w = 2
            end if
            w = w*h/(6*panels)
            x = (e - 1 + xi)*h
            do i = 1, 4
               full_h(2*e - 2 + i) = full_h(2*e - 2 + i) + w*poly(c(:, i), xi)*lift(x, length)
               full_1(2*e - 2 + i) = full_1(2*e - 2 + i) + w*poly(c(:, i), xi)
            end do
         end do
      end do
      bh = full_h(3:)
      b1 = full_1(3:)
   end subroutine simpson_load

   !> x = A^{-1} b for a small dense symmetric positive definite A (Cholesky, no LAPACK).
   function solve_spd(a, b) result(x)
      !> Matrix.
      real(wp), intent(in) :: a(:, :)
      !> Right-hand side.
      real(wp), intent(in) :: b(:)
      real(wp) :: x(size(b))
      real(wp) :: l(size(b), size(b)), y(size(b))
      integer :: i, j, n
      n = size(b)
      l = 0
      do j = 1, n
         l(j, j) = sqrt(a(j, j) - sum(l(j, :j - 1)**2))
         do i = j + 1, n
            l(i, j) = (a(i, j) - sum(l(i, :j - 1)*l(j, :j - 1)))/l(j, j)
         end do
      end do
      do i = 1, n
         y(i) = (b(i) - sum(l(i, :i - 1)*y(:i - 1)))/l(i, i)
      end do
      do i = n, 1, -1
         x(i) = (y(i) - sum(l(i + 1:, i)*x(i + 1:)))/l(i, i)
      end do
   end function solve_spd

   !> All eigenvalues (ascending) of S v = lambda M v, both in LAPACK upper band storage.
   subroutine band_eigenvalues(s, m, w, error)
      !> Stiffness, band storage (kd+1, n).
      real(wp), intent(in) :: s(:, :)
      !> Mass, band storage (kd+1, n).
      real(wp), intent(in) :: m(:, :)
      !> Eigenvalues, ascending (n).
      real(wp), allocatable, intent(out) :: w(:)
      !> Set when LAPACK fails.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: sa(:, :), ma(:, :), work(:)
      real(wp) :: zdum(1, 1)
      integer :: n, kd, info
      n = size(s, 2)
      kd = size(s, 1) - 1
      allocate (sa, source=s)
      allocate (ma, source=m)
      allocate (w(n), work(3*n))
      call dsbgv('N', 'U', n, kd, kd, sa, kd + 1, ma, kd + 1, w, zdum, 1, work, info)
      if (info /= 0) call fatal_error(error, dsbgv_message(info, n))
   end subroutine band_eigenvalues

   !> All eigenvalues (ascending) of the dense symmetric pencil (a, b), b positive definite.
   subroutine dense_eigenvalues(a, b, w, error)
      !> Symmetric matrix.
      real(wp), intent(in) :: a(:, :)
      !> Symmetric positive definite matrix.
      real(wp), intent(in) :: b(:, :)
      !> Eigenvalues, ascending.
      real(wp), allocatable, intent(out) :: w(:)
      !> Set when LAPACK fails.
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: aa(:, :), bb(:, :), work(:)
      integer :: n, info
      n = size(a, 1)
      allocate (aa, source=a)
      allocate (bb, source=b)
      allocate (w(n), work(max(1, 3*n - 1)))
      call dsygv(1, 'N', 'U', n, aa, n, bb, n, w, work, size(work), info)
      if (info /= 0) call fatal_error(error, dsygv_message(info, n))
   end subroutine dense_eigenvalues

   !> The model of a scene the engine's checks accept (validate_scene, then prepare_run, as
   !> 'test scene').
   subroutine validated_model(scene, model, error)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(out) :: model
      !> Set when the scene is refused.
      type(error_type), allocatable, intent(out) :: error
      call validate_scene(scene, 'test scene', error)
      if (allocated(error)) return
      call prepare_run(scene, 'test scene', model, error)
   end subroutine validated_model

   !> Validate, prepare and run a scene, every record kept in `rec`; the run must complete
   !> and fill exactly record_count(scene) rows.
   subroutine run_recorded(scene, rec, summary, error)
      !> Scene to run.
      type(scene_type), intent(in) :: scene
      !> Receives every record.
      type(array_recorder), intent(out) :: rec
      !> Outcome.
      type(run_summary), intent(out) :: summary
      !> Set when the scene is refused or the run does not complete.
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      call validated_model(scene, model, error)
      if (allocated(error)) return
      call rec%reserve(record_count(scene), 0_ik, scene%elements + 1, stop_count(scene))
      call simulate(scene, model, rec, summary, error)
      if (allocated(error)) return
      if (summary%status /= status_complete) then
         call fatal_error(error, 'the run ended with status '//summary%status)
         return
      end if
      if (rec%filled /= record_count(scene)) call fatal_error(error, 'the run recorded '//int_text(rec%filled)// &
         & ' rows, record_count gives '//int_text(record_count(scene)))
   end subroutine run_recorded

   !> The paper's beam on J elements with dt, beta, a contact law and t_end (the stops' stiffness
   !> 1e8 per unit mass with compliance).
   function base_scene(elements, dt, beta, law, t_end) result(scene)
      !> Number of elements J.
      integer, intent(in) :: elements
      !> Time step (s), beta, duration (s).
      real(wp), intent(in) :: dt, beta, t_end
      !> Contact law (law_none, law_signorini, law_compliance).
      integer, intent(in) :: law
      type(scene_type) :: scene
      scene%elements = elements
      scene%dt = dt
      scene%beta = beta
      scene%law = law
      scene%t_end = t_end
      if (law == law_compliance) scene%stiffness_per_mass = 1.0e8_wp
   end function base_scene

   !> The tube of input/tube_supports.nml (supports at 1/3 and 2/3, stops at the tip; Signorini,
   !> J = 30, dt = 2e-5, beta = 1/4), to t_end.
   function tube(t_end) result(scene)
      !> Duration (s).
      real(wp), intent(in) :: t_end
      type(scene_type) :: scene
      scene%law = law_signorini
      scene%beta = 0.25_wp
      scene%elements = 30
      scene%dt = 2e-5_wp
      scene%t_end = t_end
      scene%length = 1.5_wp
      scene%amplitude = 0.002_wp
      scene%omega = 40.0_wp
      scene%stop_nodes = [10, 20, 30]
      scene%stop_lower = [-0.002_wp, -0.002_wp, -0.004_wp]
      scene%stop_upper = [0.002_wp, 0.002_wp, 0.004_wp]
   end function tube

   !> The energy balance's defect over the records, max |(E_n - E_0) - (W_n - D_n - damped_n)|,
   !> relative to max |E|.
   function balance_defect(rec) result(defect)
      !> The records of a run.
      type(array_recorder), intent(in) :: rec
      real(wp) :: defect
      integer(ik) :: j
      defect = 0
      do j = 1, rec%filled
         defect = max(defect, abs((rec%rows(col_energy, j) - rec%rows(col_energy, 1)) - (rec%rows(col_work, j) &
            & - rec%rows(col_dissipated, j) - rec%rows(col_damped, j))))
      end do
      defect = defect/maxval(abs(rec%rows(col_energy, 1:rec%filled)))
   end function balance_defect

   !> Fail with "[what: ]column c differs" at the first record column whose rows differ between
   !> two recorders (each compared as its filled rows).
   subroutine same_columns(error, a, b, what)
      !> Set at the first column that differs.
      type(error_type), allocatable, intent(inout) :: error
      !> The two runs' records.
      type(array_recorder), intent(in) :: a, b
      !> What is compared, leading the message.
      character(len=*), intent(in), optional :: what
      integer :: c
      do c = 1, n_columns
         if (any(a%rows(c, 1:a%filled) /= b%rows(c, 1:b%filled))) then
            if (present(what)) then
               call fatal_error(error, what//': column '//int_text(c)//' differs')
            else
               call fatal_error(error, 'column '//int_text(c)//' differs')
            end if
            return
         end if
      end do
   end subroutine same_columns
end module test_support
