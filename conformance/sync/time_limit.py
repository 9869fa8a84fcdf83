"""A time limit on each call into the sync under test, so that a sync that hangs fails its check.

A sync call that does not return within the limit is interrupted by ``SIGALRM`` (the method
pytest-timeout uses, here around one call instead of a whole test): the kit's own work, stepping and
rendering, is never limited. The interruption is raised in the sync's own frame, so the failure can show
where the sync was; it derives from ``BaseException``, so a sync's ``except Exception`` does not swallow
it, and the alarm repeats every second until the call gives way. A hang inside C code that never returns
to Python (a deadlock in a driver) cannot be interrupted this way.

Where signals are unavailable (not the main thread, or no ``SIGALRM``, as on Windows) calls run without a
limit. A timer already set by someone else (pytest-timeout's) is put back, less the time used.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
import traceback
from typing import Iterator

__all__ = ["DEFAULT", "Expired", "limited", "stack"]

#: Seconds a sync call may take unless told otherwise (``--conformance-sync-timeout``): the kit's own
#: syncs take milliseconds a frame on a 2-core machine, a hang takes forever.
DEFAULT = 10.0


class Expired(BaseException):
    """Raised inside a call that outlived its limit; :func:`limited`'s caller turns it into a failure."""


def _alarm(signum, frame):
    raise Expired()


def _usable() -> bool:
    return hasattr(signal, "SIGALRM") and threading.current_thread() is threading.main_thread()


@contextlib.contextmanager
def limited(seconds: float | None) -> Iterator[None]:
    """Run the body with at most ``seconds`` of wall time (``None`` or 0: no limit); past it, raise
    :class:`Expired` where the body is."""
    if not seconds or not _usable():
        yield
        return
    previous_handler = signal.signal(signal.SIGALRM, _alarm)
    start = time.monotonic()
    old_delay, old_interval = signal.setitimer(signal.ITIMER_REAL, seconds, 1.0)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous_handler)
        if old_delay > 0:  # someone else's alarm: put it back, less what this call used
            signal.setitimer(signal.ITIMER_REAL, max(old_delay - (time.monotonic() - start), 1e-3), old_interval)


def stack(exc: BaseException, *, limit: int = 6) -> str:
    """The innermost frames of ``exc``'s traceback (where the call was when it expired), the kit's own
    left out unless there are no others, as indented ``File …, line …, in …`` lines with their source."""
    kit = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep  # conformance/, not only sync/
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if os.path.abspath(f.filename) != os.path.abspath(__file__)]
    outside = [f for f in frames if not os.path.abspath(f.filename).startswith(kit)]
    return "".join(traceback.format_list((outside or frames)[-limit:])).rstrip()
