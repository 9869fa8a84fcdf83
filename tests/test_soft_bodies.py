"""Soft bodies in sync mode (the ``cloth`` and ``soft_ball`` surfaces, the volumetric ``jelly``): each check that judges them fails on a
sync that draws them wrongly, and what the kit reads and restores of them is exact."""

from __future__ import annotations

import os

import numpy as np
import pytest

from conformance import scenes, sync
from conformance import test_vertices as checks
from conformance.bullet import state, truth
from conformance.checks.pytest_helpers import Kit
from conformance.errors import SceneError
from conformance.judge.tolerances import DEFAULT

Failed = pytest.fail.Exception


def kit(spec: str) -> Kit:
    return Kit(sync.load(spec), DEFAULT)


#: the soft scenes and the name of the soft body each check fails on first
SOFT = {"cloth": "cloth", "soft_ball": "ball", "jelly": "jelly(?:_urdf)?"}


@pytest.mark.parametrize("scene_name", sorted(SOFT))
@pytest.mark.parametrize("spec, frame, diagnosis", [
    # wrong from frame 0; the other two from the first frame the body moves, where late and once draw alike:
    # told apart by a run to the next frame (issue 48)
    ("soft_syncs:NodesReversed", 0, "each vertex is drawn at one of the soft body's nodes, but not at the node it follows"),
    ("soft_syncs:OneStepLateNodes", 1, r"drawn exactly at the soft body's nodes of the previous step \(frame 1\).*"
                                       r"\(told at frame 2: at frame 1 the two draw alike\)"),
    ("soft_syncs:CopiedOnce", 1, r"drawn at the soft body's nodes as built.*\(told at frame 2: at frame 1 the two draw alike\)"),
    ("soft_syncs:PartlyCopied", 1, r"only \d+ of the soft body's \d+ vertices follow its nodes"),
    ("soft_syncs:Float16Nodes", 0, "drawn at the soft body's nodes rounded to float16"),
    ("soft_syncs:VisualMesh", 0, r"drawn at the soft body's visual mesh \(getMeshData without MESH_DATA_SIMULATION_MESH"),
    ("soft_syncs:PosedAsWell", 0, r"drawn at the soft body's nodes moved again by the body's pose"),
])
def test_every_frame_check_fails_on_a_wrong_soft_body(spec, frame, diagnosis, scene_name):
    body = SOFT[scene_name]
    with pytest.raises(Failed, match=rf"'{body}' \(body \d\) vertex \d+ is drawn at .* but should be at .*: error .* > tolerance "
                                     rf".*\[{scene_name}\(.*frame {frame}, .*\ndiagnosis: .*{diagnosis}.*\n(?:.*also: .*\n)?reproduce: "):
        checks.test_vertices_match_poses_every_frame(scene_name, kit(spec))


def test_a_volumetric_body_drawn_as_a_surface_is_named_every_node():
    """A sync written for surface soft bodies draws vertex k at node k; on a tetrahedral body, whose drawn
    vertices are its boundary nodes, that puts them on the first nodes, some inside."""
    with pytest.raises(Failed, match=r"'jelly(?:_urdf)?' \(body \d\) vertex \d+ is drawn at .*\[jelly\(.*frame 0, .*\ndiagnosis: "
                                     r"vertex k is drawn at node k, the first 66 of the body's 75 nodes: this soft body is "
                                     r"volumetric"):
        checks.test_vertices_match_poses_every_frame("jelly", kit("soft_syncs:EveryNode"))
    for surface in ("cloth", "soft_ball"):  # every node drawn in order: the same sync is right there
        checks.test_vertices_match_poses_every_frame(surface, kit("soft_syncs:EveryNode"))


def test_a_volumetric_body_is_drawn_by_its_boundary_as_pybullet_draws_it():
    """The jelly's blocks, one from ``loadSoftBody(.vtk)`` and one from a ``<deformable>`` URDF: 75 nodes each, 9
    inside; drawn are the 66 boundary nodes and the 128 faces of pyBullet's own visual mesh, whose corners are
    those nodes, to the bit, before the first step and after 40."""
    import pybullet

    from conformance import backends

    with scenes.build("jelly") as scene:
        drawing = backends.build(scene)
        soft = [t for t in drawing.targets if t.nodes is not None]
        assert [t.name for t in soft] == ["jelly", "jelly_urdf"]
        for steps in (0, 40):
            scene.run(steps)
            for t, binding in zip(soft, [b for b in scene.bindings if b.soft]):
                nodes = truth.nodes(scene.p, t.body)
                visual = np.asarray(pybullet.getMeshData(t.body, -1, physicsClientId=scene.p.client)[1])
                assert (len(nodes), len(t.nodes), len(binding.shape.faces)) == (75, 66, 128)
                assert np.array_equal(nodes[binding.shape.node_faces().reshape(-1)], visual)
        drawing_now = backends.build(scene)
        for t in [t for t in drawing_now.targets if t.nodes is not None]:
            np.testing.assert_allclose(backends.world_vertices(t.actor), truth.nodes(scene.p, t.body)[t.nodes], atol=1e-6)


def test_a_deformable_urdfs_mesh_shadowed_by_a_file_where_the_kit_runs_is_refused(tmp_path, monkeypatch):
    """pyBullet looks for a URDF's mesh in the working directory first: another ``jelly.vtk`` there is loaded in
    the kit's stead, and the scene says so rather than simulate another body."""
    mesh = os.path.join(os.path.dirname(scenes.__file__), "meshes", "jelly.vtk")
    text = open(mesh, encoding="ascii").read().replace("\n-0.150000 ", "\n-0.160000 ")
    (tmp_path / "jelly.vtk").write_text(text, encoding="ascii")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError, match=r"soft body 'jelly_urdf' has 75 nodes that are not the 75 points of .*jelly.vtk "
                                         r"in order .*is there a file named 'jelly.vtk' in the directory you run from"):
        scenes.build("jelly")


@pytest.mark.parametrize("scene_name", sorted(SOFT))
def test_the_visual_mesh_a_diagnosis_expects_is_pybullets(scene_name):
    """The ``visual-mesh`` diagnosis (a sync that reads ``getMeshData`` without ``MESH_DATA_SIMULATION_MESH``) takes
    pyBullet's visual mesh of a soft body loaded from a mesh file for each face's corners in the file's order,
    and before the first step for the file's vertices as written: so it is, to the bit, at frame 0, after the
    first step and once the body has moved."""
    import types

    import pybullet

    from conformance.judge import diagnosis

    scene = scenes.build(scene_name)
    try:
        index = next(i for i, b in enumerate(scene.bindings) if b.soft)
        body = scene.bindings[index].body
        for frame, steps in ((0, 0), (1, 1), (40, 39)):
            scene.run(steps)
            nodes = truth.nodes(scene.p, body)
            predicted = diagnosis._visual_mesh(types.SimpleNamespace(scene=scene), index, nodes, frame)
            visual = np.asarray(pybullet.getMeshData(body, -1, physicsClientId=scene.p.client)[1], dtype=np.float64)
            assert predicted is not None and predicted.shape == visual.shape and len(visual) > len(nodes)
            assert np.array_equal(predicted, visual), frame
    finally:
        scene.close()


@pytest.mark.parametrize("spec, words", [
    ("soft_syncs:OneStepLateNodes", "drawn exactly at the soft body's nodes of the previous step (frame 4)"),
    ("soft_syncs:CopiedOnce", "drawn at the soft body's nodes as built: its vertices were never copied again"),
])
def test_a_late_copy_and_a_single_copy_are_told_apart_once_the_body_has_moved(spec, words):
    from conformance.judge import diagnosis
    from conformance.sync import runner

    with runner.running("soft_ball", sync.load(spec)) as run:
        run.advance(5)
        assert diagnosis.diagnose_problems(run) == "diagnosis: " + diagnosis.SOFT_WORDS[
            "previous-step" if "Late" in spec else "never-moved"].format(frame=4)
        assert words in diagnosis.diagnose_problems(run)


@pytest.mark.parametrize("scene_name", sorted(SOFT))
def test_every_frame_check_passes_the_reference_on_soft_bodies(scene_name):
    checks.test_vertices_match_poses_every_frame(scene_name, kit("reference"))


def test_the_kits_soft_events_teleport_turn_and_kick_every_node_at_once():
    """``SoftTeleport`` moves a soft body's nodes as one rigid piece (the centroid by the offset, never down; the
    shape kept), ``SoftKick`` sets every node's velocity, and both round-trip through a failure's JSON."""
    from scipy.spatial.transform import Rotation

    from conformance.bullet import events

    turn = (0.0, 0.0, 0.7071067811865476, 0.7071067811865476)
    with scenes.build("soft_ball") as scene:
        ball = next(b.body for b in scene.bindings if b.soft)
        before = truth.nodes(scene.p, ball)
        events.SoftTeleport(0, 0, (0.1, 0.0, -0.2), turn).apply(scene)
        after = truth.nodes(scene.p, ball)
        np.testing.assert_allclose(after.mean(axis=0) - before.mean(axis=0), (0.1, 0.0, 0.2), atol=1e-9)
        found, rssd = Rotation.align_vectors(after - after.mean(axis=0), before - before.mean(axis=0))
        assert rssd < 1e-9 and abs(found.magnitude() - np.pi / 2) < 1e-9  # turned a quarter turn, shape kept
        events.SoftKick(0, 0, (0.0, 0.0, 2.4)).apply(scene)
        scene.p.setGravity(0, 0, 0)
        scene.p.stepSimulation()
        np.testing.assert_allclose(truth.nodes(scene.p, ball) - after, np.tile((0.0, 0.0, 2.4 * scene.dt), (len(after), 1)),
                                   atol=1e-9)
    both = [events.SoftTeleport(3, 1, (0.1, 0.2, 0.3), turn), events.SoftKick(4, 0, (1.0, 2.0, 3.0))]
    assert events.loads(events.dumps(both)) == both
    with scenes.build("free_fall") as rigid:  # no soft body: nothing happens
        state_before = rigid.physics_state()
        for event in both:
            event.apply(rigid)
        assert rigid.physics_state() == state_before


def test_a_soft_body_drawn_in_the_frame_it_was_loaded_in_fails_once_a_teleport_turns_it():
    """``LoadFrameNodes`` poses the soft ball's nodes as a rigid body's vertices, by the body's pose: exact in the
    ball's own story, where pyBullet never turns its frame; the orientation check's turns show it (a turn of a
    soft body turns every node), and no diagnosis is named: the mistake is not in the catalogue."""
    from conformance.checks.strategies import HARD_ORIENTATIONS

    checks.test_vertices_match_poses_every_frame("soft_ball", kit("soft_syncs:LoadFrameNodes"))
    turns = checks.turned_everything("soft_ball", {}, list(HARD_ORIENTATIONS))
    assert any(type(e).__name__ == "SoftTeleport" for e in turns)
    with pytest.raises(Failed, match=r"'ball' \(body \d\) vertex \d+ is drawn at .*\[soft_ball\(.*frame [01], .*events .*soft_teleport"
                                     r".*\nreproduce: "):
        checks.check_run(kit("soft_syncs:LoadFrameNodes"), "soft_ball", {}, 2, turns)
    checks.check_run(kit("reference"), "soft_ball", {}, 2, turns)


def test_physics_check_fails_when_the_sync_moves_a_soft_body():
    with pytest.raises(Failed, match=r"the sync changed pybullet's state: .*\[cloth, frame 1"):
        checks.test_sync_does_not_touch_physics("cloth", kit("soft_syncs:MovesTheCloth"))


@pytest.mark.parametrize("scene_name", sorted(SOFT))
def test_physics_check_fails_when_the_sync_sets_the_node_velocities(scene_name):
    """pyBullet reports no node velocity, so a sync that sets them leaves every readable state as it was; the
    step after it does not, and the twin stepped without the sync shows it (``conformance.checks.twin``)."""
    # at frame 0 every node is at rest, so the first sync that changes a velocity is frame 1's
    with pytest.raises(Failed, match=rf"the step carried it on: after the step of frame 2 it differs from the same scene's "
                                     rf"stepped without the sync: .*\[{scene_name}, frame 2, .*The sync of frame 1 wrote to "
                                     rf"pybullet.*node velocities \(resetBaseVelocity\)"):
        checks.test_sync_does_not_touch_physics(scene_name, kit("soft_syncs:StillsTheNodes"))
    checks.test_sync_does_not_touch_physics(scene_name, kit("reference"))


def test_a_soft_body_is_captured_and_restored_bit_for_bit():
    with scenes.build("soft_ball") as scene:
        scene.run(90)
        captured = state.capture(scene)
        scene.run(30)
        assert state.compare(state.capture(scene), captured).position > 0.01  # the ball has moved on
        state.restore(scene, captured)
        ball = next(b.body for b in scene.bindings if b.soft)
        assert truth.nodes(scene.p, ball).tolist() == next(e["nodes"] for e in captured["bodies"] if e["body"] == ball)
        assert state.compare(state.capture(scene), captured).ok


def test_a_soft_body_is_drawn_at_its_nodes_one_vertex_each():
    from conformance import backends

    with scenes.build("cloth") as scene:
        drawing = backends.build(scene)
        cloth = next(t for t in drawing.targets if t.nodes is not None)
        nodes = truth.nodes(scene.p, cloth.body)
        assert (cloth.start, cloth.stop, cloth.shared) == (0, 25, False)
        np.testing.assert_allclose(backends.world_vertices(cloth.actor), nodes[cloth.nodes], atol=1e-6)


def test_a_soft_body_needs_a_deformable_world(tmp_path):
    with scenes.build("free_fall") as scene:
        with pytest.raises(SceneError, match="needs a deformable world"):
            scene.add_soft_body("cloth", "cloth_z_up.obj", position=(0, 0, 1), color=(1, 1, 1))


def test_a_mesh_whose_nodes_are_not_its_vertices_in_order_is_refused(monkeypatch):
    # The faces index the file's vertices; were pyBullet to keep them in another order (or weld some), the
    # faces would join the wrong nodes. Made here by reading the file's vertices back in another order.
    from conformance.scenes import base

    read = base.obj_mesh
    monkeypatch.setattr(base, "obj_mesh", lambda path: (read(path)[0][::-1], read(path)[1]))
    with pytest.raises(SceneError, match=r"has 25 nodes that are not the file's 25 vertices in order"):
        scenes.build("cloth")


def test_a_soft_body_written_back_at_frame_0_is_not_said_never_copied():
    """A sync that copies the nodes and then writes them back 1 µm higher leaves them drawn at the nodes as
    built at frame 0, which is what its one call was given: no copying mistake is named (it was "never-moved",
    the wrong name; ``sync_does_not_touch_physics`` names the write)."""
    from conformance.judge import compare, diagnosis
    from conformance.sync import runner

    with runner.running("cloth", sync.load("soft_syncs:MovesTheCloth")) as run:
        results = compare.compare_vertices(run.drawing, run.frame)
        assert not all(r.ok for r in results)
        assert diagnosis.diagnose_frame(run, results) == ""
