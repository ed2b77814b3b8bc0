"""``python -m catdae`` is the command line."""

import sys

from catdae.cli import main

sys.exit(main())
