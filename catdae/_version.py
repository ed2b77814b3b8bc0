"""The installed version of catdae (one place, imported by the package and its outputs)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("catdae")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0.0.0+unknown"
