"""Two bodies fly head-on at each other in zero gravity: they collide, or a filter lets them pass.

For checks of collision filtering (``setCollisionFilterPair``, ``setCollisionFilterGroupMask``),
observed the only two ways that do not lie (pybullet-facts.md, bullet3 #4376): the contact points
``getContactPoints`` reports after each step, and the trajectories themselves. Damping and gravity
are off, so a pair that passes through flies on exactly as ``x(n) = x0 ± n·speed·dt``, while a pair
that collides keeps its order along x and rebounds with combined restitution ``restitution²``.

Body ``a`` (red) starts at -x moving +x; body ``b`` (blue) starts at +x moving -x, both on the line
y = 0, z = 1, ``gap`` apart at their bounding spheres. With ``link=True``, ``b`` is link 0 of a
multibody whose base carries no collision shape (joined to it by a fixed joint), so the filter
rules must name that link. ``collide=False`` disables the pair with ``setCollisionFilterPair`` when
the scene is built, so a pass-through run can be replayed from the command line. ``seed`` draws
the two bodies' orientations (``numpy.random.default_rng``), so boxes meet edge or corner first and
spheres are drawn turned.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np
import pybullet
from scipy.spatial.transform import Rotation

from conformance.errors import InvalidArgument

from .base import Camera, Scene, Shape
from .registry import SceneSpec

HEIGHT = 1.0
STEPS = 240
DT = 1.0 / 240.0  # Scene's default time step
KINDS = ("sphere", "box")
COLORS = ((0.9, 0.25, 0.2), (0.2, 0.4, 0.9))
BASE_MASS_FRACTION = 0.01  # of mass_b, for the collision-less base of the ``link`` variant


def populate(scene: Scene, *, kind: str = "sphere", size_a: float = 0.15, size_b: float = 0.2,
             mass_a: float = 1.0, mass_b: float = 2.0, speed: float = 1.5, gap: float = 0.4,
             restitution: float = 0.8, link: bool = False, collide: bool = True, seed: int = 0) -> None:
    if kind not in KINDS:
        raise InvalidArgument(f"kind={kind!r} ({type(kind).__name__}), but should be one of {KINDS}")
    if not (speed > 0 and gap >= 0):
        raise InvalidArgument(f"speed={speed!r}, gap={gap!r}, but should be speed > 0 and gap >= 0")
    p = scene.p
    turns = Rotation.random(2, random_state=np.random.default_rng(seed)).as_quat()
    orn_a, orn_b = (tuple(float(c) for c in q) for q in turns)
    shape_a, shape_b = _shape(kind, size_a, COLORS[0]), _shape(kind, size_b, COLORS[1])
    x_a, x_b = start_positions(kind=kind, size_a=size_a, size_b=size_b, gap=gap)

    a = scene.add_body("a", shape_a, mass=mass_a, position=(x_a, 0.0, HEIGHT), orientation=orn_a,
                       restitution=restitution)
    if link:
        b = p.createMultiBody(
            baseMass=BASE_MASS_FRACTION * mass_b, baseCollisionShapeIndex=-1,
            basePosition=[x_b, 0.0, HEIGHT], baseOrientation=[0.0, 0.0, 0.0, 1.0],
            linkMasses=[mass_b], linkCollisionShapeIndices=[shape_b.collision_shape(p)],
            linkVisualShapeIndices=[-1], linkPositions=[[0.0, 0.0, 0.0]], linkOrientations=[list(orn_b)],
            linkInertialFramePositions=[[0.0, 0.0, 0.0]], linkInertialFrameOrientations=[[0.0, 0.0, 0.0, 1.0]],
            linkParentIndices=[0], linkJointTypes=[pybullet.JOINT_FIXED], linkJointAxis=[[0.0, 0.0, 1.0]],
        )
        p.changeDynamics(b, 0, restitution=restitution)
        scene.bind("b", b, 0, shape_b)
    else:
        b = scene.add_body("b", shape_b, mass=mass_b, position=(x_b, 0.0, HEIGHT), orientation=orn_b,
                           restitution=restitution)
    for body in (a, b):
        # Damping is one setting per multibody; off, so free flight is exactly x0 + n·v·dt.
        p.changeDynamics(body, -1, linearDamping=0, angularDamping=0)
    p.resetBaseVelocity(a, [speed, 0.0, 0.0], [0.0, 0.0, 0.0])
    p.resetBaseVelocity(b, [-speed, 0.0, 0.0], [0.0, 0.0, 0.0])
    if not collide:
        p.setCollisionFilterPair(a, b, -1, 0 if link else -1, 0)


def _shape(kind: str, size: float, color) -> Shape:
    return Shape("sphere", (size,), color=color) if kind == "sphere" else Shape("box", (size,) * 3, color=color)


def bounding_radius(kind: str, size: float) -> float:
    """Radius of the sphere around the shape (a cube of half side ``size`` reaches size·√3)."""
    return size if kind == "sphere" else size * math.sqrt(3.0)


def inner_radius(kind: str, size: float) -> float:
    """Radius of the sphere inside the shape."""
    return size


def start_positions(*, kind: str, size_a: float, size_b: float, gap: float) -> tuple[float, float]:
    """x of a's and b's centres: their bounding spheres ``gap`` apart, symmetric about x = 0."""
    return -(gap / 2 + bounding_radius(kind, size_a)), gap / 2 + bounding_radius(kind, size_b)


class Timeline:
    """When things happen in a crossing run, from its parameters alone (frames are 1-based: frame n
    is the state after the n-th ``stepSimulation``; the bodies close at 2·speed)."""

    def __init__(self, params: Mapping[str, Any], dt: float = DT):
        kind, speed = params["kind"], params["speed"]
        x_a, x_b = start_positions(kind=kind, size_a=params["size_a"], size_b=params["size_b"], gap=params["gap"])
        self.dt = dt
        self.distance = x_b - x_a
        self.reach = bounding_radius(kind, params["size_a"]) + bounding_radius(kind, params["size_b"])
        self.depth = inner_radius(kind, params["size_a"]) + inner_radius(kind, params["size_b"])
        closing = 2.0 * speed * dt
        #: Last frame at which the bounding spheres are still apart: no contact can exist yet.
        self.apart = max(int(math.floor((self.distance - self.reach) / closing)), 0)
        #: The frame at which the centres are closest (when nothing stops them).
        self.coincide = int(round(self.distance / closing))
        #: First frame at which the bounding spheres are apart again on the other side.
        self.separated = int(math.ceil((self.distance + self.reach) / closing)) + 1


def _fits(d) -> bool:
    """The pair meets after a few frames and is fully past each other well before the run ends."""
    t = Timeline(d)
    return t.apart >= 3 and t.separated <= STEPS - 40


def parameters():
    from hypothesis import strategies as st

    # At most 2 × 3 m/s / 240 = 25 mm closing per step against bodies at least 160 mm across:
    # no pair can step through another without a contact being found.
    return st.fixed_dictionaries({
        "kind": st.sampled_from(KINDS),
        "size_a": st.floats(0.08, 0.3),
        "size_b": st.floats(0.08, 0.3),
        "mass_a": st.floats(0.2, 5.0),
        "mass_b": st.floats(0.2, 5.0),
        "speed": st.floats(0.5, 3.0),
        "gap": st.floats(0.05, 0.6),
        "restitution": st.floats(0.5, 0.95),
        "link": st.booleans(),
        "collide": st.booleans(),
        "seed": st.integers(0, 2**32 - 1),
    }).filter(_fits)


SPEC = SceneSpec(
    name="crossing",
    title="Crossing",
    populate=populate,
    camera=Camera((-0.69, -4.95, 1.93), (-0.69, 0.0, 1.0), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 6.0)),
    steps=STEPS,
    origin="canonical",
    poster_step=60,
    description="Two bodies fly head-on at each other in zero gravity and rebound; with collide=False they pass through.",
    parameters=parameters,
    gravity=(0.0, 0.0, 0.0),
)
