"""The version of catdae: one place, read by the build (pyproject.toml: dynamic version) and
imported by the package and its outputs. A literal, not importlib.metadata: looking the
installed distribution up cost about 14 ms of every process's start-up."""

__version__ = "0.1.0"
