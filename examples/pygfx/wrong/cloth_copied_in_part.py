"""Cloth, FURY 2, WRONG: a cloth of 25 simulated nodes pinned at two corners, and a box dropped onto it.

pyBullet simulates the cloth as a soft body (``loadSoftBody`` of ``pybullet_data``'s ``cloth_z_up.obj``
in a world reset with ``RESET_USE_DEFORMABLE_WORLD``, two corners anchored with ``createSoftBodyAnchor``).
The program draws it as a surface built from the simulated nodes, ``getMeshData(cloth, -1,
flags=p.MESH_DATA_SIMULATION_MESH)``, triangulated once while the cloth is flat, and after every step
copies the nodes into the surface's vertices in the same order and announces them
(``positions.update_range()``); the box is posed from its body's pose.

MISTAKE: copies only the first 13 of the cloth's 25 nodes after each step (a count kept from a coarser cloth the program was first written for): the other vertices stay where they were built while their nodes fall
EXPECT: fail drawn part-copied
"""
import itertools

import numpy as np
import pybullet as p
import pybullet_data
from fury import actor, window
from scipy.spatial import Delaunay

p.connect(p.DIRECT)
p.resetSimulation(p.RESET_USE_DEFORMABLE_WORLD)
p.setAdditionalSearchPath(pybullet_data.getDataPath())
p.setGravity(0, 0, -10)
cloth = p.loadSoftBody("cloth_z_up.obj", basePosition=[0, 0, 1], scale=0.5, mass=1.0, useNeoHookean=0,
                       useBendingSprings=1, useMassSpring=1, springElasticStiffness=40, springDampingStiffness=0.1,
                       useSelfCollision=0, frictionCoeff=0.5, useFaceContact=1)
p.createSoftBodyAnchor(cloth, 0, -1, -1)
p.createSoftBodyAnchor(cloth, 24, -1, -1)
box = p.createMultiBody(0.1, p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.05] * 3), basePosition=[0, 0, 1.5])

_, nodes = p.getMeshData(cloth, -1, flags=p.MESH_DATA_SIMULATION_MESH)
nodes = np.array(nodes, dtype=np.float32)
faces = Delaunay(nodes[:, :2]).simplices.astype(np.int32)  # the cloth starts flat: its triangles from x, y
cloth_actor = actor.surface(nodes, faces, colors=np.tile([0.9, 0.9, 0.8], (len(nodes), 1)).astype(np.float32))
positions = cloth_actor.geometry.positions
box_actor = actor.box(centers=np.zeros((1, 3)), colors=np.array([[1, 0, 0]]), scales=np.array([[0.1, 0.1, 0.1]]))

scene = window.Scene()
scene.add(cloth_actor, box_actor)
showm = window.ShowManager(scene=scene, size=(300, 300))
camera = showm.screens[0].camera
camera.local.position = (0, -3, 1.5)
camera.world.reference_up = (0, 0, 1)
camera.look_at((0, 0, 0.8))
counter = itertools.count()


def sync():
    _, now = p.getMeshData(cloth, -1, flags=p.MESH_DATA_SIMULATION_MESH)
    positions.data[:13] = np.array(now[:13], dtype=np.float32)
    positions.update_range()
    pos, orn = p.getBasePositionAndOrientation(box)
    box_actor.local.position = pos
    box_actor.local.rotation = orn


def timer_callback():
    cnt = next(counter)
    p.stepSimulation()
    sync()
    showm.render()
    if cnt == 200:
        showm.cancel_callback("physics")


sync()
showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
