"""App mode's own events (:mod:`conformance.apps.perturb`) land clear of static bodies: a teleport or joint
reset that puts a body into the ground plane leaves a part of it below the plane, which pyBullet's renderer
hides behind the plane and an app that does not draw the plane shows (measured: R2-D2 rejected by
``pictured`` in most draws of 20 perturbed runs, on both FURYs)."""

from __future__ import annotations

import pybullet
import pytest

from conformance.apps import perturb
from conformance.apps.bodies import Frame
from conformance.bullet import events


@pytest.fixture
def world():
    client = pybullet.connect(pybullet.DIRECT)
    plane = pybullet.createMultiBody(0, pybullet.createCollisionShape(pybullet.GEOM_PLANE, physicsClientId=client),
                                     physicsClientId=client)
    box = pybullet.createMultiBody(1.0, pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.2, 0.2, 0.2],
                                                                      physicsClientId=client),
                                   basePosition=[0, 0, 0.5], physicsClientId=client)
    frames = [Frame(client, plane, -1, "plane", 0.0, ()), Frame(client, box, -1, "box", 1.0, ())]
    yield client, box, frames
    pybullet.disconnect(client)


def _bottom(client, box) -> float:
    return pybullet.getAABB(box, -1, physicsClientId=client)[0][2]


def test_a_teleport_into_the_ground_lands_on_it(world):
    client, box, frames = world
    down = events.Teleport(frame=1, which=0, offset=(0.3, 0.0, -0.45), orientation=(0.0, 0.0, 0.38268343, 0.92387953))
    perturb.apply([down], 1, frames)
    position = pybullet.getBasePositionAndOrientation(box, physicsClientId=client)[0]
    assert position[0] == pytest.approx(0.3) and _bottom(client, box) >= -perturb.DEPTH - 1e-6, position


def test_a_teleport_in_the_air_is_left_where_it_went(world):
    client, box, frames = world
    perturb.apply([events.Teleport(frame=1, which=0, offset=(0.1, 0.2, 0.3), orientation=(0.0, 0.0, 0.0, 1.0))], 1, frames)
    assert pybullet.getBasePositionAndOrientation(box, physicsClientId=client)[0] == pytest.approx((0.1, 0.2, 0.8))
