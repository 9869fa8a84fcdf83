"""Runs of the kit in pytest processes of their own, started when the session starts.

``test_discrimination`` and ``test_readme_example`` each run the whole kit in a subprocess, and
those runs are most of ``./kit test``. Started only when their test comes, they would leave the
other cores idle while this process runs everything else; so ``conftest.py`` asks each collected
test module for the runs it will need (its ``background_runs(items)``: key -> (priority, callable))
and starts them all at once, longest first, one per core. A test then waits for its run's result.
Under pytest-xdist the workers already share the cores: each run is started when its test asks.
"""

from __future__ import annotations

import os
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Callable

__all__ = ["result", "start_all", "stop"]

_pool: ThreadPoolExecutor | None = None
_futures: dict[str, Future] = {}


def _executor() -> ThreadPoolExecutor:
    global _pool
    if _pool is None:
        _pool = ThreadPoolExecutor(max_workers=os.cpu_count() or 1, thread_name_prefix="kit-run")
    return _pool


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
    global _pool
    for future in _futures.values():
        future.cancel()
    if _pool is not None:
        _pool.shutdown(wait=True)
    _pool = None
    _futures.clear()
