"""catdae: the exact 3-D elastic catenary cable element for statics, modes and dynamics."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from ._kernel_cache import purge_stale as _purge_stale
from .errors import (
    CaseError,
    CatdaeError,
    ConvergenceError,
    Interrupted,
    OutputError,
    SolverError,
)

try:
    __version__ = version("catdae")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0.0.0+unknown"

# numba's cache follows each kernel's own file only: drop cached kernels whose callees changed
_purge_stale()



def run(case_or_path, **kwargs):
    """Run every step of a case (path, TOML text or Case); see :func:`catdae.analysis.run`."""
    from .analysis import run as _run

    return _run(case_or_path, **kwargs)


def load_case(path_or_text, **kwargs):
    """Read and validate a case file; see :func:`catdae.case.load_case`."""
    from .case import load_case as _load

    return _load(path_or_text, **kwargs)


def read_results(path):
    """Open a results file written by catdae as an ``xarray.DataTree`` (in memory)."""
    from .results import read_tree

    return read_tree(path)


__all__ = ["CaseError", "CatdaeError", "ConvergenceError", "Interrupted", "OutputError",
           "SolverError", "__version__", "load_case", "read_results", "run"]


def __getattr__(name):
    """``catdae.plot`` and ``catdae.export`` on first use (matplotlib and meshio load then)."""
    if name in ("plot", "export"):
        import importlib

        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'catdae' has no attribute {name!r}")
