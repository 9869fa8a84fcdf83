"""A pendulum (or double pendulum) built as one multibody: a fixed base and revolute links about y.

For checks that links are drawn at their LINK frame (getLinkState[4:6]), not their centre-of-mass
frame (getLinkState[0:2]): each link frame sits at its hinge while its centre of mass, and the bob
drawn there, hangs ``length`` below it. The inertial frame is also turned, so a sync that mixes
the link position with the COM orientation is caught too. Damping and pybullet's default joint
motors are off, so the swing keeps its energy and its period is the textbook one.

With ``pendulums`` > 1 there are several such multibodies side by side (one behind the other along
y, each released from a larger angle), so every link index names a link of several bodies; with
``shared`` their bobs are drawn by one shared actor (the guide's joint recipe).
"""

from __future__ import annotations

import math

import pybullet

from conformance.errors import InvalidArgument

from .base import IDENTITY, Camera, Scene, Shape
from .registry import SceneSpec

PIVOT = (0.0, 0.0, 2.0)
MOUNT = (0.2, 0.08, 0.05)  # half extents of the fixed base; the hinge is at its bottom face
# A sphere's inertia is the same in any frame, so turning its principal axes changes no physics,
# only makes getLinkState's COM orientation differ from the link frame's.
INERTIAL_TURN = (math.sin(0.25), 0.0, 0.0, math.cos(0.25))  # 0.5 rad about x
BOB_COLORS = ((0.85, 0.2, 0.2), (0.2, 0.6, 0.3))


def populate(scene: Scene, *, length: float = 1.0, radius: float = 0.15, mass: float = 1.0,
             angle: float = 0.6, links: int = 1, pendulums: int = 1, shared: bool = False) -> None:
    if links not in (1, 2):
        raise InvalidArgument(f"links={links!r}, but should be 1 or 2")
    if not 1 <= pendulums <= 8:
        raise InvalidArgument(f"pendulums={pendulums!r}, but should be 1 to 8")
    spacing = max(0.5, 4 * radius)  # along y, across the swing plane: neighbours never touch
    for i in range(pendulums):
        _pendulum(scene, suffix="" if i == 0 else f"_{i + 1}", y=(i - (pendulums - 1) / 2) * spacing,
                  length=length, radius=radius, mass=mass, angle=angle + 0.3 * i, links=links,
                  actor="bobs" if shared else None)


def _pendulum(scene: Scene, *, suffix: str, y: float, length: float, radius: float, mass: float, angle: float,
              links: int, actor: str | None) -> None:
    p = scene.p
    mount = Shape("box", MOUNT, color=(0.5, 0.5, 0.5))
    bobs = [Shape("sphere", (radius,), color=BOB_COLORS[i], position=(0.0, 0.0, -length)) for i in range(links)]
    below = (0.0, 0.0, -length)
    body = p.createMultiBody(
        baseMass=0.0,
        baseCollisionShapeIndex=mount.collision_shape(p),
        basePosition=[PIVOT[0], PIVOT[1] + y, PIVOT[2] + MOUNT[2]],
        baseOrientation=list(IDENTITY),
        linkMasses=[mass] * links,
        linkCollisionShapeIndices=[bob.collision_shape(p) for bob in bobs],
        linkVisualShapeIndices=[-1] * links,
        # Relative to the parent's link frame: the first hinge at the mount's bottom face, the
        # second at the first bob's centre.
        linkPositions=[[0.0, 0.0, -MOUNT[2]]] + [list(below)] * (links - 1),
        linkOrientations=[list(IDENTITY)] * links,
        linkInertialFramePositions=[list(below)] * links,
        linkInertialFrameOrientations=[list(INERTIAL_TURN)] * links,
        # pybullet numbers parents 0 = base, k = link k-1.
        linkParentIndices=list(range(links)),
        linkJointTypes=[pybullet.JOINT_REVOLUTE] * links,
        linkJointAxis=[[0.0, 1.0, 0.0]] * links,
    )
    # Damping is one setting for the whole multibody (base and links alike).
    p.changeDynamics(body, -1, linearDamping=0, angularDamping=0)
    for link in range(links):
        # With a turned inertial frame pybullet takes the inertia of the bob's bounding box
        # (2/3·m·r², measured); give it back a solid sphere's.
        p.changeDynamics(body, link, jointDamping=0, localInertiaDiagonal=[0.4 * mass * radius ** 2] * 3)
        # Every revolute joint starts with a velocity motor holding it still; force 0 frees it.
        p.setJointMotorControl2(body, link, pybullet.VELOCITY_CONTROL, targetVelocity=0, force=0)
    p.resetJointState(body, 0, angle)
    scene.bind(f"mount{suffix}", body, -1, mount)
    for link, bob in enumerate(bobs):
        scene.bind(f"bob{link + 1}{suffix}", body, link, bob, actor=actor)


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "length": st.floats(0.3, 1.2),
        "radius": st.floats(0.03, 0.15),
        "mass": st.floats(0.1, 10.0),
        "angle": st.floats(-1.5, 1.5),
        "links": st.sampled_from([1, 2]),
        "pendulums": st.integers(1, 3),
        "shared": st.booleans(),
    })


SPEC = SceneSpec(
    name="pendulum",
    title="Pendulum",
    populate=populate,
    camera=Camera((0.0, -5.0, 1.15), (0.0, 0.0, 1.15), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 6.0)),
    # 2 s: about one period at the defaults (2π√(I/mgL) = 2.00 s, +2 % for the 0.6 rad amplitude).
    steps=480,
    origin="canonical",
    poster_step=60,
    description="A bob on a 1 m massless arm, hinged about y to a fixed mount, swings from 0.6 rad without losses.",
    parameters=parameters,
    # Several multibodies whose links share indices, drawn whole and by a shared actor.
    examples=({"pendulums": 3, "links": 2}, {"pendulums": 3, "links": 2, "shared": True}),
    # No golden variant: one pendulum's "shared" actor holds one bob, drawn as a whole actor, and the
    # shared examples above are another picture. Their drawing path (link vertex ranges rewritten and
    # announced) is judged by the vertex checks every frame, and in pictures by mixed_shapes-by_kind
    # and brick_wall_single, whose goldens draw through shared actors.
)
