"""Two sync implementations side by side on one scene: where their drawings differ, and which one
pyBullet agrees with (no pytest here; ``python -m conformance compare`` prints what this returns).

Both implementations run the same scene with the same parameters, each in its own
``runner.running(...)`` (its own pyBullet client and actors), stepped in lockstep: frame 0 (right
after set-up), then one step and one sync each per frame. At every frame, for every target:

* the *gap*: the largest distance between the same vertex as A draws it and as B draws it;
* each one's *error*: its worst vertex against the kit's truth (:func:`conformance.judge.compare.compare_vertices`),
  in units of that target's tolerance.

Besides, it notes the first frame at which either sync changed pyBullet's state (it must only read
it) and every change either made to an actor's data without telling the renderer (``Modified()``).

What is guaranteed: a :class:`SceneComparison` holds, per target, the largest gap and its frame and
each side's worst error and its frame, over every frame that ran; a side "agrees with pyBullet" on a
scene when every error of it was within tolerance at every frame (a non-finite vertex never is), it
announced every change to the renderer, left pyBullet's state alone and did not raise. A sync that
raises stops the scene's comparison at that frame (:attr:`SceneComparison.error` says which side,
which scene, which frame, and what was raised); the frames before it are kept.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from conformance import backends
from conformance.sync import runner
from conformance.judge import compare
from conformance.bullet import truth
from conformance.errors import SyncError
from conformance.checks.survey import times
from conformance.judge.tolerances import DEFAULT, Tolerance

__all__ = ["Judgement", "SceneComparison", "TargetComparison", "compare_scene", "verdict"]

#: The two sides, as every message names them.
SIDES = ("A", "B")


def verdict(a_agrees: bool, b_agrees: bool) -> str:
    """``both``, ``A agrees``, ``B agrees`` or ``neither``: which side pyBullet agrees with."""
    return {(True, True): "both", (True, False): "A agrees", (False, True): "B agrees"}.get((a_agrees, b_agrees), "neither")


@dataclass
class Judgement:
    """One side's worst vertex of one target against pyBullet, over every frame so far."""

    error: float = 0.0
    tolerance: float = math.inf
    frame: int | None = None
    result: Any = None  # the worst compare.VertexResult, for its describe()

    @property
    def ratio(self) -> float:
        if self.error != self.error or math.isinf(self.error):
            return math.inf
        return self.error / self.tolerance if self.tolerance else (0.0 if self.error == 0 else math.inf)

    @property
    def agrees(self) -> bool:
        return self.ratio <= 1.0

    @property
    def finite(self) -> bool:
        return math.isfinite(self.error)

    def note(self, result) -> None:
        """Keep ``result`` if it is worse (ties keep the earlier frame, so a NaN names its first frame)."""
        ratio = math.inf if not math.isfinite(result.error) else (
            result.error / result.tolerance if result.tolerance else math.inf)
        if self.frame is None or ratio > self.ratio:
            self.error, self.tolerance, self.frame, self.result = result.error, result.tolerance, result.frame, result

    def describe(self) -> str:
        if self.frame is None:
            return "–"
        if not self.finite:
            return f"non-finite (frame {self.frame})"
        return f"{times(self.ratio)}×tol (frame {self.frame})"


@dataclass
class TargetComparison:
    """One target: the largest gap between A's and B's drawings, and each side's judgement."""

    target: str
    gap: float = 0.0
    gap_frame: int | None = None
    gap_tolerance: float = math.inf  # the target's vertex tolerance at the gap's frame
    a: Judgement = field(default_factory=Judgement)
    b: Judgement = field(default_factory=Judgement)

    @property
    def differs(self) -> bool:
        """The two drawings are further apart than one tolerance somewhere (or one is not finite)."""
        return not self.gap <= self.gap_tolerance

    @property
    def verdict(self) -> str:
        return verdict(self.a.agrees, self.b.agrees)

    def describe_gap(self) -> str:
        if self.gap_frame is None:
            return "–"
        if not math.isfinite(self.gap):
            return f"non-finite (frame {self.gap_frame})"
        ratio = self.gap / self.gap_tolerance if self.gap_tolerance else math.inf
        return f"{self.gap:.3g} m = {times(ratio)}×tol (frame {self.gap_frame})"


@dataclass
class SceneComparison:
    """Two implementations on one scene: per target, how their drawings differ and who is right."""

    scene: str
    specs: tuple[str, str]
    params: Mapping[str, Any]
    frames: int  # the last frame asked for
    targets: list[TargetComparison] = field(default_factory=list)
    last_frame: int = -1  # the last frame both sides drew (frames, unless a sync raised)
    error: str | None = None  # a sync raised: which side, scene, frame, and what
    raised: str | None = None  # the side that raised
    raised_frame: int | None = None
    physics_diverged: int | None = None  # first frame the two runs' poses differed (a sync changed pyBullet)
    #: side -> the first frame whose sync call changed pyBullet's state (a sync must only read it).
    touched_physics: dict[str, int] = field(default_factory=dict)
    #: side -> its run's (frame, actor) of every sync that changed an actor's data without Modified().
    unannounced: dict[str, list] = field(default_factory=dict)
    image: Any = None  # rendering.records.ImageCheck of A's picture against B's, when asked
    image_frame: int | None = None

    def draws_right(self, side: str) -> bool:
        """Whether every vertex ``side`` drew was within tolerance of pyBullet's pose at every frame."""
        return all((t.a if side == "A" else t.b).agrees for t in self.targets)

    def agrees(self, side: str) -> bool:
        """Whether pyBullet agrees with ``side`` everywhere on this scene: it drew every vertex right,
        told the renderer of every change (or a live window shows the old vertices), left pyBullet's state
        alone, and did not raise."""
        return (self.raised != side and self.draws_right(side) and side not in self.touched_physics
                and not self.unannounced.get(side))

    @property
    def verdict(self) -> str:
        return verdict(self.agrees("A"), self.agrees("B"))

    @property
    def differing(self) -> list[TargetComparison]:
        """Targets drawn further apart than a tolerance, or judged differently, largest gap first."""
        rows = [t for t in self.targets if t.differs or not (t.a.agrees and t.b.agrees)]
        return sorted(rows, key=lambda t: (-(t.gap if t.gap == t.gap else math.inf), t.target))

    def worst(self, side: str) -> Judgement:
        judgements = [(t.a if side == "A" else t.b) for t in self.targets]
        return max(judgements, key=lambda j: j.ratio, default=Judgement())

    def worst_target(self, side: str) -> TargetComparison | None:
        return max(self.targets, key=lambda t: (t.a if side == "A" else t.b).ratio, default=None)


class _Raised(Exception):
    def __init__(self, side: str, frame: int, error: SyncError):
        super().__init__(str(error))
        self.side, self.frame, self.error = side, frame, error


@contextlib.contextmanager
def _running(side: str, scene: str, implementation, params: Mapping[str, Any]):
    """``runner.running`` that says which side raised while being set up or syncing frame 0."""
    try:
        with runner.running(scene, implementation, **params) as run:
            yield run
    except SyncError as err:
        raise _Raised(side, 0, err) from err


def _advance(side: str, run, touched: dict[str, int]) -> None:
    """Step and sync one frame; note in ``touched`` the first frame whose sync changed pyBullet's
    state (compared before and after the call, as ``test_sync_does_not_touch_physics`` does)."""
    run.step()
    before = run.scene.physics_state() if side not in touched else None
    try:
        run.sync()
    except SyncError as err:
        raise _Raised(side, run.frame, err) from err
    if before is not None and run.scene.physics_state() != before:
        touched[side] = run.frame


def _gaps(run_a, run_b) -> list[float]:
    """Per target, the largest distance between A's and B's drawing of the same vertex (inf if either
    is not finite)."""
    drawn_a, drawn_b, gaps = {}, {}, []
    for ta, tb in zip(run_a.drawing.targets, run_b.drawing.targets):
        if id(ta.actor) not in drawn_a:
            drawn_a[id(ta.actor)] = backends.world_vertices(ta.actor)
        if id(tb.actor) not in drawn_b:
            drawn_b[id(tb.actor)] = backends.world_vertices(tb.actor)
        distance = np.linalg.norm(drawn_a[id(ta.actor)][ta.start:ta.stop] - drawn_b[id(tb.actor)][tb.start:tb.stop], axis=1)
        distance = np.where(np.isfinite(distance), distance, np.inf)
        gaps.append(float(distance.max()) if len(distance) else 0.0)
    return gaps


def _poses(run) -> np.ndarray:
    positions, orientations = truth.link_frames(run.drawing.world.p, truth.items_of(run.drawing.targets))
    return np.concatenate([positions, orientations], axis=1)


def compare_scene(scene: str, a, b, *, frames: int, params: Mapping[str, Any] | None = None,
                  tolerance: Tolerance = DEFAULT, image_frame: int | None = None, image_tolerance=None) -> SceneComparison:
    """Run implementations ``a`` and ``b`` (loaded :class:`~conformance.sync.SyncImplementation`) on
    ``scene`` in lockstep for frames 0..``frames`` and compare them at every frame. With
    ``image_frame``, also render both at that frame and compare the pictures within
    ``image_tolerance`` (default: same-renderer, since both are rendered here); call it inside
    :func:`conformance.backends.display.virtual_display`."""
    params = dict(params or {})
    result = SceneComparison(scene=scene, specs=(a.spec, b.spec), params=params, frames=frames, image_frame=image_frame)
    try:
        with _running("A", scene, a, params) as run_a, _running("B", scene, b, params) as run_b:
            result.params = dict(run_a.params)
            result.targets = [TargetComparison(t.name) for t in run_a.drawing.targets]
            result.unannounced = {"A": run_a.unannounced, "B": run_b.unannounced}
            for frame in range(frames + 1):
                if frame:
                    _advance("A", run_a, result.touched_physics)
                    _advance("B", run_b, result.touched_physics)
                _observe(result, run_a, run_b, frame, tolerance)
                if image_frame is not None and frame in (0, image_frame):
                    # Frame 0 too, as a live window draws it: vertex data changed later without
                    # Modified() then stays drawn as it was, as it would on screen.
                    pictures = _compare_pictures(run_a, run_b, frame, image_tolerance)
                    if frame == image_frame:
                        result.image = pictures
    except _Raised as raised:
        spec = result.specs[SIDES.index(raised.side)]
        result.raised, result.raised_frame = raised.side, raised.frame
        result.error = (f"{raised.side} ({spec!r}) raised on scene {scene!r} at frame {raised.frame}, so the "
                        f"comparison stops there (frames 0..{result.last_frame} compared): {raised.error}")
    return result


def _observe(result: SceneComparison, run_a, run_b, frame: int, tolerance: Tolerance) -> None:
    judged_a = compare.compare_vertices(run_a.drawing, frame, tolerance)
    judged_b = compare.compare_vertices(run_b.drawing, frame, tolerance)
    for target, gap, ra, rb in zip(result.targets, _gaps(run_a, run_b), judged_a, judged_b):
        target.a.note(ra)
        target.b.note(rb)
        if target.gap_frame is None or gap > target.gap:  # ties keep the earlier frame
            target.gap, target.gap_frame, target.gap_tolerance = gap, frame, ra.tolerance
    if result.physics_diverged is None and not np.array_equal(_poses(run_a), _poses(run_b)):
        result.physics_diverged = frame
    result.last_frame = frame


def _compare_pictures(run_a, run_b, frame: int, image_tolerance):
    from conformance.rendering import compare as image_compare

    camera, size = run_a.scene.camera, run_a.scene.image_size
    picture_a = backends.render(run_a.drawing, camera, size)
    picture_b = backends.render(run_b.drawing, camera, size)
    return image_compare.compare_images(picture_a, picture_b, image_tolerance or image_compare.SAME_RENDERER,
                                        scene=run_a.scene.name, frame=frame)
