"""`python -m gryffin_ros.cli` is `gryffin-ros`."""

import sys

from . import main

sys.exit(main())
