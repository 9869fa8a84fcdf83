"""A ball dropped onto a static plate, bouncing several times.

For checks of restitution (pybullet combines e_ball · e_ground, so both are set: one alone gives no
bounce) and of syncing fast vertical motion through impacts. Damping is off, so between impacts
the ball is in free fall and each rebound height is about (e_ball · e_ground)² of the previous one.
"""

from __future__ import annotations

from .base import Camera, Scene, Shape
from .registry import SceneSpec

PLATE = (1.5, 1.5, 0.05)  # half extents; the plate's top face is z = 0


def populate(scene: Scene, *, radius: float = 0.1, mass: float = 1.0, height: float = 1.0,
             ball_restitution: float = 0.9, ground_restitution: float = 0.8) -> None:
    scene.add_body("ground", Shape("box", PLATE, color=(0.6, 0.6, 0.6)),
                   mass=0.0, position=(0.0, 0.0, -PLATE[2]), restitution=ground_restitution)
    # `height` is the drop height of the ball's lowest point above the plate.
    ball = scene.add_body("ball", Shape("sphere", (radius,), color=(0.2, 0.4, 0.9)),
                          mass=mass, position=(0.0, 0.0, height + radius), restitution=ball_restitution)
    scene.p.changeDynamics(ball, -1, linearDamping=0, angularDamping=0)


def parameters():
    from hypothesis import strategies as st

    # Combined e stays well above pybullet's 0.2 m/s restitution threshold for these drops, and
    # below 1, where penetration correction would make bounces grow.
    return st.fixed_dictionaries({
        "radius": st.floats(0.05, 0.3),
        "mass": st.floats(0.1, 10.0),
        "height": st.floats(0.3, 1.5),
        "ball_restitution": st.floats(0.5, 0.95),
        "ground_restitution": st.floats(0.5, 0.95),
    })


SPEC = SceneSpec(
    name="bouncing_ball",
    title="Bouncing ball",
    populate=populate,
    camera=Camera((0.0, -3.6, 1.9), (0.0, 0.0, 0.45), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 7.0)),
    # 2 s: the drop and four impacts at the defaults (about 0.45, 1.09, 1.55 and 1.89 s).
    steps=480,
    origin="canonical",
    poster_step=100,
    description="A ball dropped from 1 m onto a plate bounces with combined restitution 0.9 × 0.8.",
    parameters=parameters,
)
