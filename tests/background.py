"""Runs of the kit in pytest processes of their own, started when the session starts.

``test_discrimination`` and ``test_readme_example`` each run the whole kit in a subprocess, and
those runs are most of ``./kit test``. Started only when their test comes, they would leave the
other cores idle while this process runs everything else; so ``conftest.py`` asks each collected
test module for the runs it will need (its ``background_runs(items)``: key -> (priority, callable))
and starts them all at once, longest first, one per core. A test then waits for its run's result.
Under pytest-xdist the workers already share the cores: each run is started when its test asks.

This process is then single-threaded in BLAS (:func:`one_blas_thread`): the runs start their processes
from threads while the main thread computes, and a fork while the main thread is inside a multi-threaded
OpenBLAS call deadlocks both, in OpenBLAS's own fork handler (measured: a ``./kit test`` hung for good with
the main thread in a matmul of the app judge and a run's thread in ``blas_thread_shutdown_``).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
import threading
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Callable

from threadpoolctl import threadpool_limits

__all__ = ["HOME", "OWN_SYNCS", "one_blas_thread", "result", "share_states", "start_all", "stop"]

#: The options of a run of the kit's own syncs (``tests/*_syncs.py``): in pytest's own process, as they do
#: not crash; a pytest-xdist worker of its own cost each run 2.5 s of CPU more (``test_discrimination``).
OWN_SYNCS = ["--conformance-isolation", "none"]

_pool: ThreadPoolExecutor | None = None
_futures: dict[str, Future] = {}
_PREFIX = "kit-run"
_states: str | None = None  # share_states' directory

#: The directory the session started in, where every run of the pool starts (:func:`_started_at_home`).
HOME = os.getcwd()


def _started_at_home() -> None:
    """Every subprocess a thread of the pool starts without a ``cwd`` of its own starts in :data:`HOME`, not
    wherever this process stands when it starts. Tests run the kit's commands in a directory of their own by
    changing this process's (``os.chdir``, ``monkeypatch.chdir``), and a run the pool started meanwhile ran
    there: test_animation found a background run's ``.hypothesis`` in its temporary directory (FURY 2,
    2026-11-28), and a test's ``pytest.ini`` there would configure a kill-rate run."""
    original = subprocess.Popen.__init__
    if getattr(original, "_kit_home", False):
        return

    def __init__(self, *args, **kwargs):
        if len(args) < 9 and kwargs.get("cwd") is None and threading.current_thread().name.startswith(_PREFIX):
            kwargs["cwd"] = HOME
        original(self, *args, **kwargs)

    __init__._kit_home = True
    subprocess.Popen.__init__ = __init__


def one_blas_thread() -> None:
    """Every BLAS library loaded in this process computes on one thread from now on (the kit's arrays are
    stacks of small matrices: it loses nothing), so no fork can meet a BLAS call mid-way (see above)."""
    threadpool_limits(limits=1, user_api="blas")


def _executor() -> ThreadPoolExecutor:
    global _pool
    if _pool is None:
        one_blas_thread()
        _started_at_home()
        _pool = ThreadPoolExecutor(max_workers=os.cpu_count() or 1, thread_name_prefix=_PREFIX)
    return _pool


def share_states() -> None:
    """One directory for the whole session where every process replays each scene's golden physics once
    (``conformance.rendering.snapshots.SHARED_STATES``, inherited by the runs): each right sync's run, the
    random draws' and the README example's stepped the same three wall scenes again (3.1 s of CPU a run)."""
    global _states
    from conformance.rendering import snapshots

    if _states is None and not os.environ.get(snapshots.SHARED_STATES):
        _states = tempfile.mkdtemp(prefix="kit-states-")
        os.environ[snapshots.SHARED_STATES] = _states


def start_all(runs: dict[str, tuple[float, Callable[[], object]]]) -> None:
    """Start every run not started yet, highest priority (longest) first."""
    for key, (_, call) in sorted(runs.items(), key=lambda kv: -kv[1][0]):
        if key not in _futures:
            _futures[key] = _executor().submit(call)


def result(key: str, call: Callable[[], object]):
    """The result of run ``key``, started now if it was not started with the session."""
    if key not in _futures:
        _futures[key] = _executor().submit(call)
    return _futures[key].result()


def stop() -> None:
    """Cancel what has not started; wait for what has (their processes end on their own)."""
    global _pool, _states
    for future in _futures.values():
        future.cancel()
    if _pool is not None:
        _pool.shutdown(wait=True)
    _pool = None
    _futures.clear()
    if _states is not None:
        from conformance.rendering import snapshots

        os.environ.pop(snapshots.SHARED_STATES, None)
        shutil.rmtree(_states, ignore_errors=True)
        _states = None
