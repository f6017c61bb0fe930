"""``python -m beamstops COMMAND ...`` (see :mod:`beamstops.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
