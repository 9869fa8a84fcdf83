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
    ((0.0, 0.0, 0.05), ""),                           # 5 cm up "so it does not sink": outside the catalogue
])
def test_a_link_drawn_off_its_visual_shape_fails_with_the_mistake_named(offset, diagnosis):
    placed = _drawn(_leg_frame(), _leg_in_link_frame(offset))
    assert not placed.passed and "off its visual shape (box)" in placed.lines[0], placed.lines
    assert placed.diagnoses == ([diagnosis] if diagnosis else []), placed.lines


def test_a_visual_shape_drawn_without_its_frame_is_named():
    placed = _drawn(_leg_frame(), _leg_in_link_frame(framed=False))
    assert not placed.passed and placed.diagnoses == ["visual-frame"], placed.lines


def test_a_mesh_drawn_without_its_scale_is_named():
    """A gear modelled in millimetres, which the URDF scales by 0.001, drawn a thousand times too large."""
    gear = _primitive_points("box", (30.0, 10.0, 30.0))  # the mesh file's extreme points, in millimetres
    frame = _leg_frame((_visual("mesh", (0.001, 0.001, 0.001), ((0.0, 0.0, 0.0), IDENTITY), gear * 0.001),))
    assert _drawn(frame, gear * 0.001).passed
    placed = _drawn(frame, gear)
    assert not placed.passed and placed.diagnoses == ["mesh-scale"], placed.lines
