"""The benchmark's peer (scripts/bench_peer.py, Siconos under /usr/bin/python3) solves the engine's problem.

Before the first impact (t ≈ 0.088 s) the stops do nothing and both schemes are second-order
discretizations of the same linear system (the same M, S, load and initial data): at dt = 5e-5 s
their tips agree to O(dt²), far below what a wrong mass, load, sign or start would give (centimetres).
After the first impacts Siconos' Moreau–Jean scheme lets the tip pass the stops by O(dt·|v|); the
engine's projection keeps it on them. Skipped where Siconos does not import under /usr/bin/python3.
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import h5py
import pytest

ROOT = Path(__file__).resolve().parents[2]
SYSTEM_PYTHON = Path("/usr/bin/python3")


def siconos_present() -> bool:
    if not SYSTEM_PYTHON.exists():
        return False
    return subprocess.run([str(SYSTEM_PYTHON), "-c", "import siconos.kernel"], capture_output=True).returncode == 0


pytestmark = pytest.mark.skipif(not siconos_present(), reason="Siconos (python3-siconos) absent under /usr/bin/python3")


def peer(t_end: float) -> dict:
    done = subprocess.run([str(SYSTEM_PYTHON), str(ROOT / "scripts" / "bench_peer.py"), "--t-end", str(t_end)],
                          capture_output=True, text=True, check=True)
    result = json.loads(done.stdout)
    assert result["available"]
    return result


def engine_tip(program: str, tmp_path: Path, t_end: float) -> float:
    out = tmp_path / "free.h5"
    nml = tmp_path / "free.nml"
    nml.write_text(
        "&beam     length=1.501, k2=282.84, mass_per_length=0.11938 /\n"
        "&support  amplitude=0.2, omega=10.0 /\n"
        "&stops    lower=-0.1, upper=0.1, law='signorini' /\n"
        "&mesh     elements=19 /\n"
        f"&time     dt=5e-5, t_end={t_end}, beta=0.25, load_rule='centered', start='taylor' /\n"
        f"&output   file='{out}', record_every=1, snapshot_every=0 /\n")
    subprocess.run([program, "run", str(nml)], check=True, capture_output=True)
    with h5py.File(out, "r") as f:
        t, u = f["tip/t"][()], f["tip/u"][()]
    assert abs(t[-1] - t_end) < 1e-9
    return float(u[-1])


def test_peer_before_the_first_impact_is_the_engine_to_dt_squared(program: str, tmp_path: Path) -> None:
    t_end = 0.08  # the tip near its first excursion towards the upper stop (0.1 m), before reaching it
    theirs = peer(t_end)
    ours = engine_tip(program, tmp_path, t_end)
    assert abs(ours) > 0.05  # a large displacement, not a zero crossing
    assert theirs["max_violation"] == 0  # no contact yet
    assert abs(theirs["u_tip_final"] - ours) < 1e-4  # (dt ω_tip)² scale; a wrong model is off by ~1e-2


def test_peer_passes_the_stops_after_impacts() -> None:
    theirs = peer(0.2)
    # Moreau–Jean enforces the stops on velocities: positions pass them, by O(dt |v|) (|v| ~ 1 m/s).
    assert 0 < theirs["max_violation"] < 5e-5 * 10
