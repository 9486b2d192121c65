"""``python -m mbdyn ...`` is the ``mbdyn`` command."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
