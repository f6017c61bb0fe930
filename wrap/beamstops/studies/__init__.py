"""Studies of speed against accuracy (issue 6): convergence tables, work-precision charts,
stability maps, normal compliance. Each module has a ``study`` function writing PNGs,
markdown and CSV into out/<study>, a ``register`` for ``python -m beamstops`` and a ``main``
for scripts/. Every run and every CPU time comes from the engine; these modules compare,
classify and draw. With ``--qoi`` the convergence and work-precision studies chart the engine's
statistics (value ± 95 % half-width after a transient) instead of pointwise tip errors.
"""

__all__ = ["common", "convergence", "workprecision", "stability_map", "compliance", "cli", "qoi", "qoi_report",
           "qoi_workprecision", "qoi_convergence"]
