"""Shared fixtures of the Python tests.

The tests exercise the *installed* package (``pip install .``): the repository's
wrap/beamstops holds only the pure-Python sources, without the compiled extension, and
is never put on sys.path. ``program`` is the ``beamstops`` program installed with that
package (the same build as the extension), which the bit-for-bit comparisons need.
"""

from __future__ import annotations

import os
import shutil
import sysconfig
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
INPUT = ROOT / "input"

# Plots must never need a display.
os.environ.setdefault("MPLBACKEND", "Agg")


def installed_program() -> str | None:
    """The `beamstops` program next to this interpreter's scripts (a venv's bin), else on PATH."""
    explicit = os.environ.get("BEAMSTOPS_PROGRAM")
    if explicit:
        return explicit
    beside = Path(sysconfig.get_path("scripts")) / "beamstops"
    if beside.is_file() and os.access(beside, os.X_OK):
        return str(beside)
    return shutil.which("beamstops")


@pytest.fixture(scope="session")
def program() -> str:
    path = installed_program()
    if path is None:
        pytest.skip("the beamstops program is not installed")
    return path


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return ROOT


@pytest.fixture
def write_spec(tmp_path: Path) -> Callable[..., Path]:
    """``write_spec(text, name="spec.toml")``: a sweep specification written into the test's
    tmp_path; gives its path."""

    def write(text: str, name: str = "spec.toml") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path

    return write


#: Columns of a sweep's summary that differ from one run of the same points to the next.
TIMING = ("cpu_seconds", "wall_seconds")


@pytest.fixture(scope="session")
def without_timing() -> Callable[[list[dict[str, Any]]], list[dict[str, Any]]]:
    """Summary rows without their timings, for comparing two runs of the same points."""

    def strip(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
        return [{k: v for k, v in row.items() if k not in TIMING} for row in rows]

    return strip
