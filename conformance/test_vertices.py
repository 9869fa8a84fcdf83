"""Vertex conformance: after every frame, what FURY draws is where pybullet says each body is.

Ground truth is the kit's own (``conformance.truth``): each target's geometry captured in its link
frame when the actor was built, moved by pybullet's link-frame pose; read-back is what VTK will draw
(polydata points through the actor's full matrix). The sync's own bookkeeping is never read.
"""

from __future__ import annotations

from conformance import compare, scenes
from conformance.pytest_helpers import assert_vertices_match, each_scene, sync_run


@each_scene()
def test_vertices_match_poses_every_frame(scene_name, sync_implementation):
    """The guide's scenes with their own parameters: every target, every frame of the default run."""
    spec = scenes.get(scene_name)
    with sync_run(scene_name, sync_implementation) as run:
        assert_vertices_match(compare.compare_vertices(run.drawing, 0), run=run, sync=sync_implementation.spec)
        for frame in run.frames(spec.steps):
            assert_vertices_match(compare.compare_vertices(run.drawing, frame), run=run, sync=sync_implementation.spec)
