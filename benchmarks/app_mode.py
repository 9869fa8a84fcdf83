"""App mode's cost: what recording and judging an app add to each of its ticks, against the app's own tick.

The baseline is the app's own work in the same run and process: the time inside its per-frame callbacks
(its ``stepSimulation``, its sync, its ``showm.render()``), less the kit's reads made inside them. Against
it: the kit's recording per tick (reading every link frame before each step and after each tick, every
actor's vertices and normals through its matrix, the announcements), measured in the app's process, and
the judgement per tick (:func:`conformance.apps.judge` on the recording, in the kit's process). Apart, per
run: the ``pictured`` check's two pictures at the run's end and their comparison. Each app is run once per
round as ``python -m conformance app`` runs it; a figure is the best round.

Apps: the guide-sized brick wall of ``examples/`` (101 bodies, one actor each, and one shared actor), and
``benchmarks/apps/boxes_BACKEND.py``, 1,000 boxes in one actor.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

from .timing import RatioToBaseline

__all__ = ["AppFigure", "VerdictFigure", "apps", "measure", "verdict_cost", "verdict_pairs"]

ROOT = Path(__file__).resolve().parent.parent
TICKS = 60


@dataclass(frozen=True)
class AppFigure(RatioToBaseline):
    """Per tick: ``seconds`` the kit adds (recording + judging), ``baseline`` the app's own tick."""

    name: str
    ticks: int
    seconds: float
    baseline: float
    record: float
    judge: float
    #: seconds per run (not per tick) of the ``pictured`` check: the two pictures at the run's end, in
    #: the app's process, and their comparison
    picture: float = 0.0


def apps(backend: str) -> list[tuple[str, Path, dict]]:
    """(name, script, environment) of each app measured, on ``backend``."""
    examples = ROOT / "examples" / backend
    return [(f"guide brick wall, one actor a body (`examples/{backend}/brick_wall.py`)", examples / "brick_wall.py", {}),
            (f"guide brick wall, bricks in one actor (`examples/{backend}/brick_wall_single.py`)",
             examples / "brick_wall_single.py", {}),
            (f"1,000 boxes in one actor (`benchmarks/apps/boxes_{backend}.py`)",
             ROOT / "benchmarks" / "apps" / f"boxes_{backend}.py", {"BENCH_BODIES": "1000"})]


def measure(name: str, script: Path, environment: dict, *, repeats: int, ticks: int = TICKS) -> AppFigure:
    from conformance.apps import CHECKS, judge, launch
    from conformance.judge.tolerances import DEFAULT

    best = None
    for _ in range(repeats):
        saved = {k: os.environ.get(k) for k in environment}
        os.environ.update(environment)
        try:
            recording = launch.record(script, ticks=ticks)
        finally:
            for key, value in saved.items():
                if value is None:
                    os.environ.pop(key, None)
                else:
                    os.environ[key] = value
        start = time.perf_counter()
        judge(recording, tolerance=DEFAULT)
        everything = time.perf_counter() - start
        # the per-tick checks alone, as before pictures, so that the columns stay comparable
        start = time.perf_counter()
        judge(recording, tolerance=DEFAULT, checks=tuple(c for c in CHECKS if c != "pictured"))
        judged = time.perf_counter() - start
        n = max(recording.ticks, 1)
        figure = AppFigure(name, recording.ticks, (recording.seconds["record"] + judged) / n,
                           recording.seconds["app"] / n, recording.seconds["record"] / n, judged / n,
                           recording.seconds.get("picture", 0.0) + max(everything - judged, 0.0))
        if best is None or figure.ratio < best.ratio:
            best = figure
    return best


@dataclass(frozen=True)
class VerdictFigure(RatioToBaseline):
    """A failing app's whole verdict (``seconds``) against a passing one of the same robot (``baseline``),
    each ``python -m conformance app`` as a user runs it: the own run, then (passing) the perturbed runs,
    or (failing) the diagnosis of what failed."""

    name: str
    seconds: float
    baseline: float


def verdict_pairs(backend: str) -> list[tuple[str, Path, Path]]:
    """(name, right app, wrong app) of the robots whose verdicts are compared (issue 29: an ``attached``
    failure on a 15-link robot cost 3 to 7 times a pass, most of it the diagnosis)."""
    examples = ROOT / "examples" / backend
    return [(f"KUKA iiwa, links read without computeForwardKinematics (`{backend}/wrong/kuka_no_forward_kinematics.py`) "
             f"against `{backend}/kuka.py`", examples / "kuka.py", examples / "wrong" / "kuka_no_forward_kinematics.py"),
            (f"R2-D2, welded links left unsynced (`{backend}/wrong/r2d2_welded_links_unsynced.py`) against "
             f"`{backend}/r2d2.py`", examples / "r2d2.py", examples / "wrong" / "r2d2_welded_links_unsynced.py")]


def verdict_cost(name: str, right: Path, wrong: Path, *, repeats: int) -> VerdictFigure:
    """The best of ``repeats`` wall times of each verdict, one after the other in the same run."""
    import subprocess
    import sys

    def timed(script: Path) -> float:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "conformance", "app", str(script)], capture_output=True, timeout=1800)
        return time.perf_counter() - start

    passing = failing = float("inf")
    for _ in range(repeats):
        passing = min(passing, timed(right))
        failing = min(failing, timed(wrong))
    return VerdictFigure(name, failing, passing)
