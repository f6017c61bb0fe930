"""Work-precision chart (PNG, markdown, CSV) into out/work_precision.

Runs the installed package's study (beamstops.studies.workprecision); options: --quick (seconds),
-o DIR, --quiet, --qoi NAME ... (statistics under impacts), --half-width H;
see --help. Same as `python -m beamstops work-precision`.
"""

from __future__ import annotations

import sys

from beamstops.studies.workprecision import main

if __name__ == "__main__":
    sys.exit(main())
