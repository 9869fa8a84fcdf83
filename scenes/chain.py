"""A chain of spherical-joint links hanging from a pivot that swings to and fro.

Reproduces the guide's "Rendering Joints" section and its "Chain Simulation" (FURY
``docs/examples/viz_chain.py``): a tiny base box pinned by a fixed constraint at (0, 0, 2), with
``n_links`` links of length ``link_length`` hanging below it, each a cylinder collision shape whose
centre sits half a link below its joint. Joint friction is a velocity motor (kp 0, kd 1, small
force). Before every step the pivot moves to (0.9 sin(2π 0.6 t), 0, 2), t the time after the step.

Correction: FURY draws each link as a cylinder along (1, 1, 1) centred on the joint; the collision
cylinder lies along the link's z axis, half a link below the joint. Here the drawn shape is the
collision shape. The collision radius 0.5 (each link a 1 m wide, 0.1 m thick disc) is kept, since
that is the physics the example simulates.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import pybullet

from conformance.errors import InvalidArgument

from .base import IDENTITY, Camera, MovingPivot, Scene, Shape
from .registry import SceneSpec

HINGE = Shape("box", (0.01, 0.01, 0.01), color=(1.0, 0.0, 0.0))


def populate(scene: Scene, *, n_links: int = 20, link_length: float = 0.1, radius: float = 0.5,
             link_mass: float = 0.5, base_mass: float = 0.1, joint_friction: float = 0.0005,
             height: float = 2.0, amplitude: float = 0.9, frequency: float = 0.6, max_force: float = 500.0,
             seed: int = 0) -> None:
    if n_links < 1:
        raise InvalidArgument(f"n_links={n_links!r}, but a chain needs at least one link")
    colors = np.random.default_rng(seed).random((n_links, 3))
    shapes = [link_cylinder(radius, link_length, colors[j]) for j in range(n_links)]
    rope, pin = add_rope(scene, shapes, [link_mass] * n_links, link_length=link_length, base_mass=base_mass,
                         position=(0.0, 0.0, height), joint_friction=joint_friction)
    scene.bind("hinge", rope, -1, HINGE)
    for j, shape in enumerate(shapes):
        scene.bind(f"link_{j}", rope, j, shape, actor="links")
    scene.actions.append(MovingPivot(pin, centre=(0.0, 0.0, height), amplitude=(amplitude, 0.0, 0.0),
                                     frequency=frequency, max_force=max_force))


def link_cylinder(radius: float, length: float, color) -> Shape:
    """A rope link's collision cylinder: along the link's z, centred half a link below its joint."""
    return Shape("cylinder", (radius, length), color=tuple(map(float, color)), position=(0.0, 0.0, -length / 2))


def add_rope(scene: Scene, shapes: Sequence[Shape], masses: Sequence[float], *, link_length: float,
             base_mass: float, position, joint_friction: float) -> tuple[int, int]:
    """The examples' rope: a ``HINGE`` base at ``position`` pinned there by a fixed constraint, and a
    serial chain of spherical joints, link j hanging ``link_length`` below link j - 1.

    Returns the multibody and the constraint. Nothing is bound: the caller decides how to draw it.
    """
    n = len(shapes)
    # One collision shape per distinct geometry, as the examples create one for all links.
    collision: dict = {}
    indices = []
    for s in shapes:
        key = (s.kind, s.size, s.position, s.orientation)
        if key not in collision:
            collision[key] = s.collision_shape(scene.p)
        indices.append(collision[key])
    rope = scene.p.createMultiBody(
        baseMass=base_mass,
        baseCollisionShapeIndex=HINGE.collision_shape(scene.p),
        baseVisualShapeIndex=-1,
        basePosition=list(position),
        baseOrientation=list(IDENTITY),
        linkMasses=[float(m) for m in masses],
        linkCollisionShapeIndices=indices,
        linkVisualShapeIndices=[-1] * n,
        # Real floats: FURY 0.11-0.12's wrecking ball cast these to int, collapsing every link onto the base.
        linkPositions=[[0.0, 0.0, -float(link_length)]] * n,
        linkOrientations=[list(IDENTITY)] * n,
        linkInertialFramePositions=[[0.0, 0.0, 0.0]] * n,
        linkInertialFrameOrientations=[list(IDENTITY)] * n,
        linkParentIndices=list(range(n)),
        linkJointTypes=[pybullet.JOINT_SPHERICAL] * n,
        linkJointAxis=[[1.0, 0.0, 0.0]] * n,
    )
    # A velocity motor with zero position gain acts as joint friction: it only resists joint motion.
    for j in range(n):
        scene.p.setJointMotorControlMultiDof(rope, j, pybullet.POSITION_CONTROL, targetPosition=[0, 0, 0, 1],
                                            targetVelocity=[0, 0, 0], positionGain=0, velocityGain=1,
                                            force=[joint_friction] * 3)
    pin = scene.p.createConstraint(rope, -1, -1, -1, pybullet.JOINT_FIXED, [0, 0, 0], [0, 0, 0], list(position))
    return rope, pin


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "n_links": st.integers(1, 12),
        "link_length": st.floats(0.05, 0.2),
        "radius": st.floats(0.02, 0.5),
        "link_mass": st.floats(0.1, 1.0),
        "amplitude": st.floats(0.0, 1.0),
        "frequency": st.floats(0.2, 2.0),
        "seed": st.integers(0, 2**32 - 1),
    })


SPEC = SceneSpec(
    name="chain",
    title="Chain",
    populate=populate,
    camera=Camera((3.9, -4.93, 4.17), (0.47, 0.0, 1.02), (-0.2, 0.2, 1.0), view_angle=30.0, clipping_range=(0.5, 9.0)),
    steps=131,
    origin="guide",
    description="A 20-link chain of spherical joints hangs from a pivot at z = 2 that swings along x.",
    parameters=parameters,
)
