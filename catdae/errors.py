"""The package's own exceptions. Library code raises these; the CLI turns them into one line."""

from __future__ import annotations


class CatdaeError(Exception):
    """Base class of every error catdae raises on purpose."""


class CaseError(CatdaeError):
    """A case file is unreadable or invalid.

    ``problems`` lists every problem found as ``(field_path, message)``; ``path`` is the file.
    """

    def __init__(self, path: str | None, problems: list[tuple[str, str]]):
        self.path = path
        self.problems = list(problems)
        where = path or "<case>"
        lines = [f"{where}: {field}: {msg}" if field else f"{where}: {msg}"
                 for field, msg in problems]
        super().__init__("\n".join(lines) if lines else f"{where}: invalid case")


class ConvergenceError(CatdaeError):
    """A nonlinear solve (element or global Newton) did not converge."""


class SolverError(CatdaeError):
    """The time integrator stopped before the end of a step.

    ``termination`` says why; ``partial`` holds whatever was computed before the failure.
    """

    def __init__(self, message: str, termination: str = "failed", partial=None):
        super().__init__(message)
        self.termination = termination
        self.partial = partial
