"""``python -m passmd``: the command line (:mod:`passmd.cli`)."""

import sys

from passmd.cli import main

sys.exit(main())
