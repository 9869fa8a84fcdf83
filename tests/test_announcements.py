"""Every change a sync makes to a buffer the renderer draws from is announced, buffer by buffer and
vertex by vertex: on FURY 2 pygfx uploads each buffer's announced chunks alone (issue: every change
reaches the screen). On FURY 0.12 one ``Modified()`` re-uploads the whole geometry, which
``tests/test_vertex_checks.py``'s ``ForgetsModified`` cases cover."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from conformance import backends, sync
from conformance.sync import runner

pytestmark = pytest.mark.skipif(backends.NAME != "pygfx", reason="per-buffer, per-range uploads are pygfx's; "
                                "FURY 0.12 re-uploads all of an actor's geometry on any Modified()")

SHARED = {"grouping": "by_kind"}  # mixed_shapes with its spheres, boxes and cylinders in shared actors


def _unannounced(spec: str, scene: str = "mixed_shapes", params=SHARED, frames: int = 30) -> list:
    with runner.running(scene, sync.load(spec), **params) as run:
        run.advance(frames)
        return list(run.unannounced)


@pytest.mark.parametrize("spec, scene, params", [
    ("wrong_syncs_pygfx:NormalsUnannounced", "mixed_shapes", SHARED),
    ("wrong_syncs_pygfx:AnnouncesLastRangeOnly", "mixed_shapes", SHARED),
    ("wrong_syncs_pygfx:AnnouncesLastRangeOnly", "brick_wall_single", {}),
])
def test_a_change_left_unannounced_in_a_buffer_or_a_range_is_found(spec, scene, params):
    found = _unannounced(spec, scene, params)
    assert found, f"{spec} on {scene}({params}): no unannounced change found, but its un-uploaded changes should be"
    buffer = "normals" if "Normals" in spec else "positions"
    frame, actor, missed = found[0]
    assert re.fullmatch(rf"its {buffer} changed at vertices? \d+(–\d+)?.*, (outside every range|with nothing) announced "
                        r"on them", missed), missed


@pytest.mark.parametrize("spec", ["reference", "right_syncs_pygfx:PerTargetSync", "guide-vertex"])
def test_right_syncs_announce_every_change(spec):
    for scene, params in (("mixed_shapes", SHARED), ("brick_wall_single", {})):
        found = _unannounced(spec, scene, params)
        assert not found, f"{spec} on {scene}({params}): unannounced changes at {found[:3]}, but should be none"


def test_the_check_fails_a_sync_that_announces_only_the_positions(pytester, monkeypatch):
    # In its own process: pygfx objects of this one's runs would outlive pytester's module snapshot.
    tests = str(Path(__file__).resolve().parent)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [tests, os.environ.get("PYTHONPATH")])))
    result = pytester.runpytest_subprocess("--pyargs", "conformance", "-p", "no:cacheprovider", "--hypothesis-profile", "default",
                                "--sync", "wrong_syncs_pygfx:NormalsUnannounced",
                                "-k", "test_vertices_match_poses_every_frame and mixed_shapes")
    result.assert_outcomes(failed=1)
    assert "without marking it modified" in result.stdout.str() and "diagnosis:" in result.stdout.str()
    assert re.search(r"actor '\w+': at frame \d+ its normals changed at vertices \d+", result.stdout.str()), result.stdout.str()
