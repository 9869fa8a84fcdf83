"""A scene's default run, stepped once and watched by every check that looks at it.

Several checks look at the same run: the scene with its default parameters, synced from frame 0
after every step (each vertex every frame, the mesh kept, pyBullet untouched, the bounds, pyBullet's
silhouettes at the golden frames; ``tumbling``'s no-drift check). Run one by one, each would build,
step and sync the scene again. Here a check registers a *watcher* (:func:`watcher`): what it looks
at after each frame's sync, up to which frame. The first of them to run steps the scene once, as far
as the furthest of the selected watchers needs, and every selected watcher looks at its frames; each
check then reports what its own watcher saw (:func:`report`), as it would have alone: in default
mode its first failure, in survey mode every kind with its worst figure. The verdicts are the same
as before: each watcher sees the same frames, drawn by a sync called the same way, in the same order.

A watcher records through a :class:`~conformance.checks.pytest_helpers.Kit` of its own, in survey mode, so
nothing it finds stops the others; a sync that raises stops the run, and every check that shares it
fails with the same paragraph. Only watchers whose check is selected for the scene in this session
run (``-k`` narrows the shared run too). Under pytest-xdist each worker keeps its own shared runs, so
two workers may step the same scene (``--dist loadgroup`` keeps a scene's checks on one worker).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any, Callable

import pytest

from conformance import scenes
from conformance.checks import survey as survey_module
from conformance.reports import misplaced
from conformance.errors import SyncError

__all__ = ["Watcher", "WATCHERS", "report", "seen", "watcher"]


@dataclass(frozen=True)
class Watcher:
    """What one check looks at in the shared run: ``look(run, kit)`` after the sync of every frame
    from 0 to ``last(spec)`` (``physics``: also ``look(run, kit, before=…)`` with pyBullet's state
    captured just before the sync, for frames 1 to ``last``)."""

    check: str
    last: Callable[[Any], int]
    look: Callable[..., None]
    scenes: tuple[str, ...] | None = None  # None: every scene
    physics: bool = False


#: The registered watchers, by check name (registered when the check's module is imported).
WATCHERS: dict[str, Watcher] = {}
_RUNS = pytest.StashKey[dict]()


def watcher(check: str, *, last: Callable[[Any], int], scenes: tuple[str, ...] | None = None, physics: bool = False):
    """Register ``look`` as the watcher of ``check`` (a decorator)."""

    def register(look):
        WATCHERS[check] = Watcher(check, last, look, scenes, physics)
        return look

    return register


def _selected(session, scene: str) -> list[Watcher]:
    """The watchers whose check is selected for ``scene`` in this session."""
    names = {getattr(item, "originalname", item.name) for item in session.items
             if (m := item.get_closest_marker("scene")) is not None and m.args[0] == scene}
    return [w for name, w in WATCHERS.items() if name in names and (w.scenes is None or scene in w.scenes)]


def _run(kit, scene: str, watchers: list[Watcher], config) -> dict[str, Any]:
    """Step ``scene`` once with the kit's sync; each watcher records into a survey-mode Kit of its own
    (whose ``_node`` has a ``stash`` dict and the session's ``config``)."""
    from conformance.checks.pytest_helpers import Kit

    spec = scenes.get(scene)
    seen = {w.check: SimpleNamespace(stash={}, config=config) for w in watchers}
    kits = {w.check: Kit(kit.implementation, kit.tolerance, seen[w.check], survey=True) for w in watchers}
    last = max(w.last(spec) for w in watchers)
    try:
        with kit.run(scene) as run:
            for frame in range(last + 1):
                active = [w for w in watchers if frame <= w.last(spec)]
                before = None
                if frame:
                    run.step()
                    if any(w.physics for w in active):
                        before = run.scene.physics_state()
                    run.sync()
                for w in active:
                    if w.physics:
                        if before is not None:
                            w.look(run, kits[w.check], before=before)
                    else:
                        w.look(run, kits[w.check])
    except SyncError as err:  # what sync_run turns into a failure: every sharing check fails with it
        return {"error": str(err)}
    except pytest.fail.Exception as failure:
        return {"error": str(failure)}
    return seen


def seen(kit, check: str, scene: str) -> dict:
    """The stash of ``check``'s watcher in ``scene``'s shared run, made on first use in this session
    (a kit outside a pytest session, as the kit's own tests make, gets a run of its own watcher);
    fails the check if the sync raised."""
    __tracebackhide__ = True
    node = kit._node
    config = getattr(node, "config", None)
    if config is None:
        found = _run(kit, scene, [WATCHERS[check]], None)
    else:
        runs = config.stash.setdefault(_RUNS, {})
        key = (kit.implementation, kit.tolerance, scene)
        if key not in runs or (check not in runs[key] and "error" not in runs[key]):
            runs[key] = _run(kit, scene, _selected(node.session, scene) or [WATCHERS[check]], config)
        found = runs[key]
    if "error" in found:
        pytest.fail(found["error"], pytrace=False)
    return found[check].stash


def report(kit, check: str, scene: str) -> None:
    """Fail (or, in survey mode, note) what ``check``'s watcher saw in ``scene``'s shared run, as
    the check would have alone."""
    __tracebackhide__ = True
    _replay(kit, seen(kit, check, scene))


def _replay(kit, stash: dict) -> None:
    __tracebackhide__ = True
    from conformance.checks.pytest_helpers import WORST

    node = kit._node
    worst = stash.get(WORST)
    if worst is not None and node is not None:
        best = node.stash.get(WORST, None)
        if best is None or not (best["ratio"] >= worst["ratio"]):
            node.stash[WORST] = worst
    found = stash.get(survey_module.SURVEY)
    if found is None or not found.kinds:
        return
    picture = stash.get(misplaced.PICTURE)
    if picture is not None and node is not None and misplaced.PICTURE not in node.stash:
        record, images = picture  # the watcher's failing frame, in this check's report
        node.stash[misplaced.PICTURE] = (dataclasses.replace(record, nodeid=getattr(node, "nodeid", "")), images)
    if kit.survey is not None:
        kit.survey.merge(found)
        return
    if node is not None:  # the record names the kind and figure of what default mode raises
        node.stash[survey_module.RAISED] = {found.first_kind: found.kinds[found.first_kind]}
    pytest.fail(found.first, pytrace=False)
