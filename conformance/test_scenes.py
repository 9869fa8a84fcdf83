"""Checks on the reference scenes themselves: they build, repeat exactly, clean up, and draw their
collision geometry. A failure here is the kit's fault (or pybullet's), not the sync's."""

from __future__ import annotations

import numpy as np
import pybullet
import pytest
from hypothesis import given

from conformance import backends, scenes
from conformance.checks import determinism
from conformance.judge import compare
from conformance.errors import InvalidArgument
from conformance.implementations.reference import ReferenceSync
from conformance.checks.profiles import check_settings
from conformance.checks.pytest_helpers import assert_geometry_matches, each_scene


def _open_clients() -> set[int]:
    return {c for c in range(256) if pybullet.isConnected(physicsClientId=c)}


@each_scene()
def test_builds_with_defaults(scene_name):
    """The scene builds from its defaults and every binding names a body (and link) that exists."""
    spec = scenes.get(scene_name)
    with spec.build() as scene:
        assert scene.bindings, f"scene {scene_name!r} binds nothing to draw"
        assert scene.steps > 0 and scene.image_size[0] > 0 and scene.image_size[1] > 0
        for b in scene.bindings:
            assert b.link < scene.p.getNumJoints(b.body), f"binding {b.name!r} names link {b.link} of body {b.body}, which has {scene.p.getNumJoints(b.body)}"
        assert np.isfinite(scene.poses()).all()


@pytest.mark.draws
@each_scene()
def test_builds_across_parameters(scene_name):
    """Every parameter set the scene's strategy can draw builds, steps and stays finite."""
    spec = scenes.get(scene_name)
    if spec.parameters is None:
        from conformance.sync import own_scenes

        if own_scenes.source_of(scene_name) is not None:  # yours: optional; the kit's: required
            pytest.skip(f"scene {scene_name!r} declares no parameter strategy (SceneSpec.parameters), so only its "
                        "defaults are checked; give it one to have Hypothesis vary it")
        pytest.fail(f"scene {scene_name!r} declares no parameter strategy, so Hypothesis cannot vary it")

    @check_settings(examples=3)
    @given(params=spec.parameters())
    def check(params):
        with spec.build(**params) as scene:
            for step in range(5):
                scene.advance(step)
            poses = scene.poses()
            assert np.isfinite(poses).all(), f"non-finite poses after 5 steps of {scene.reproduce()}"

    check()


@each_scene()
def test_is_deterministic_in_process(scene_name):
    """Two builds with the same parameters give bit-identical poses and velocities after every step."""
    first = determinism.digest(scene_name)
    second = determinism.digest(scene_name)
    assert first == second, f"scene {scene_name!r}: two runs with default parameters differ (digest {first} vs {second})"


@pytest.fixture(scope="session")
def subprocess_digests():
    return determinism.digests_in_subprocess(scenes.names())


@each_scene()
def test_is_deterministic_across_processes(scene_name, subprocess_digests):
    """A fresh Python process computes the same trajectory bit for bit."""
    here = determinism.digest(scene_name)
    assert subprocess_digests[scene_name] == here, (
        f"scene {scene_name!r}: digest {here} in this process, but {subprocess_digests[scene_name]} in a fresh one"
    )


@each_scene()
def test_disconnects_its_client(scene_name):
    """Closing the scene, leaving its ``with`` block by an exception, or failing to build, leaves no client."""
    before = _open_clients()
    spec = scenes.get(scene_name)
    with spec.build() as scene:
        client = scene.client
        assert pybullet.isConnected(physicsClientId=client)
    assert not pybullet.isConnected(physicsClientId=client), "client still connected after the with block"

    with pytest.raises(RuntimeError):
        with spec.build() as scene:
            raise RuntimeError("boom")
    assert _open_clients() == before, "client left connected after an exception in the with block"

    with pytest.raises(InvalidArgument):
        spec.build(no_such_parameter=1)
    assert _open_clients() == before, "client left connected after a failed build"


@each_scene()
@pytest.mark.parametrize("when", ["first", "last"])
def test_draws_its_collision_geometry(scene_name, when):
    """Every drawn body is its pybullet collision shape: same kind, size and frame (vertices on the
    shape's surface and spanning it), at the first frame and after the default run."""
    spec = scenes.get(scene_name)
    with spec.build() as scene:
        drawing = backends.build(scene)
        sync = ReferenceSync(drawing.world)
        sync()
        frame = 0
        if when == "last":
            scene.run(scene.steps)
            sync()
            frame = scene.steps
        results = compare.compare_collision_geometry(drawing, frame)
        assert_geometry_matches(results, scene=scene_name, params=scene.params, frame=frame)
