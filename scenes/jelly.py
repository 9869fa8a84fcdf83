"""Two jelly blocks dropped tilted onto a plate: they land on an edge, squash, rock and settle.

pyBullet simulates each block as a volumetric soft body: a tetrahedral mesh (``meshes/jelly.vtk``,
75 nodes of which 9 are inside, 192 tetrahedra, made by ``meshes/make_jelly.py``) with a NeoHookean
material, in a world reset with ``RESET_USE_DEFORMABLE_WORLD``. The left block is loaded with
``loadSoftBody``, the right one through ``loadURDF`` as a ``<deformable>`` body (``meshes/jelly.urdf``).
What is drawn is each block's boundary, 128 triangles through its 66 outer nodes, as pyBullet's own visual
mesh is: a sync copies the nodes ``Target.nodes`` names (the boundary ones) from
``getMeshData(block, -1, flags=MESH_DATA_SIMULATION_MESH)`` into the vertices.
"""

from __future__ import annotations

import math
import os

import pybullet

from .base import Camera, Scene, Shape
from .registry import SceneSpec

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "meshes")
MESH = os.path.join(HERE, "jelly.vtk")
URDF = os.path.join(HERE, "jelly.urdf")
PLATE = (0.7, 0.5, 0.05)  # half extents; the plate's top face is z = 0
APART = 0.22  # each block's centre this far from the middle, along x


def populate(scene: Scene, *, height: float = 0.35, tilt: float = 0.3, mu: float = 400.0, lam: float = 600.0,
             mass: float = 0.5) -> None:
    scene.add_body("plate", Shape("box", PLATE, color=(0.6, 0.6, 0.6)), mass=0.0, position=(0.0, 0.0, -PLATE[2]))
    # `height` is the drop height of each block's centre; tilted about x and y so each lands on an edge.
    scene.add_soft_body("jelly", MESH, position=(-APART, 0.0, height), color=(0.9, 0.3, 0.4),
                        orientation=pybullet.getQuaternionFromEuler((tilt, 0.6 * tilt, 0.0)), mass=mass,
                        useNeoHookean=1, NeoHookeanMu=mu, NeoHookeanLambda=lam, NeoHookeanDamping=0.001,
                        useSelfCollision=0, frictionCoeff=0.5, collisionMargin=0.006)
    scene.add_deformable("jelly_urdf", URDF, position=(APART, 0.0, height + 0.1), color=(0.3, 0.7, 0.4),
                         orientation=pybullet.getQuaternionFromEuler((-tilt, 0.0, math.pi / 8)))


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "height": st.floats(0.2, 0.5),
        "tilt": st.floats(0.0, 0.5),
        "mu": st.floats(250.0, 600.0),
        "lam": st.floats(400.0, 900.0),
        "mass": st.floats(0.3, 0.8),
    })


SPEC = SceneSpec(
    name="jelly",
    title="Jelly blocks",
    populate=populate,
    camera=Camera((0.0, -1.9, 0.8), (0.0, 0.0, 0.1), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 6.0)),
    # 1 s: the blocks land at about 0.2 s, squash, rock and settle.
    steps=240,
    origin="canonical",
    poster_step=70,
    description="Two tetrahedral NeoHookean blocks (75 nodes each), one from loadSoftBody(.vtk) and one from a "
                "<deformable> URDF, dropped tilted onto a plate: they land on an edge, squash and settle.",
    parameters=parameters,
    deformable=True,
    # Soft-rigid contact amplifies last-bit differences: a 1 nm nudge of every node grows past 1 µm after
    # step 56, at the landing (tests/test_chaos.py).
    chaotic_after=55,
)
