"""Progress on the long commands (``verdicts``, ``kill-rate``, ``regen``, ``bench``), on stderr.

A bar only when stderr is a terminal: in CI logs and pipes the commands print their results and
nothing else, so a log stays readable and a captured output stays comparable.
"""

from __future__ import annotations

import sys
from typing import Iterable, Iterator, TypeVar

__all__ = ["progress"]

T = TypeVar("T")


def progress(items: Iterable[T], *, total: int | None = None, what: str = "") -> Iterator[T]:
    """Iterate ``items``, showing a bar labelled ``what`` on a terminal; silently otherwise."""
    if not sys.stderr.isatty():
        yield from items
        return
    from tqdm import tqdm

    yield from tqdm(items, total=total, desc=what, unit="", leave=False, file=sys.stderr, dynamic_ncols=True)
