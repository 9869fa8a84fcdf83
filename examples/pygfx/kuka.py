"""KUKA iiwa, FURY 2: pybullet_data's ``kuka_iiwa/model.urdf`` on a fixed base, its seven joints on
position motors tracing a slow wave; each link drawn from its visual mesh.

A robot as users draw it: each link's visual shapes as pyBullet holds them (``getVisualShapeData``: the
mesh file, its scale, and the shape's frame in the link frame), the mesh read with trimesh and built
into one actor per link, its vertices moved once by the visual frame and scale. After every step each
actor's ``local.position`` and ``local.rotation`` (pyBullet's x, y, z, w quaternion as it is) are its link frame: ``getLinkState(arm, j, computeForwardKinematics=1)[4:6]`` for a
link, and for the base ``getBasePositionAndOrientation`` with the base's centre-of-mass offset
(``getDynamicsInfo(arm, -1)[3:5]``; the iiwa's base has one) undone.

Gravity -10, 1/240 s, 150 steps; the joints follow 0.6 sin(2 pi 0.8 t + j) with 300 N m at most.

EXPECT: pass
"""

import itertools

import numpy as np
import pybullet as p
import pybullet_data
import trimesh
from fury import actor, window
from scipy.spatial.transform import Rotation

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
    link_actors.append(actor.surface(v.astype(np.float32), f.astype(np.int32),
                                     colors=np.tile(colour, (len(v), 1)).astype(np.float32)))


def link_frame(link):
    if link == -1:
        com_pos, com_orn = p.getBasePositionAndOrientation(arm)
        inertial_pos, inertial_orn = p.getDynamicsInfo(arm, -1)[3:5]
        return p.multiplyTransforms(com_pos, com_orn, *p.invertTransform(inertial_pos, inertial_orn))
    return p.getLinkState(arm, link, computeForwardKinematics=1)[4:6]


def sync_actors():
    for link, link_actor in zip(links, link_actors):
        pos, orn = link_frame(link)
        link_actor.local.position = pos
        link_actor.local.rotation = orn


sync_actors()

scene = window.Scene()
scene.add(*link_actors)
showm = window.ShowManager(scene=scene, size=(900, 768), title="FURY 2 + pyBullet: KUKA iiwa")
camera = showm.screens[0].camera
camera.local.position = (2.6, -2.4, 1.6)
camera.world.reference_up = (0.0, 0.0, 1.0)
camera.look_at((0.0, 0.0, 0.6))

counter = itertools.count()


def timer_callback():
    cnt = next(counter)
    t = cnt / 240
    targets = [0.6 * np.sin(2 * np.pi * 0.8 * t + j) for j in joints]
    p.setJointMotorControlArray(arm, joints, p.POSITION_CONTROL, targetPositions=targets, forces=[300] * len(joints))

    p.stepSimulation()

    sync_actors()

    showm.render()

    if cnt == nb_steps - 1:
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
