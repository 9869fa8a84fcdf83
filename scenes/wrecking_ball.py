"""A ball on a chain hanging beside a block of bricks, its pinned hinge given one push.

Reproduces the guide's "Wrecking Ball Simulation" (FURY ``docs/examples/viz_wrecking_ball.py``): a
``wall_length`` × ``wall_breadth`` × ``wall_height`` block of bricks on a static plate, and a rope
of ``n_links`` spherical-joint links pinned at (0, 0, 2) whose last link is a heavy sphere. The rope
base is pushed once with ``force``.

The push reaches the ball only through a clamp: the pinned 0.1 kg hinge would absorb it, but 500 N
for one step asks the first joint for ~208 rad/s, pybullet clamps joint speeds to 100 rad/s
(maxJointVelocity), and the difference flings the chain at ~10 m/s (pushes below ~240 N move
nothing). The ball smashes the block within ~15 steps and then loops over the hinge; from about
step 90 the chain whips chaotically (link speeds above 100 m/s). Runs are still bit-reproducible.

Corrections to FURY 0.11-0.12:
- the link positions are passed as real floats; FURY's ``linkPositions.astype(int)`` truncated
  (0, 0, -0.1) to (0, 0, 0), so every link sat at the hinge and the ball never swung;
- the chain is sliced per link (FURY divided the chain's vertices by the brick count) and each
  cylinder is drawn as its collision shape, along the link's z and half a link below the joint
  (FURY drew it along (1, 1, 1) at the joint);
- the hinge box is drawn where it is (FURY never moved its actor from the origin).
"""

from __future__ import annotations

import numpy as np

from conformance.errors import InvalidArgument

from .base import Camera, ExternalForce, Scene, Shape
from .brick_wall import add_base_plate
from .chain import HINGE, add_rope, link_cylinder
from .registry import SceneSpec


def populate(scene: Scene, *, wall_length: int = 5, wall_breadth: int = 5, wall_height: int = 5,
             brick_size: tuple = (0.2, 0.4, 0.2), brick_mass: float = 0.5, brick_friction: float = 0.1,
             brick_restitution: float = 0.1, wall_origin: tuple = (-1.8, -0.9, 0.0),
             n_links: int = 15, link_length: float = 0.1, link_radius: float = 0.1, link_mass: float = 0.5,
             base_mass: float = 0.1, ball_radius: float = 0.5, ball_mass: float = 5.0,
             joint_friction: float = 0.0005, height: float = 2.0, force: tuple = (-500.0, 0.0, 0.0),
             base_size: tuple = (5.0, 5.0, 0.2), base_friction: float = 0.3, base_restitution: float = 0.5,
             seed: int = 0) -> None:
    if min(wall_length, wall_breadth, wall_height) < 1 or n_links < 1:
        raise InvalidArgument(f"wall {wall_length}×{wall_breadth}×{wall_height} with n_links={n_links}, "
                              "but each count should be at least 1")
    rng = np.random.default_rng(seed)
    add_base_plate(scene, base_size, friction=base_friction, restitution=base_restitution)

    # The example's layout: brick (i, j, k) centred at origin + (0.2 i, 0.4 j, 0.2 k + 0.1).
    dx, dy, dz = brick_size
    x0, y0, z0 = wall_origin
    colors = rng.random((wall_length * wall_breadth * wall_height, 3))
    index = 0
    for i in range(wall_length):
        for k in range(wall_height):
            for j in range(wall_breadth):
                shape = Shape("box", (dx / 2, dy / 2, dz / 2), color=tuple(map(float, colors[index])))
                scene.add_body(f"brick_{index}", shape, mass=brick_mass,
                               position=(x0 + i * dx, y0 + j * dy, z0 + (k + 0.5) * dz), actor="bricks",
                               friction=brick_friction, restitution=brick_restitution)
                index += 1

    link_colors = rng.random((n_links - 1, 3))
    shapes = [link_cylinder(link_radius, link_length, c) for c in link_colors]
    shapes.append(Shape("sphere", (ball_radius,), color=(1.0, 0.0, 1.0)))
    masses = [link_mass] * (n_links - 1) + [ball_mass]
    rope, _ = add_rope(scene, shapes, masses, link_length=link_length, base_mass=base_mass,
                       position=(0.0, 0.0, height), joint_friction=joint_friction)
    scene.bind("hinge", rope, -1, HINGE)
    for j, shape in enumerate(shapes[:-1]):
        scene.bind(f"link_{j}", rope, j, shape, actor="links")
    scene.bind("ball", rope, n_links - 1, shapes[-1])

    scene.actions.append(ExternalForce(rope, tuple(force)))


def parameters():
    from hypothesis import strategies as st

    def aim(d):
        # As in the example, the ball hangs just touching the plate with the block's near face
        # 0.4 m from it; the block is centred on the ball's plane (the example's is 0.1 m off).
        dx, dy = 0.2, 0.4
        near = -d["ball_radius"] - 0.4 - dx / 2
        return {**d, "height": d["n_links"] * 0.1 + d["ball_radius"],
                "wall_origin": (near - (d["wall_length"] - 1) * dx, -(d["wall_breadth"] - 1) * dy / 2, 0.0)}

    return st.fixed_dictionaries({
        "wall_length": st.integers(1, 3),
        "wall_breadth": st.integers(1, 4),
        "wall_height": st.integers(2, 3),
        "brick_mass": st.floats(0.1, 2.0),
        "n_links": st.integers(10, 15),
        "link_radius": st.floats(0.02, 0.1),
        "ball_radius": st.floats(0.2, 0.5),
        "ball_mass": st.floats(1.0, 10.0),
        "seed": st.integers(0, 2**32 - 1),
    }).map(aim)


SPEC = SceneSpec(
    name="wrecking_ball",
    title="Wrecking ball",
    populate=populate,
    camera=Camera((10.28, -7.1, 6.39), (0.0, 0.0, 0.4), (-0.35, 0.26, 1.0), view_angle=30.0, clipping_range=(0.5, 19.0)),
    steps=131,
    origin="guide",
    poster_step=45,
    # Measured with conformance.checks.determinism.first_divergence: a 1 nm nudge of every body exceeds the physics
    # verdict's tolerance after step 1 (bricks resting on bricks; the ball's whip later).
    chaotic_after=1,
    description="A 5 kg ball on a 15-link chain pinned at z = 2, its hinge pushed once, smashes a 5×5×5 brick block.",
    parameters=parameters,
)
