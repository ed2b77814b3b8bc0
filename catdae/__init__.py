"""catdae: the exact 3-D elastic catenary cable element for statics, modes and dynamics."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from .errors import CaseError, CatdaeError, ConvergenceError, SolverError

try:
    __version__ = version("catdae")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0.0.0+unknown"

__all__ = ["CaseError", "CatdaeError", "ConvergenceError", "SolverError", "__version__"]
