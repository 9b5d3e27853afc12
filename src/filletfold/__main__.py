"""``python -m filletfold``: the command line (:mod:`filletfold.cli`)."""

import sys

from .cli import main

sys.exit(main())
