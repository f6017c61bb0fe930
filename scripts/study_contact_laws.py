"""Contact laws compared: energy, violation, chatter, convergence in Δt (PNG, markdown, CSV) into out/contact_laws.

Runs the installed package's study (beamstops.studies.contact_laws); options: --quick (seconds),
-o DIR, --quiet; see --help. Same as `python -m beamstops contact-laws`.
"""

from __future__ import annotations

import sys

from beamstops.studies.contact_laws import main

if __name__ == "__main__":
    sys.exit(main())
