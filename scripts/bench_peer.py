#!/usr/bin/python3
"""A peer on the paper's scene: Siconos (Debian's ``python3-siconos``, 4.4), timed in its own loop.

    /usr/bin/python3 scripts/bench_peer.py [--quick] [--dt 5e-5] [--t-end 2.0]

Prints one JSON object: ``{"available": false, "note": ...}`` when Siconos does not import
(it imports only under the system Python, not in a venv), else the version, the steps, the
seconds of the loop, µs per step and the largest violation of the stops (m). scripts/bench.py
runs it as a subprocess under ``/usr/bin/python3`` and puts it beside the engine.

The same finite-element model as the engine: Hermite cubics on J = 19 elements, M and S per
unit mass, the load vector g of the vibrating support (``reference_scheme.assemble``, numpy
only), the beam at rest relative to the support at t = 0. Siconos' own scheme: a
``LagrangianLinearTIDS`` integrated by ``MoreauJeanOSI`` with θ = 1/2, the two stops as two
unilateral ``LagrangianLinearTIR`` (u_tip - lower >= 0, upper - u_tip >= 0), each with a
``NewtonImpactNSL`` (e = 0, the paper's inelastic impact), an ``LCP`` each step, a
``TimeStepping`` loop of ``computeOneStep``/``nextStep``.

The support's forcing sin(ωt) g has to reach Siconos' C++ loop without a Python callback per
step (which would time Python, not Siconos): it is the state of one more degree of freedom,
an oscillator x'' = -ω² x with x(0) = 0, x'(0) = ω, i.e. x = sin(ωt), coupled into the beam by
the stiffness entry -g (q = [u, x], K = [[S, -g], [0, ω²]]). Its phase error under θ = 1/2 is
O((ω dt)²) ≈ 1e-7 at dt = 5e-5: nothing beside the violations measured.

The timed loop reads the tip each step (one small copy out of Siconos) to find the largest
violation max(u_tip - upper, lower - u_tip, 0): Moreau–Jean enforces the stops on velocities,
so positions may pass them by O(dt·|v|). The same loop without the read is timed too.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

try:  # Debian's python3-siconos brings python3-numpy; without either there is no peer to run
    import numpy as np

    import reference_scheme  # (numpy only at import)
except ImportError as missing_numpy:  # main() says so in its JSON
    np = None
    reference_scheme = None
    MISSING: ImportError | None = missing_numpy
else:
    MISSING = None

# The paper's scene (input/paper_fig2.nml without its load rule: Siconos sees the load pointwise).
SCENE = dict(length=1.501, k2=282.84, amplitude=0.2, omega=10.0, lower=-0.1, upper=0.1, elements=19)


def dense(ab: np.ndarray) -> np.ndarray:
    return reference_scheme.band_to_dense(ab)


def build(kernel, dt: float, t_end: float):
    """The Siconos model and its simulation; returns (simulation, beam, tip index)."""
    s = SCENE
    J, L, a, w = s["elements"], s["length"], s["amplitude"], s["omega"]
    M, S, bh, b1 = reference_scheme.assemble(J, L, s["k2"])
    n, tip = 2 * J, 2 * J - 2
    g = a * (w**2 * bh + (8.0 * s["k2"] / L**4) * b1)  # G(t) = sin(ωt) g, as reference_scheme
    mass = np.zeros((n + 1, n + 1))
    mass[:n, :n] = dense(M)
    mass[n, n] = 1.0
    stiffness = np.zeros((n + 1, n + 1))
    stiffness[:n, :n] = dense(S)
    stiffness[:n, n] = -g
    stiffness[n, n] = w**2
    xn = np.arange(1, J + 1) * (L / J)
    q0, v0 = np.zeros(n + 1), np.zeros(n + 1)
    v0[0:n:2] = -a * w * reference_scheme.h_shape(xn, L)
    v0[1:n:2] = -a * w * reference_scheme.h_shape_dx(xn, L)
    v0[n] = w  # x = sin(ωt)
    beam = kernel.LagrangianLinearTIDS(q0, v0, mass)
    beam.setKPtr(stiffness)

    model = kernel.NonSmoothDynamicalSystem(0.0, t_end)
    model.insertDynamicalSystem(beam)
    for sign, offset in ((1.0, -s["lower"]), (-1.0, s["upper"])):  # y = ±u_tip + offset >= 0
        C = np.zeros((1, n + 1))
        C[0, tip] = sign
        stop = kernel.Interaction(kernel.NewtonImpactNSL(0.0), kernel.LagrangianLinearTIR(C, np.array([offset])))
        model.link(stop, beam)
    osi = kernel.MoreauJeanOSI(0.5)
    lcp = kernel.LCP()
    simulation = kernel.TimeStepping(model, kernel.TimeDiscretisation(0.0, dt), osi, lcp)
    return simulation, beam, tip


def run(kernel, dt: float, t_end: float, watch: bool) -> dict[str, float]:
    simulation, beam, tip = build(kernel, dt, t_end)
    lower, upper = SCENE["lower"], SCENE["upper"]
    violation, steps = 0.0, 0
    start = time.process_time()
    if watch:
        while simulation.hasNextEvent():
            simulation.computeOneStep()
            u_tip = beam.q()[tip]
            violation = max(violation, u_tip - upper, lower - u_tip)
            simulation.nextStep()
            steps += 1
    else:
        while simulation.hasNextEvent():
            simulation.computeOneStep()
            simulation.nextStep()
            steps += 1
    seconds = time.process_time() - start
    return {"steps": steps, "seconds": seconds, "us_per_step": 1e6 * seconds / steps,
            "max_violation": violation, "u_tip_final": float(beam.q()[tip])}


def package_version(siconos) -> str:
    """Debian's package version when dpkg knows it (the module's own ``version`` reads 4.5.0 in 4.4.0)."""
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "python3-siconos"], capture_output=True,
                             text=True, check=True).stdout.strip()
        return f"python3-siconos {out}"
    except (OSError, subprocess.CalledProcessError):
        return f"siconos {getattr(siconos, 'version', '?')}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="0.2 s of simulated time instead of 2 s")
    parser.add_argument("--dt", type=float, default=5e-5, help="time step (s), default 5e-5")
    parser.add_argument("--t-end", type=float, default=None, help="simulated time (s), default 2 (quick 0.2)")
    args = parser.parse_args()
    t_end = args.t_end or (0.2 if args.quick else 2.0)
    try:
        if MISSING is not None:
            raise MISSING
        import siconos
        import siconos.kernel as kernel
    except ImportError as exc:
        print(json.dumps({"available": False, "note": f"Siconos does not import under {sys.executable} ({exc}); "
                          "Debian: sudo apt-get install python3-siconos"}))
        return 0
    watched = run(kernel, args.dt, t_end, watch=True)
    bare = run(kernel, args.dt, t_end, watch=False)
    print(json.dumps({"available": True, "version": package_version(siconos), "python": sys.executable,
                      "dt": args.dt, "t_end": t_end, "steps": bare["steps"],
                      "us_per_step": bare["us_per_step"], "us_per_step_watched": watched["us_per_step"],
                      "max_violation": watched["max_violation"], "u_tip_final": watched["u_tip_final"]}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
