"""The committed confusion records (``docs/confusion-BACKEND.json``, made by ``python -m conformance confusion
--json``) and the assertion the CI tests hold each case to: its cell no worse than recorded (issue 48)."""

from __future__ import annotations

import functools
from pathlib import Path

from conformance import backends
from conformance.discrimination import confusion

RECORD = Path(__file__).resolve().parent.parent / "docs" / f"confusion-{backends.NAME}.json"


@functools.cache
def recorded() -> dict:
    """corpus → item → cell, as committed for this FURY."""
    return confusion.record(confusion.load(RECORD)[1])


def assert_named_no_worse(corpus: str, item: str, *, actual: str, expected: str, where: str) -> None:
    """The case ``item`` of ``corpus``, which should name ``expected`` ("-": nothing) and named ``actual``, is no
    worse than the committed record says (right, then none, then a wrong name); a case the record lacks may
    be right or silent, never named wrong."""
    __tracebackhide__ = True
    now = confusion.cell(expected, actual)
    before = recorded().get(corpus, {}).get(item, "none")
    assert not confusion.worse(before, now), (
        f"{item} is named {actual or 'nothing'!r}, but should be named {expected if expected != '-' else 'nothing'!r} "
        f"(recorded: {before}; now: {now}) [{corpus}, {where}]; if the change is meant, make the record again: "
        f"`python -m conformance confusion --json {RECORD.relative_to(RECORD.parent.parent)} …` (docs/confusion.md "
        "has the whole command)")
