"""Off-screen rendering is repeatable: the same scene rendered twice in one process gives the same pixels.

Golden-image comparison builds on this; if it fails, no tolerance can be trusted.
"""

from __future__ import annotations

from conformance import backends
from conformance.checks import shared_run
from conformance.checks.pytest_helpers import each_scene, sync_run
from conformance.rendering import images

#: The frame of the default run both builds are rendered at.
FRAME = 30
_PICTURES = "test_same_scene_renders_identically:pictures"


def _at(spec) -> int:
    return min(spec.steps, FRAME)


@shared_run.watcher("test_same_scene_renders_identically", last=_at)
def _first_build(run, kit):
    if run.frame == _at(run.scene):
        kit._node.stash[_PICTURES] = [backends.render(run.drawing, run.scene.camera, run.scene.image_size)
                                      for _ in range(2)]


@each_scene()
def test_same_scene_renders_identically(scene_name, kit):
    """Render the default run at frame 30 twice (the scene's shared run,
    :mod:`conformance.checks.shared_run`, is the first build), then a second, freshly built copy at the
    same frame once."""
    first, again = shared_run.seen(kit, "test_same_scene_renders_identically", scene_name)[_PICTURES]
    with sync_run(scene_name, kit.implementation) as run:
        run.advance(_at(run.scene))
        second = backends.render(run.drawing, run.scene.camera, run.scene.image_size)
    images.assert_identical(first, again, what=f"{scene_name}: the same drawing rendered twice")
    images.assert_identical(first, second, what=f"{scene_name}: two builds of the scene rendered")
