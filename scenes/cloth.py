"""A cloth pinned at its four corners, and a box dropped onto it that lands, sinks in and bounces.

pyBullet simulates the cloth as a soft body: ``pybullet_data``'s ``cloth_z_up.obj`` (a 5 × 5 grid of
nodes, 32 triangles) loaded with ``loadSoftBody`` as a mass-spring surface in a world reset with
``RESET_USE_DEFORMABLE_WORLD``, its corners held by ``createSoftBodyAnchor``. A sync draws it from
``getMeshData(cloth, -1, flags=MESH_DATA_SIMULATION_MESH)``, one vertex per node; the box is a rigid
body, drawn from its pose. Deformable physics replays bit for bit on one machine and across the
kit's two environments (measured: the same nodes' bytes after 240 steps, docs/scenes.md).
"""

from __future__ import annotations

import os

from .base import Camera, Scene, Shape
from .registry import SceneSpec

#: The grid's corner nodes in the file's order: (1, 1), (-1, 1), (-1, -1), (1, -1) before scaling.
CORNERS = (15, 19, 20, 24)
HEIGHT = 0.6  # the cloth's plane


def populate(scene: Scene, *, box_half: float = 0.08, drop: float = 0.4, stiffness: float = 40.0,
             box_mass: float = 0.1) -> None:
    import pybullet_data

    scene.add_soft_body("cloth", os.path.join(pybullet_data.getDataPath(), "cloth_z_up.obj"), position=(0.0, 0.0, HEIGHT),
                        color=(0.9, 0.85, 0.6), scale=0.5, anchors=CORNERS, mass=1.0, useNeoHookean=0,
                        useBendingSprings=1, useMassSpring=1, springElasticStiffness=stiffness,
                        springDampingStiffness=0.1, useSelfCollision=0, frictionCoeff=0.5, useFaceContact=1)
    # Off the middle node a little, so that the box lands on a face and tips as the cloth gives.
    scene.add_body("box", Shape("box", (box_half,) * 3, color=(0.85, 0.2, 0.2)), mass=box_mass,
                   position=(0.05, -0.05, HEIGHT + drop + box_half))


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "box_half": st.floats(0.05, 0.1),
        "drop": st.floats(0.1, 0.5),
        "stiffness": st.floats(30.0, 80.0),
        "box_mass": st.floats(0.05, 0.2),
    })


SPEC = SceneSpec(
    name="cloth",
    title="Cloth",
    populate=populate,
    camera=Camera((0.0, -2.8, 1.7), (0.0, 0.0, 0.55), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 6.0)),
    # 1 s: the box lands at about 0.3 s, sinks the cloth, bounces and lands again.
    steps=240,
    origin="canonical",
    poster_step=100,
    description="A cloth pinned at four corners (a soft body of 25 nodes) catches a box dropped onto it.",
    parameters=parameters,
    deformable=True,
    # Soft-rigid contact amplifies last-bit differences: a 1 nm nudge of every node and of the box grows past
    # 1 µm after step 141 (tests/test_chaos.py).
    chaotic_after=140,
)
