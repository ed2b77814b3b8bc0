"""catdae: the exact 3-D elastic catenary cable element for statics, modes and dynamics."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys

from catdae._numpy_extras import defer as _defer_numpy_extras
from catdae._version import __version__
from catdae.element.cache import purge_stale as _purge_stale
from catdae.element.cache import write_bytecode as _write_bytecode
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
if sys.flags.dont_write_bytecode:  # catdae's own bytecode all the same (catdae/element/cache.py)
    _write_bytecode()
# numpy.f2py and numpy.testing load at their first use, not with scipy (catdae/_numpy_extras.py)
_defer_numpy_extras()



def run(case_or_path, **kwargs):
    """Run every step of a case (path, TOML text or Case); see :func:`catdae.analysis.run`."""
    from catdae.analysis import run as _run

    return _run(case_or_path, **kwargs)


def load_case(path_or_text, **kwargs):
    """Read and validate a case file; see :func:`catdae.case.load_case`."""
    from catdae.case import load_case as _load

    return _load(path_or_text, **kwargs)


def read_results(path):
    """Open a results file written by catdae as an ``xarray.DataTree`` (in memory). Raises
    ``catdae.errors.ResultsError`` (a ``CatdaeError``) for a missing, empty, truncated,
    corrupted or foreign file, as ``catdae plot`` reports it (a file of a run that failed
    before its first step is returned: it holds the status)."""
    from catdae.output.reading import read_results_file

    return read_results_file(path, steps=False)


__all__ = ["CaseError", "CatdaeError", "ConvergenceError", "Interrupted", "OutputError",
           "SolverError", "__version__", "load_case", "read_results", "run"]


_PUBLIC = {"plot": "catdae.output.plot", "export": "catdae.output.export"}


def __getattr__(name):
    """``catdae.plot`` and ``catdae.export`` (catdae/output/), and ``catdae.study``, on first
    use (matplotlib, meshio, Dask load then)."""
    if name in _PUBLIC:
        return importlib.import_module(_PUBLIC[name])
    if name == "study":  # catdae/study/, with Dask, on first use
        return importlib.import_module("catdae.study")
    raise AttributeError(f"module 'catdae' has no attribute {name!r}")


class _PublicModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """``import catdae.plot`` / ``from catdae.export import write_vtk`` (the documented names)
    give the modules in catdae/output/, loaded on first use."""

    def find_spec(self, fullname, path=None, target=None):
        real = _PUBLIC.get(fullname.removeprefix("catdae.")) if fullname.startswith(
            "catdae.") else None
        return importlib.util.spec_from_loader(fullname, self) if real else None

    def create_module(self, spec):
        return importlib.import_module(_PUBLIC[spec.name.removeprefix("catdae.")])

    def exec_module(self, module):
        pass  # the real module is already executed


sys.meta_path.append(_PublicModules())
