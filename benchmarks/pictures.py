"""What one picture costs at a scene's own image size, as a ratio to one frame of the same scene.

The baseline, *one frame*, is what a run does every frame without looking: one ``stepSimulation()``
of the scene and the reference sync. Against it, in the same rounds:

* **render + read-back**: ``backends.render``, the off-screen picture the golden check takes;
* **golden comparison**: ``rendering.compare.compare_images`` of two renders, with the same-renderer
  tolerance; of two identical pictures (the usual pass on the machine that made the goldens: FLIP is
  skipped when no pixel differs) and of pictures one frame apart (FLIP computed);
* **pyBullet-renderer check**: the silhouette check as the conformance checks make it (FURY's flat ID
  render, pyBullet's ``getCameraImage`` segmentation mask with its tiny renderer, the per-target
  IoU), and each of its two renders alone;
* **the frame checks**: what every checked frame costs beside its step and sync, ``Kit.assert_frame``
  (vertices and normals against pyBullet's link frames, announcements), no picture.

The scenes are the kit's own, at a frame in the middle of the action, synced by ``reference``.
"""

from __future__ import annotations

from dataclasses import dataclass

from conformance import backends, scenes, sync
from conformance.sync import runner
from conformance.rendering import compare, silhouettes

from .timing import Candidate, RatioToBaseline, race

__all__ = ["FRAME", "PictureFigure", "SCENES", "measure"]

#: Whole actors (every brick its own) and one shared actor (the bricks drawn together).
SCENES = ("brick_wall", "brick_wall_single")
FRAME = "one frame: `stepSimulation()` + `reference` sync"


@dataclass(frozen=True)
class PictureFigure(RatioToBaseline):
    """``seconds`` per call of ``name`` on ``scene``; ``baseline``: one frame of the same scene."""

    scene: str
    name: str
    seconds: float
    baseline: float
    size: tuple[int, int]


def measure(scene_name: str, *, repeats: int, number: int = 1) -> list[PictureFigure]:
    """Every picture cost of ``scene_name`` against one of its frames."""
    from conformance.checks.pytest_helpers import Kit
    from conformance.judge.tolerances import DEFAULT

    spec = scenes.get(scene_name)
    reference = sync.load("reference")
    kit = Kit(reference, DEFAULT)
    with runner.running(scene_name, reference) as run:
        run.advance(spec.poster_step or spec.steps // 2)
        scene, drawing = run.scene, run.drawing
        camera, size = scene.camera, tuple(scene.image_size)
        names = [t.name for t in drawing.targets]
        limits = silhouettes.thresholds(scene.bindings)
        render = lambda: backends.render(drawing, camera, size)  # noqa: E731
        golden = render()  # also makes the window and the drawing's stage: not part of any figure
        run.advance(1)
        moved = render()
        same = golden.copy()
        tolerance = compare.SAME_RENDERER

        def frame():
            scene.p.stepSimulation()
            run.syncer(run.frame)

        def fury_ids():
            return backends.render_ids(drawing, camera, size)

        def pybullet_ids():
            return silhouettes.pybullet_mask(scene, scene.bindings, camera, size)

        def silhouette_check():
            return silhouettes.compare_silhouettes(fury_ids(), pybullet_ids(), min_iou=limits, names=names,
                                                   scene=scene_name, frame=run.frame)

        candidates = [
            Candidate(FRAME, frame),
            Candidate("render + read-back", render),
            Candidate("golden comparison, identical pictures (no FLIP)",
                      lambda: compare.compare_images(golden, same, tolerance)),
            Candidate("golden comparison, pictures one frame apart (FLIP)",
                      lambda: compare.compare_images(golden, moved, tolerance)),
            Candidate("pyBullet-renderer (silhouette) check", silhouette_check),
            Candidate("… of which FURY's flat ID render", fury_ids),
            Candidate("… of which pyBullet's `getCameraImage` (tiny renderer)", pybullet_ids),
            Candidate("the frame checks (`Kit.assert_frame`: vertices, normals, announcements)", lambda: kit.assert_frame(run)),
        ]
        best = race(candidates, repeats=repeats, number=number)
    return [PictureFigure(scene_name, name, seconds, best[FRAME], size) for name, seconds in best.items()]
