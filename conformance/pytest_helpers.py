"""Helpers the checks share: scene parametrization, running a sync, and ``assert_*`` with readable messages.

Messages follow array-api-tests: ``x=…, but should be … [scene(params), frame]``, followed by a
command that reproduces the failure.
"""

from __future__ import annotations

import contextlib
import json
import shlex
from typing import Any, Iterable, Iterator, Mapping

import pytest

from conformance import scenes
from conformance.errors import SyncError

__all__ = [
    "assert_geometry_matches",
    "assert_vertices_match",
    "each_scene",
    "reproduce_command",
    "sync_run",
]


def each_scene(argname: str = "scene_name", origin: str | None = None):
    """Parametrize a check over every registered scene, one pytest id (and ``scene`` mark) each."""
    return pytest.mark.parametrize(
        argname, [pytest.param(n, id=n, marks=pytest.mark.scene(n)) for n in scenes.names(origin)]
    )


def reproduce_command(scene: str, sync: str, frames: int, params: Mapping[str, Any]) -> str:
    """The command line that replays a run frame by frame and prints every target's error."""
    words = ["python", "-m", "conformance", "check", scene, "--sync", sync, "--frames", str(frames)]
    if params:
        words += ["--params", json.dumps(dict(params), sort_keys=True)]
    return shlex.join(words)


def _label(scene: str, params: Mapping[str, Any]) -> str:
    inner = ", ".join(f"{k}={v!r}" for k, v in params.items())
    return f"{scene}({inner})"


@contextlib.contextmanager
def sync_run(scene: str, implementation, **params: Any) -> Iterator[Any]:
    """``runner.running`` for a check: a sync implementation that raises fails the check with one
    clear paragraph instead of a traceback through the kit."""
    from conformance import runner

    try:
        with runner.running(scene, implementation, **params) as run:
            yield run
    except SyncError as err:
        pytest.fail(str(err), pytrace=False)


def assert_vertices_match(results: Iterable[Any], *, run: Any, sync: str) -> None:
    """Every target is drawn where pybullet says it is, within tolerance."""
    __tracebackhide__ = True
    failures = [r for r in results if not r.ok]
    if not failures:
        return
    worst = max(failures, key=lambda r: (r.error != r.error, r.error))  # NaN first, then largest
    lines = [
        f"{worst.describe()} [{_label(run.scene.name, run.params)}, frame {worst.frame}, sync {sync!r}]",
    ]
    if len(failures) > 1:
        others = ", ".join(sorted({r.target for r in failures} - {worst.target}))
        lines.append(f"{len(failures)} targets out of tolerance at this frame" + (f" (also: {others[:300]})" if others else ""))
    lines.append("reproduce: " + reproduce_command(run.scene.name, sync, worst.frame, run.params))
    pytest.fail("\n".join(lines), pytrace=False)


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
