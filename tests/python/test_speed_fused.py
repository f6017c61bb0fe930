"""The optimized path of the time loop against the LAPACK path, to round-off.

The engine solves A x = b with fused forward/back substitutions on LAPACK's own factor
(src/beamstops/band_solve.f90) and runs the step arranged around them
(advance_fused in src/beamstops/scheme.f90); state%lapack_solve selects the reference
step (dpbtrs, one operation after the other). Both are reached through the small f2py
module of scripts/bench_step.f90, built by scripts/bench_ext.py against a meson build of
the engine: $BEAMSTOPS_BUILD, else build/tests (scripts/test.sh), build/bench
(scripts/bench.py) or a build/speed-test configured here. No timing is asserted.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import solveh_banded

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "scripts"))

import bench_ext  # noqa: E402
import reference_scheme  # noqa: E402

EPS = np.finfo(float).eps
SIGNORINI, NONE, COMPLIANCE = 1, 0, 2


def _find_build() -> Path:
    return bench_ext.meson_build(bench_ext.existing_build("speed-test"), bench=False)


@pytest.fixture(scope="module")
def ext():
    if shutil.which("meson") is None or shutil.which(os.environ.get("FC", "gfortran")) is None:
        pytest.skip("meson and a Fortran compiler are needed to build the test extension")
    return bench_ext.step_extension(_find_build())


def random_spd_band(n: int, rng: np.random.Generator, spread: float) -> np.ndarray:
    """A random SPD matrix with half-bandwidth 3 in LAPACK upper band storage (4, n):
    A = U^T U with U upper band, diagonal entries spanning `spread` decades."""
    u = np.zeros((4, n))
    u[3] = 10.0 ** rng.uniform(-spread / 2, spread / 2, n)
    for d in range(1, min(4, n)):
        u[3 - d, d:] = rng.standard_normal(n - d) * 0.5 * np.minimum(u[3, d:], u[3, :-d])
    dense_u = np.zeros((n, n))
    for d in range(min(4, n)):
        idx = np.arange(d, n)
        dense_u[idx - d, idx] = u[3 - d, d:]
    a = dense_u.T @ dense_u
    ab = np.zeros((4, n))
    for d in range(min(4, n)):
        idx = np.arange(d, n)
        ab[3 - d, d:] = a[idx - d, idx]
    return ab


def condition(ab: np.ndarray) -> float:
    return float(np.linalg.cond(reference_scheme.band_to_dense(ab)))


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 38, 101, 1000])
@pytest.mark.parametrize("spread", [0.0, 3.0])
def test_fused_solve_matches_dpbtrs_on_random_spd_band(ext, n, spread):
    rng = np.random.default_rng(1000 * n + int(10 * spread))
    for _ in range(5):
        ab = random_spd_band(n, rng, spread)
        b = rng.standard_normal(n)
        x_lapack, x_fused, status = ext.solve_both(ab, b)
        assert status == 0
        scale = np.linalg.norm(x_lapack)
        # both backward stable: agreement to a modest multiple of cond(A) eps
        assert np.linalg.norm(x_fused - x_lapack) <= 50 * n * condition(ab) * EPS * scale
        # and both solve the system (scipy's own banded Cholesky as a third opinion)
        assert np.allclose(x_fused, solveh_banded(ab, b), rtol=0, atol=50 * n * condition(ab) * EPS * scale)


@pytest.mark.parametrize("dt, beta", [(1e-6, 0.5), (5e-5, 0.5), (5e-6, 0.25)])
def test_fused_solve_matches_dpbtrs_on_the_paper_matrix(ext, dt, beta):
    m, s, _, _ = reference_scheme.assemble(19, 1.501, 282.84)
    ab = m + dt * dt * beta * s
    rng = np.random.default_rng(7)
    for _ in range(10):
        b = rng.standard_normal(38)
        x_lapack, x_fused, status = ext.solve_both(ab, b)
        assert status == 0
        assert np.max(np.abs(x_fused - x_lapack)) <= 1e-13 * np.max(np.abs(x_lapack))


def whole_run(ext, lapack: bool, *, elements=19, dt=5e-5, t_end=0.3, beta=0.5, law=SIGNORINI,
              stiffness=0.0, every=1) -> np.ndarray:
    assert ext.init(elements, dt, t_end, beta, law, stiffness, every, int(lapack)) == 0
    capacity = int(round(t_end / dt)) // every + 2
    rows, filled, status = ext.run_records(capacity)
    assert status == 0
    return rows[:, :filled]


def relative_differences(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Largest difference of each record column, relative to the column's largest value."""
    assert a.shape == b.shape
    scale = np.maximum(np.max(np.abs(b), axis=1), 1e-300)
    return np.max(np.abs(a - b), axis=1) / scale


# columns: t, tip u, tip v, reaction, energy, work, dissipated
@pytest.mark.parametrize("elements", [1, 2, 3, 4, 19])
@pytest.mark.parametrize("every", [1, 3])
def test_whole_run_free_beam_matches_lapack_path(ext, elements, every):
    """No stops: a linear recursion, where round-off grows only slowly (40,000 steps)."""
    kwargs = dict(elements=elements, dt=5e-5, t_end=2.0, law=NONE, every=every)
    fused, lapack = whole_run(ext, False, **kwargs), whole_run(ext, True, **kwargs)
    rel = relative_differences(fused, lapack)
    assert rel[0] == 0
    assert np.all(rel[[1, 2, 4, 5]] < 1e-9), rel


@pytest.mark.parametrize("elements", [1, 2, 3, 4, 19])
def test_whole_run_signorini_matches_lapack_path(ext, elements):
    """Signorini stops over the first impacts (6,000 steps, beta = 1/2)."""
    kwargs = dict(elements=elements, dt=5e-5, t_end=0.3, law=SIGNORINI)
    fused, lapack = whole_run(ext, False, **kwargs), whole_run(ext, True, **kwargs)
    assert np.count_nonzero(lapack[3]) > 0, "the run should reach the stops"
    rel = relative_differences(fused, lapack)
    assert np.all(rel < 1e-6), rel
    assert np.all(rel[[1, 4, 5]] < 1e-8), rel


def test_whole_run_compliance_matches_lapack_path(ext):
    """Normal compliance (1/eps = 1e8 per unit mass, beta = 1/4, dt = 1e-6) through the first
    contact. The stiff spring amplifies round-off (here two compilations of the same code,
    with and without -march=native, differ by 2e-4 in the reaction), hence looser bounds."""
    kwargs = dict(elements=19, dt=1e-6, t_end=0.15, beta=0.25, law=COMPLIANCE, stiffness=1e8, every=10)
    fused, lapack = whole_run(ext, False, **kwargs), whole_run(ext, True, **kwargs)
    assert np.count_nonzero(lapack[3]) > 0, "the run should reach the stops"
    rel = relative_differences(fused, lapack)
    assert np.all(rel < 3e-3), rel
    assert rel[1] < 3e-5, rel


def test_per_step_calls_match_one_call(ext):
    """Driving the engine one step per call from Python gives the same state as one call."""
    assert ext.init(19, 1e-6, 1.0, 0.5, SIGNORINI, 0.0, 0, 0) == 0
    stepped = [ext.step() for _ in range(2000)][-1]
    assert ext.init(19, 1e-6, 1.0, 0.5, SIGNORINI, 0.0, 0, 0) == 0
    assert ext.steps(2000) == stepped
