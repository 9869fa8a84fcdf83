"""Whole runs of the checks, as subprocesses, against the physics every run must do at least once.

The baseline is *the physics of every reference scene once*: each registered scene built and stepped
through all its frames, with nothing drawn and no sync, in this process (best of the rounds). No
conformance run can cost less than that; what a run costs beyond it is checks, pictures, Hypothesis'
extra examples and Python's start-up. Each run is one subprocess from the checkout's root, timed
wall clock; they take minutes, so by default each is run once (``--suite-repeats`` for the best of N).

* ``pytest --collect-only conformance``: start-up, imports and collection, the fixed cost of any run;
* ``pytest conformance``, serial and with ``-n 2`` (pytest-xdist): the conformance checks against
  the reference sync;
* ``pytest conformance --sync wrong_syncs:OneStepLate``, serial: a wrong sync's full verdict (it fails
  about a third of the checks, on every scene), to hold against the right one's (:data:`WRONG`);
* ``pytest conformance --sync right_syncs:PerTargetSync``, serial, isolated (the default for a user's
  sync: the run goes to one pytest-xdist worker, so a crash is a verdict) and with
  ``--conformance-isolation none`` (in process): what crash isolation costs (:data:`ISOLATED`);
* ``./kit test``: what CI runs, the kit's own tests and the checks (profile ``ci``).

``checks_only`` leaves out ``./kit test`` (half an hour on this machine), for the runs of the
conformance checks alone.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

from conformance import scenes

from .timing import Candidate, RatioToBaseline, race, timed

__all__ = ["BASELINE", "IN_PROCESS", "ISOLATED", "RIGHT", "ROOT", "WRONG", "SuiteFigure", "commands", "measure",
           "physics_of_every_scene"]

ROOT = Path(__file__).resolve().parent.parent
BASELINE = "the physics of every reference scene once (build + every step, in process)"
#: The serial run of the checks against the reference sync, and against a wrong sync (from ``tests/``).
RIGHT = "`pytest conformance`"
WRONG_SYNC = "wrong_syncs:OneStepLate"
WRONG = f"`pytest conformance --sync {WRONG_SYNC}`"
#: A right sync of the user's (not a short name, so isolated by default), isolated and in process.
USER_SYNC = "right_syncs:PerTargetSync"
ISOLATED = f"`pytest conformance --sync {USER_SYNC}` (isolated)"
IN_PROCESS = f"`pytest conformance --sync {USER_SYNC} --conformance-isolation none`"


@dataclass(frozen=True)
class SuiteFigure(RatioToBaseline):
    """``seconds`` of wall time of ``name`` (``command``), which exited with ``returncode``."""

    name: str
    command: str
    seconds: float
    baseline: float
    returncode: int = 0
    tail: str = ""  # the end of its output when it failed
    failed: int | None = None  # checks failed and passed, from pytest's last line (None: not a pytest run)
    passed: int | None = None


def commands(python: str = sys.executable, *, checks_only: bool = False) -> list[tuple[str, list[str]]]:
    """(name, argv) of each run, from the checkout's root (the wrong sync is found in ``tests/``)."""
    pytest = [python, "-m", "pytest", "conformance", "-q", "-p", "no:cacheprovider"]
    runs = [
        ("`pytest --collect-only conformance`", pytest + ["--collect-only"]),
        (RIGHT, pytest),
        ("`pytest conformance -n 2`", pytest + ["-n", "2"]),
        (WRONG, pytest + ["--sync", WRONG_SYNC]),
        (ISOLATED, pytest + ["--sync", USER_SYNC]),
        (IN_PROCESS, pytest + ["--sync", USER_SYNC, "--conformance-isolation", "none"]),
        ("`./kit test`", [str(ROOT / "kit"), "test", "-q"]),
    ]
    return runs[:-1] if checks_only else runs


def physics_of_every_scene() -> None:
    for name in scenes.names():
        with scenes.build(name) as scene:
            scene.run(scenes.get(name).steps)


def _run(argv: Sequence[str]) -> tuple[int, str, str]:
    # tests/ on the path, for the wrong sync; the results of a run go to a place of their own.
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT / "tests"), os.environ.get("PYTHONPATH")])))
    done = subprocess.run(list(argv), cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    lines = done.stdout.splitlines()
    return done.returncode, "" if done.returncode == 0 else "\n".join(lines[-5:]), (lines[-1] if lines else "")


def _count(summary: str, outcome: str) -> int | None:
    """How many checks had ``outcome`` in pytest's summary line (``3 failed, 290 passed in …``)."""
    if " in " not in summary:
        return None
    found = re.search(rf"(\d+) {outcome}", summary)
    return int(found.group(1)) if found else 0


def measure(*, repeats: int, baseline_repeats: int = 5, runs: Sequence[tuple[str, list[str]]] | None = None,
            baseline: Callable[[], object] = physics_of_every_scene) -> list[SuiteFigure]:
    """Every run in ``runs`` (default :func:`commands`), best of ``repeats``, against ``baseline``."""
    base = race([Candidate(BASELINE, baseline)], repeats=baseline_repeats, number=1)[BASELINE]
    figures = [SuiteFigure(BASELINE, "", base, base)]
    for name, argv in (commands() if runs is None else runs):
        seconds, (returncode, tail, summary) = timed(lambda: _run(argv), repeats=repeats)
        figures.append(SuiteFigure(name, " ".join(argv), seconds, base, returncode, tail,
                                   _count(summary, "failed"), _count(summary, "passed")))
    return figures
