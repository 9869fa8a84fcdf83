"""Soft ball, FURY 2, WRONG: a hollow ball of 162 simulated nodes dropped onto a table, where it lands and squashes.

pyBullet simulates the ball as a soft body: a sphere made with ``trimesh`` (an icosphere, 162 vertices,
320 triangles) is written to an OBJ file and loaded with ``loadSoftBody`` as a mass-spring surface, in a
world reset with ``RESET_USE_DEFORMABLE_WORLD``; the table is a static box. pyBullet keeps the OBJ's
vertices as the ball's nodes in the file's order (``getMeshData(ball, -1,
flags=p.MESH_DATA_SIMULATION_MESH)``), so the program draws the ball from the same sphere, its
triangles as they are, and after every step copies the nodes into the positions buffer in that order,
gives the surface its normals once, when it is built, and announces the positions (``update_range()``).

MISTAKE: the normals are computed once, for the round ball, and never again: when the ball lands and squashes, FURY still shades it round
EXPECT: fail normals surface-normals
"""
import itertools
import os
import tempfile

import numpy as np
import pybullet as p
import trimesh
from fury import actor, utils, window

sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.2)
mesh_file = os.path.join(tempfile.mkdtemp(), "ball.obj")
sphere.export(mesh_file)

p.connect(p.DIRECT)
p.resetSimulation(p.RESET_USE_DEFORMABLE_WORLD)
p.setGravity(0, 0, -10)
table = p.createMultiBody(0, p.createCollisionShape(p.GEOM_BOX, halfExtents=[1, 1, 0.05]), basePosition=[0, 0, -0.05])
ball = p.loadSoftBody(mesh_file, basePosition=[0, 0, 1], mass=0.5, useNeoHookean=0, useBendingSprings=1,
                      useMassSpring=1, springElasticStiffness=300, springDampingStiffness=1.0,
                      springBendingStiffness=150, useSelfCollision=0, frictionCoeff=0.5, useFaceContact=1)

faces = np.asarray(sphere.faces, dtype=np.int32)
_, nodes = p.getMeshData(ball, -1, flags=p.MESH_DATA_SIMULATION_MESH)
nodes = np.array(nodes, dtype=np.float32)
ball_actor = actor.surface(nodes, faces, normals=utils.normals_from_v_f(nodes, faces).astype(np.float32),
                           colors=np.tile([0.2, 0.5, 0.9], (len(nodes), 1)).astype(np.float32))
positions, normals = ball_actor.geometry.positions, ball_actor.geometry.normals
table_actor = actor.box(centers=np.array([[0, 0, -0.05]]), colors=np.array([[0.6, 0.5, 0.4]]),
                        scales=np.array([[2, 2, 0.1]]))

scene = window.Scene()
scene.add(table_actor, ball_actor)
showm = window.ShowManager(scene=scene, size=(300, 300))
camera = showm.screens[0].camera
camera.local.position = (0, -3, 1.2)
camera.world.reference_up = (0, 0, 1)
camera.look_at((0, 0, 0.4))
counter = itertools.count()


def sync():
    _, now = p.getMeshData(ball, -1, flags=p.MESH_DATA_SIMULATION_MESH)
    positions.data[:] = np.array(now, dtype=np.float32)
    positions.update_range()


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
