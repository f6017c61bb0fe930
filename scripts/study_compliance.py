"""Normal compliance: spurious oscillations and penetration (PNG, markdown, CSV) into out/compliance.

Runs the installed package's study (beamstops.studies.compliance); options: --quick (seconds),
-o DIR, --quiet; see --help. Same as `python -m beamstops compliance`.
"""

from __future__ import annotations

import sys

from beamstops.studies.compliance import main

if __name__ == "__main__":
    sys.exit(main())
