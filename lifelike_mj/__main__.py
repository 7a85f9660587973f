"""``python -m lifelike_mj`` is the ``lifelike-mj`` command."""

import sys

from lifelike_mj.cli import main

if __name__ == "__main__":
    sys.exit(main())
