"""``python -m catdae`` is the command line.

A finished ``catdae run`` ends without the interpreter's teardown: freeing every module it
loaded (numba and llvmlite, xarray and pandas, scipy, netCDF4) took about 0.3 s of CPU after the
results file had been written and closed (benchmarks/cheaper_steps.md). The standard streams
are flushed first; an exception still ends the process the ordinary way, and so does a run
under a profiler or tracer (``python -m cProfile -m catdae run``, coverage), which writes what
it measured at the teardown.
"""

import os
import sys

from catdae.cli import main

code = main()
# not under a profiler, tracer or coverage tool: they write their results at the teardown
if sys.argv[1:2] == ["run"] and sys.getprofile() is None and sys.gettrace() is None:
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):  # a closed or broken stream: the ordinary exit reports it
        sys.exit(code)
    os._exit(int(code or 0))
sys.exit(code)
