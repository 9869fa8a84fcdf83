"""Whole runs of the checks, as subprocesses, against the physics every run must do at least once.

The baseline is *the physics of every reference scene once*: each registered scene built and stepped
through all its frames, with nothing drawn and no sync, in this process (best of the rounds). No
conformance run can cost less than that; what a run costs beyond it is checks, pictures, Hypothesis'
extra examples and Python's start-up. Each run is one subprocess from the checkout's root, timed
wall clock; they take minutes, so by default each is run once (``--suite-repeats`` for the best of N).

* ``pytest --collect-only conformance``: start-up, imports and collection, the fixed cost of any run;
* ``pytest conformance``, serial and with ``-n 2`` (pytest-xdist): the conformance checks against
  the reference sync;
* ``./kit test``: what CI runs, the kit's own tests and the checks (profile ``ci``).
"""

from __future__ import annotations

import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

from conformance import scenes

from .timing import Candidate, RatioToBaseline, race, timed

__all__ = ["BASELINE", "ROOT", "SuiteFigure", "commands", "measure", "physics_of_every_scene"]

ROOT = Path(__file__).resolve().parent.parent
BASELINE = "the physics of every reference scene once (build + every step, in process)"


@dataclass(frozen=True)
class SuiteFigure(RatioToBaseline):
    """``seconds`` of wall time of ``name`` (``command``), which exited with ``returncode``."""

    name: str
    command: str
    seconds: float
    baseline: float
    returncode: int = 0
    tail: str = ""  # the end of its output when it failed


def commands(python: str = sys.executable) -> list[tuple[str, list[str]]]:
    """(name, argv) of each run, from the checkout's root."""
    pytest = [python, "-m", "pytest", "conformance", "-q", "-p", "no:cacheprovider"]
    return [
        ("`pytest --collect-only conformance`", pytest + ["--collect-only"]),
        ("`pytest conformance`", pytest),
        ("`pytest conformance -n 2`", pytest + ["-n", "2"]),
        ("`./kit test`", [str(ROOT / "kit"), "test", "-q"]),
    ]


def physics_of_every_scene() -> None:
    for name in scenes.names():
        with scenes.build(name) as scene:
            scene.run(scenes.get(name).steps)


def _run(argv: Sequence[str]) -> tuple[int, str]:
    done = subprocess.run(list(argv), cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return done.returncode, "" if done.returncode == 0 else "\n".join(done.stdout.splitlines()[-5:])


def measure(*, repeats: int, baseline_repeats: int = 5, runs: Sequence[tuple[str, list[str]]] | None = None,
            baseline: Callable[[], object] = physics_of_every_scene) -> list[SuiteFigure]:
    """Every run in ``runs`` (default :func:`commands`), best of ``repeats``, against ``baseline``."""
    base = race([Candidate(BASELINE, baseline)], repeats=baseline_repeats, number=1)[BASELINE]
    figures = [SuiteFigure(BASELINE, "", base, base)]
    for name, argv in (commands() if runs is None else runs):
        seconds, (returncode, tail) = timed(lambda: _run(argv), repeats=repeats)
        figures.append(SuiteFigure(name, " ".join(argv), seconds, base, returncode, tail))
    return figures
