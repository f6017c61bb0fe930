"""Stability maps in (β, Δt) and (J, Δt) (PNG, markdown, CSV) into out/stability_map.

Runs the installed package's study (beamstops.studies.stability_map); options: --quick (seconds),
-o DIR, --quiet; see --help. Same as `python -m beamstops stability-map`.
"""

from __future__ import annotations

import sys

from beamstops.studies.stability_map import main

if __name__ == "__main__":
    sys.exit(main())
