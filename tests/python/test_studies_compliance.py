"""Normal-compliance study (issue 6): penetration against stiffness, reversals in contact."""

from __future__ import annotations

import math

import beamstops
from beamstops import Scene
from beamstops.studies import compliance

BASE = Scene(t_end=0.12, beta=0.25, dt=5e-6)


def test_penetration_falls_with_stiffness_and_signorini_never_penetrates() -> None:
    pens = [beamstops.run(BASE.replace(law="compliance", stiffness_per_mass=k)).attrs["max_violation"]
            for k in (1e6, 1e8, 1e10)]
    assert pens[0] > pens[1] > pens[2] > 0
    signorini = beamstops.run(BASE)
    assert signorini.attrs["max_violation"] == 0
    per_contact, contacts = compliance.reversals(signorini)
    assert contacts > 0 and 1 <= per_contact < 2  # a clean impact reverses once


def test_no_contact_gives_no_reversal() -> None:
    result = beamstops.run(BASE.replace(t_end=0.05))
    per_contact, contacts = compliance.reversals(result)
    assert contacts == 0 and math.isnan(per_contact)
    assert 0 <= compliance.hf_fraction(result, 5000.0) < 1
