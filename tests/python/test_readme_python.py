"""The README's Python-side text says what the code does: the sweep's specification keys and
empty reductions, incomplete runs from Python and `plot`."""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import beamstops
from beamstops.sweep import reductions, spec

README = Path(__file__).resolve().parents[2] / "README.md"


def section(title: str) -> str:
    text = README.read_text(encoding="utf-8").split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0]
    return " ".join(text.split())


def test_the_sweep_section_names_every_key_of_the_specification() -> None:
    text = section("Parameter sweeps")
    for key in ("base", "max_points", "timeout", "zip", "mode", "lockstep", "records_per_period", "shared_grid"):
        assert re.search(rf"`(\[\w+\] )?{key}\b", text), key
    assert '`spacing = "log"`' in text and "include `stop`" in text and "default the paper's scene" in text
    for kind, keys in spec.REDUCTION_KINDS.items():
        assert f"`{kind}`" in text, kind
        for key in keys:
            assert f"`{key}`" in text, (kind, key)
    for quantity in spec.QUANTITIES:
        assert f"`{quantity}`" in text, quantity
    assert "`NAME_offset`" in text and "`NAME_period`" in text
    assert "gives an empty value: an empty cell in `summary.csv`, `null`" in text


def test_a_reduction_with_an_empty_window_is_empty() -> None:
    t = np.linspace(0.0, 1.0, 11)
    run = SimpleNamespace(t=t, tip_u=np.sin(t), attrs={"omega": 2 * np.pi})
    out = reductions.reduce(run, {"late": {"kind": "max", "quantity": "tip_u", "after": 5.0, "after_periods": None},
                                  "strobe": {"kind": "strobe", "quantity": "tip_u", "transient_periods": 9,
                                             "phase": 0.0, "tolerance": 1e-6, "max_period": 4}})
    assert out == {"late": None, "strobe": [], "strobe_offset": None, "strobe_period": 0}


def test_the_python_section_says_how_an_incomplete_run_is_read() -> None:
    text = section("Python")
    assert "raises `beamstops.IncompleteRunError`" in text and "allow_incomplete=True" in text
    assert "--allow-incomplete" in text and "`.gif` for `animation`" in text
    diverging = beamstops.Scene(beta=0.0, dt=2e-5, t_end=0.5, allow_unstable=True, record_every=100)
    with pytest.raises(beamstops.IncompleteRunError) as caught:
        beamstops.run(diverging)
    assert isinstance(caught.value, ValueError) and caught.value.result is not None
    assert beamstops.run(diverging, allow_incomplete=True).status == "diverged"
