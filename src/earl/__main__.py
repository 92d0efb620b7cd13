"""`python -m earl …` is the `earl` command, for an environment whose scripts directory is not on PATH."""

import sys

from earl.cli.main import script

sys.exit(script())
