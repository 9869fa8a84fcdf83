"""Helpers the checks share: scene parametrization, the ``kit`` fixture's object, and ``assert_*``
helpers with readable messages.

Messages follow array-api-tests: ``x=…, but should be … [scene(params), frame]``, followed by a
command that reproduces the failure.

Two modes (:mod:`conformance.checks.survey`): by default an assertion fails the check at its first failing
frame; in survey mode (``--conformance-survey``) :class:`Kit` notes each failure by kind, with the
same message, and the check runs on and fails at its end with every kind it found.
"""

from __future__ import annotations

import contextlib
import functools
import weakref
from typing import Any, Callable, Iterable, Iterator, Mapping, Sequence

import pytest

from conformance import figures, scenes
from conformance.checks import profiles, survey as survey_module
from conformance.judge import compare, diagnosis
from conformance.bullet import events as events_module
from conformance.errors import SyncError
from conformance.checks.survey import WORST  # noqa: F401  (where the plugin and older callers find it)
from conformance.sync.printed import reproduce_command
from conformance.judge.tolerances import Tolerance

#: The label of the vertex checks' ``hypothesis.target``: the worst vertex error over its tolerance.
VERTEX_TARGET = "worst vertex error / tolerance"
#: Frames a replay runs past a failure to tell apart two mistakes that drew alike there (:func:`_told_apart`):
#: a step late and copied once part at the next frame; a body posed as rigid and its nodes posed again part
#: once it changes shape (tests/test_soft_bodies.py)
TELLING_FRAMES = 8

__all__ = [
    "VERTEX_TARGET",
    "Kit",
    "assert_geometry_matches",
    "assert_vertices_match",
    "bounds_figure",
    "each_golden_variant",
    "each_scene",
    "sync_run",
]


def each_scene(argname: str = "scene_name", origin: str | None = None, only: Sequence[str] | None = None):
    """Parametrize a check over every registered scene (or ``only`` these), one pytest id and
    ``scene`` mark each, so ``-k chain`` selects a scene and the verdict table groups by scene."""
    names = [n for n in scenes.names(origin) if only is None or n in only]
    return pytest.mark.parametrize(argname, [pytest.param(n, id=n, marks=pytest.mark.scene(n)) for n in names])


def variant_id(params: Mapping[str, Any]) -> str:
    """A golden variant's part of a pytest id: ``by_kind`` for ``grouping='by_kind'``, ``shared`` for
    ``shared=True``."""
    return "-".join(k if v is True else str(v) for k, v in params.items())


def each_golden_variant(argnames: str = "scene_name, variant"):
    """Parametrize a golden check over every scene (``variant={}``) and each of its golden variants
    (``SceneSpec.golden_variants``, ids such as ``mixed_shapes-by_kind``), all marked with the scene."""
    params = []
    for name in scenes.names():
        params.append(pytest.param(name, {}, id=name, marks=pytest.mark.scene(name)))
        params += [pytest.param(name, dict(v), id=f"{name}-{variant_id(v)}", marks=pytest.mark.scene(name))
                   for v in scenes.get(name).golden_variants]
    return pytest.mark.parametrize(argnames, params)


def _label(scene: str, params: Mapping[str, Any]) -> str:
    inner = ", ".join(f"{k}={v!r}" for k, v in params.items())
    return f"{scene}({inner})"


@contextlib.contextmanager
def sync_run(scene: str, implementation, events: Sequence = (), **params: Any) -> Iterator[Any]:
    """``runner.running`` for a check: a sync implementation that raises fails the check with one clear
    paragraph instead of a traceback through the kit."""
    from conformance.sync import runner

    try:
        with runner.running(scene, implementation, events=events, **params) as run:
            yield run
    except SyncError as err:  # the paragraph alone: the kit's frames and the error's chain say nothing more
        raise pytest.fail.Exception(str(err), pytrace=False) from None


def _context(run: Any, sync: str, frame: int) -> str:
    text = f"[{_label(run.scene.name, run.params)}, frame {frame}, sync {sync!r}"
    if run.events:
        text += f", events {events_module.dumps(run.events)}"
    return text + "]"


def _by_ratio(r: Any) -> tuple[bool, float]:
    """Sort key of vertex results: NaN first, then the largest error in tolerances."""
    return (r.error != r.error, r.error / r.tolerance if r.tolerance else r.error)


def _largest(failures: Sequence[Any]) -> Any:
    return max(failures, key=lambda r: (r.error != r.error, r.error))  # NaN first, then largest


def _drawn(run: Any, results: Sequence[Any], failures: Sequence[Any] = ()) -> dict[str, Any]:
    """What the failing targets ``results`` are drawn as now, and those of ``failures`` that are soft bodies,
    for their diagnoses (made later, if at all)."""
    soft = diagnosis.soft_names(run)
    return diagnosis.drawn_now(run, {r.target for r in results} | {r.target for r in failures if r.target in soft},
                               results[0].frame)


def _vertices_message(failures: Sequence[Any], run: Any, sync: str, worst: Any = None, drawn=None, tolerance=None) -> str:
    """The message of a frame's vertex failures, about ``worst`` (default: the largest error, NaN first),
    with the known mistake that explains its drawing (``drawn``: :func:`_drawn`), if one does."""
    if worst is None:
        worst = _largest(failures)
    lines = [f"{worst.describe()} {_context(run, sync, worst.frame)}"]
    if drawn:  # a soft body drawn as a rigid one first, whichever target is the worst
        found = diagnosis.explain_failures(run, drawn, worst, failures)
        pair = diagnosis.undecided(found, worst.frame)
        if pair:
            found = _told_apart(run, sync, worst, pair, tolerance) or found
        if found:
            lines.append(found[1])
    if len(failures) > 1:
        others = ", ".join(sorted({r.target for r in failures} - {worst.target}))
        lines.append(f"{len(failures)} targets out of tolerance at this frame" + (f" (also: {others[:300]})" if others else ""))
    lines.append("reproduce: " + reproduce_command(run.scene.name, sync, worst.frame, run.params, run.events, tolerance))
    return "\n".join(lines)


def _told_apart(run: Any, sync: str, worst: Any, pair: tuple[str, str], tolerance=None) -> tuple[str, str] | None:
    """A soft body's drawing that two mistakes (``pair``) draw alike at ``worst``'s frame (copied one step late or
    only once at the first step, where the previous nodes are the built ones; posed as a rigid body or its nodes
    posed again, until it changes shape): told apart at a later frame, in a run of its own from the start
    (issue 48). None when that run cannot be made, or tells nothing more within a few frames."""
    from conformance import sync as sync_module
    from conformance.sync import runner

    try:
        with runner.running(run.scene.name, sync_module.load(sync), run.events, **run.params) as again:
            again.advance(worst.frame + 1)
            for _ in range(TELLING_FRAMES):
                results = compare.compare_vertices(again.drawing, again.frame, *([tolerance] if tolerance is not None else []))
                failing = [r for r in results if r.target == worst.target and not r.ok]
                if not failing:
                    return None
                found = diagnosis.explain(again, diagnosis.drawn_now(again, {worst.target}, again.frame)[worst.target],
                                          failing[0].tolerance)
                if found and found[0] in pair and not diagnosis.undecided(found, again.frame):
                    break
                again.advance(1)
            else:
                return None
    except Exception:  # noqa: BLE001 - the failure stands as it is; the replay only refines its diagnosis
        return None
    return found[0], f"{found[1]} (told at frame {again.frame}: at frame {worst.frame} the two draw alike)"


def _normals_message(failures: Sequence[Any], run: Any, sync: str, tolerance=None) -> str:
    """The message of a frame's normals failures, with the known mistake that explains the worst (made
    from the run as it stands: call it at the failing frame, as survey mode's ``note`` does)."""
    worst = max(failures, key=lambda r: r.angle)
    found = diagnosis.diagnose_normals(run, worst)
    return "\n".join([f"{worst.describe()} {_context(run, sync, worst.frame)}", *([found] if found else []),
                      "reproduce: " + reproduce_command(run.scene.name, sync, worst.frame, run.params, run.events,
                                                        tolerance)])


def _unannounced_message(frame: int, actor: str, missed: str, run: Any, sync: str) -> str:
    from conformance import backends

    return (f"actor {actor!r}: at frame {frame} {missed}: the sync changed its vertex data without marking it "
            f"modified (no {backends.ANNOUNCE} covering it), so a live window keeps drawing the old ones "
            f"{_context(run, sync, frame)}\n{diagnosis.unannounced()}")


def assert_vertices_match(results: Iterable[Any], *, run: Any, sync: str) -> None:
    """Every target is drawn where pybullet says it is, within tolerance."""
    __tracebackhide__ = True
    failures = [r for r in results if not r.ok]
    if failures:
        pytest.fail(_vertices_message(failures, run, sync, drawn=_drawn(run, [_largest(failures)], failures)), pytrace=False)


def assert_geometry_matches(results: Iterable[Any], *, scene: str, params: Mapping[str, Any], frame: int) -> None:
    """Every target is drawn as exactly its collision shape."""
    __tracebackhide__ = True
    failures = [r for r in results if not r.ok]
    if failures:
        lines = [f"{r.target!r} ({r.kind}): {'; '.join(r.problems)}" for r in failures[:10]]
        pytest.fail(
            "drawn geometry is not the collision geometry [" + _label(scene, params) + f", frame {frame}]:\n"
            + "\n".join(lines),
            pytrace=False,
        )


class Kit:
    """What a check needs about the run it is part of: the sync under test, the tolerances, a place
    to record the worst error it saw (for the verdict table), and the mode. Provided as the ``kit``
    fixture.

    Default mode: :meth:`assert_frame` and :meth:`fail` raise at the first failure, with the messages
    the ``assert_*`` helpers give. Survey mode (``survey=True``, or ``--conformance-survey`` for the
    fixture): they note each failure in :attr:`survey` by kind and return, so the check runs every
    frame it would have run; the plugin fails the check at its end (:func:`conformance.checks.survey.settle`),
    or call :meth:`finish`."""

    def __init__(self, implementation, tolerance: Tolerance, node: pytest.Item | None = None,
                 survey: bool | None = None):
        self.implementation = implementation
        self.tolerance = tolerance
        self._node = node
        if survey is None:
            survey = node is not None and survey_module.enabled(node.config)
        #: Survey mode's findings (shared by every Kit of one check); None in default mode.
        self.survey: survey_module.Survey | None = None
        if survey:
            self.survey = survey_module.Survey() if node is None else node.stash.setdefault(
                survey_module.SURVEY, survey_module.Survey())
        #: The worst vertex error in tolerances since :meth:`aiming` began: how close the example came to failing.
        self.closest = 0.0
        # run -> how many of its unannounced changes are noted; weak, so a later run never inherits a count
        self._announced: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

    @property
    def sync(self) -> str:
        return self.implementation.spec

    def run(self, scene: str, events: Sequence = (), **params: Any):
        return sync_run(scene, self.implementation, events=events, **params)

    @contextlib.contextmanager
    def aiming(self, label: str = VERTEX_TARGET) -> Iterator[None]:
        """Around one Hypothesis example: the worst vertex error it saw, in tolerances, becomes its
        ``hypothesis.target`` (:func:`conformance.checks.profiles.aim`) when it ends without failing."""
        self.closest = 0.0
        yield
        profiles.aim(self.closest, label)

    def _record(self, worst: Any) -> None:
        """Note ``worst`` (a frame's worst vertex record, in tolerances; None: no target) as the figure."""
        if worst is None:
            return
        ratio = worst.error / worst.tolerance if worst.tolerance else worst.error
        figures.note("vertex position", worst.error, worst.tolerance, where=f"{worst.target!r} frame {worst.frame}")
        if not self.closest >= ratio:  # NaN wins
            self.closest = ratio
        if self._node is None:
            return
        best = self._node.stash.get(WORST, None)
        if best is None or not (best["ratio"] >= ratio):  # NaN ratios win
            self._node.stash[WORST] = {"ratio": ratio, "error": worst.error, "tolerance": worst.tolerance,
                                       "target": worst.target, "frame": worst.frame}

    def assert_frame(self, run: Any) -> None:
        """What is drawn now is right: vertices where pybullet says, normals turned with them, and
        every change announced to the renderer. Survey mode checks all three and notes what failed."""
        __tracebackhide__ = True
        frames = compare.link_poses(run.drawing)  # read once for vertices and normals alike
        results = compare.compare_vertices(run.drawing, run.frame, self.tolerance, frames=frames)
        self._record(results.worst())
        sync = self.sync
        # Vertices (with assert_vertices_match's message), then normals, then announcements: default mode
        # raises the first of them, survey mode notes each.
        failures = results.failures()
        if failures:
            worst = max(failures, key=_by_ratio)
            # What the failing targets are drawn as, read only if a message or picture is made (a survey
            # notes every failing frame and words few of them), always at this frame.
            drawn = functools.lru_cache(maxsize=None)(lambda: _drawn(run, [worst, _largest(failures)], failures))
            # The figure is the worst in tolerances, and so is its message; the first failure's message
            # stays default mode's own (about the largest error in metres).
            first = _vertices_message(failures, run, sync, drawn=drawn(), tolerance=self.tolerance) if self.survey is None else None
            self._picture(run, failures, first, drawn)
            self._failed("vertices", lambda w=worst: _vertices_message(failures, run, sync, w, drawn(), self.tolerance),
                         first=(lambda: first) if first is not None else (
                             lambda: _vertices_message(failures, run, sync, drawn=drawn(), tolerance=self.tolerance)),
                         value=worst.error, limit=worst.tolerance, unit="m", frame=worst.frame, target=worst.target)
        normals = compare.compare_normals(run.drawing, run.frame, self.tolerance, frames=frames)
        if normals:
            worst = max(normals, key=lambda r: r.angle / r.tolerance)
            figures.note("normals angle", worst.angle, worst.tolerance, where=f"{worst.target!r} frame {worst.frame}")
        if normals and self._node is not None:
            worst = max(normals, key=lambda r: r.angle / r.tolerance)
            best = self._node.stash.get(survey_module.WORST_NORMALS, None)
            if best is None or not (best["ratio"] >= worst.angle / worst.tolerance):  # NaN wins
                self._node.stash[survey_module.WORST_NORMALS] = {
                    "ratio": worst.angle / worst.tolerance, "error": worst.angle, "tolerance": worst.tolerance,
                    "target": worst.target, "frame": worst.frame}
        turned = [r for r in normals if not r.ok]
        if turned:
            worst = max(turned, key=lambda r: (r.angle / r.tolerance if r.tolerance else r.angle))
            self._failed("normals", lambda: _normals_message(turned, run, sync, self.tolerance), value=worst.angle,
                         limit=worst.tolerance, unit="rad", frame=worst.frame, target=worst.target)
        seen = self._announced.get(run, 0)
        for frame, actor, missed in run.unannounced[seen:]:
            self._failed("Modified", lambda: _unannounced_message(frame, actor, missed, run, sync), frame=frame,
                         target=actor)
        self._announced[run] = len(run.unannounced)

    def _picture(self, run: Any, failures: Sequence[Any], message: str | None, drawn: Callable[[], dict[str, Any]]) -> None:
        """The failing frame's picture for the report, with pyBullet's outline (:mod:`conformance.reports.misplaced`)."""
        from conformance.reports import misplaced

        worst = _largest(failures)
        if message is None:  # survey mode: the first failure's words, made only if its picture is kept
            if self._node is None or misplaced.PICTURE in self._node.stash:
                return
            message = _vertices_message(failures, run, self.sync, drawn=drawn(), tolerance=self.tolerance)
        misplaced.note(self._node, run, failures, worst, sync=self.sync, message=message, first=self.survey is not None)

    def fail(self, kind: str, message: str, *, exception: type[BaseException] | None = None, **numbers: Any) -> None:
        """A failure of ``kind`` (:data:`conformance.checks.survey.KINDS`) that a check found: raised now in
        default mode (``pytest.fail(message)``, or ``exception(message)`` for a check that has always
        failed with that type), noted in survey mode with ``numbers`` (``value``, ``limit``, ``unit``,
        ``frame``, ``target``, as :func:`conformance.checks.survey.figure` takes them)."""
        __tracebackhide__ = True
        self._failed(kind, message, exception=exception, **numbers)

    def _failed(self, kind: str, message, *, first=None, exception: type[BaseException] | None = None,
                **numbers: Any) -> None:
        """:meth:`fail` with ``message`` a string or a callable that makes it (called only when needed);
        ``first``, if given, is default mode's message, raised there and kept as a survey's first."""
        __tracebackhide__ = True
        if self.survey is not None:
            self.survey.note(kind, message, first=first, **numbers)
            return
        text = (first or message)() if callable(first or message) else (first or message)
        if self._node is not None:  # the plugin's record names the kind and figure of what was raised
            self._node.stash[survey_module.RAISED] = {kind: survey_module.figure(**numbers, message=text)}
        if exception is not None:
            raise exception(text)
        pytest.fail(text, pytrace=False)

    def finish(self) -> None:
        """Survey mode: fail now if anything was noted, with the first failure and every kind (what
        the plugin does at the end of a check). Nothing in default mode."""
        __tracebackhide__ = True
        if self.survey is not None and self.survey.kinds:
            pytest.fail(self.survey.failure_text(), pytrace=False)


def bounds_figure(problems: Sequence[str]) -> dict[str, Any]:
    """The worst of a target's bounds problems as figure numbers (value, limit, unit), read from the
    problems :func:`conformance.judge.compare.compare_bounds` states."""
    fig = survey_module.figure_from_message("bounds", "; ".join(problems))
    return {"value": fig["value"], "limit": fig["limit"], "unit": fig["unit"]}
