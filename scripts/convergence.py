"""Convergence tables in Δt and h (markdown and CSV) into out/convergence.

Runs the installed package's study (beamstops.studies.convergence); options: --quick (seconds),
-o DIR, --quiet, --qoi NAME ... (statistics under impacts), --half-width H;
see --help. Same as `python -m beamstops converge`.
"""

from __future__ import annotations

import sys

from beamstops.studies.convergence import main

if __name__ == "__main__":
    sys.exit(main())
