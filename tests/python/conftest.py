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
from pathlib import Path

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
