"""The kinds of figure :mod:`beamstops.plots` draws, apart from it: the command line lists them
without importing matplotlib (about a second of every ``python -m beamstops`` start)."""

from __future__ import annotations

#: Every kind :func:`beamstops.plots.save` writes, 'all' included.
KINDS = ("tip", "shape", "spacetime", "energy", "phase", "reaction", "stops", "impacts", "pdf", "psd", "poincare",
         "animation", "all")
#: The kinds that are still figures (:func:`beamstops.plots.figure`); 'animation' is written by save only.
FIGURE_KINDS = tuple(kind for kind in KINDS if kind != "animation")
#: Kinds that take ``transient`` (s): only what comes after it is drawn.
TRANSIENT_KINDS = ("pdf", "psd", "poincare")
#: What ``transient`` is, in the messages of the command line (``--transient``) and of Python alike.
TRANSIENT = "a time in s"
