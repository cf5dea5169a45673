"""`python3 -m wrapsim ...`: the same command as the `wrapsim` console script."""

import sys

from .cli import main

sys.exit(main())
