"""One zoo program judged: written out, run under app mode, its verdict kept as a journal line.

The verdict is app mode's, as ``python -m conformance app PROGRAM --ticks TICKS --perturbed 1`` gives it:
its own run, then (if that passed) the perturbed opening, the one run of the kit's events every app meets
first (bodies turned to hard orientations, a joint reset, a kick, a body turned between the step and the
sync). :data:`TICKS` is as few ticks as the verdicts need: the pictures are taken at four ticks of the run,
and every check but ``pictured`` judges every tick.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from conformance.apps.verdict import lead
from conformance.zoo.mistakes import LIMITS
from conformance.zoo.models import Model
from conformance.zoo.programs import program
from conformance.zoo.styles import Style

__all__ = ["SAME", "TICKS", "Outcome", "judge_program", "judge_wrong", "load_journal", "write_program"]

#: ticks of a program's own run (the perturbed run has apps.PERTURBED_TICKS)
TICKS = 40
#: a wrong program whose every vertex is within this (m) of the right one's, in its own run and in the
#: perturbed opening, shows nothing of its mistake: the mistake changes nothing this model shows
SAME = 1e-4


@dataclass
class Outcome:
    """What app mode said of one program: ``accepted``, ``rejected`` (with the checks that failed, the first
    failing line and the diagnoses named), or ``error`` (the kit could not judge it: why)."""

    model: str
    style: str
    backend: str
    outcome: str
    #: the mistake injected ("" for a right program); a wrong one's outcome is "rejected", "missed" (accepted
    #: though its drawing differs from the right one's by ``shown`` m), "limit" (a miss with its reason in
    #: :data:`conformance.zoo.mistakes.LIMITS`) or "no-difference" (it does not differ)
    mistake: str = ""
    shown: float = 0.0
    failed: list = field(default_factory=list)
    first: str = ""
    diagnoses: list = field(default_factory=list)
    seconds: float = 0.0
    reproduce: str = ""

    def line(self) -> str:
        return json.dumps(asdict(self), sort_keys=True)


def write_program(model: Model, style: Style, backend: str, directory: Path, mistake: str = "") -> Path:
    """The program's file under ``directory`` (``MODEL--STYLE.py``, ``MODEL--STYLE--MISTAKE.py``), written whole."""
    from conformance.files import write_atomically

    name = f"{model.name}--{style.name}" + (f"--{mistake}" if mistake else "")
    return write_atomically(Path(directory) / f"{name}.py", program(model, style, backend, mistake).encode("utf-8"))


def judge_program(path: Path, model: Model, style: Style, backend: str, *, ticks: int = TICKS,
                  perturbed: int = 1, tolerance=None) -> Outcome:
    """App mode's verdict on the program at ``path``: its own run of ``ticks`` ticks, then ``perturbed``
    perturbed runs while it passes."""
    from conformance import apps
    from conformance.apps import perturbed as perturbed_mod

    start = time.perf_counter()
    outcome = Outcome(model.path, style.name, backend, "accepted")
    try:
        result = apps.check_app(path, ticks=ticks, tolerance=tolerance)
        if result.passed and perturbed:
            result = perturbed_mod.search(path, examples=perturbed, tolerance=tolerance) or result
    except apps.KitFailed as err:
        outcome.outcome, outcome.first = "error", str(err).splitlines()[0][:400]
    except apps.AppFailed as err:
        outcome.outcome, outcome.failed, outcome.first = "rejected", ["runs"], str(err).splitlines()[0][:400]
    else:
        failing = {check: v for check, v in result.verdicts.items() if not v.passed}
        if failing:
            outcome.outcome = "rejected"
            outcome.failed = list(failing)
            first = next(iter(failing.values()))
            outcome.first = f"{next(iter(failing))}: {first.lines[0] if first.lines else ''}"[:400]
            named = list(dict.fromkeys(d for v in failing.values() for d in v.diagnoses))  # as the report reads
            outcome.diagnoses = sorted(named, key=lambda d: d != lead(named))
            outcome.reproduce = result.reproduce()
    outcome.seconds = round(time.perf_counter() - start, 2)
    return outcome


def judge_wrong(wrong: Path, right: Path, model: Model, style: Style, backend: str, mistake: str, *,
                ticks: int = TICKS, tolerance=None) -> Outcome:
    """App mode's verdict on the program ``wrong`` (``right`` with ``mistake`` made), as :func:`judge_program`
    gives it; a wrong program accepted is then held against an independent oracle: its drawing against the
    right program's (:func:`_apart`), in its own run and in the perturbed opening. Within :data:`SAME` at
    every tick, the mistake changes nothing this model shows ("no-difference"); further, app mode missed it."""
    from conformance.apps import launch, perturb, perturbed as perturbed_mod

    outcome = judge_program(wrong, model, style, backend, ticks=ticks, tolerance=tolerance)
    outcome.mistake = mistake
    if outcome.outcome != "accepted":
        return outcome
    start = time.perf_counter()
    opening = [perturb.as_dict(e) for e in perturbed_mod.opening()]
    shown = 0.0
    for run_ticks, events in ((ticks, ()), (None, opening)):
        from conformance import apps

        run_ticks = run_ticks or apps.PERTURBED_TICKS
        drawn = [launch.record(path, ticks=run_ticks, events=events) for path in (wrong, right)]
        if len(drawn[0].actors) != len(drawn[1].actors):
            shown = float("inf")
            break
        for a, b in zip(drawn[0].actors, drawn[1].actors):
            if a.vertices.shape != b.vertices.shape:
                shown = float("inf")
                break
            shown = max(shown, _apart(a.vertices, b.vertices))
    outcome.shown = shown
    outcome.outcome = "missed" if shown > SAME else "no-difference"
    if outcome.outcome == "missed" and (model.path, mistake) in LIMITS:
        outcome.outcome, outcome.first = "limit", LIMITS[(model.path, mistake)]
    outcome.seconds = round(outcome.seconds + time.perf_counter() - start, 2)
    return outcome


def _apart(wrong, right) -> float:
    """How far the drawing ``wrong`` ``(T, n, 3)`` is from ``right`` at its worst tick: vertex by vertex, or,
    where that differs, as point sets (each vertex's distance to the other drawing's nearest, both ways). A
    shape turned onto itself (a cart's box turned a half turn by a reordered quaternion) shows the same
    surface with its vertices renumbered: what the model shows is the set, not the numbering."""
    import numpy as np
    from scipy.spatial import cKDTree

    each = float(np.max(np.linalg.norm(wrong - right, axis=-1), initial=0.0))
    if each <= SAME or not np.isfinite(wrong).all() or not np.isfinite(right).all():
        return each
    worst = 0.0
    for w, r in zip(wrong, right):
        worst = max(worst, float(np.max(cKDTree(r).query(w)[0], initial=0.0)),
                    float(np.max(cKDTree(w).query(r)[0], initial=0.0)))
    return worst


def load_journal(paths) -> list[Outcome]:
    """Every outcome the journal files hold (a line cut short by a kill is left out; for a program judged
    again, the line of the file written last wins: one file a process, so a later sitting's)."""
    found: dict[tuple, Outcome] = {}
    for path in sorted((Path(p) for p in paths if Path(p).exists()), key=lambda p: p.stat().st_mtime):
        for line in path.read_text(encoding="utf-8").splitlines():
            try:
                outcome = Outcome(**json.loads(line))
            except (ValueError, TypeError):
                continue
            if outcome.outcome == "missed" and (outcome.model, outcome.mistake) in LIMITS:  # its reason stated since
                outcome.outcome, outcome.first = "limit", LIMITS[(outcome.model, outcome.mistake)]
            found[(outcome.model, outcome.style, outcome.backend, outcome.mistake)] = outcome
    return list(found.values())
