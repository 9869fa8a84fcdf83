"""Soft bodies in app mode (issue 32, points 1 and 2): a program that draws a cloth from pyBullet's
simulated mesh runs under the kit (it used to stop on the kit's own ``getCollisionShapeData``), each
drawn vertex that follows a node is held to that node at every tick, and every moving node must be
followed. The right cloth app (``examples/<backend>/cloth.py``) passes; copied with one mistake it
fails the check that sees it, naming the soft body."""

from __future__ import annotations

from pathlib import Path

import pybullet
import pybullet_data
import pytest

from conformance import apps, backends
from conformance.apps import bodies, perturbed

CLOTH = Path(__file__).resolve().parent.parent / "examples" / backends.NAME / "cloth.py"
SOURCE = CLOTH.read_text(encoding="utf-8")
STEP = "    p.stepSimulation()\n    sync()\n"
COPY = ("    cloth_vertices[:] = np.array(now)\n" if backends.NAME == "vtk"
        else "    positions.data[:] = np.array(now, dtype=np.float32)\n")


def _copy(tmp_path, text) -> Path:
    path = tmp_path / "cloth.py"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_soft_bodys_nodes_are_frames_with_a_position_and_no_turn():
    client = pybullet.connect(pybullet.DIRECT)
    try:
        pybullet.resetSimulation(pybullet.RESET_USE_DEFORMABLE_WORLD, physicsClientId=client)
        pybullet.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=client)
        cloth = pybullet.loadSoftBody("cloth_z_up.obj", basePosition=[0, 0, 1], scale=0.5, mass=1.0,
                                      physicsClientId=client)
        frames = bodies.frames_of([client])
        nodes = pybullet.getMeshData(cloth, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH, physicsClientId=client)[1]
        assert [f.node for f in frames] == list(range(len(nodes))) and all(f.body == cloth for f in frames)
        assert frames[3].label.startswith(f"body {cloth} node 3")
        positions, orientations = bodies.read_poses(frames)
        assert (positions == nodes).all() and (orientations == (0, 0, 0, 1)).all()
    finally:
        pybullet.disconnect(client)


@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_the_right_cloth_app_passes_its_own_run_and_a_perturbed_one():
    result = apps.check_app(CLOTH, ticks=60)
    assert result.passed, {k: v.message() for k, v in result.verdicts.items() if not v.passed}
    assert any("soft body 0 (cloth_z_up)" in note for note in result.verdicts["placed"].notes)
    assert perturbed.search(CLOTH, examples=1) is None


@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_a_cloth_copied_before_the_step_is_one_step_late(tmp_path):
    late = SOURCE.replace(STEP, "    sync()\n    p.stepSimulation()\n")
    assert late != SOURCE
    verdict = apps.check_app(_copy(tmp_path, late), ticks=30).verdicts["attached"]
    assert not verdict.passed and "previous-step" in verdict.diagnoses
    assert "each follows a node of soft body 0 (cloth_z_up)" in verdict.message(), verdict.message()


def test_a_cloth_never_copied_is_not_drawn(tmp_path):
    never = SOURCE.replace(COPY, "    pass\n")
    assert never != SOURCE
    verdict = apps.check_app(_copy(tmp_path, never), ticks=60).verdicts["drawn"]
    assert not verdict.passed
    assert "soft body 0 (cloth_z_up): nodes 1, 2, 3" in verdict.message(), verdict.message()
    assert "MESH_DATA_SIMULATION_MESH" in verdict.message()
    assert "cloth_actor vertices" in verdict.message() and verdict.diagnoses == ["never-moved"], verdict.message()


def test_a_cloth_drawn_off_its_nodes_is_not_placed(tmp_path):
    """Each vertex that follows a node is drawn at it: one moved 5 cm off (a grid of the user's own,
    a cloth built in another order than its nodes are copied) follows its node rigidly and is still wrong."""
    if backends.NAME == "vtk":
        off = SOURCE.replace(COPY, "    cloth_vertices[:] = np.array(now) + [0.05, 0, 0]\n")
    else:
        off = SOURCE.replace(COPY, "    positions.data[:] = np.array(now, dtype=np.float32) + np.float32([0.05, 0, 0])\n")
    assert off != SOURCE
    verdict = apps.check_app(_copy(tmp_path, off), ticks=30).verdicts["placed"]
    assert not verdict.passed and verdict.diagnoses == ["node-order"], verdict.message()
    assert "are not drawn at the node they follow" in verdict.message() and "0.05 m away" in verdict.message()


def test_a_cloth_copied_but_for_its_last_nodes_leaves_them_undrawn(tmp_path):
    short = SOURCE.replace(COPY, COPY.replace("[:]", "[:-3]").replace("np.array(now", "np.array(now[:-3]"))
    assert short != SOURCE
    verdict = apps.check_app(_copy(tmp_path, short), ticks=60).verdicts
    failed = {k for k, v in verdict.items() if not v.passed}
    assert "drawn" in failed or "attached" in failed, failed


def test_the_right_cloth_is_pictured_where_pybullet_draws_it():
    """``pictured`` judges a soft body as one surface: the right cloth's pixels are pyBullet's, to a few edge
    pixels, at every picture."""
    verdict = apps.check_app(CLOTH, ticks=60).verdicts["pictured"]
    assert verdict.passed, verdict.message()
    cloth = [t for record, _ in verdict.pictures for t in record.details["targets"] if t["target"].startswith("soft body")]
    assert len(cloth) == len([p for p in verdict.pictures]) and all(t["iou"] >= 0.98 for t in cloth), cloth


@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_a_cloth_whose_triangles_join_other_nodes_is_not_pictured(tmp_path):
    """Every vertex on its node, every node followed, the triangles made for the nodes sorted by np.unique:
    no vertex check can see it; the picture does (``face-order``)."""
    old = "nodes = np.array(nodes)\n" if backends.NAME == "vtk" else "nodes = np.array(nodes, dtype=np.float32)\n"
    sorted_nodes = SOURCE.replace(old, f"nodes = np.unique({old.split(' = ')[1].strip()}, axis=0)\n")
    assert sorted_nodes != SOURCE
    verdicts = apps.check_app(_copy(tmp_path, sorted_nodes), ticks=30).verdicts
    assert {k for k, v in verdicts.items() if not v.passed} == {"pictured"}, {k: v.message() for k, v in verdicts.items()}
    assert verdicts["pictured"].diagnoses == ["face-order"], verdicts["pictured"].message()
    assert "soft body 0 (cloth_z_up) is not where pyBullet's renderer draws it" in verdicts["pictured"].message()


@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_a_soft_ball_whose_normals_follow_its_shape_passes():
    """A right program recomputes a deforming surface's normals every tick; a node has no turn for them to
    follow, so ``normals`` judges them against the surface drawn instead of rejecting the right ball with
    ``stale-normals`` (which it did once the ball landed and squashed, at tick 95); the same ball with its
    normals computed once is ``examples/*/wrong/soft_ball_normals_once.py``. The ball is judged in the
    pictures as one surface."""
    ball = CLOTH.parent / "soft_ball.py"
    result = apps.check_app(ball, ticks=120)
    assert result.passed, {k: v.message() for k, v in result.verdicts.items() if not v.passed}
    assert any("162 vertices follow soft-body nodes: their normals are those of the surface drawn" in note
               for note in result.verdicts["normals"].notes), result.verdicts["normals"].notes
    pictured = [t["target"] for record, _ in result.verdicts["pictured"].pictures for t in record.details["targets"]]
    assert pictured.count("soft body 1 (ball)") == len(result.verdicts["pictured"].pictures), pictured


def test_the_nodes_inside_a_tetrahedral_body_are_not_drawn_by_pybullet():
    """pyBullet draws a tetrahedral body by its visual mesh, the boundary's triangles with every corner at a node:
    the 9 nodes inside the kit's jelly block are on none of them (``Frame.shown`` 0) and need not be drawn. A
    surface from an OBJ file away from the origin, whose visual mesh is the file's vertices unmoved before its
    first step, cannot be told so: every node is asked for (-1)."""
    from conformance import scenes

    with scenes.build("jelly") as scene:
        frames = bodies.frames_of([scene.client])
        for binding in [b for b in scene.bindings if b.soft]:
            shown = {f.node: f.shown for f in frames if f.body == binding.body}
            assert sorted(n for n, s in shown.items() if s == 1) == list(binding.shape.nodes)
            assert sum(s == 0 for s in shown.values()) == 9 and len(shown) == 75
    with scenes.build("cloth") as scene:
        assert {f.shown for f in bodies.frames_of([scene.client]) if f.node >= 0} == {-1}


def test_a_soft_body_drawn_as_one_rigid_piece_is_told_from_one_that_deforms():
    """``drawn-as-rigid``: vertices held by no node that move as one rigid piece (a deformable URDF posed by its
    base's pose); vertices that squash, or never move, are not."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    from conformance.apps import soft_bodies

    rng = np.random.default_rng(0)
    block = rng.uniform(-0.15, 0.15, (75, 3))
    turns = Rotation.from_rotvec(np.outer(np.linspace(0, 0.8, 20), [0.3, 1.0, 0.2]))
    rigid = np.stack([turn.apply(block) + [0.01 * t, 0.0, -0.02 * t] for t, turn in enumerate(turns)])
    assert soft_bodies._rigid(rigid, 1e-6)
    squashed = rigid.copy()
    squashed[..., 2] *= np.linspace(1.0, 0.7, 20)[:, None]  # flattened a little more each tick
    assert not soft_bodies._rigid(squashed, 1e-6)
    assert not soft_bodies._rigid(np.repeat(block[None], 20, axis=0), 1e-6)  # never moved: another mistake


def test_a_soft_bodys_nodes_moved_again_by_a_pose_are_told_from_its_nodes_and_from_a_rigid_piece():
    """``soft-posed``: at every tick the vertices are the nodes, moved by one rigid pose that does move them (an
    actor given the soft body's getBasePositionAndOrientation on top of its copied nodes), paired in the
    actor's order or, when the actor has more vertices than nodes, by the nearest node once their centres meet.
    The nodes themselves, or a rigid piece that does not deform as the nodes do, are not."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    from conformance.apps import soft_bodies

    rng = np.random.default_rng(1)
    start = rng.uniform(-0.2, 0.2, (25, 3))
    nodes = np.stack([start * [1.0, 1.0, 1.0 - 0.02 * t] + [0.0, 0.0, -0.01 * t] for t in range(20)])  # sagging
    turns = Rotation.from_rotvec(np.outer(np.linspace(0, 0.5, 20), [0.2, 1.0, 0.1]))
    posed = np.stack([turn.apply(now) + [0.05 * t, 0.0, 1.0] for t, (turn, now) in enumerate(zip(turns, nodes))])
    rows = np.arange(25)
    assert soft_bodies._posed(posed, rows, nodes, 1e-6)
    assert soft_bodies._posed(posed[:, ::-1], rows, nodes, 1e-6)  # built in another order: paired by the nearest node
    assert not soft_bodies._posed(nodes, rows, nodes, 1e-6)  # the nodes as they are: drawn right, no pose
    rigid = np.stack([turn.apply(start) + [0.05 * t, 0.0, 1.0] for t, turn in enumerate(turns)])
    assert not soft_bodies._posed(rigid, rows, nodes, 1e-6)  # posed as if rigid: `drawn-as-rigid`, not this
