"""The engine, through the f2py extension ``beamstops._engine``.

Every number here comes from the Fortran engine: the scene is passed as flat scalars
to plain wrapper subroutines (wrap/beamstops_wrap.f90), which validate it with the
engine's ``validate_scene``, build the model and run the same time loop as the
``beamstops`` program, recording into memory instead of an HDF5 file. An engine error
(status /= 0) becomes a :class:`ValueError` carrying the engine's message.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Callable, Optional

import numpy as np

from . import _engine
from .result import IncompleteRunError, Result
from .scene import LAWS, PathLike, Scene

__all__ = ["run", "stability", "validate", "sizes", "read_namelist", "tube", "version", "Stability"]

_LAW_NAMES = {code: name for name, code in LAWS.items()}
_RUN_STATUS = {0: "complete", 1: "diverged", 2: "failed"}
# A flag for integers beyond what the wrapper's integer(8) arguments hold.
_INT64 = 2**63


def _text(value: Any) -> str:
    """f2py returns fixed-length character outputs as bytes, blank-padded (character inputs
    are passed as bytes too, file-system encoded, so that any path goes through)."""
    if isinstance(value, (bytes, np.bytes_)):
        value = bytes(value).decode("utf-8", errors="replace")
    return str(value).rstrip(" \x00")


def _flat(scene: Scene) -> tuple[Any, ...]:
    """The scene as the wrapper's flat arguments (see wrap/beamstops_wrap.f90)."""
    if not isinstance(scene, Scene):
        raise TypeError(f"expected a beamstops.Scene, not {type(scene).__name__}")
    for key in ("elements", "record_every", "snapshot_every"):
        value = getattr(scene, key)
        if not -_INT64 < value < _INT64:
            group = "mesh" if key == "elements" else "output"
            raise ValueError(f"scene: &{group} {key} = {value} is out of range; allowed: |{key}| < 2**31")
    if any(not -_INT64 < node < _INT64 for node in scene.nodes):
        raise ValueError("scene: &stops nodes is out of range; allowed: 1 <= nodes <= elements")
    if scene.nodes:
        tip_lower, tip_upper = Scene.lower, Scene.upper  # unused with stops along the span
        lower, upper = scene.lower, scene.upper
    else:
        tip_lower, tip_upper = scene.lower, scene.upper
        lower = upper = ()
    # The stops' arrays carry one padding value (f2py refuses input arrays of size 0).
    return (scene.length, scene.k2, scene.mass_per_length, scene.amplitude, scene.omega, tip_lower,
            tip_upper, LAWS[scene.law], scene.stiffness_per_mass, scene.elements, scene.dt, scene.t_end,
            scene.beta, int(scene.load_rule == "centered"), int(scene.start == "taylor"),
            int(scene.allow_unstable), scene.record_every, scene.snapshot_every, scene.max_output_gb,
            np.array(list(scene.nodes) + [0], dtype=np.int64), np.array(list(lower) + [0.0]),
            np.array(list(upper) + [0.0]))


def _check(status: int, message: Any) -> None:
    if status != 0:
        raise ValueError(_text(message))


def version() -> str:
    """The engine's version."""
    return _text(_engine.bs_version())


def validate(scene: Scene, source: str = "scene") -> None:
    """Check a scene with the engine's ``validate_scene``; ValueError names group, key and range."""
    _check(*_engine.bs_validate(*_flat(scene), os.fsencode(source)))


def sizes(scene: Scene) -> tuple[int, int, int]:
    """Records and snapshots of a complete run, and nodes J+1 per snapshot."""
    records, snapshots, nodes, status, message = _engine.bs_sizes(*_flat(scene))
    _check(status, message)
    return int(records), int(snapshots), int(nodes)


@dataclass(frozen=True)
class Stability:
    """Spectrum and time-step limits of a scene (SPEC §6), all from the engine's model."""

    kappa_h: float
    """Largest generalized eigenvalue κ_h of (S, M) (1/s²)."""
    kappa_bound: float
    """The paper's upper bound κ̃ (5.2) (1/s²)."""
    kappa_contact: float
    """Largest eigenvalue with the compliance spring at the tip (= κ_h for other laws) (1/s²)."""
    kappa_method: str
    """How κ_h was computed: 'dsbgv' (exact) or 'inverse iteration'."""
    dt_limit_newmark: float
    """Linear Newmark limit 2/sqrt((1-4β)κ) for β < 1/4, +inf otherwise (s)."""
    dt_limit_paper: float
    """Paper's condition (3.1) with the exact κ_h, 2/sqrt((1-2β)κ_h); +inf for β = 1/2 (s)."""
    dt_limit_paper_bound: float
    """Paper's condition (3.1) with its bound κ̃ (s); 3.3469e-6 s for the paper's scene at β = 1/4."""
    dt: float
    """The scene's time step (s)."""
    refusal: Optional[str]
    """Why the engine would refuse to run the scene (dt beyond the linear limit), or None."""

    @property
    def runnable(self) -> bool:
        """Whether :func:`run` accepts the scene's time step."""
        return self.refusal is None


def stability(scene: Scene) -> Stability:
    """κ_h, the paper's κ̃ and the time-step limits of a scene (builds the model, does not run)."""
    (kappa_h, kappa_bound, kappa_contact, dt_newmark, dt_paper, dt_paper_bound, method, refused, refusal,
     status, message) = _engine.bs_stability(*_flat(scene))
    _check(status, message)
    return Stability(kappa_h=float(kappa_h), kappa_bound=float(kappa_bound), kappa_contact=float(kappa_contact),
                     kappa_method=_text(method), dt_limit_newmark=float(dt_newmark),
                     dt_limit_paper=float(dt_paper), dt_limit_paper_bound=float(dt_paper_bound),
                     dt=scene.dt, refusal=_text(refusal) if refused else None)


def run(scene: Scene, *, allow_incomplete: bool = False) -> Result:
    """Run a scene in memory and return its :class:`Result` (no file is written).

    Same engine loop as ``beamstops run``: for the same scene, every array and every
    attribute but ``cpu_seconds`` equals the program's HDF5 output bit for bit.
    A run that does not complete (it diverged) raises :class:`IncompleteRunError`
    (a ValueError holding the partial result) unless ``allow_incomplete``.
    """
    flat = _flat(scene)
    records, snapshots, nodes = sizes(scene)
    (t, tip_u, tip_v, reaction, energy, work, dissipated, snapshot_t, snapshot_x, snapshot_u, stops_u,
     stops_reaction, filled, snaps, kappa_h, kappa_bound, dt_newmark, dt_paper, dt_paper_bound, steps, t_final,
     cpu_seconds, impacts, max_violation, run_status, run_message, status, message) = _engine.bs_run(
        *flat, records, snapshots, nodes)
    _check(status, message)
    filled, snaps = int(filled), int(snaps)
    attrs: dict[str, Any] = {
        "status": _RUN_STATUS.get(int(run_status), "failed"),
        "version": version(),
        "length": scene.length, "k2": scene.k2, "mass_per_length": scene.mass_per_length,
        "amplitude": scene.amplitude, "omega": scene.omega,
    }
    if scene.nodes:
        attrs["stops"] = len(scene.nodes)
    else:
        attrs.update({"lower": scene.lower, "upper": scene.upper})
    attrs["law"] = scene.law
    if scene.law == "compliance":
        attrs["stiffness_per_mass"] = scene.stiffness_per_mass
    attrs.update({
        "elements": scene.elements, "dt": scene.dt, "t_end": scene.t_end, "beta": scene.beta,
        "load_rule": scene.load_rule, "start": scene.start, "record_every": scene.record_every,
        "snapshot_every": scene.snapshot_every, "allow_unstable": int(scene.allow_unstable),
        "max_output_gb": scene.max_output_gb,
        "kappa_h": float(kappa_h), "kappa_bound": float(kappa_bound), "dt_limit_newmark": float(dt_newmark),
        "dt_limit_paper": float(dt_paper), "dt_limit_paper_bound": float(dt_paper_bound),
        "steps": int(steps), "t_final": float(t_final), "cpu_seconds": float(cpu_seconds),
        "impacts": int(impacts), "max_violation": float(max_violation),
    })
    if attrs["status"] != "complete":
        attrs["message"] = _text(run_message)
    cut: Callable[[np.ndarray], np.ndarray] = (lambda a: a) if filled == records else (lambda a: a[:filled].copy())
    result = Result(
        t=cut(t), tip_u=cut(tip_u), tip_v=cut(tip_v), reaction=cut(reaction), energy=cut(energy),
        work=cut(work), dissipated=cut(dissipated),
        snapshot_t=snapshot_t[:snaps] if snaps == snapshots else snapshot_t[:snaps].copy(),
        snapshot_x=snapshot_x,
        snapshot_u=np.ascontiguousarray(snapshot_u.T[:snaps]),
        stops_x=snapshot_x[list(scene.nodes)] if scene.nodes else np.empty(0),
        stops_node=np.array(scene.nodes, dtype=np.float64),
        stops_lower=np.array(scene.lower if scene.nodes else (), dtype=np.float64),
        stops_upper=np.array(scene.upper if scene.nodes else (), dtype=np.float64),
        stops_u=np.ascontiguousarray(stops_u.T[:filled]), stops_reaction=np.ascontiguousarray(stops_reaction.T[:filled]),
        attrs=attrs, source="memory")
    if attrs["status"] != "complete" and not allow_incomplete:
        raise IncompleteRunError(f"scene: run {attrs['status']}: {attrs.get('message', '')}", result)
    return result


def read_namelist(path: PathLike) -> Scene:
    """The scene the program itself (the engine's namelist reader) reads from a file."""
    (length, k2, mass_per_length, amplitude, omega, lower, upper, law, stiffness_per_mass, elements, dt, t_end,
     beta, centered_load, taylor_start, allow_unstable, record_every, snapshot_every, max_output_gb, stop_count,
     file, status, message) = _engine.bs_read_scene(os.fsencode(path))
    _check(status, message)
    nodes: tuple[int, ...] = ()
    if stop_count > 0:
        stop_nodes, stop_lower, stop_upper, status, message = _engine.bs_read_stops(os.fsencode(path), stop_count)
        _check(status, message)
        nodes = tuple(int(n) for n in stop_nodes)
        lower, upper = tuple(float(v) for v in stop_lower), tuple(float(v) for v in stop_upper)
    return Scene(length=length, k2=k2, mass_per_length=mass_per_length, amplitude=amplitude, omega=omega,
                 lower=lower, upper=upper, nodes=nodes, law=_LAW_NAMES[int(law)],
                 stiffness_per_mass=stiffness_per_mass,
                 elements=int(elements), dt=dt, t_end=t_end, beta=beta,
                 load_rule="centered" if centered_load else "paper", start="taylor" if taylor_start else "euler",
                 allow_unstable=bool(allow_unstable), file=_text(file), record_every=int(record_every),
                 snapshot_every=int(snapshot_every), max_output_gb=max_output_gb)


def tube(youngs_modulus: float, density: float, outer_diameter: float, wall_thickness: float) -> tuple[float, float]:
    """k² = EI/(ρS) and ρS of a tube, by the engine's formulas (as the namelist reader derives them)."""
    k2, mass_per_length = _engine.bs_tube(youngs_modulus, density, outer_diameter, wall_thickness)
    return float(k2), float(mass_per_length)
