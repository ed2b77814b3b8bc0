"""numpy's ``f2py`` and ``testing`` as lazy modules: loaded at their first use, not by scipy.

scipy 1.17's array-API layer (``scipy._lib.array_api_compat.numpy``, imported by
``scipy.sparse``, ``scipy.linalg`` and scipy.optimize) copies numpy's namespace with ``from numpy
import *``, and numpy's ``__all__`` names its lazily imported submodules ``f2py`` and ``testing``:
the copy imports both (the Fortran wrapper generator with its Fortran parser, and numpy's test
helpers with ``unittest``). Neither is used by a catdae run: about 0.1 s of CPU in every process
(benchmarks/startup.md). Here both are entered in ``sys.modules`` (and as numpy's attributes, as
an import would) as ``importlib.util.LazyLoader`` modules: the copy takes the module object
without looking inside, and the first attribute anybody reads (``numpy.testing.assert_allclose``,
``numpy.f2py.compile``) executes the real module, after which it is the ordinary module. Nothing
changes where either is already imported, or where numpy names neither as lazy.
"""

from __future__ import annotations

import importlib.util
import sys

LAZY = ("f2py", "testing")


def defer() -> list[str]:
    """Make numpy's ``f2py`` and ``testing`` lazy where they are not imported yet; the names of
    those made lazy."""
    import numpy

    done = []
    for name in LAZY:
        full = f"numpy.{name}"
        if full in sys.modules or name in vars(numpy):  # imported: leave it
            continue
        try:
            spec = importlib.util.find_spec(full)
        except (ImportError, ValueError):
            continue
        if spec is None or spec.loader is None:
            continue
        loader = importlib.util.LazyLoader(spec.loader)
        spec.loader = loader
        module = importlib.util.module_from_spec(spec)
        sys.modules[full] = module
        loader.exec_module(module)  # lazy: runs the module at its first attribute read
        setattr(numpy, name, module)  # as the import system does for a loaded submodule
        done.append(full)
    return done
