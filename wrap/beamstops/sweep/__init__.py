"""Parameter sweeps: one command from a laptop to a cluster (``python -m beamstops sweep``).

A TOML specification names a base scene, the axes (lists or ranges, product or zip)
and the reductions (:mod:`beamstops.sweep.spec`). Every point runs as the ``beamstops``
program on its own namelist and writes its own HDF5 file; a ``concurrent.futures``
executor runs the points (local processes, or MPI ranks through ``mpi4py.futures``);
the sweep resumes where it stopped and gathers one summary table
(:mod:`beamstops.sweep.runner`)::

    from beamstops import sweep
    spec = sweep.load_spec("input/sweeps/bifurcation.toml")
    sweep.run_sweep(spec, "out/bifurcation")
    rows = sweep.read_summary("out/bifurcation")
"""

from .runner import EXECUTORS, Outcome, find_program, make_executor, read_summary, run_sweep
from .spec import Point, Spec, SpecError, load_spec, parse_spec

__all__ = ["Spec", "Point", "SpecError", "Outcome", "EXECUTORS", "load_spec", "parse_spec", "run_sweep",
           "read_summary", "find_program", "make_executor"]
