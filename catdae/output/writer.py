"""Writing a run's results as they come: snapshots of a long transient, the final tree, and
the tree of a failed or interrupted run, never over a file the run did not write
(docs/case-format.md, "Limits" and the exit codes)."""

from __future__ import annotations

from pathlib import Path

from catdae._xr import xr
from catdae.case import Case
from catdae.case.frame import rotate_back
from catdae.errors import OutputError
from catdae.interrupts import deferred
from catdae.output import results
from catdae.output.files import check_output, clean_stale, free_name, warm_writer
from catdae.output.transient import as_dataset


class ResultWriter:
    """The one writer of a run's results (atomically, through results.write_tree).

    - ``write_increment``: during long transient steps, a snapshot ``<stem>.partial.nc`` whose
      unfinished step is marked ``running``; a disk error there is remembered, not fatal. When a
      file of that name is already there (another run's live snapshot, or a user's file), the
      snapshot goes to ``<stem>.partial-2.nc`` (-3, ...): never over a file it did not write.
    - ``write_final``: the complete tree to the output; the snapshot is then removed (only one
      that this process wrote).
    - ``keep_failed``: the tree of a failed or interrupted run, to the output, or beside it
      (``<stem>.failed.nc``, ``.failed-2.nc``, ...) when a file is there: never over a file.
    A disk error (a full disk, a lost mount) becomes one OutputError that says what was lost
    and where the last snapshot is, if there is one. Signals wait until a file is complete.
    """

    def __init__(self, case: Case, output, groups: dict[str, xr.Dataset], rotation=None):
        self.case = case
        self.rotation = rotation
        self.output = None if output is None else check_output(output, case)
        self.groups = groups
        self.existed = self.output is not None and self.output.exists()
        self.snapshot_error: OSError | None = None
        self.snapshot_written = False  # the snapshot file is this process's own
        self._partial: Path | None = None
        if self.output is not None:
            clean_stale(self.output.parent, self.output.stem)
            warm_writer(self.output)  # so that writing after a MemoryError maps no library

    @property
    def partial_path(self) -> Path | None:
        """The snapshot's name, chosen at the first snapshot: the first of ``<stem>.partial.nc``,
        ``<stem>.partial-2.nc``, ... that is not already there."""
        if self.output is None:
            return None
        if self._partial is None:
            self._partial = free_name(self.output, ".partial")
        return self._partial

    def _remove_snapshot(self) -> None:
        if self.snapshot_written:
            self.partial_path.unlink(missing_ok=True)
            self.snapshot_written = False

    def _write(self, tree: xr.DataTree, path: Path) -> None:
        with deferred():
            results.write_tree(tree, path)

    def write_increment(self, name: str, ds, reached: str | None = None) -> None:
        """A readable snapshot of the run so far (a dataset or a transient's output record),
        beside the output (never over it); ``reached``: how far the step got ("t = ... s"),
        by default the last output time."""
        if self.output is None:
            return
        ds = as_dataset(ds)
        t = (f" at {reached}" if reached else
             f" at t = {float(ds.time[-1]):.6g} s" if ds.sizes.get("time") else "")
        ds = ds.assign_attrs(status=f"running (snapshot{t}; the step has not finished)")
        tree = results.make_tree(self.case, {**self.groups,
                                             name: rotate_back(ds, self.rotation)},
                                 status=f"running step '{name}' (snapshot, not a result)")
        target = self.partial_path
        if not self.snapshot_written and target.exists():
            return  # a file of that name appeared since: not ours to replace
        try:
            self._write(tree, target)
        except OSError as exc:  # the run goes on; the final write says if it fails too
            self.snapshot_error = exc
        else:
            self.snapshot_written = True

    def _lost(self, target: Path, exc: OSError, what: str) -> str:
        reason = exc.strerror or str(exc)
        if self.snapshot_written and self.partial_path.exists():
            kept = f"the last snapshot of the run is kept in {self.partial_path}"
        elif self.snapshot_error is not None:
            snap = self.snapshot_error.strerror or str(self.snapshot_error)
            kept = f"they are lost (the snapshots could not be written either: {snap})"
        else:
            kept = "they are lost"
        return f"cannot write {what} to {target}: {reason}; {kept}"

    def write_final(self, tree: xr.DataTree) -> None:
        if self.output is None:
            return
        try:
            self._write(tree, self.output)
        except OSError as exc:
            raise OutputError(self._lost(self.output, exc, "the results")) from None
        self._remove_snapshot()

    def failed_path(self) -> Path:
        target = self.output
        k = 1
        while (self.existed and target == self.output) or target.exists():
            target = self.output.with_name(
                f"{self.output.stem}.failed{'' if k == 1 else f'-{k}'}.nc")
            k += 1
        return target

    def keep_failed(self, exc: BaseException, tree: xr.DataTree) -> None:
        """Write the tree of a failed or interrupted run; record on ``exc`` the tree
        (``partial``), where it went (``output_path``) or why it could not be written
        (``output_error``)."""
        exc.partial = tree
        exc.output_path = None
        if self.output is None:
            return
        target = self.failed_path()
        try:
            self._write(tree, target)
        except OSError as err:
            exc.output_error = self._lost(target, err, "the results computed so far")
            return
        exc.output_path = target
        self._remove_snapshot()
