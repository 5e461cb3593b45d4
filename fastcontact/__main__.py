"""``python -m fastcontact ...``: the command-line interface (see :mod:`fastcontact.cli`)."""
import sys

from fastcontact.cli import main

if __name__ == "__main__":
    sys.exit(main())
