"""``python -m planardyn``: the command-line interface (see :mod:`planardyn.cli`)."""

import sys

from .cli import main

sys.exit(main())
