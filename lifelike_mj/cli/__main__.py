"""``python -m lifelike_mj.cli``: the ``lifelike-mj`` command."""

import sys

from lifelike_mj.cli import main

sys.exit(main())
