"""``python -m catdae`` is the command line.

A finished ``catdae run`` ends without the interpreter's teardown: freeing every module it
loaded (numba and llvmlite, xarray and pandas, scipy, netCDF4) took about 0.3 s of CPU after the
results file had been written and closed (benchmarks/cheaper_steps.md). The standard streams
are flushed first; an exception still ends the process the ordinary way.
"""

import os
import sys

from catdae.cli import main

code = main()
if sys.argv[1:2] == ["run"]:
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):  # a closed or broken stream: the ordinary exit reports it
        sys.exit(code)
    os._exit(int(code or 0))
sys.exit(code)
