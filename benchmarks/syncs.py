"""Sync cost per frame against the floor, on the bench grid, for whole actors and one shared actor.

For one size and drawing style: one grid scene (:mod:`.grid`); every candidate gets its own drawing of
it (its own actors, the one pyBullet client), is set up through its factory and synced once untimed
(frame 0), as the kit does. Then, in every round (:func:`.timing.race`), each candidate is timed on
``number`` frames, each after one untimed ``stepSimulation()``, so that every pose has changed, as in
a run. ``stepSimulation()`` itself is timed in the same rounds, for scale.

A figure is seconds per frame (best of the rounds); its ratio is to the floor's (:mod:`.floor`) for
the same size and style. After timing, every candidate syncs one more frame and is judged by the
kit's own vertex check (``conformance.judge.compare.compare_vertices``), so a sync cannot look fast by
skipping work without the table saying it draws wrong.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from conformance import backends, sync
from conformance.judge import compare

from . import grid
from .floor import Floor
from .timing import Candidate, race

__all__ = ["GUIDE_RECIPES", "STEP", "STYLES", "SyncFigure", "frames_per_round", "measure"]

STYLES = ("whole", "shared")
#: The guide's recipes that apply to each drawing style: the actor recipe moves whole actors, the
#: vertex recipe bodies sharing an actor (the joint recipe moves links, which the grid has none of;
#: ``guide``, the three combined, runs exactly the one recipe that applies).
GUIDE_RECIPES = {"whole": ("guide-actor",), "shared": ("guide-vertex",)}
FLOOR = "floor"
STEP = "stepSimulation()"


@dataclass(frozen=True)
class SyncFigure:
    """One candidate at one size and style: ``seconds`` per frame, and the floor's for the same."""

    style: str
    bodies: int
    name: str  # "floor", "stepSimulation()", or a sync implementation's spec
    seconds: float
    floor: float
    #: Targets drawn outside the kit's vertex tolerance after the timed frames, and the largest vertex
    #: error (m); None where not judged (the floor and the step draw nothing of their own).
    wrong: int | None = None
    worst_error: float | None = None

    @property
    def ratio(self) -> float:
        return self.seconds / self.floor

    @property
    def per_body(self) -> float:
        """Seconds per body per frame."""
        return self.seconds / self.bodies

    def as_dict(self) -> dict:
        return {**asdict(self), "ratio": self.ratio, "per_body": self.per_body}


def frames_per_round(bodies: int) -> int:
    """Frames timed per round: a few milliseconds of the floor's work, so that a round is long against
    the timer and short against the slow spells of a shared machine (the best round is kept)."""
    return max(3, 3_000 // max(bodies, 1))


def measure(bodies: int, style: str, specs: list[str], *, repeats: int, number: int | None = None) -> list[SyncFigure]:
    """The floor, ``stepSimulation()`` and every sync in ``specs`` at ``bodies`` bodies drawn ``style``."""
    if style not in STYLES:
        raise ValueError(f"style={style!r}, but should be one of {STYLES}")
    implementations = [sync.load(spec) for spec in specs]
    with grid.grid(bodies, shared=style == "shared") as scene:
        drawings, candidates = {}, []
        for name, factory in [(FLOOR, Floor)] + [(i.spec, i.factory) for i in implementations]:
            drawing = backends.build(scene)
            fn = factory(drawing.world)
            fn()  # frame 0, untimed, as the kit calls it right after set-up
            drawings[name] = (drawing, fn)
            candidates.append(Candidate(name, fn, before=scene.p.stepSimulation))
        candidates.append(Candidate(STEP, scene.p.stepSimulation))
        best = race(candidates, repeats=repeats, number=number or frames_per_round(bodies))
        # One more frame for everyone, then the kit's vertex check on each sync's drawing.
        scene.p.stepSimulation()
        for _, fn in drawings.values():
            fn()
        figures = []
        for name, seconds in best.items():
            wrong = worst = None
            if name not in (FLOOR, STEP):
                records = compare.compare_vertices(drawings[name][0], frame=-1)
                wrong = sum(not r.ok for r in records)
                worst = max((r.error for r in records), default=0.0)
            figures.append(SyncFigure(style, bodies, name, seconds, best[FLOOR], wrong, worst))
    return figures
