"""A flat box launched along +x across a static plate, stopped by Coulomb friction alone.

For checks of friction (deceleration = μ_box · μ_ground · g while it slides, pybullet's product
rule) and of syncing a body that translates without turning. Damping is off, so friction is the
only horizontal force.
"""

from __future__ import annotations

from .base import Camera, Scene, Shape
from .registry import SceneSpec

GRAVITY = 10.0  # |g| of SceneSpec's default gravity, to keep the stopping distance on the plate
START_X = -1.2
PLATE = (3.0, 1.0, 0.05)  # half extents; the plate's top face is z = 0


def populate(scene: Scene, *, size: float = 0.2, mass: float = 1.0, speed: float = 3.0,
             box_friction: float = 0.5, ground_friction: float = 0.6) -> None:
    scene.add_body("ground", Shape("box", PLATE, color=(0.6, 0.6, 0.6)),
                   mass=0.0, position=(0.0, 0.0, -PLATE[2]), friction=ground_friction)
    # `size` is the half length along the motion. Low and wide: a box tips over its front edge
    # once μ·hz > hx (pybullet-facts.md, "Materials").
    half = (size, 0.75 * size, 0.3 * size)
    box = scene.add_body("box", Shape("box", half, color=(0.9, 0.4, 0.1)),
                         mass=mass, position=(START_X, 0.0, half[2]), friction=box_friction)
    # pybullet's default quadratic damping would add to friction and spoil μ·g.
    scene.p.changeDynamics(box, -1, linearDamping=0, angularDamping=0)
    scene.p.resetBaseVelocity(box, [speed, 0.0, 0.0], [0.0, 0.0, 0.0])


def stopping_distance(speed: float, box_friction: float, ground_friction: float) -> float:
    return speed ** 2 / (2 * GRAVITY * box_friction * ground_friction)


def _stops_on_plate(d) -> bool:
    """Comes to rest well inside the default 360 steps (1.5 s), before the plate's far edge."""
    deceleration = GRAVITY * d["box_friction"] * d["ground_friction"]
    distance = stopping_distance(d["speed"], d["box_friction"], d["ground_friction"])
    return d["speed"] / deceleration <= 1.2 and START_X + d["size"] + distance < PLATE[0] - 0.2


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "size": st.floats(0.05, 0.4),
        "mass": st.floats(0.1, 10.0),
        "speed": st.floats(0.5, 3.0),
        "box_friction": st.floats(0.3, 1.0),
        "ground_friction": st.floats(0.3, 1.0),
    }).filter(_stops_on_plate)


SPEC = SceneSpec(
    name="sliding_box",
    title="Sliding box",
    populate=populate,
    camera=Camera((-0.45, -4.0, 2.2), (-0.45, 0.0, 0.0), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 7.0)),
    steps=360,
    origin="canonical",
    description="A flat box launched at 3 m/s along +x slides on a static plate until friction stops it.",
    parameters=parameters,
)
