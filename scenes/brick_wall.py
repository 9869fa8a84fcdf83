"""A heavy ball thrown at a brick wall standing on a static plate.

Reproduces the guide's "Brick Wall Simulation" (FURY ``docs/examples/viz_brick_wall.py``): a wall
of ``rows`` × ``columns`` bricks one brick thick, a ball pushed once towards it, gravity -10.
Every body here is drawn by its own whole actor; ``brick_wall_single`` is the same physics with
all bricks drawn by one shared actor, as the guide's "Rendering multiple objects by a single
actor" section (and FURY's example itself) does.

The example's comments say the force is applied "5 times" and the run lasts "2000 steps"; its code
pushes once and stops after 131 frames, which is what is reproduced here.
"""

from __future__ import annotations

import numpy as np

from conformance.errors import InvalidArgument

from .base import Camera, ExternalForce, Scene, Shape
from .registry import SceneSpec

WHITE = (1.0, 1.0, 1.0)


def populate(scene: Scene, *, rows: int = 10, columns: int = 10, brick_size: tuple = (0.2, 0.4, 0.2),
             brick_mass: float = 0.5, brick_friction: float = 0.1, brick_restitution: float = 0.1,
             wall_x: float = -1.0, ball_radius: float = 0.3, ball_mass: float = 3.0,
             ball_position: tuple = (2.0, 0.0, 1.5), ball_friction: float = 0.3, ball_restitution: float = 0.5,
             force: tuple = (-10000.0, 0.0, 0.0), base_size: tuple = (5.0, 5.0, 0.2),
             base_friction: float = 0.3, base_restitution: float = 0.5, seed: int = 0,
             single_actor: bool = False) -> None:
    if rows < 1 or columns < 1:
        raise InvalidArgument(f"rows={rows!r}, columns={columns!r}, but a wall needs at least one brick")
    # Created in the example's order (ball, base, bricks) so body ids match it.
    ball = scene.add_body("ball", Shape("sphere", (ball_radius,), color=(1.0, 0.0, 0.0)), mass=ball_mass,
                          position=ball_position, friction=ball_friction, restitution=ball_restitution)
    add_base_plate(scene, base_size, friction=base_friction, restitution=base_restitution)

    # Centred on y = 0: for 10 columns this is the example's y = 0.4 j - 1.8, bit for bit.
    dx, dy, dz = brick_size
    colors = np.random.default_rng(seed).random((rows * columns, 3))
    for k in range(rows):
        for j in range(columns):
            i = k * columns + j
            scene.add_body(f"brick_{i}", Shape("box", (dx / 2, dy / 2, dz / 2), color=tuple(map(float, colors[i]))),
                           mass=brick_mass, position=(wall_x, j * dy - (columns - 1) * dy / 2, (k + 0.5) * dz),
                           actor="bricks" if single_actor else None,
                           friction=brick_friction, restitution=brick_restitution)

    scene.actions.append(ExternalForce(ball, tuple(force)))


def add_base_plate(scene: Scene, size, *, friction: float, restitution: float, name: str = "base") -> int:
    """The static plate the examples stand their bodies on: its top face is z = 0."""
    sx, sy, sz = size
    return scene.add_body(name, Shape("box", (sx / 2, sy / 2, sz / 2), color=WHITE), mass=0.0,
                          position=(0.0, 0.0, -sz / 2), friction=friction, restitution=restitution)


def parameters():
    from hypothesis import strategies as st

    base = st.fixed_dictionaries({
        "rows": st.integers(1, 4),
        "columns": st.integers(1, 4),
        "brick_mass": st.floats(0.1, 2.0),
        "ball_radius": st.floats(0.15, 0.4),
        "ball_mass": st.floats(1.0, 5.0),
        "seed": st.integers(0, 2**32 - 1),
    })
    # Aim the ball low enough to hit a short wall: it drops ~0.2 m before reaching it.
    return base.flatmap(lambda d: st.floats(d["ball_radius"], d["ball_radius"] + 0.2 * d["rows"]).map(
        lambda z: {**d, "ball_position": (2.0, 0.0, z)}))


SPEC = SceneSpec(
    name="brick_wall",
    title="Brick wall",
    populate=populate,
    camera=Camera((10.46, -8.13, 6.18), (0.0, 0.0, 0.79), (-0.27, 0.26, 0.9), view_angle=30.0, clipping_range=(0.5, 20.0)),
    steps=131,
    # Measured with conformance.checks.determinism.first_divergence: a 1 nm nudge of every body exceeds the physics
    # verdict's tolerance after step 2 (bricks resting on bricks).
    chaotic_after=2,
    origin="guide",
    description="A 3 kg ball pushed once with 10 kN flies into a 10 × 10 brick wall; every body is its own actor.",
    parameters=parameters,
)
