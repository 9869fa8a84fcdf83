"""Helpers the checks share: scene parametrization, the ``kit`` fixture's object, and ``assert_*``
helpers with readable messages.

Messages follow array-api-tests: ``x=…, but should be … [scene(params), frame]``, followed by a
command that reproduces the failure.
"""

from __future__ import annotations

import contextlib
import json
import shlex
from typing import Any, Iterable, Iterator, Mapping, Sequence

import pytest

from conformance import compare, events as events_module, scenes
from conformance.errors import SyncError
from conformance.tolerances import Tolerance

__all__ = [
    "Kit",
    "assert_geometry_matches",
    "assert_vertices_match",
    "each_scene",
    "reproduce_command",
    "sync_run",
]

WORST = pytest.StashKey[dict]()


def each_scene(argname: str = "scene_name", origin: str | None = None, only: Sequence[str] | None = None):
    """Parametrize a check over every registered scene (or ``only`` these), one pytest id and
    ``scene`` mark each, so ``-k chain`` selects a scene and the verdict table groups by scene."""
    names = [n for n in scenes.names(origin) if only is None or n in only]
    return pytest.mark.parametrize(argname, [pytest.param(n, id=n, marks=pytest.mark.scene(n)) for n in names])


def reproduce_command(scene: str, sync: str, frames: int, params: Mapping[str, Any], events: Sequence = ()) -> str:
    """The command line that replays a run frame by frame and prints every target's error."""
    words = ["python", "-m", "conformance", "check", scene, "--sync", sync, "--frames", str(frames)]
    if params:
        words += ["--params", json.dumps(dict(params), sort_keys=True)]
    if events:
        words += ["--events", events_module.dumps(events)]
    return shlex.join(words)


def _label(scene: str, params: Mapping[str, Any]) -> str:
    inner = ", ".join(f"{k}={v!r}" for k, v in params.items())
    return f"{scene}({inner})"


@contextlib.contextmanager
def sync_run(scene: str, implementation, events: Sequence = (), **params: Any) -> Iterator[Any]:
    """``runner.running`` for a check: a sync implementation that raises fails the check with one
    clear paragraph instead of a traceback through the kit."""
    from conformance import runner

    try:
        with runner.running(scene, implementation, events=events, **params) as run:
            yield run
    except SyncError as err:
        pytest.fail(str(err), pytrace=False)


def _context(run: Any, sync: str, frame: int) -> str:
    text = f"[{_label(run.scene.name, run.params)}, frame {frame}, sync {sync!r}"
    if run.events:
        text += f", events {events_module.dumps(run.events)}"
    return text + "]"


def assert_vertices_match(results: Iterable[Any], *, run: Any, sync: str) -> None:
    """Every target is drawn where pybullet says it is, within tolerance."""
    __tracebackhide__ = True
    failures = [r for r in results if not r.ok]
    if not failures:
        return
    worst = max(failures, key=lambda r: (r.error != r.error, r.error))  # NaN first, then largest
    lines = [f"{worst.describe()} {_context(run, sync, worst.frame)}"]
    if len(failures) > 1:
        others = ", ".join(sorted({r.target for r in failures} - {worst.target}))
        lines.append(f"{len(failures)} targets out of tolerance at this frame" + (f" (also: {others[:300]})" if others else ""))
    lines.append("reproduce: " + reproduce_command(run.scene.name, sync, worst.frame, run.params, run.events))
    pytest.fail("\n".join(lines), pytrace=False)


def assert_normals_turn(results: Iterable[Any], *, run: Any, sync: str) -> None:
    """Stored vertex normals turn with their body, so the body is lit as it is posed."""
    __tracebackhide__ = True
    failures = [r for r in results if not r.ok]
    if failures:
        worst = max(failures, key=lambda r: r.angle)
        pytest.fail(f"{worst.describe()} {_context(run, sync, worst.frame)}\nreproduce: "
                    + reproduce_command(run.scene.name, sync, worst.frame, run.params, run.events), pytrace=False)


def assert_changes_announced(run: Any, *, sync: str) -> None:
    """Every change a sync makes to an actor's data is announced to VTK (``Modified()``), or a live
    renderer keeps drawing the old vertices (FURY's ``utils.update_actor`` does this)."""
    __tracebackhide__ = True
    if run.unannounced:
        frame, actor = run.unannounced[0]
        pytest.fail(
            f"actor {actor!r}: the sync changed its vertex data at frame {frame} without marking it modified "
            "(no Modified()/utils.update_actor), so a live VTK window keeps drawing the old vertices "
            f"{_context(run, sync, frame)}", pytrace=False)


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
    """What a check needs about the run it is part of: the sync under test, the tolerances, and a
    place to record the worst error it saw (for the verdict table). Provided as the ``kit`` fixture."""

    def __init__(self, implementation, tolerance: Tolerance, node: pytest.Item | None = None):
        self.implementation = implementation
        self.tolerance = tolerance
        self._node = node

    @property
    def sync(self) -> str:
        return self.implementation.spec

    def run(self, scene: str, events: Sequence = (), **params: Any):
        return sync_run(scene, self.implementation, events=events, **params)

    def _record(self, results: Sequence[Any]) -> None:
        if self._node is None or not results:
            return
        worst = max(results, key=lambda r: (r.error != r.error, r.error / r.tolerance if r.tolerance else r.error))
        ratio = worst.error / worst.tolerance if worst.tolerance else worst.error
        best = self._node.stash.get(WORST, None)
        if best is None or not (best["ratio"] >= ratio):  # NaN ratios win
            self._node.stash[WORST] = {"ratio": ratio, "error": worst.error, "tolerance": worst.tolerance,
                                       "target": worst.target, "frame": worst.frame}

    def assert_frame(self, run: Any) -> None:
        """What is drawn now is right: vertices where pybullet says, normals turned with them, and
        every change announced to VTK."""
        __tracebackhide__ = True
        results = compare.compare_vertices(run.drawing, run.frame, self.tolerance)
        self._record(results)
        assert_vertices_match(results, run=run, sync=self.sync)
        assert_normals_turn(compare.compare_normals(run.drawing, run.frame, self.tolerance), run=run, sync=self.sync)
        assert_changes_announced(run, sync=self.sync)
