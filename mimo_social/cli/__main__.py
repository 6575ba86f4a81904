"""`python -m mimo_social.cli`: the same as the `mimo-social` command."""

import sys

from . import main

sys.exit(main())
