"""Cloth, FURY 0.12, WRONG: a cloth of 25 simulated nodes pinned at two corners, and a box dropped onto it.

pyBullet simulates the cloth as a soft body (``loadSoftBody`` of ``pybullet_data``'s ``cloth_z_up.obj``
in a world reset with ``RESET_USE_DEFORMABLE_WORLD``, two corners anchored with ``createSoftBodyAnchor``).
The program draws it as a surface built from the simulated nodes, ``getMeshData(cloth, -1,
flags=p.MESH_DATA_SIMULATION_MESH)``, triangulated once while the cloth is flat, and after every step
copies the nodes into the surface's vertices in the same order and announces them
(``utils.update_actor(cloth_actor)``); the box is posed from its body's pose.

MISTAKE: copies the cloth's nodes into the surface only on the sync's first call ("the cloth's vertices are set up once"), and from then on poses the box alone: the cloth stays drawn flat where it was built while pyBullet's sags and folds under the box
EXPECT: fail drawn never-moved
"""
import itertools

import numpy as np
import pybullet as p
import pybullet_data
from fury import actor, utils, window
from scipy.spatial import Delaunay
from scipy.spatial.transform import Rotation
from vtkmodules.vtkCommonMath import vtkMatrix4x4

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
nodes = np.array(nodes)
faces = Delaunay(nodes[:, :2]).simplices  # the cloth starts flat: its triangles from the nodes' x, y
cloth_actor = actor.surface(nodes, faces=faces, colors=np.tile([0.9, 0.9, 0.8], (len(nodes), 1)))
cloth_vertices = utils.vertices_from_actor(cloth_actor)
box_actor = actor.box(centers=np.zeros((1, 3)), colors=np.array([[1, 0, 0]]), scales=np.array([[0.1, 0.1, 0.1]]))

scene = window.Scene()
scene.add(cloth_actor, box_actor)
showm = window.ShowManager(scene=scene, size=(300, 300))
showm.initialize()
scene.set_camera(position=(0, -3, 1.5), focal_point=(0, 0, 0.8), view_up=(0, 0, 1))
counter = itertools.count()

copied = []


def sync():
    _, now = p.getMeshData(cloth, -1, flags=p.MESH_DATA_SIMULATION_MESH)
    if not copied:
        copied.append(True)
        cloth_vertices[:] = np.array(now)
    utils.update_actor(cloth_actor)
    pos, orn = p.getBasePositionAndOrientation(box)
    m = np.eye(4); m[:3, :3] = Rotation.from_quat(orn).as_matrix(); m[:3, 3] = pos
    u = vtkMatrix4x4(); u.DeepCopy(m.ravel()); box_actor.SetUserMatrix(u)


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
