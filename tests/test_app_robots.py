"""App mode on robots as users draw them, on recordings made by hand (issue 29): a link drawn from its
visual shapes (``getVisualShapeData``: a mesh's scale, each shape's frame in the link frame) is judged as
tightly as a box, and the usual mistakes get their diagnosis; a mistake outside the catalogue gets none.
The whole programs are ``examples/*/kuka.py``, ``r2d2.py``, ``racecar.py`` and their ``wrong/`` twins."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import app_recordings as rec
from conformance.apps import judge
from conformance.apps.bodies import Frame, _primitive_points

IDENTITY = (0.0, 0.0, 0.0, 1.0)
#: A leg as R2-D2's: a box 0.6 x 0.2 x 0.1 whose visual frame is 0.3 m down the link's z, turned 90° about y.
LEG = (0.6, 0.2, 0.1)
LEG_FRAME = ((0.0, 0.0, -0.3), tuple(Rotation.from_euler("y", 90, degrees=True).as_quat()))
#: The centre of mass in the link frame.
INERTIAL = (0.05, 0.02, -0.1)


def _visual(kind, dims, frame, points):
    return (kind, tuple(dims), frame[0], frame[1], tuple(map(tuple, points)))


def _leg_frame(visuals=None) -> Frame:
    corners = _primitive_points("box", LEG)
    visuals = visuals or (_visual("box", LEG, LEG_FRAME, corners),)
    return Frame(0, 0, 3, "right_leg", 1.0, (("mesh", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0), IDENTITY),), INERTIAL,
                 visuals=visuals)


def _drawn(frame: Frame, geometry: np.ndarray):
    """``placed`` on a recording of ``frame`` moving, drawn by one actor whose vertices are ``geometry`` in its link frame."""
    poses = rec.motion()
    recording = rec.recording([frame], [poses], [rec.track(rec.draw(*poses, geometry), label="leg_actor")])
    return judge(recording, checks=("attached", "placed"))["placed"]


def _leg_in_link_frame(offset=(0.0, 0.0, 0.0), framed=True) -> np.ndarray:
    corners = _primitive_points("box", LEG)
    if framed:
        corners = Rotation.from_quat(LEG_FRAME[1]).apply(corners) + LEG_FRAME[0]
    return corners + np.asarray(offset)


def test_a_link_drawn_as_its_visual_shape_is_on_it():
    placed = _drawn(_leg_frame(), _leg_in_link_frame())
    assert placed.passed and not placed.notes, (placed.lines, placed.notes)


@pytest.mark.parametrize("offset, diagnosis", [
    (INERTIAL, "com-frame"),                          # drawn at the centre of mass (getLinkState()[0:2])
    (tuple(2 * np.asarray(INERTIAL)), "offset-sign"),  # the offset added where it should be taken away
    (tuple(-np.asarray(INERTIAL)), "offset-sign"),     # the offset taken away twice
    # 4 cm up "so it does not sink": outside the catalogue, and inside the frame's reach (5 cm, the default
    # bounding radius of a mesh shape whose vertices were not read: at 5 cm the float noise of the drawn centre
    # decided whether it was "another body's")
    ((0.0, 0.0, 0.04), ""),
])
def test_a_link_drawn_off_its_visual_shape_fails_with_the_mistake_named(offset, diagnosis):
    placed = _drawn(_leg_frame(), _leg_in_link_frame(offset))
    assert not placed.passed and "off its visual shape (box)" in placed.lines[0], placed.lines
    assert placed.diagnoses == ([diagnosis] if diagnosis else []), placed.lines


def test_a_visual_shape_without_its_frame_at_its_centre_of_mass_is_named_by_its_frame():
    """A bob whose <inertial> and <visual> share their <origin>: drawn without its visual frame it is also off by
    minus the inertial offset, which the offset turned round would draw too; the visual frame is named (the
    zoo's pendulum5.urdf and cartpole.urdf were named offset-sign)."""
    origin = ((0.0, 0.0, -0.3), IDENTITY)
    frame = Frame(0, 0, 3, "bob", 1.0, (("mesh", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0), IDENTITY),), origin[0],
                  visuals=(_visual("box", LEG, origin, _primitive_points("box", LEG)),))
    assert _drawn(frame, _primitive_points("box", LEG) + origin[0]).passed
    placed = _drawn(frame, _primitive_points("box", LEG))
    assert not placed.passed and placed.diagnoses == ["visual-frame"], placed.lines


def test_a_visual_frame_composed_the_wrong_way_round_is_named():
    """A shape actor given ``visual_frame @ link_frame`` (the two matrices multiplied in the wrong order) sits
    right only while the link's pose is the identity: ``attached`` names the visual frame."""
    poses = rec.motion()
    shape = _primitive_points("box", LEG)  # the shape in its own (visual) frame
    p_v, r_v = np.asarray(LEG_FRAME[0]), Rotation.from_quat(LEG_FRAME[1]).as_matrix()
    r_l = Rotation.from_quat(poses[1]).as_matrix()
    wrong = np.einsum("ij,tjk,nk->tni", r_v, r_l, shape) + (poses[0] @ r_v.T + p_v)[:, None, :]
    recording = rec.recording([_leg_frame()], [poses], [rec.track(wrong, label="leg_actor")])
    verdict = judge(recording, checks=("attached",))["attached"]
    assert not verdict.passed and verdict.diagnoses == ["visual-frame"], verdict.lines
    right = rec.draw(*poses, _leg_in_link_frame())
    assert judge(rec.recording([_leg_frame()], [poses], [rec.track(right, label="leg_actor")]), checks=("attached",))["attached"].passed


def test_a_visual_frame_whose_offset_is_turned_by_its_own_rotation_is_named():
    """``R_v (x + p_v)`` where ``R_v x + p_v`` is meant (the visual frame's turn applied after its offset, the
    zoo's ``links`` and ``shared`` drawings of visual-order): rigid in the link frame, so ``placed`` names it
    (it named another body: the leg is 0.42 m off)."""
    turn = Rotation.from_quat(LEG_FRAME[1])
    placed = _drawn(_leg_frame(), turn.apply(_primitive_points("box", LEG) + LEG_FRAME[0]))
    assert not placed.passed and placed.diagnoses == ["visual-frame"], placed.lines


def test_a_shape_of_a_link_with_several_visual_frames_composed_the_wrong_way_round_is_named():
    """One actor per visual shape posed by ``visual_frame @ link_frame``, on a link with two visual shapes in
    different frames (a robot's link often has several): the catalogue's variant composes one frame only, so
    each shape is tried under its frame (the zoo's ``shapes`` and ``merged`` drawings were named nothing)."""
    poses = rec.motion()
    other = ((0.1, 0.2, 0.0), tuple(Rotation.from_euler("x", 30, degrees=True).as_quat()))
    shape = _primitive_points("box", LEG)
    frame = _leg_frame((_visual("box", LEG, LEG_FRAME, shape), _visual("box", LEG, other, shape)))
    p_v, r_v = np.asarray(LEG_FRAME[0]), Rotation.from_quat(LEG_FRAME[1]).as_matrix()
    r_l = Rotation.from_quat(poses[1]).as_matrix()
    wrong = np.einsum("ij,tjk,nk->tni", r_v, r_l, shape) + (poses[0] @ r_v.T + p_v)[:, None, :]
    verdict = judge(rec.recording([frame], [poses], [rec.track(wrong, label="leg_actor")]), checks=("attached",))["attached"]
    assert not verdict.passed and verdict.diagnoses == ["visual-frame"], verdict.lines
    right = rec.draw(*poses, Rotation.from_quat(LEG_FRAME[1]).apply(shape) + LEG_FRAME[0])
    assert judge(rec.recording([frame], [poses], [rec.track(right, label="leg_actor")]), checks=("attached",))["attached"].passed


def test_a_visual_shape_drawn_without_its_frame_is_named():
    placed = _drawn(_leg_frame(), _leg_in_link_frame(framed=False))
    assert not placed.passed and placed.diagnoses == ["visual-frame"], placed.lines


@pytest.mark.parametrize("scale, diagnosis", [
    # A gear modelled in millimetres, which the URDF scales by 0.001, drawn a thousand times too large: one
    # factor, which is also what loadURDF's globalScaling left out draws (pyBullet keeps it in the mesh scale).
    ((0.001, 0.001, 0.001), "scaled"),
    ((0.001, 0.002, 0.0005), "mesh-scale"),  # a scale that differs by axis is the mesh's own
])
def test_a_mesh_drawn_without_its_scale_is_named(scale, diagnosis):
    gear = _primitive_points("box", (30.0, 10.0, 30.0))  # the mesh file's extreme points, in millimetres
    frame = _leg_frame((_visual("mesh", scale, ((0.0, 0.0, 0.0), IDENTITY), gear * scale),))
    assert _drawn(frame, gear * scale).passed
    placed = _drawn(frame, gear)
    assert not placed.passed and placed.diagnoses == [diagnosis], placed.lines
    assert ("at 1000 times its size: its mesh scale 0.001" in placed.lines[0]) == (diagnosis == "scaled"), placed.lines


# -- the rotation mistakes a robot's links show: angle-axis in degrees, pyBullet's float32 angle-axis ------

def _turning(small: bool):
    """A box moving and turning: by large angles, or (``small``) by under 2 milliradians about a tilted axis,
    as a link whose joint barely moves."""
    positions, orientations = rec.motion()
    if small:
        t = np.linspace(0, 1, len(positions))[:, None]
        orientations = Rotation.from_rotvec(t * 0.0018 * np.array([0.0, 0.6, 0.8])).as_quat()
    return positions, orientations


def _attached(positions, orientations, rotations):
    """``attached`` on a box drawn at ``positions`` with ``rotations`` (3x3 per tick) in place of pyBullet's."""
    vertices = np.einsum("tij,nj->tni", rotations, rec.CORNERS) + positions[:, None, :]
    recording = rec.recording([rec.box_frame()], [(positions, orientations)], [rec.track(vertices)])
    return judge(recording, checks=("attached",))["attached"]


def test_an_angle_in_radians_given_as_degrees_is_named():
    """VTK's RotateWXYZ takes degrees; given getAxisAngleFromQuaternion's radians, a link barely turns."""
    positions, orientations = _turning(small=False)
    turned = Rotation.from_quat(orientations)
    wrong = Rotation.from_rotvec(turned.as_rotvec() * np.pi / 180).as_matrix()
    verdict = _attached(positions, orientations, wrong)
    assert not verdict.passed and verdict.diagnoses == ["radians-as-degrees"], verdict.lines


def test_pybullets_float32_angle_axis_is_named():
    """A link drawn with pybullet.getAxisAngleFromQuaternion's axis and angle: below about 2 mrad its axis
    is (1, 0, 0), so a link turning 1.8 mrad about (0, 0.6, 0.8) is drawn turned about x (the issue's rope
    was 0.12 mm off against a 1.8 µm allowance)."""
    import pybullet

    positions, orientations = _turning(small=True)
    drawn = []
    for q in orientations:
        axis, angle = pybullet.getAxisAngleFromQuaternion(q)
        drawn.append(Rotation.from_rotvec(np.asarray(axis) * angle).as_matrix())
    verdict = _attached(positions, orientations, np.array(drawn))
    assert not verdict.passed and verdict.diagnoses == ["float32-angle-axis"], verdict.lines
    # The same turn drawn from the quaternion itself is right
    assert _attached(positions, orientations, Rotation.from_quat(orientations).as_matrix()).passed


def test_a_sync_every_other_tick_is_named_skipped():
    """Half the ticks drawn at the previous step's pose: the median reference of half-wrong ticks fit
    neither pose, and the mistake went without a diagnosis (issue 29)."""
    positions, orientations = rec.motion()
    rotations = Rotation.from_quat(orientations).as_matrix()
    drawn_pos, drawn_rot = positions.copy(), rotations.copy()
    drawn_pos[2::2], drawn_rot[2::2] = positions[1:-1:2], rotations[1:-1:2]  # even ticks keep the last drawing
    vertices = np.einsum("tij,nj->tni", drawn_rot, rec.CORNERS) + drawn_pos[:, None, :]
    recording = rec.recording([rec.box_frame()], [(positions, orientations)], [rec.track(vertices)])
    verdict = judge(recording, checks=("attached",))["attached"]
    assert not verdict.passed and verdict.diagnoses == ["skipped"], verdict.lines


def test_actors_are_named_by_the_expression_that_reaches_them(monkeypatch):
    """Actors kept in tuples inside a list, in a dict, or on an object of the app's own class are named as
    the app reaches them (before: 'actor #N')."""
    import sys
    import types

    from conformance.apps import driver

    app = types.ModuleType("__main__")
    actors = [object() for _ in range(6)]

    class Robot:
        def __init__(self):
            self.parts = {"arm": actors[4]}

    Robot.__module__ = "__main__"  # as a class of the app's script is (it runs as __main__)

    app.rope_actor = actors[0]
    app.links = [(actors[1], "link one"), (actors[2], "link two")]
    app.by_name = {"ball": actors[3]}
    app.robot = Robot()
    app.alias = actors[0]  # a second, longer-to-sort name of the same actor: the first found stays
    monkeypatch.setitem(sys.modules, "__main__", app)
    names = driver._labels(actors)
    assert [names.get(id(a)) for a in actors] == ["rope_actor", "links[0][0]", "links[1][0]", "by_name['ball']",
                                                  "robot.parts['arm']", None]


def test_a_body_left_unsynced_is_blamed_on_its_own_drawing_not_a_decoration_beside_it():
    """A rope's last bead never synced, and a nail drawn (static) beside where the bead starts: ``drawn``
    names the bead's actor, which has the bead's shape, not the nail (before: the first range near it)."""
    positions, orientations = rec.motion()
    start = np.broadcast_to(positions[:1], positions.shape), np.broadcast_to(orientations[:1], orientations.shape)
    nail = np.array([[x, y, z] for x in (-0.01, 0.01) for y in (-0.01, 0.01) for z in (-0.05, 0.05)]) + [0.08, 0.0, 0.0]
    tracks = [rec.track(rec.draw(*start, nail), label="nail_actor"), rec.track(rec.draw(*start), label="bead_actors[9]")]
    verdict = judge(rec.recording([rec.box_frame()], [(positions, orientations)], tracks), checks=("attached", "drawn"))["drawn"]
    assert not verdict.passed and "bead_actors[9] vertices 0:8 stays where it was built" in verdict.lines[0], verdict.lines
    assert verdict.diagnoses == ["never-moved"]


def test_pybullets_euler_angles_are_computed_as_pybullet_computes_them():
    """The Euler form of radians-as-degrees shrinks pyBullet's own angles, which split a turn at a pitch of ±90°
    otherwise than scipy's ``as_euler`` (the kit's perturbed runs turn bodies there: a soccer ball drawn with
    ``from_euler('xyz', getEulerFromQuaternion(q), degrees=True)`` went unnamed)."""
    import pybullet

    from conformance.apps.attachment import pybullet_euler

    rng = np.random.default_rng(3)
    turns = [Rotation.random(500, random_state=4).as_quat()]
    turns += [Rotation.from_euler("xyz", [[rng.uniform(-3, 3), pitch, rng.uniform(-3, 3)] for _ in range(20)]).as_quat()
              for pitch in (np.pi / 2, -np.pi / 2, np.pi / 2 - 1e-4)]
    quaternions = np.concatenate(turns + [[[0.5773502691896258, 0.5773502691896258, 0.5773502691896258, 6.1e-17]]])
    expected = np.array([pybullet.getEulerFromQuaternion(q) for q in quaternions.tolist()])
    assert np.max(np.abs(pybullet_euler(quaternions) - expected)) < 1e-12


def test_an_actor_per_visual_shape_never_posed_is_named_never_moved():
    """A body dropped from 10 cm above the world's origin, drawn by an actor built in its visual shape's own
    frame (posed each tick by ``link @ visual``) that the sync skips: the actor stays at the origin, the shape
    without its visual frame. ``drawn`` names it never moved (the zoo's lego and domino, one shape never synced)."""
    positions, orientations = rec.motion(offset=(0.0, 0.0, -1.9))  # starts 10 cm above the origin
    shape = _primitive_points("box", LEG)
    left = np.broadcast_to(shape, (len(positions),) + shape.shape).copy()
    recording = rec.recording([_leg_frame()], [(positions, orientations)], [rec.track(left, label="shape_actor")])
    drawn = judge(recording, checks=("attached", "drawn"))["drawn"]
    assert not drawn.passed and drawn.diagnoses == ["never-moved"], drawn.lines
