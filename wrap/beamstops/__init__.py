"""beamstops: an elastic cantilever beam on a vibrating support between rigid stops.

The Fortran engine (the Dumont–Paoli scheme) from Python::

    import beamstops
    scene = beamstops.Scene.from_namelist("input/paper_fig2.nml").replace(t_end=0.5)
    result = beamstops.run(scene)            # in memory, through the extension
    same = beamstops.load("paper_fig2.h5")   # the program's HDF5 output
    limits = beamstops.stability(scene)      # kappa_h, the paper's kappa bound, dt limits

Plots live in :mod:`beamstops.plots`; ``python -m beamstops plot OUT.h5`` draws them. The
submodules (``beamstops.plots``, ``beamstops.plan``, ``beamstops.sweep``, ...) are imported on
first use, so ``import beamstops`` stays light (no matplotlib) and ``beamstops.plots.save(...)``
works after it.
"""

import importlib
from types import ModuleType

from .engine import Stability, run, stability, version
from .result import IncompleteRunError, Result, Statistic, load
from .scene import Scene

__version__ = version()

__all__ = ["Scene", "Result", "Statistic", "Stability", "IncompleteRunError", "run", "load", "stability", "version",
           "__version__"]

#: Submodules reachable as attributes of the package, imported when first used.
SUBMODULES = ("plots", "plan", "sweep", "studies", "animation", "transforms", "observations")


def __getattr__(name: str) -> ModuleType:
    if name in SUBMODULES:
        return importlib.import_module(f".{name}", __name__)  # sets the attribute: later uses do not come here
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *SUBMODULES})
