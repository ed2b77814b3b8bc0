"""catdae: the exact 3-D elastic catenary cable element for statics, modes and dynamics."""

from __future__ import annotations

from catdae._version import __version__
from catdae.element.cache import purge_stale as _purge_stale
from catdae.errors import (
    CaseError,
    CatdaeError,
    ConvergenceError,
    Interrupted,
    OutputError,
    SolverError,
)

# numba's cache follows each kernel's own file only: drop cached kernels whose callees changed
_purge_stale()



def run(case_or_path, **kwargs):
    """Run every step of a case (path, TOML text or Case); see :func:`catdae.analysis.run`."""
    from catdae.analysis import run as _run

    return _run(case_or_path, **kwargs)


def load_case(path_or_text, **kwargs):
    """Read and validate a case file; see :func:`catdae.case.load_case`."""
    from catdae.case import load_case as _load

    return _load(path_or_text, **kwargs)


def read_results(path):
    """Open a results file written by catdae as an ``xarray.DataTree`` (in memory)."""
    from catdae.output.results import read_tree

    return read_tree(path)


__all__ = ["CaseError", "CatdaeError", "ConvergenceError", "Interrupted", "OutputError",
           "SolverError", "__version__", "load_case", "read_results", "run"]


def __getattr__(name):
    """``catdae.plot`` and ``catdae.export`` (catdae/output/) on first use (matplotlib, meshio
    load then)."""
    if name in ("plot", "export"):
        import importlib

        return importlib.import_module(f"catdae.output.{name}")
    raise AttributeError(f"module 'catdae' has no attribute {name!r}")
