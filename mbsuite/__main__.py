"""`python -m mbsuite`: the command line (`mbsuite`)."""

import sys

from .cli import main

sys.exit(main())
