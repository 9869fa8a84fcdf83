"""How close a check came to failing: the largest use of each of its allowances, whatever it judged.

Every assertion of the kit that holds a measured figure to an allowance notes it here (:func:`note`):
the vertex and normal checks, the silhouettes (at golden frames, in the sync-order machine, in any
orientation), the physics laws. The plugin opens a tally around each check (:func:`tally`) and writes
it into the check's record, so a run of right syncs over many random draws says, per check and per
allowance, how much of the allowance the worst draw used (``python -m conformance precision``, issue
28: a false alarm seen coming before it happens). A use is ``measured / limit`` for an upper bound and
``(1 - measured) / (1 - limit)`` for a score that is 1 when perfect (an IoU); 1 or more fails, a NaN
counts as the worst.

No pytest, no pyBullet: any layer may note a figure.
"""

from __future__ import annotations

import contextlib
import math
from typing import Iterator

__all__ = ["note", "tally", "use"]

_open: list[dict[str, dict]] = []


def use(measured: float, limit: float, *, at_least: bool = False) -> float:
    """The fraction of the allowance ``measured`` takes (NaN for a NaN figure; inf for an allowance of nothing)."""
    measured, limit = float(measured), float(limit)
    if at_least:
        room = 1.0 - limit
        return (1.0 - measured) / room if room > 0 else (0.0 if measured >= limit else math.inf)
    if limit > 0:
        return measured / limit
    return 0.0 if measured <= 0 else math.inf


def note(allowance: str, measured: float, limit: float, *, at_least: bool = False, where: str = "") -> None:
    """Count one figure of ``allowance`` (a short name: ``"silhouette IoU (box)"``) against its limit in
    every open tally, keeping the worst; outside a tally it does nothing."""
    if not _open:
        return
    fraction = use(measured, limit, at_least=at_least)
    for kept in _open:
        old = kept.get(allowance)
        if old is None or (not math.isnan(old["use"]) and not (old["use"] >= fraction)):  # NaN is the worst and stays
            kept[allowance] = {"use": fraction, "measured": float(measured), "limit": float(limit), "where": where,
                               "count": (old or {}).get("count", 0) + 1}
        else:
            old["count"] += 1


@contextlib.contextmanager
def tally() -> Iterator[dict[str, dict]]:
    """Around one check: every figure noted inside, as ``{allowance: {use, measured, limit, where, count}}``."""
    kept: dict[str, dict] = {}
    _open.append(kept)
    try:
        yield kept
    finally:
        del _open[next(i for i, k in enumerate(_open) if k is kept)]  # by identity: two tallies may be equal
