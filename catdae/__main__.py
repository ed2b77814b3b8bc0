"""``python -m catdae`` is the command line (catdae._entry: the same as the ``catdae``
command)."""

import sys

from catdae._entry import main

sys.exit(main())
