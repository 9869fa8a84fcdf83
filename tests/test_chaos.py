"""Which scenes' physics is chaotic, measured: the golden physics verdict may only be lenient there."""

from __future__ import annotations

import pytest

from conformance import scenes
from conformance.checks import determinism
from conformance.bullet import state

pytestmark = pytest.mark.fury_free("its verdict cannot depend on the FURY: pyBullet alone")


@pytest.mark.parametrize("scene_name", scenes.names())
def test_chaotic_after_is_where_a_nanometre_nudge_diverges(scene_name):
    """``SceneSpec.chaotic_after`` is exactly the last step before a 1 nm nudge of every body grows past
    the physics verdict's tolerance (within the scene's golden frames), and None where it never does:
    the golden physics check is lenient where, and only where, another platform's rounding may show."""
    spec = scenes.get(scene_name)
    last = max(spec.frames_with_goldens())
    diverges = determinism.first_divergence(scene_name, last)
    assert (None if diverges is None else diverges - 1) == spec.chaotic_after, (
        f"{scene_name}: a 1 nm nudge diverges after step {diverges}, but chaotic_after={spec.chaotic_after}")


def test_a_reset_keeps_velocity_when_nudged():
    with scenes.build("free_fall") as scene:
        before = scene.p.getBaseVelocity(0)
        state.nudged(scene)
        assert scene.p.getBaseVelocity(0) == before
