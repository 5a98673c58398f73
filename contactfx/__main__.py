"""``python3 -m contactfx``: the command line."""

import sys

from contactfx.cli import main

sys.exit(main())
