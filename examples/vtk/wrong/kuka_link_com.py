"""KUKA iiwa, FURY 0.12, WRONG: each link drawn at its centre of mass, getLinkState()[0:2], not its link frame.
position motors tracing a slow wave; each link drawn from its visual mesh.

A robot as users draw it: each link's visual shapes as pyBullet holds them (``getVisualShapeData``: the
mesh file, its scale, and the shape's frame in the link frame), the mesh read with trimesh and built
into one actor per link, its vertices moved once by the visual frame and scale. After every step each
actor's user matrix is its link frame: ``getLinkState(arm, j, computeForwardKinematics=1)[4:6]`` for a
link, and for the base ``getBasePositionAndOrientation`` with the base's centre-of-mass offset
(``getDynamicsInfo(arm, -1)[3:5]``; the iiwa's base has one) undone.

Gravity -10, 1/240 s, 150 steps; the joints follow 0.6 sin(2 pi 0.8 t + j) with 300 N m at most.

MISTAKE: places each link's actor at getLinkState(arm, j)[0:2] (the link's centre of mass) and the base's at getBasePositionAndOrientation, where the meshes are given in the link frame, getLinkState()[4:6]: every link drawn 2-13 cm off, rigidly, so only where it sits in its frame tells
EXPECT: fail placed com-frame
"""

import itertools

import numpy as np
import pybullet as p
import pybullet_data
import trimesh
from fury import utils, window
from scipy.spatial.transform import Rotation
from vtkmodules.vtkCommonMath import vtkMatrix4x4

client = p.connect(p.DIRECT)
p.setAdditionalSearchPath(pybullet_data.getDataPath())
p.setTimeStep(1 / 240)
p.setGravity(0, 0, -10)
nb_steps = 150

arm = p.loadURDF("kuka_iiwa/model.urdf", [0, 0, 0], useFixedBase=True)
joints = list(range(p.getNumJoints(arm)))
links = [-1] + joints


def visual_geometry(link):
    """The link's visual meshes as one triangle mesh in its link frame, and a colour."""
    vertices, faces, colour = [], [], (0.8, 0.8, 0.8)
    for shape in p.getVisualShapeData(arm):
        if shape[1] != link or shape[2] != p.GEOM_MESH:
            continue
        mesh = trimesh.load(shape[4].decode(), force="mesh")
        placed = Rotation.from_quat(shape[6]).apply(np.asarray(mesh.vertices) * shape[3]) + shape[5]
        faces.append(np.asarray(mesh.faces) + sum(len(v) for v in vertices))
        vertices.append(placed)
        colour = shape[7][:3]
    return np.concatenate(vertices), np.concatenate(faces), colour


link_actors = []
for link in links:
    v, f, colour = visual_geometry(link)
    link_actors.append(utils.get_actor_from_primitive(v, f, colors=np.tile(colour, (len(v), 1))))


def link_frame(link):
    if link == -1:
        return p.getBasePositionAndOrientation(arm)
    return p.getLinkState(arm, link, computeForwardKinematics=1)[0:2]


def sync_actors():
    for link, link_actor in zip(links, link_actors):
        pos, orn = link_frame(link)
        matrix = np.eye(4)
        matrix[:3, :3] = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
        matrix[:3, 3] = pos
        user = vtkMatrix4x4()
        user.DeepCopy(matrix.ravel())
        link_actor.SetUserMatrix(user)


sync_actors()

scene = window.Scene()
scene.add(*link_actors)
scene.set_camera(position=(2.6, -2.4, 1.6), focal_point=(0.0, 0.0, 0.6), view_up=(0.0, 0.0, 1.0))
showm = window.ShowManager(scene, size=(900, 768), reset_camera=False, order_transparent=True)
showm.initialize()

counter = itertools.count()


def timer_callback(_obj, _event):
    cnt = next(counter)
    t = cnt / 240
    targets = [0.6 * np.sin(2 * np.pi * 0.8 * t + j) for j in joints]
    p.setJointMotorControlArray(arm, joints, p.POSITION_CONTROL, targetPositions=targets, forces=[300] * len(joints))

    p.stepSimulation()

    sync_actors()

    showm.render()

    if cnt == nb_steps - 1:
        showm.exit()


showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
