"""Loaded bodies: spheres, boxes and cylinders whose centre of mass is off their centre, dropped spinning.

Each body's inertial frame (``baseInertialFramePosition``/``Orientation``) is moved off its link
frame, like a loaded die, so pybullet's base pose (``getBasePositionAndOrientation``: the centre of
mass) is not where the shape is drawn from. A sync that draws the shape at the centre of mass draws
every body shifted, and turned wrongly where the inertial frame is rotated. Every kind is drawn both
by a whole actor (even-numbered bodies) and by a shared actor per kind (odd-numbered ones).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.errors import InvalidArgument

from .base import Camera, Scene, Shape
from .registry import SceneSpec

KINDS = ("sphere", "box", "cylinder")
COLORS = {"sphere": (0.85, 0.35, 0.2), "box": (0.25, 0.45, 0.85), "cylinder": (0.3, 0.7, 0.35)}
CYLINDER_HEIGHT = 2.0  # × radius: one ratio for all, so the shared cylinder actor can draw them
SPACING = 0.8  # m between drop points; more than two of the largest bodies' bounding spheres
PLATE = (4.0, 2.0, 0.05)  # half extents; the plate's top face is z = 0


def populate(scene: Scene, *, count: int = 6, offset: float = 0.6, spin: float = 4.0, seed: int = 0) -> None:
    if not 0.0 <= offset < 1.0:
        raise InvalidArgument(f"offset={offset!r}, but should be in [0, 1): the centre of mass as a fraction "
                              "of the way from the centre to the surface")
    rng = np.random.default_rng(seed)
    scene.add_body("ground", Shape("box", PLATE, color=(0.6, 0.6, 0.6)), mass=0.0, position=(0.0, 0.0, -PLATE[2]))
    turns = Rotation.random(2 * count, random_state=rng).as_quat() if count else np.empty((0, 4))
    for i in range(count):
        kind = KINDS[i % len(KINDS)]
        half = float(rng.uniform(0.12, 0.25))
        size = {"sphere": (half,), "box": (half, 0.7 * half, 0.5 * half), "cylinder": (half, CYLINDER_HEIGHT * half)}[kind]
        shade = 0.75 + 0.25 * rng.random()
        direction = rng.normal(size=3)
        inertial = offset * 0.5 * half * direction / np.linalg.norm(direction)  # inside even the box's thin side
        body = scene.add_body(
            f"{kind}{i}", Shape(kind, size, color=tuple(float(c * shade) for c in COLORS[kind])),
            mass=1.0, position=((i - (count - 1) / 2) * SPACING, 0.0, 0.8 + 0.4 * (i % 2)),
            orientation=tuple(float(q) for q in turns[i]), actor=f"{kind}s" if i % 2 else None,
            inertial_position=tuple(float(c) for c in inertial),
            inertial_orientation=tuple(float(q) for q in turns[count + i]))
        axis = rng.normal(size=3)
        scene.p.resetBaseVelocity(body, [0.0, 0.0, 0.0], (spin * axis / np.linalg.norm(axis)).tolist())


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "count": st.integers(1, 8),
        "offset": st.floats(0.0, 0.95),
        "spin": st.floats(0.0, 12.0),
        "seed": st.integers(0, 2**32 - 1),
    })


SPEC = SceneSpec(
    name="weighted",
    title="Loaded bodies",
    populate=populate,
    camera=Camera((-0.11, -9.09, 5.06), (-0.11, 0.04, 0.77), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 14.0)),
    steps=480,
    origin="canonical",
    description="Six spinning bodies whose centre of mass is off their centre fall onto a plate and rock.",
    parameters=parameters,
    poster_step=150,
)
