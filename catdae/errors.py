"""The package's own exceptions. Library code raises these; the CLI turns them into one line."""

from __future__ import annotations

import signal


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


class OutputError(CatdaeError):
    """The results cannot be written (a directory, no permission, a full disk, ...)."""


class OutOfMemory(CatdaeError):
    """A step needed more memory than the process was given (a MemoryError): the step fails,
    what the steps before it computed is written, and the status says why."""

    @classmethod
    def in_step(cls, name: str) -> OutOfMemory:
        return cls(f"step '{name}' ran out of memory (the machine or a limit such as ulimit -v "
                   "or a batch scheduler's gave it less than it needs): use fewer elements, "
                   "fewer outputs or fewer modes")


class InternalError(CatdaeError):
    """An unexpected exception inside a step (a bug in catdae): the step fails like any other,
    what the steps before it computed is kept, and the original exception is the cause."""

    @classmethod
    def in_step(cls, name: str, exc: Exception) -> InternalError:
        return cls(f"internal error in step '{name}' ({type(exc).__name__}: {exc}); this is a "
                   "bug in catdae: please report it with the case file")


class ResultsError(CatdaeError):
    """A results file that cannot be read: missing, empty, truncated, corrupted, or not one
    that catdae wrote (bad input to ``catdae plot`` and ``export``: exit 2)."""


class Interrupted(KeyboardInterrupt):
    """A run stopped by a signal: SIGINT (Ctrl-C), SIGTERM (``timeout``, batch schedulers,
    container stops) or SIGHUP (the terminal closed). A ``KeyboardInterrupt``, so that every
    layer that keeps partial results on Ctrl-C keeps them on the others too; ``exit_code`` is
    the shell's 128 + signal number.

    Like a ``CatdaeError`` of a failed run, it carries ``partial`` (what was computed) and
    ``output_path`` (where that went) once the pipeline has written it.
    """

    def __init__(self, signum: int = signal.SIGINT):
        self.signum = int(signum)
        super().__init__(signal.Signals(self.signum).name)

    @property
    def exit_code(self) -> int:
        return 128 + self.signum
