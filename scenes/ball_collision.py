"""Two balls pushed towards each other in zero gravity collide head-on.

Reproduces the guide's "Ball Collision Simulation" (FURY ``docs/examples/viz_ball_collide.py``):
a red ball at +x and a blue ball at -x, each pushed once with ``force`` newtons towards the other.

The push is far stronger than it looks: 40 kN for one 1/240 s step on 0.5 kg would give 333 m/s,
but pybullet clamps each multibody base velocity component to ±100 m/s (maxJointVelocity) and its
quadratic damping slows the balls further, so those two, not the force, set the closing speed.
Both balls carry restitution 0.6; the pair's combined restitution is the product, 0.36.
"""

from __future__ import annotations

from .base import Camera, ExternalForce, Scene, Shape
from .registry import SceneSpec


def populate(scene: Scene, *, radius: float = 0.5, mass: float = 0.5, distance: float = 10.0,
             force: float = 40000.0, restitution: float = 0.6, seed: int = 0) -> None:
    # Nothing here is random; ``seed`` is accepted so every guide scene takes one.
    red = scene.add_body("red_ball", Shape("sphere", (radius,), color=(1.0, 0.0, 0.0)), mass=mass,
                         position=(distance, 0.0, 0.0), restitution=restitution)
    blue = scene.add_body("blue_ball", Shape("sphere", (radius,), color=(0.0, 0.0, 1.0)), mass=mass,
                          position=(-distance, 0.0, 0.0), restitution=restitution)
    scene.actions.append(ExternalForce(red, (-force, 0.0, 0.0)))
    scene.actions.append(ExternalForce(blue, (force, 0.0, 0.0)))


def parameters():
    from hypothesis import strategies as st

    # Pushes of at least 20 kN on at most 2 kg start the balls at >= 41 m/s, so they meet well
    # within the 51 frames from any distance drawn here. At up to 100 m/s each they close 0.83 m
    # per step: balls of radius below ~0.42 can step through each other without a contact.
    return st.fixed_dictionaries({
        "radius": st.floats(0.45, 1.0),
        "mass": st.floats(0.2, 2.0),
        "distance": st.floats(1.5, 6.0),
        "force": st.floats(20000.0, 40000.0),
        "restitution": st.floats(0.0, 1.0),
        "seed": st.integers(0, 2**32 - 1),
    })


SPEC = SceneSpec(
    name="ball_collision",
    title="Ball collision",
    populate=populate,
    camera=Camera((0.31, -39.89, 1.03), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 45.0)),
    steps=51,
    origin="guide",
    poster_step=31,
    description="Two 0.5 kg balls 20 m apart, pushed once towards each other in zero gravity, collide and rebound.",
    parameters=parameters,
    gravity=(0.0, 0.0, 0.0),
)
