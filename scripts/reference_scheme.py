"""Pure numpy/scipy reference implementation of the beamstops scheme (SPEC.md §3-§6).

Independent of the Fortran engine: used as the "what a user would write in
Python" baseline in benchmarks and as a cross-check in tests.  Same conventions
as the engine: Hermite cubics on J equal elements (node 0 clamped and removed,
unknowns (u_1, u'_1, ..., u_J, u'_J), tip value at 0-based index 2J-2), matrices
per unit mass in LAPACK upper band storage (kd = 3), the paper's Newmark-type
scheme in increment form with the tip-only Signorini projection (Lemma 4.1).

Run as ``python scripts/reference_scheme.py`` or ``python -m scripts.reference_scheme``.
"""

from __future__ import annotations

import time

import numpy as np

KD = 3  # half-bandwidth of the Hermite-cubic matrices


def h_shape(x: np.ndarray, L: float) -> np.ndarray:
    """Lifting function h(x) = 1 - 2s^2 + (4/3)s^3 - (1/3)s^4, s = x/L."""
    s = np.asarray(x) / L
    return 1.0 - 2.0 * s**2 + (4.0 / 3.0) * s**3 - (1.0 / 3.0) * s**4


def h_shape_dx(x: np.ndarray, L: float) -> np.ndarray:
    """Derivative h'(x)."""
    s = np.asarray(x) / L
    return (-4.0 * s + 4.0 * s**2 - (4.0 / 3.0) * s**3) / L


def band_matvec(ab: np.ndarray, x: np.ndarray) -> np.ndarray:
    """y = A x for symmetric A in upper band storage ab[kd + i - j, j] = A[i, j]."""
    kd = ab.shape[0] - 1
    y = ab[kd] * x
    for d in range(1, kd + 1):
        a = ab[kd - d, d:]  # A[j-d, j], j = d..n-1
        y[:-d] += a * x[d:]
        y[d:] += a * x[:-d]
    return y


def band_to_dense(ab: np.ndarray) -> np.ndarray:
    """Unpack upper symmetric band storage into a dense symmetric matrix."""
    kd, n = ab.shape[0] - 1, ab.shape[1]
    A = np.zeros((n, n))
    for d in range(kd + 1):
        idx = np.arange(d, n)
        A[idx - d, idx] = ab[kd - d, d:]
        A[idx, idx - d] = ab[kd - d, d:]
    return A


def assemble(J: int, L: float, k2: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Assemble (M, S, b_h, b_1): M, S of shape (4, 2J) in upper band storage,
    b_h[i] = ∫ h ϕ_i dx and b_1[i] = ∫ ϕ_i dx by 4-point Gauss-Legendre per element."""
    n, h = 2 * J, L / J
    Me = h / 420.0 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                               [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])
    Se = 2.0 * k2 / h**3 * np.array([[6, 3 * h, -6, 3 * h], [3 * h, 2 * h * h, -3 * h, h * h],
                                     [-6, -3 * h, 6, -3 * h], [3 * h, h * h, -3 * h, 2 * h * h]])
    xg, wg = np.polynomial.legendre.leggauss(4)
    xi, w = 0.5 * (xg + 1.0), 0.5 * wg * h  # nodes on [0, 1], weights scaled to the element
    N = np.array([1 - 3 * xi**2 + 2 * xi**3, h * (xi - 2 * xi**2 + xi**3),
                  3 * xi**2 - 2 * xi**3, h * (-xi**2 + xi**3)])  # (4 shapes, 4 points)
    M, S = np.zeros((KD + 1, n)), np.zeros((KD + 1, n))
    bh, b1 = np.zeros(n), np.zeros(n)
    for e in range(J):
        dofs = [2 * e - 2, 2 * e - 1, 2 * e, 2 * e + 1]  # global dofs of nodes e, e+1 (-1: clamped)
        he = N @ (w * h_shape(e * h + xi * h, L))
        ie = N @ w
        for a, I in enumerate(dofs):
            if I < 0:
                continue
            bh[I] += he[a]
            b1[I] += ie[a]
            for b, Jg in enumerate(dofs):
                if I <= Jg:
                    M[KD + I - Jg, Jg] += Me[a, b]
                    S[KD + I - Jg, Jg] += Se[a, b]
    return M, S, bh, b1


def run_reference(J: int = 19, L: float = 1.501, k2: float = 282.84, amplitude: float = 0.2,
                  omega: float = 10.0, lower: float = -0.1, upper: float = 0.1, dt: float = 5e-5,
                  t_end: float = 2.0, beta: float = 0.5, load_rule: str = "centered",
                  start: str = "taylor", mass_per_length: float = 0.11938,
                  contact: bool = True) -> dict[str, np.ndarray | float | int]:
    """Run the scheme; return time series (length N+1) of t, tip_u, tip_v, reaction [N],
    energy, work, dissipated [J] plus cpu_seconds (loop only) and steps = N."""
    from scipy.linalg import cho_solve_banded, cholesky_banded  # here: assemble needs numpy only (bench_peer.py)

    if load_rule not in ("paper", "centered") or start not in ("euler", "taylor"):
        raise ValueError(f"bad load_rule={load_rule!r} or start={start!r}")
    M, S, bh, b1 = assemble(J, L, k2)
    n, tip, dt2, N = 2 * J, 2 * J - 2, dt * dt, int(round(t_end / dt))
    g = amplitude * (omega**2 * bh + (8.0 * k2 / L**4) * b1)
    # time-averaged sin(omega t) over a cell of width dt centred at c_k, k = 0..N+1
    k = np.arange(N + 2, dtype=float)
    c = (k + 0.5) * dt if load_rule == "paper" else k * dt
    x = 0.5 * omega * dt
    sbar = np.sin(omega * c) * (np.sin(x) / x if x != 0.0 else 1.0)
    wG = np.zeros(N + 1)
    wG[1:] = beta * sbar[2:] + (1.0 - 2.0 * beta) * sbar[1:-1] + beta * sbar[:-2]
    # initial data: u0 = 0, v0 = -a*omega*h Hermite-interpolated
    xn = np.arange(1, J + 1) * (L / J)
    u0, v0 = np.zeros(n), np.empty(n)
    v0[0::2], v0[1::2] = -amplitude * omega * h_shape(xn, L), -amplitude * omega * h_shape_dx(xn, L)
    u1 = u0 + dt * v0
    if start == "taylor":  # G(0) = sin(0) g = 0 pointwise
        a0 = cho_solve_banded((cholesky_banded(M), False), 0.0 * g - band_matvec(S, u0))
        u1 = u1 + 0.5 * dt2 * a0
    cA = cholesky_banded(M + dt2 * beta * S)
    z = cho_solve_banded((cA, False), np.eye(n)[tip])
    if contact and not lower <= u1[tip] <= upper:
        bound = upper if u1[tip] > upper else lower
        u1 = u1 + (bound - u1[tip]) / z[tip] * z
        u1[tip] = bound

    def energy(d: np.ndarray, un: np.ndarray, Sun: np.ndarray, up: np.ndarray, Sup: np.ndarray) -> float:
        return 0.5 * d @ band_matvec(M, d) / dt2 + 0.5 * (
            beta * (un @ Sun) + beta * (up @ Sup) + (1.0 - 2.0 * beta) * (up @ Sun))

    out = {key: np.zeros(N + 1) for key in ("tip_u", "tip_v", "reaction", "energy", "work", "dissipated")}
    out["t"] = np.arange(N + 1) * dt
    u_prev, u, d, Su = u0, u1, u1 - u0, band_matvec(S, u1)
    out["tip_u"][0], out["tip_v"][0] = u0[tip], v0[tip]
    out["energy"][0] = mass_per_length * energy(d, u1, Su, u0, band_matvec(S, u0))
    work = diss = 0.0
    t0 = time.process_time()
    for step in range(1, N + 1):
        G = wG[step] * g
        d = d + cho_solve_banded((cA, False), dt2 * (G - Su), check_finite=False)
        u_new = u + d
        r = 0.0
        if contact and not lower <= u_new[tip] <= upper:
            bound = upper if u_new[tip] > upper else lower
            cc = (bound - u_new[tip]) / z[tip]
            u_new += cc * z
            u_new[tip] = bound
            d = u_new - u
            r = cc / dt2
        Su_new = band_matvec(S, u_new)
        out["tip_u"][step] = u[tip]
        out["tip_v"][step] = (u_new[tip] - u_prev[tip]) / (2.0 * dt)
        out["reaction"][step] = mass_per_length * r
        work += 0.5 * (G @ (u_new - u_prev))
        diss -= 0.5 * r * (u_new[tip] - u_prev[tip])
        out["work"][step], out["dissipated"][step] = mass_per_length * work, mass_per_length * diss
        out["energy"][step] = mass_per_length * energy(d, u_new, Su_new, u, Su)
        u_prev, u, Su = u, u_new, Su_new
    result: dict[str, np.ndarray | float | int] = dict(out)
    result["cpu_seconds"], result["steps"] = time.process_time() - t0, N
    return result


def main() -> None:
    """Paper's Figure 2 scene (beta = 1/2, dt = 5e-5, J = 19) up to t = 0.2 s."""
    lower, upper = -0.1, 0.1
    res = run_reference(J=19, beta=0.5, dt=5e-5, t_end=0.2, lower=lower, upper=upper)
    tip_u, steps = np.asarray(res["tip_u"]), int(res["steps"])  # type: ignore[arg-type]
    viol = max(0.0, float(np.max(tip_u - upper)), float(np.max(lower - tip_u)))
    print(f"steps                 {steps}")
    print(f"microseconds per step {1e6 * float(res['cpu_seconds']) / steps:.2f}")  # type: ignore[arg-type]
    print(f"max |tip_u| [m]       {np.max(np.abs(tip_u)):.6f}")
    print(f"max stop violation    {viol:.3e}")


if __name__ == "__main__":
    main()
