"""``python -m marbellous COMMAND ...``: the ``marbellous`` command (``marbellous/cli.py``) without its
script on the ``PATH``."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
