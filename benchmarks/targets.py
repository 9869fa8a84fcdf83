"""The team's performance targets for a sync, judged pass or miss on the sync figures (never a failing test).

For the sync under judgement (``reference`` unless ``--sync`` names another), in both drawing styles:

* **near the floor**: at most ``within`` (1.5) times the floor, at every size but the smallest
  (default 1,000 and 10,000 bodies; at 100 the fixed cost of a frame weighs in);
* **faster than the guide**: at least ``faster`` (8) times faster than the guide's per-body recipe for
  that style, at the second size (default 1,000 bodies);
* **linear**: its cost per body at the largest size at most ``linear`` (1.5) times that at the
  size before (default 10,000 against 1,000);
* **right**: the kit's vertex check passes on its drawing after the timed frames at every size: a
  sync cannot meet the others by skipping work.

And for whole runs (``--suite``): ``pytest conformance`` serial within 90 s, with ``-n 2`` within 60 s,
and ``./kit test`` within 5 minutes, each exiting 0 (the team's targets for this 2-core machine; on
another machine they say how it compares); and a wrong sync's full serial verdict within
:data:`WRONG_OVER_RIGHT` (1.5) times the right one's, failing (exit 1), so a user with a wrong sync
waits about as long as one with a right sync (issue 16).

Where a target cannot be met by any sync that reads every pose, because the floor itself (pyBullet's
per-body read) does not meet it, the verdict says so with the floor's figure.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Sequence

from .syncs import FLOOR, GUIDE_RECIPES, STYLES, SyncFigure

__all__ = ["Limits", "SUITE_LIMITS", "Verdict", "evaluate", "evaluate_suite"]


@dataclass(frozen=True)
class Limits:
    within: float = 1.5
    faster: float = 8.0
    linear: float = 1.5


@dataclass(frozen=True)
class Verdict:
    """One target: what is asked, what was measured, and whether it passed."""

    target: str
    measured: str
    passed: bool
    note: str = ""

    def as_dict(self) -> dict:
        return asdict(self)


def _find(figures, style: str, bodies: int, name: str) -> SyncFigure | None:
    return next((f for f in figures if (f.style, f.bodies, f.name) == (style, bodies, name)), None)


def _style(style: str) -> str:
    return "whole actors" if style == "whole" else "one shared actor"


def evaluate(figures: Sequence[SyncFigure], subject: str, limits: Limits = Limits()) -> list[Verdict]:
    """Pass or miss of every target that ``figures`` have the numbers for."""
    sizes = sorted({f.bodies for f in figures})
    if not sizes:
        return []
    verdicts = []
    near = sizes[1:] or sizes
    middle = sizes[1] if len(sizes) > 1 else sizes[0]
    for style in STYLES:
        where = _style(style)
        for bodies in near:
            mine = _find(figures, style, bodies, subject)
            if mine is not None:
                verdicts.append(Verdict(f"`{subject}` ≤ {limits.within:g}× the floor, {where}, {bodies:,} bodies",
                                        f"{mine.ratio:.2f}×", mine.ratio <= limits.within))
        guide = GUIDE_RECIPES[style][0]
        mine, theirs = _find(figures, style, middle, subject), _find(figures, style, middle, guide)
        if mine is not None and theirs is not None and guide != subject:
            speedup = theirs.seconds / mine.seconds
            note = ""
            if theirs.ratio < limits.faster:
                note = (f"out of reach: `{guide}` itself costs only {theirs.ratio:.1f}× the floor, so even the floor "
                        f"is only {theirs.ratio:.1f}× faster than it; no sync that reads every pose can be {limits.faster:g}×")
            verdicts.append(Verdict(f"`{subject}` ≥ {limits.faster:g}× faster than `{guide}`, {where}, {middle:,} bodies",
                                    f"{speedup:.1f}×", speedup >= limits.faster, note))
        if len(sizes) > 1:
            small, large = sizes[-2], sizes[-1]
            mine_small, mine_large = _find(figures, style, small, subject), _find(figures, style, large, subject)
            if mine_small is not None and mine_large is not None:
                growth = mine_large.per_body / mine_small.per_body
                floor_small, floor_large = _find(figures, style, small, FLOOR), _find(figures, style, large, FLOOR)
                floor_growth = floor_large.per_body / floor_small.per_body
                verdicts.append(Verdict(
                    f"`{subject}` linear: cost per body at {large:,} ≤ {limits.linear:g}× that at {small:,}, {where}",
                    f"{growth:.2f}× ({mine_small.per_body * 1e6:.2f} → {mine_large.per_body * 1e6:.2f} µs)",
                    growth <= limits.linear, f"the floor's: {floor_growth:.2f}×"))
        judged = [f for f in figures if f.style == style and f.name == subject and f.wrong is not None]
        if judged:
            wrong = [f for f in judged if f.wrong]
            worst = max(f.worst_error for f in judged)
            measured = ("every body right" if not wrong else
                        "; ".join(f"{f.wrong:,} of {f.bodies:,} wrong" for f in wrong)) + f", worst vertex error {worst:.2g} m"
            verdicts.append(Verdict(f"`{subject}` draws every body right (the kit's vertex check), {where}",
                                    measured, not wrong))
    return verdicts


#: A wrong sync's full serial run may take at most this many times the reference's.
WRONG_OVER_RIGHT = 1.5

#: A user's sync run isolated (one pytest-xdist worker: a crash is a verdict) may take at most this many
#: times the same run in process: isolation is a fixed start-up cost (about 2 s measured on a 39-check subset).
ISOLATED_OVER_IN_PROCESS = 1.1

#: Whole runs and the wall time each should stay within, in seconds.
SUITE_LIMITS = {"`pytest conformance`": 90.0, "`pytest conformance -n 2`": 60.0, "`./kit test`": 300.0}


def evaluate_suite(figures) -> list[Verdict]:
    """Pass or miss of each whole run with a limit in :data:`SUITE_LIMITS` that was measured."""
    verdicts = []
    for figure in figures:
        limit = SUITE_LIMITS.get(figure.name)
        if limit is None:
            continue
        measured = f"{figure.seconds:.1f} s" + ("" if figure.returncode == 0 else f", exit {figure.returncode}")
        verdicts.append(Verdict(f"{figure.name} within {limit:g} s, exit 0", measured,
                                figure.seconds <= limit and figure.returncode == 0))
    from .suite import IN_PROCESS, ISOLATED, RIGHT, WRONG

    by = {f.name: f for f in figures}
    if ISOLATED in by and IN_PROCESS in by:
        isolated, in_process = by[ISOLATED], by[IN_PROCESS]
        ratio = isolated.seconds / in_process.seconds if in_process.seconds > 0 else float("inf")
        verdicts.append(Verdict(f"crash isolation: {ISOLATED} within {ISOLATED_OVER_IN_PROCESS:g}× the run in process, exit 0",
                                f"{ratio:.2f}× ({isolated.seconds:.1f} s against {in_process.seconds:.1f} s, "
                                f"exit {isolated.returncode} and {in_process.returncode})",
                                ratio <= ISOLATED_OVER_IN_PROCESS and isolated.returncode == 0 == in_process.returncode))
    if RIGHT in by and WRONG in by:
        right, wrong = by[RIGHT], by[WRONG]
        ratio = wrong.seconds / right.seconds if right.seconds > 0 else float("inf")
        counts = f", {wrong.failed} of {wrong.failed + wrong.passed} checks failed" if wrong.failed is not None and wrong.passed is not None else ""
        verdicts.append(Verdict(f"a wrong sync's full verdict ({WRONG}) within {WRONG_OVER_RIGHT:g}× the right one's, exit 1",
                                f"{ratio:.2f}× ({wrong.seconds:.0f} s against {right.seconds:.0f} s{counts}, exit {wrong.returncode})",
                                ratio <= WRONG_OVER_RIGHT and wrong.returncode == 1 and right.returncode == 0))
    return verdicts
