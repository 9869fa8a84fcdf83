"""The kit's own reading of pybullet (``conformance.bullet.truth``) agrees with pybullet."""

from __future__ import annotations

import numpy as np
import pybullet
import pytest
from hypothesis import given, settings, strategies as st

from conformance.checks import strategies
from conformance.bullet import truth
from conformance.bullet.client import BoundClient

pytestmark = pytest.mark.fury_free("its verdict cannot depend on the FURY: pyBullet alone")

sizes = st.floats(0.05, 0.5)
offsets = st.tuples(*[st.floats(-0.3, 0.3)] * 3)


@settings(max_examples=60, deadline=None)
@given(kind=st.sampled_from(["box", "sphere", "cylinder"]), half=st.tuples(sizes, sizes, sizes),
       turn=strategies.orientations(), inertial_position=st.one_of(st.just((0.0, 0.0, 0.0)), offsets),
       inertial_turn=st.one_of(st.just((0.0, 0.0, 0.0, 1.0)), strategies.orientations()))
def test_predicted_aabb_is_pybullets(kind, half, turn, inertial_position, inertial_turn):
    """``aabb_half_extents`` is exactly the box ``getAABB`` reports, loose as it is, for every kind,
    turn and inertial offset; and the link frame is where the shape is, not the centre of mass."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        p = BoundClient(client)
        shape = {"box": lambda: p.createCollisionShape(pybullet.GEOM_BOX, halfExtents=list(half)),
                 "sphere": lambda: p.createCollisionShape(pybullet.GEOM_SPHERE, radius=half[0]),
                 "cylinder": lambda: p.createCollisionShape(pybullet.GEOM_CYLINDER, radius=half[0], height=2 * half[1])}[kind]()
        body = p.createMultiBody(1.0, shape, basePosition=[0.5, -1.0, 2.0], baseOrientation=list(turn),
                                 baseInertialFramePosition=list(inertial_position),
                                 baseInertialFrameOrientation=list(inertial_turn))
        low, high = (np.asarray(v) for v in p.getAABB(body))
        np.testing.assert_allclose(truth.aabb_half_extents(p, body, -1), (high - low) / 2, atol=1e-9)
        position, _ = truth.link_frame(p, body, -1)
        np.testing.assert_allclose(position, [0.5, -1.0, 2.0], atol=1e-6)
        np.testing.assert_allclose((high + low) / 2, position, atol=1e-6)
    finally:
        pybullet.disconnect(client)
