"""Best-of-N timing with ``time.perf_counter``, candidates interleaved so that noise hits them alike.

The machines this runs on are shared and noisy: a figure is the least, over several rounds, of the
mean time of a few calls. The least is the run least disturbed by anything else, which is what a
ratio between two candidates should compare. Candidates measured against each other run in the
same rounds, in an order rotated every round, so that a slow spell of the machine lands on all of
them rather than on one. As in ``timeit``, Python's cyclic garbage collector is off while timing:
when it runs depends on everything else alive in the process, not on the code timed.
"""

from __future__ import annotations

import gc
import time
from dataclasses import asdict, dataclass
from typing import Callable, Sequence

__all__ = ["Candidate", "RatioToBaseline", "race", "timed"]


class RatioToBaseline:
    """For a figure dataclass with ``seconds`` and the ``baseline`` it is measured against: the ratio
    every table prints, and the figure as JSON with it."""

    @property
    def ratio(self) -> float:
        return self.seconds / self.baseline

    def as_dict(self) -> dict:
        return {**asdict(self), "ratio": self.ratio}


@dataclass(frozen=True)
class Candidate:
    """``fn`` is what is timed; ``before``, if given, runs untimed before every call (e.g. one
    ``stepSimulation``, so that a sync is timed on a frame that moved, as in a real run)."""

    name: str
    fn: Callable[[], object]
    before: Callable[[], object] | None = None


def _round(candidate: Candidate, number: int) -> float:
    clock, fn, before = time.perf_counter, candidate.fn, candidate.before
    total = 0.0
    for _ in range(number):
        if before is not None:
            before()
        start = clock()
        fn()
        total += clock() - start
    return total / number


def race(candidates: Sequence[Candidate], *, repeats: int, number: int) -> dict[str, float]:
    """Seconds per call of each candidate: the least, over ``repeats`` rounds, of the mean of
    ``number`` calls. Every round runs every candidate, starting one further along each time."""
    if repeats < 1 or number < 1:
        raise ValueError(f"repeats={repeats!r}, number={number!r}, but both should be at least 1")
    best = {c.name: float("inf") for c in candidates}
    was_enabled = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        for r in range(repeats):
            for k in range(len(candidates)):
                candidate = candidates[(r + k) % len(candidates)]
                best[candidate.name] = min(best[candidate.name], _round(candidate, number))
    finally:
        if was_enabled:
            gc.enable()
    return best


def timed(fn: Callable[[], object], *, repeats: int = 1) -> tuple[float, object]:
    """The least wall time of ``repeats`` calls of ``fn`` (for runs too long to repeat many times),
    and what the last call returned."""
    best, result = float("inf"), None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result
