"""`python -m mbsuite.cli`."""

import sys

from . import main

sys.exit(main())
