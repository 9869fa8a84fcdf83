"""The silhouette and framing checks: the matrices are pyBullet's and the backend's (VTK's camera,
pygfx's camera), the match is proved on a single box, and the checks fail on a body moved by 2 px, turned by 3°, a wrong camera, a clipped or
tiny body."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pybullet
import pytest

from conformance import backends, scenes, sync
from conformance.sync import runner
from conformance.rendering import framing, silhouettes
from conformance.backends import projection

REFERENCE = sync.load("reference")


def _backend_composite(camera, size) -> np.ndarray:
    """World to clip coordinates as the backend's own camera computes them, depth mapped to [-1, 1]."""
    if backends.NAME == "vtk":
        from vtkmodules.vtkRenderingCore import vtkCamera

        vtk = vtkCamera()
        vtk.SetPosition(camera.position)
        vtk.SetFocalPoint(camera.focal_point)
        vtk.SetViewUp(camera.view_up)
        vtk.SetViewAngle(camera.view_angle)
        vtk.SetClippingRange(*camera.clipping_range)
        m = vtk.GetCompositeProjectionTransformMatrix(size[0] / size[1], -1, 1)
        return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])
    import pygfx

    from conformance.backends import pygfx as backend

    theirs = pygfx.PerspectiveCamera()
    backend._set_camera(theirs, camera, size)
    theirs.set_view_size(*size)  # what the renderer does with the picture's size
    composite = np.asarray(theirs.projection_matrix) @ np.linalg.inv(np.asarray(theirs.world.matrix))
    composite[2] = 2 * composite[2] - composite[3]  # wgpu's depth runs 0..1, OpenGL's -1..1
    return composite


@pytest.mark.parametrize("scene_name", scenes.names())
def test_matrices_are_the_backends_and_pybullets(scene_name):
    camera, size = scenes.get(scene_name).camera, scenes.get(scene_name).image_size
    np.testing.assert_allclose(projection.composite(camera, size), _backend_composite(camera, size), rtol=1e-9, atol=1e-9)
    view, proj = projection.pybullet_matrices(camera, size)
    np.testing.assert_allclose(view, pybullet.computeViewMatrix(camera.position, camera.focal_point, camera.view_up),
                               rtol=1e-6, atol=1e-6)  # pyBullet computes in float32
    np.testing.assert_allclose(proj, pybullet.computeProjectionMatrixFOV(camera.view_angle, size[0] / size[1],
                                                                          *camera.clipping_range), rtol=1e-6, atol=1e-6)


def masks(run, camera=None):
    scene = run.scene
    fury = backends.render_ids(run.drawing, camera or scene.camera, scene.image_size)
    bullet = silhouettes.pybullet_mask(scene, scene.bindings, scene.camera, scene.image_size)
    return fury, bullet


def check(run, camera=None):
    fury, bullet = masks(run, camera)
    return silhouettes.compare_silhouettes(fury, bullet, min_iou=silhouettes.thresholds(run.scene.bindings),
                                           rounding=silhouettes.roundings(run.scene.bindings),
                                           discs=silhouettes.projected_discs(run.scene, run.scene.bindings, run.scene.camera, run.scene.image_size),
                                           radii=silhouettes.projected_radii(run.scene, run.scene.bindings, run.scene.camera, run.scene.image_size),
                                           names=[t.name for t in run.drawing.targets], scene=run.scene.name,
                                           frame=run.frame,
                                           touching=silhouettes.touching_pairs(run.scene, run.scene.bindings, fury, bullet))


def test_single_box_matches_pixel_for_pixel_and_top_row_first():
    """free_fall is one box: both masks agree on every pixel (after pyBullet's half-pixel offset is
    corrected), and the box is where projection.project puts it, so row 0 is the top in both."""
    with runner.running("free_fall", REFERENCE) as run:
        fury, bullet = masks(run)
        assert (fury == 0).sum() > 1000
        assert np.array_equal(fury, bullet)
        target = run.drawing.targets[0]
        pixels, _ = projection.project(run.scene.camera, run.scene.image_size,
                                       backends.world_vertices(target.actor)[target.start:target.stop])
        rows, cols = np.nonzero(fury == 0)
        assert pixels[:, 1].min() - 1 <= rows.min() and rows.max() <= pixels[:, 1].max() + 1
        assert pixels[:, 0].min() - 1 <= cols.min() and cols.max() <= pixels[:, 0].max() + 1


def test_pybullet_draws_collision_only_bodies_of_every_kind():
    """Scenes create bodies with collision shapes only; the tiny renderer draws boxes, spheres and cylinders."""
    with runner.running("mixed_shapes", REFERENCE) as run:
        _, bullet = masks(run)
        drawn = {run.scene.bindings[i].shape.kind for i in np.unique(bullet) if i >= 0}
        assert drawn == {"box", "sphere", "cylinder"}


def _material(actor):
    """What colours an actor: VTK's property object, pygfx's material."""
    return actor.GetProperty() if backends.NAME == "vtk" else actor.material


def test_id_render_restores_the_actors_exactly():
    with runner.running("chain", REFERENCE) as run:
        actor = run.drawing.actors["links"]
        before = (backends.mesh_signature(actor), _material(actor), backends.world_vertices(actor).copy())
        picture = backends.render(run.drawing, run.scene.camera, run.scene.image_size)
        backends.render_ids(run.drawing, run.scene.camera, run.scene.image_size)
        assert backends.mesh_signature(actor) == before[0]
        assert _material(actor) is before[1]
        assert np.array_equal(backends.world_vertices(actor), before[2])
        assert np.array_equal(backends.render(run.drawing, run.scene.camera, run.scene.image_size), picture)


def _pixel_size(camera, size, point) -> float:
    """Metres per pixel at ``point``'s depth."""
    _, depth = projection.project(camera, size, [point])
    return 2 * depth[0] * math.tan(math.radians(camera.view_angle) / 2) / size[1]


def test_fails_on_a_body_moved_by_two_pixels():
    with runner.running("free_fall", REFERENCE) as run:
        camera, size = run.scene.camera, run.scene.image_size
        assert check(run).passed
        target = run.drawing.targets[0]
        centre = backends.world_vertices(target.actor).mean(axis=0)
        side = projection.view_matrix(camera)[0, :3]
        moved = np.eye(4)
        moved[:3, 3] = 2 * _pixel_size(camera, size, centre) * side
        with backends.perturbed(target, transform=moved):
            record = check(run)
        assert not record.passed, record.message
        assert "'body'" in record.message and "free_fall, frame 0" in record.message


def test_which_of_two_touching_bodies_is_in_front_is_left_out_but_where_each_is_counts():
    """Pixels where the masks show two different targets are left out of both when pyBullet has the
    two in contact (renderers disagree about which of two touching curved bodies is in front); between
    bodies apart, and where a target is drawn over background, every pixel counts."""
    fury = np.full((40, 40), -1)
    fury[5:25, 5:25] = 0
    fury[15:30, 15:30] = 1  # 1 in front of 0
    bullet = np.full((40, 40), -1)
    bullet[15:30, 15:30] = 1
    bullet[5:25, 5:25] = 0  # 0 in front of 1
    record = silhouettes.compare_silhouettes(fury, bullet, min_iou=0.98, slack=0, touching={(0, 1)})
    assert record.passed, record.message
    apart = silhouettes.compare_silhouettes(fury, bullet, min_iou=0.98, slack=0)  # not in contact: it counts
    assert not apart.passed, apart.message
    moved = np.full((40, 40), -1)
    moved[15:30, 15:30] = 1
    moved[5:25, 8:28] = 0  # and body 0 drawn 3 px to the right, over background
    record = silhouettes.compare_silhouettes(fury, moved, min_iou=0.98, slack=0, touching={(0, 1)})
    assert not record.passed and "#0" in record.message, record.message


def test_touching_pairs_are_bodies_in_contact():
    """A cylinder sunk into the ground (the case the orientation property once failed a right sync on)
    is in contact with it; two spheres half a metre apart are not."""
    from conformance.bullet import events
    from conformance.checks.pytest_helpers import sync_run

    turn = events.loads('[{"kind":"teleport","frame":0,"which":0,"offset":[0.0,0.0,0.0],'
                        '"orientation":[0.7071067811865476,4.329780281177467e-17,0.0,0.7071067811865476]}]')
    params = {"count": 12, "grouping": "per_body", "moving": 0.5, "seed": 0, "size_range": (0.08, 0.25)}
    with sync_run("mixed_shapes", REFERENCE, events=turn, **params) as run:
        names = [t.name for t in run.drawing.targets]
        cylinder, ground, sphere = (names.index(n) for n in ("cylinder4", "ground", "sphere8"))
        everywhere = np.zeros((2, 2), dtype=int)
        fury, bullet = everywhere + cylinder, everywhere + ground
        fury[0, 0], bullet[0, 0] = cylinder, sphere
        pairs = silhouettes.touching_pairs(run.scene, run.scene.bindings, fury, bullet)
        assert pairs == {tuple(sorted((cylinder, ground)))}
        assert check(run).passed


def _turn(centre, axis, degrees) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    turn = np.eye(4)
    turn[:3, :3] = Rotation.from_rotvec(np.radians(degrees) * np.asarray(axis) / np.linalg.norm(axis)).as_matrix()
    turn[:3, 3] = centre - turn[:3, :3] @ centre
    return turn


@pytest.mark.xfail(strict=True, reason="measured: with the 1 px edge slack a 3° turn of free_fall's 55 px box "
                   "leaves IoU 1.000 (plain IoU 0.960-0.968); needs slack 0 for boxes, not yet measured on every scene")
@pytest.mark.parametrize("axis", ["view", "z"])
def test_fails_on_a_box_turned_by_three_degrees(axis):
    with runner.running("free_fall", REFERENCE) as run:
        target = run.drawing.targets[0]
        centre = backends.world_vertices(target.actor).mean(axis=0)
        direction = projection.view_matrix(run.scene.camera)[2, :3] if axis == "view" else (0.0, 0.0, 1.0)
        with backends.perturbed(target, transform=_turn(centre, direction, 3.0)):
            record = check(run)
        assert not record.passed, record.message


@pytest.mark.parametrize("change", [{"view_angle": 33.0}, {"focal_point": (0.03, 0.0, 2.0)}])
def test_fails_on_a_wrong_camera(change):
    with runner.running("free_fall", REFERENCE) as run:
        record = check(run, dataclasses.replace(run.scene.camera, **change))
        assert not record.passed, record.message


def test_framing_fails_on_a_clipped_body_and_a_tiny_body():
    with runner.running("free_fall", REFERENCE) as run:
        camera, size = run.scene.camera, run.scene.image_size
        assert framing.framing(run.drawing, camera, size).passed
        target = run.drawing.targets[0]
        centre = backends.world_vertices(target.actor).mean(axis=0)
        side = projection.view_matrix(camera)[0, :3]
        # Aim the camera so that the body's centre is on the picture's right edge.
        shift = (size[0] / 2) * _pixel_size(camera, size, centre) * side
        aside = dataclasses.replace(camera, focal_point=tuple(np.asarray(camera.focal_point) - shift),
                                    position=tuple(np.asarray(camera.position) - shift))
        record = framing.framing(run.drawing, aside, size, scene="free_fall")
        assert not record.passed and "'body'" in record.message and "right edge" in record.message, record.message
        far = dataclasses.replace(camera, position=tuple(np.asarray(camera.focal_point) + 200 * (
            np.asarray(camera.position) - camera.focal_point)), clipping_range=(0.5, 2000.0))
        record = framing.framing(run.drawing, far, size, scene="free_fall")
        assert not record.passed and "px across" in record.message, record.message
        near = dataclasses.replace(camera, clipping_range=(0.5, 5.0))
        assert "clipping range" in framing.framing(run.drawing, near, size).message


# -- what a right drawing may differ by: corners and seams of small bodies, the tessellation of spheres ------

def _square(size=(40, 40), top_left=(10, 10), side=8, index=0) -> np.ndarray:
    mask = np.full(size, -1)
    mask[top_left[0]:top_left[0] + side, top_left[1]:top_left[1] + side] = index
    return mask


def test_a_few_pixels_off_a_small_body_pass_and_a_body_moved_by_two_pixels_fails():
    """A 64-pixel box with 3 pixels flipped beyond the edge slack (a corner seen edge-on, a seam: the
    wrecking ball's 72-pixel brick at ``--hypothesis-seed=5`` had 3, IoU 0.959 against 0.98) passes;
    the same box drawn 2 px aside is off along two sides and fails."""
    bullet = _square()
    stray = bullet.copy()
    stray[7, 12:15] = 0  # a sliver 3 pixels long, 3 px above the box
    record = silhouettes.compare_silhouettes(stray, bullet, min_iou=0.98)
    target = record.details["targets"][0]
    assert record.passed and target["off"] == 3 and target["iou"] < 0.98, record.message
    moved = silhouettes.compare_silhouettes(_square(top_left=(10, 12)), bullet, min_iou=0.98)
    assert not moved.passed and moved.details["targets"][0]["off"] > silhouettes.LEAST_OFF, moved.message
    more = stray.copy()
    more[7, 12:19] = 0  # 7 pixels off: more than a corner flips
    assert not silhouettes.compare_silhouettes(more, bullet, min_iou=0.98).passed


def _disc(size, centre, radius, index, mask=None) -> np.ndarray:
    rows, cols = np.indices(size)
    mask = np.full(size, -1) if mask is None else mask.copy()
    mask[np.hypot(rows + 0.5 - centre[0], cols + 0.5 - centre[1]) <= radius] = index
    return mask


def test_a_sphere_outline_is_judged_within_each_renderers_tessellation():
    """pyBullet's sphere lies up to 8 % of its radius inside FURY's: a disc of radius 100 px drawn by FURY
    over pyBullet's of radius 94 passes, and so does the box behind it, seen in pyBullet's picture in the
    6-pixel ring the coarser sphere leaves; FURY's disc drawn 12 px aside fails."""
    size = (260, 260)
    box = np.full(size, -1)
    box[20:240, 20:240] = 1
    fury = _disc(size, (130, 130), 100, 0, box)
    bullet = _disc(size, (130, 130), 94, 0, box)
    rounding = [silhouettes.ROUNDING["sphere"], None]
    record = silhouettes.compare_silhouettes(fury, bullet, min_iou=0.98, rounding=rounding)
    assert record.passed, record.message
    unrounded = silhouettes.compare_silhouettes(fury, bullet, min_iou=0.98)
    assert not unrounded.passed, unrounded.message
    aside = silhouettes.compare_silhouettes(_disc(size, (130, 142), 100, 0, box), bullet, min_iou=0.98, rounding=rounding)
    assert not aside.passed and "#0" in aside.message, aside.message


def test_pybullets_sphere_lies_inside_its_outline_by_at_most_its_rounding():
    """What ``ROUNDING`` allows pyBullet's tiny renderer, measured: a sphere 160 px across in 60
    orientations (a near-orthographic camera), its outline's deepest point inside the true circle."""
    from scipy import ndimage
    from scipy.spatial.transform import Rotation

    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.createMultiBody(0, pybullet.createCollisionShape(pybullet.GEOM_SPHERE, radius=1.0, physicsClientId=client),
                                        physicsClientId=client)
        side, dist = 400, 200.0
        fov = 2 * math.degrees(math.atan(1.25 / dist))
        view = pybullet.computeViewMatrix([0, -dist, 0], [0, 0, 0], [0, 0, 1])
        proj = pybullet.computeProjectionMatrixFOV(fov, 1.0, dist - 5, dist + 5)
        radius = side / 2 / (dist * math.tan(math.radians(fov) / 2))
        deepest = 0.0
        for q in Rotation.random(60, random_state=1).as_quat():
            pybullet.resetBasePositionAndOrientation(body, [0, 0, 0], q, physicsClientId=client)
            seg = np.asarray(pybullet.getCameraImage(side, side, view, proj, renderer=pybullet.ER_TINY_RENDERER,
                                                     physicsClientId=client)[4]).reshape(side, side)
            mask = seg == body
            rows, cols = np.nonzero(mask & ~ndimage.binary_erosion(mask))
            deepest = max(deepest, (radius - np.hypot(cols + 0.5 - side / 2, rows + 0.5 - side / 2).min()) / radius)
    finally:
        pybullet.disconnect(client)
    assert 0.05 < deepest <= silhouettes.ROUNDING["sphere"][1], deepest


def test_the_kits_sphere_lies_inside_its_outline_by_at_most_its_rounding():
    """What ``ROUNDING`` allows FURY: the kit's sphere mesh's hull, its faces' deepest point inside the sphere."""
    from scipy.spatial import ConvexHull

    with runner.running("free_fall", REFERENCE, kind="sphere") as run:
        target = run.drawing.targets[0]
        vertices = backends.world_vertices(target.actor)[target.start:target.stop]
        centre = (vertices.max(axis=0) + vertices.min(axis=0)) / 2
        radius = np.linalg.norm(vertices - centre, axis=1).max()
        hull = ConvexHull(vertices - centre)
        deepest = 1 - (-hull.equations[:, 3]).min() / radius
    assert 0.01 < deepest <= silhouettes.ROUNDING["sphere"][0], deepest


def test_a_sphere_large_on_screen_drawn_right_passes():
    """free_fall's sphere of 1 m at frame 0 covers about 31,000 pixels; drawn by the reference it failed
    (IoU 0.962 against 0.98: pyBullet's coarse sphere 5 px inside FURY's) before ``ROUNDING``."""
    with runner.running("free_fall", REFERENCE, kind="sphere", size=1.0) as run:
        record = check(run)
        assert record.passed and record.details["targets"][0]["fury_pixels"] > 20000, record.message


def test_a_sphere_hidden_but_for_a_rim_is_judged_against_where_physics_has_it():
    """A ball 24 px in radius behind a wall shows a 2-px rim past the wall's edge in FURY's picture and
    none in pyBullet's (its coarser sphere does not reach past the edge): measured, the wrecking ball's
    ball behind its turned ground plate, 14 pixels off with a 3 px slack. Inside the disc physics puts
    the ball in, FURY's pixels are the ball's; a rim outside that disc still counts."""
    size = (120, 120)
    wall = np.full(size, -1)
    wall[:, 38:] = 1  # a wall in front of the ball, from column 38 on
    fury, bullet = _disc(size, (60, 60), 24, 0, wall), _disc(size, (60, 60), 22, 0, wall)  # pyBullet's coarser
    fury[wall == 1], bullet[wall == 1] = 1, 1
    fury, bullet = _disc(size, (60, 60), 10, 0, fury), _disc(size, (60, 60), 10, 0, bullet)  # where it pokes through
    # FURY's rim past the wall's edge (columns 36-37) lies 20 px from any ball pixel pyBullet shows
    rounding = [silhouettes.ROUNDING["sphere"], None]
    assert not silhouettes.compare_silhouettes(fury, bullet, min_iou=0.98, rounding=rounding).passed
    disc = [(60.0, 60.0, 24.0), None]
    record = silhouettes.compare_silhouettes(fury, bullet, min_iou=0.98, rounding=rounding, discs=disc)
    assert record.passed, record.message
    elsewhere = fury.copy()
    elsewhere[10:20, 30:42] = 0  # drawn beyond the disc: counts
    assert not silhouettes.compare_silhouettes(elsewhere, bullet, min_iou=0.98, rounding=rounding, discs=disc).passed


def test_two_bodies_in_contact_share_their_outline_where_they_overlap():
    """Two discs of a chain interpenetrate; FURY draws the pair's lower edge with disc 0, pyBullet with
    disc 1, whose rim lies 2 px lower: those pixels of disc 1 over background are the pair's outline
    (measured: FURY 0.12's chain example kicked into a stack, 18 such pixels on a 91-pixel disc). Apart,
    or further off than the slack, they count."""
    size = (60, 80)
    fury = np.full(size, -1)
    fury[10:45, 20:60] = 1
    fury[25:45, 10:70] = 0       # disc 0 in front where they overlap; the pair's lower edge at row 44
    bullet = np.full(size, -1)
    bullet[25:45, 10:70] = 0
    bullet[10:46, 20:60] = 1     # disc 1 in front, its rim a row lower: 40 of its pixels over background
    record = silhouettes.compare_silhouettes(fury, bullet, min_iou=0.98, slack=1, touching={(0, 1)})
    assert record.passed, record.message
    assert not silhouettes.compare_silhouettes(fury, bullet, min_iou=0.98, slack=1).passed  # not in contact
    far = bullet.copy()
    far[46:55, 20:60] = 1        # 10 rows lower: more than the edge slack from disc 0
    assert not silhouettes.compare_silhouettes(fury, far, min_iou=0.98, slack=1, touching={(0, 1)}).passed
