"""Soft ball, FURY 0.12, WRONG: a hollow ball of 162 simulated nodes dropped onto a table, where it lands and squashes.

pyBullet simulates the ball as a soft body: a sphere made with ``trimesh`` (an icosphere, 162 vertices,
320 triangles) is written to an OBJ file and loaded with ``loadSoftBody`` as a mass-spring surface, in a
world reset with ``RESET_USE_DEFORMABLE_WORLD``; the table is a static box. pyBullet keeps the OBJ's
vertices as the ball's nodes in the file's order (``getMeshData(ball, -1,
flags=p.MESH_DATA_SIMULATION_MESH)``), so the program draws the ball from the same sphere, its
triangles as they are, and after every step copies the nodes into the vertices in that order,
gives the surface its normals once, when it is built, and announces both (``utils.update_actor``).

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

faces = np.asarray(sphere.faces)
_, nodes = p.getMeshData(ball, -1, flags=p.MESH_DATA_SIMULATION_MESH)
ball_actor = actor.surface(np.array(nodes), faces=faces, colors=np.tile([0.2, 0.5, 0.9], (len(nodes), 1)))
ball_vertices = utils.vertices_from_actor(ball_actor)
utils.normals_to_actor(ball_actor, utils.normals_from_v_f(ball_vertices, faces))
table_actor = actor.box(centers=np.array([[0, 0, -0.05]]), colors=np.array([[0.6, 0.5, 0.4]]),
                        scales=np.array([[2, 2, 0.1]]))

scene = window.Scene()
scene.add(table_actor, ball_actor)
showm = window.ShowManager(scene=scene, size=(300, 300))
showm.initialize()
scene.set_camera(position=(0, -3, 1.2), focal_point=(0, 0, 0.4), view_up=(0, 0, 1))
counter = itertools.count()


def sync():
    _, now = p.getMeshData(ball, -1, flags=p.MESH_DATA_SIMULATION_MESH)
    ball_vertices[:] = np.array(now)
    utils.update_actor(ball_actor)


def timer_callback(_obj, _event):
    cnt = next(counter)
    p.stepSimulation()
    sync()
    showm.render()
    if cnt == 200:
        showm.exit()


sync()
showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
