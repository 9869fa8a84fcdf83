"""Silhouettes and framing: FURY draws each body where pyBullet's own renderer draws it, with no golden.

At each scene's golden frames (first, middle, last) the sync under test has placed the actors; FURY
renders every target flat in its own colour (``backends.render_ids``) and pyBullet renders its
segmentation mask with the same camera (``getCameraImage``, tiny renderer); each target's silhouettes
must agree (``rendering.silhouettes``). The scene's camera must show every body whole and large enough
for that to mean something (``rendering.framing``).
"""

from __future__ import annotations

import pytest
from hypothesis import given, strategies as st

from conformance import backends, scenes
from conformance.checks import image_options, shared_run, strategies
from conformance.bullet.events import Teleport
from conformance.checks.profiles import check_settings
from conformance.checks.pytest_helpers import _context, each_scene
from conformance.judge import diagnosis
from conformance.rendering import framing, golden, silhouettes

def assert_passed(record, run, sync: str) -> None:
    __tracebackhide__ = True
    if not record.passed:
        pytest.fail(f"{record.message} {_context(run, sync, run.frame)}\nreproduce: {record.reproduce}\n"
                    f"the same run's vertices, frame by frame: {record.details['replay']}", pytrace=False)


#: Where the watcher of the golden-frame check leaves its records (and a failure's pictures) for the check.
_SEEN = "silhouettes at golden frames"


@shared_run.watcher("test_silhouettes_match_pybullet_at_golden_frames", last=lambda spec: max(spec.frames_with_goldens()))
def _silhouettes(run, kit):
    if run.frame not in scenes.get(run.scene.name).frames_with_goldens():
        return
    scene = run.scene
    if not silhouettes.pybullet_draws_it(scene, run.frame):
        return  # frame 0 of a scene with a soft body: the vertex checks judge it
    ids_fury = backends.render_ids(run.drawing, scene.camera, scene.image_size)
    ids_bullet = silhouettes.pybullet_mask(scene, scene.bindings, scene.camera, scene.image_size)
    record = silhouettes.silhouette_record(run, kit.sync, ids_fury, ids_bullet, f"test_silhouettes_match_pybullet_at_golden_frames[{scene.name}]",
                     kit.tolerance)
    config = kit._node.config  # None outside a pytest session: nothing is kept then but failures
    keep = not record.passed or (config is not None and image_options.from_config(config).keep_passing)
    kit._node.stash.setdefault(_SEEN, []).append((record, silhouettes.mask_images(ids_fury, ids_bullet) if keep else {}))
    if not record.passed:
        worst = max(record.details["targets"], key=lambda t: t["off"] / max(t["allowed_off"], 1))
        soft = diagnosis.soft_drawn_as_rigid(run, kit.tolerance)  # a sync written before soft bodies: told first
        lines = [f"{record.message} {_context(run, kit.sync, run.frame)}", *([soft] if soft else []),
                 f"reproduce: {record.reproduce}", f"the same run's vertices, frame by frame: {record.details['replay']}"]
        kit.fail("silhouette", "\n".join(lines),
                 value=worst["off"], limit=worst["allowed_off"], unit="pixels off", frame=run.frame,
                 target=worst["target"])


@each_scene()
def test_silhouettes_match_pybullet_at_golden_frames(scene_name, kit, pictures, request):
    """Each target's FURY silhouette overlaps pyBullet's at the first, middle and last golden frame
    (of the scene's shared run, :mod:`conformance.checks.shared_run`)."""
    check = "test_silhouettes_match_pybullet_at_golden_frames"
    for record, images in shared_run.seen(kit, check, scene_name).get(_SEEN, ()):
        record.nodeid = request.node.nodeid
        pictures.keep(record, images)
    shared_run.report(kit, check, scene_name)


@each_scene()
def test_scene_camera_frames_every_body(scene_name, pictures, request):
    """The scene's goldens show it: at each golden frame, drawn by the reference sync, every body is
    inside the picture and the clipping range, at least 3 px across, and the picture is not blank.
    A property of the scene and its camera, not of the sync under test."""
    from conformance import sync
    from conformance.sync import runner

    with runner.running(scene_name, sync.load("reference")) as run:
        camera, size = run.scene.camera, run.scene.image_size
        for frame in scenes.get(scene_name).frames_with_goldens():
            run.advance(frame - run.frame)
            record = framing.of_scene(run.drawing, camera, size, scene=scene_name, frame=frame)
            record.sync, record.nodeid = "reference", request.node.nodeid
            picture = backends.render(run.drawing, camera, size)
            if record.passed and (picture == picture[0, 0]).all():
                record.passed, record.message = False, f"{scene_name} frame {frame}: the picture is blank"
            pictures.keep(record, {"actual": picture})
            if not record.passed:
                pytest.fail(f"{record.message}. Move the scene's camera (its SceneSpec's Camera: position, focal "
                            "point, view angle, clipping range) until every body is inside the picture, then make its "
                            f"goldens anew: {golden.regen_command(scene_name, pictures.golden_dir_for(scene_name))}",
                            pytrace=False)


#: Scenes whose bodies are large on screen and free to turn: where a turn shows in a silhouette.
TURNING_SCENES = ("free_fall", "mixed_shapes", "weighted", "pendulum")


@pytest.mark.draws
def test_silhouettes_match_in_any_orientation(kit):
    """Bodies teleported to arbitrary orientations before the first sync: each still has pyBullet's silhouette."""

    @check_settings(examples=3)
    @given(scene_name=st.sampled_from(TURNING_SCENES),
           turns=st.lists(st.tuples(st.integers(0, 20), strategies.orientations()), min_size=1, max_size=3))
    def check(scene_name, turns):
        events = [Teleport(0, which, (0.0, 0.0, 0.0), orientation) for which, orientation in turns]
        with kit.run(scene_name, events=events) as run:
            assert_passed(silhouettes.silhouette_check(run, kit.sync, tolerance=kit.tolerance), run, kit.sync)

    check()
