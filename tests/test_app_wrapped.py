"""App mode and the scene checks agree on the kit's own syncs.

``tests/apps/kit_scene.py`` makes a whole program of a kit scene, the kit's actors and a sync: a
ShowManager callback that steps and syncs. Run through app mode, the kit's ``reference`` and right syncs
in other styles pass every check and a perturbed run, on scenes that exercise each drawing path (shared
actors, multibodies, inertial offsets, every shape kind); wrong syncs that the scene checks reject are
rejected by app mode too, on the scene that shows their mistake, with the diagnosis the scene check's
mistake calls for. The whole cross-check (every wrong sync of the kill rate on every scene) is the
command in ``docs/apps.md``; this is its fixed sample.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conformance import apps
from conformance.apps import perturbed

APP = Path(__file__).parent / "apps" / "kit_scene.py"
TICKS = 40


@pytest.fixture
def wrapped(monkeypatch):
    def run(scene: str, sync: str, params: dict | None = None, **kwargs):
        monkeypatch.setenv("KIT_SCENE", scene)
        monkeypatch.setenv("KIT_PARAMS", json.dumps(params or {}))
        monkeypatch.setenv("KIT_SYNC", sync)
        monkeypatch.setenv("KIT_STEPS", str(TICKS))
        monkeypatch.setenv("PYTHONPATH", str(Path(__file__).parent))  # the child imports tests' sync modules
        return apps.check_app(APP, ticks=TICKS, **kwargs)
    return run


@pytest.mark.parametrize("scene, sync", [
    ("brick_wall_single", "reference"),
    ("chain", "reference"),
    ("mixed_shapes", "reference"),
    ("weighted", "reference"),
    ("wrecking_ball", "reference"),
    ("brick_wall_single", "right_syncs:IncrementalSync"),
    ("pendulum", "right_syncs:PositionOrientationSync"),
])
@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_right_syncs_wrapped_as_apps_pass(wrapped, scene, sync):
    result = wrapped(scene, sync)
    assert result.passed, "\n".join(v.message() for v in result.verdicts.values() if not v.passed)
    assert result.recording.ticks == TICKS
    assert perturbed.search(APP, examples=1) is None


@pytest.mark.parametrize("scene, sync, check, diagnosis", [
    ("crossing", "wrong_syncs:OneStepLate", "attached", "previous-step"),
    ("pendulum", "wrong_syncs:StaleLinkState", "attached", "previous-step"),
    ("pendulum", "wrong_syncs:TransposedRotation", "attached", "conjugate"),
    ("weighted", "wrong_syncs:IgnoresBaseInertialFrame", "placed", "com-frame"),
    ("crossing", "wrong_syncs:SkipsLastTarget", "drawn", None),
    ("weighted", "wrong_syncs:WritesPoseBack", "untouched", "written-back"),
    ("wrecking_ball", "wrong_syncs:WrongVertexRange", "placed", "other-body"),
    # shared sphere actors (the scene's default draws each body by its own actor, whose normals VTK and
    # pygfx turn with its matrix)
    ("mixed_shapes:by_kind", "wrong_syncs:NormalsNotRotated", "normals", "stale-normals"),
])
@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_wrong_syncs_wrapped_as_apps_fail_with_their_diagnosis(wrapped, scene, sync, check, diagnosis):
    scene, _, grouping = scene.partition(":")
    result = wrapped(scene, sync, {"grouping": grouping} if grouping else None)
    verdict = result.verdicts[check]
    assert not verdict.passed, f"{sync} on {scene}: {check} passed"
    if diagnosis is not None:
        assert diagnosis in verdict.diagnoses, verdict.message()


def test_a_sync_gated_on_velocity_fails_the_perturbed_opening(wrapped):
    """``VelocityGated`` skips bodies whose velocity is exactly zero. After a step under gravity no
    falling body's is, so the app's own run passes; the opening's teleport between the step and the sync
    of tick 4 leaves one at rest, drawn where it was (:class:`conformance.apps.perturb.AfterStep`). Without
    that teleport, ``free_fall``'s opening passes it (measured)."""
    assert wrapped("free_fall", "wrong_syncs:VelocityGated").passed
    found = perturbed.search(APP, examples=1)
    assert found is not None, "the perturbed opening passed VelocityGated"
    assert not found.verdicts["attached"].passed, found.verdicts["attached"].message()
    assert any(e.get("after_step") for e in found.events)
    # drawn where it was before the step only at the teleport's tick, right at every other: skipped, not late
    assert found.verdicts["attached"].diagnoses == ["skipped"], found.verdicts["attached"].message()
