"""Off-screen rendering is repeatable: the same scene rendered twice in one process gives the same pixels.

Golden-image comparison builds on this; if it fails, no tolerance can be trusted.
"""

from __future__ import annotations

from conformance import backends
from conformance.rendering import images
from conformance.checks.pytest_helpers import each_scene, sync_run


@each_scene()
def test_same_scene_renders_identically(scene_name, sync_implementation):
    """Render after the default run, render again, and render a second, freshly built copy."""
    pictures = []
    for again in (True, False):  # the second build's drawing is rendered once: a second picture of it was never compared
        with sync_run(scene_name, sync_implementation) as run:
            run.advance(min(run.scene.steps, 30))
            pictures.append(backends.render(run.drawing, run.scene.camera, run.scene.image_size))
            if again:
                pictures.append(backends.render(run.drawing, run.scene.camera, run.scene.image_size))
    images.assert_identical(pictures[0], pictures[1], what=f"{scene_name}: the same drawing rendered twice")
    images.assert_identical(pictures[0], pictures[2], what=f"{scene_name}: two builds of the scene rendered")
