"""The ``catdae`` command (the console script) and ``python -m catdae``: the command line, with
two things only a process entry can do.

- A Ctrl-C while the modules load (about a second: numpy, scipy, xarray, numba) says
  "interrupted" and exits 130, not a traceback from deep inside an import (tester t75).
- A finished ``catdae run`` ends without the interpreter's teardown: freeing every module it
  loaded (numba and llvmlite, xarray and pandas, scipy, netCDF4) took about 0.3 s of CPU after
  the results file had been written and closed (benchmarks/cheaper_steps.md). The standard
  streams are flushed first; an exception still ends the process the ordinary way, and so does
  a run under a profiler or tracer (``python -m cProfile -m catdae run``, coverage), which
  writes what it measured at the teardown. The console script skipped this before (only
  ``python -m catdae`` had it).
"""

from __future__ import annotations

import os
import sys


def main() -> int:
    try:
        from catdae.cli import main as cli_main
    except KeyboardInterrupt:  # the signal policy is installed by the command, after this
        print("catdae: interrupted while starting (nothing was computed)", file=sys.stderr)
        return 130
    code = cli_main()
    # not under a profiler, tracer or coverage tool: they write their results at the teardown
    if sys.argv[1:2] == ["run"] and sys.getprofile() is None and sys.gettrace() is None:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        except (OSError, ValueError):  # a closed or broken stream: the ordinary exit reports
            return code
        os._exit(int(code or 0))
    return code
