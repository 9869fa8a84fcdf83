"""A soft ball dropped onto a plate: it lands, squashes and bounces.

pyBullet simulates the ball as a soft body: ``meshes/soft_ball.obj`` (an icosphere of 42 nodes, 80
triangles) loaded with ``loadSoftBody`` as a mass-spring surface in a world reset with
``RESET_USE_DEFORMABLE_WORLD``; the plate is a static box. A sync draws the ball from
``getMeshData(ball, -1, flags=MESH_DATA_SIMULATION_MESH)``, one vertex per node.
"""

from __future__ import annotations

import os

from .base import Camera, Scene, Shape
from .registry import SceneSpec

MESH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "meshes", "soft_ball.obj")
PLATE = (0.6, 0.6, 0.05)  # half extents; the plate's top face is z = 0


def populate(scene: Scene, *, radius: float = 0.2, height: float = 0.6, stiffness: float = 300.0,
             mass: float = 0.5) -> None:
    scene.add_body("plate", Shape("box", PLATE, color=(0.6, 0.6, 0.6)), mass=0.0, position=(0.0, 0.0, -PLATE[2]))
    # `height` is the drop height of the ball's lowest node above the plate.
    scene.add_soft_body("ball", MESH, position=(0.0, 0.0, height + radius), color=(0.2, 0.5, 0.9), scale=radius,
                        mass=mass, useNeoHookean=0, useBendingSprings=1, useMassSpring=1,
                        springElasticStiffness=stiffness, springDampingStiffness=1.0, springBendingStiffness=stiffness / 2,
                        useSelfCollision=0, frictionCoeff=0.5, useFaceContact=1)


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "radius": st.floats(0.12, 0.25),
        "height": st.floats(0.2, 0.8),
        "stiffness": st.floats(200.0, 500.0),
        "mass": st.floats(0.2, 1.0),
    })


SPEC = SceneSpec(
    name="soft_ball",
    title="Soft ball",
    populate=populate,
    camera=Camera((0.0, -2.4, 1.0), (0.0, 0.0, 0.3), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 6.0)),
    # 1 s: the ball lands at about 0.33 s, squashes, bounces and settles.
    steps=240,
    origin="canonical",
    poster_step=90,
    description="A soft ball (a mass-spring surface of 42 nodes) dropped from 0.6 m onto a plate squashes and bounces.",
    parameters=parameters,
    deformable=True,
    # Soft-rigid contact amplifies last-bit differences: a 1 nm nudge of every node grows past 1 µm after
    # step 86, at the landing (tests/test_chaos.py).
    chaotic_after=85,
)
