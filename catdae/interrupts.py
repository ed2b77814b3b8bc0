"""SIGINT, SIGTERM and SIGHUP as one exception: a stopped command keeps and marks its work.

Every command (``catdae run``, ``study``, ``plot``, ``export``) installs
:func:`signals_as_interrupts` around its work (a closed terminal sends SIGHUP): each signal raises
:class:`~catdae.errors.Interrupted` (a ``KeyboardInterrupt``) in the main thread, which every step
turns into partial results with a status saying where it stopped. Once one is raised, further
signals are ignored until the context ends, so that a second Ctrl-C cannot cut short the writing
of the partial results; and inside :func:`deferred` (the writers) a signal waits until the file is
complete. Without the context (``catdae.run`` in a user's program) Python's own Ctrl-C handling
is left alone and :func:`deferred` does nothing.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from catdae.errors import Interrupted

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)  # Ctrl-C, kill/timeout, hang-up


class _State:
    installed = False
    stopping = False  # an Interrupted has been raised: ignore further signals
    deferring = 0  # depth of deferred() blocks
    pending: int | None = None  # a signal received inside deferred()


def _handler(signum, frame):
    if _State.stopping:
        return
    if _State.deferring:
        _State.pending = signum
        return
    if _in_llvm(frame):  # an exception raised there is dropped (a ctypes callback): again soon
        threading.Timer(RESEND, os.kill, (os.getpid(), signum)).start()
        return
    _State.stopping = True
    raise Interrupted(signum)


RESEND = 0.02  # s: a signal that came inside llvmlite is sent again after this


def _in_llvm(frame) -> bool:
    """Whether the main thread is inside llvmlite (numba loading or compiling a kernel): its
    execution engine calls back into Python through ctypes, which drops an exception raised
    in the callback ("Exception ignored on calling ctypes callback function"), so a Ctrl-C
    there was lost, and every later signal ignored as if the run were stopping (tester t75:
    exit 0, status completed, after SIGINT, SIGINT and SIGTERM)."""
    while frame is not None:
        if "llvmlite" in frame.f_code.co_filename:
            return True
        frame = frame.f_back
    return False


@contextmanager
def signals_as_interrupts() -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP raise Interrupted inside the block (main thread only; elsewhere a
    no-op; an ignored signal stays ignored). The previous handlers are restored afterwards."""
    if threading.current_thread() is not threading.main_thread() or _State.installed:
        yield
        return
    # a signal the parent set to be ignored (SIGINT of a background job, nohup) stays ignored
    previous = {s: h for s in SIGNALS if (h := signal.getsignal(s)) != signal.SIG_IGN}
    _State.installed, _State.stopping, _State.pending = True, False, None
    try:
        for s in previous:
            signal.signal(s, _handler)
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
        _State.installed, _State.stopping, _State.pending = False, False, None


@contextmanager
def deferred() -> Iterator[None]:
    """A signal that arrives inside the block is raised when the block ends, not in it: a file
    being written is finished first (with the handlers of :func:`signals_as_interrupts`)."""
    _State.deferring += 1
    try:
        yield
    finally:
        _State.deferring -= 1
    if not _State.deferring and _State.pending is not None and not _State.stopping:
        signum, _State.pending = _State.pending, None
        _State.stopping = True
        raise Interrupted(signum)
