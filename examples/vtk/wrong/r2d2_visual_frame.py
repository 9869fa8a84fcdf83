"""R2-D2, FURY 0.12, WRONG: each visual shape is built at its link frame's origin, its visual frame left out.

A robot as users load it: ``p.loadURDF("r2d2.urdf")`` from ``pybullet_data``, with its fixed joints kept
(legs and wheel bases welded to the body, finger tips to the fingers, the box on the head), so six of
its 15 links never move relative to their parent. Each link is one actor built from the link's visual
shapes as pyBullet holds them (``getVisualShapeData``: the kind and dimensions, a mesh's file and
scale, and the shape's frame in the link frame): boxes, cylinders and the head's sphere made with
trimesh, the finger meshes read with it, each moved once by its visual frame. After every step each
actor is placed at its link frame: ``getLinkState(robot, j, computeForwardKinematics=1)[4:6]`` for a
link, and for the base ``getBasePositionAndOrientation`` with its centre-of-mass offset undone
(``getDynamicsInfo(robot, -1)[3:5]``).

The wheels turn on velocity motors (the right pair faster, so it arcs), the head swivels, the gripper
pole slides out and the fingers open and close; gravity -10, 1/240 s, 150 steps, on ``plane.urdf``.

MISTAKE: builds each visual shape at its link frame's origin and leaves out getVisualShapeData's local frame (the URDF's <visual><origin>), so the legs are drawn lying across the body 0.3 m too high and the fingers' tips inside the fingers
EXPECT: fail placed visual-frame
"""

import itertools

import numpy as np
import pybullet as p
import pybullet_data
from fury import actor, primitive, utils, window
import trimesh
from vtkmodules.vtkCommonMath import vtkMatrix4x4

client = p.connect(p.DIRECT)
p.setAdditionalSearchPath(pybullet_data.getDataPath())
p.setTimeStep(1 / 240)
p.setGravity(0, 0, -10)
nb_steps = 150

plane = p.loadURDF("plane.urdf")
robot = p.loadURDF("r2d2.urdf", [0, 0, 0.5])
links = list(range(-1, p.getNumJoints(robot)))
names = {j: p.getJointInfo(robot, j)[12].decode() for j in links if j >= 0}
wheels = [j for j in links if j >= 0 and names[j].endswith("wheel")]
head = next(j for j in links if j >= 0 and names[j] == "head")
pole = next(j for j in links if j >= 0 and names[j] == "gripper_pole")
fingers = [j for j in links if j >= 0 and names[j] in ("left_gripper", "right_gripper")]


def quaternion_matrix(q):
    return np.reshape(p.getMatrixFromQuaternion(q), (3, 3))


def link_geometry(j):
    """The link's visual shapes as one triangle mesh, in its link frame."""
    vertices, triangles = [], []
    for shape in p.getVisualShapeData(robot):
        if shape[1] != j:
            continue
        kind, dims, path, local_pos, local_orn = shape[2], shape[3], shape[4], shape[5], shape[6]
        if kind == p.GEOM_MESH:
            mesh = trimesh.load(path.decode(), force="mesh")
            mesh.apply_scale(dims)
        elif kind == p.GEOM_BOX:
            mesh = trimesh.creation.box(extents=dims)
        elif kind == p.GEOM_CYLINDER:
            mesh = trimesh.creation.cylinder(radius=dims[1], height=dims[0], sections=32)
        elif kind == p.GEOM_SPHERE:
            mesh = trimesh.creation.icosphere(subdivisions=3, radius=dims[0])
        else:
            continue
        v = np.asarray(mesh.vertices)
        triangles.append(np.asarray(mesh.faces) + sum(len(x) for x in vertices))
        vertices.append(v)
    return np.concatenate(vertices), np.concatenate(triangles)


colors = np.random.default_rng(2).uniform(0.3, 1.0, (len(links), 3))
link_actors = []
for k, j in enumerate(links):
    v, f = link_geometry(j)
    link_actors.append(utils.get_actor_from_primitive(v, f.astype(int), colors=np.tile(colors[k], (len(v), 1))))


def link_frame(j):
    if j == -1:
        com_pos, com_orn = p.getBasePositionAndOrientation(robot)
        inertial_pos, inertial_orn = p.getDynamicsInfo(robot, -1)[3:5]
        return p.multiplyTransforms(com_pos, com_orn, *p.invertTransform(inertial_pos, inertial_orn))
    return p.getLinkState(robot, j, computeForwardKinematics=1)[4:6]


def sync_actors():
    for j, link_actor in zip(links, link_actors):
        pos, orn = link_frame(j)
        matrix = np.eye(4)
        matrix[:3, :3] = quaternion_matrix(orn)
        matrix[:3, 3] = pos
        user = vtkMatrix4x4()
        user.DeepCopy(matrix.ravel())
        link_actor.SetUserMatrix(user)


sync_actors()

scene = window.Scene()
scene.add(*link_actors)
scene.set_camera(position=(2.2, -2.6, 1.6), focal_point=(0.1, 0.1, 0.35), view_up=(0.0, 0.0, 1.0))
showm = window.ShowManager(scene, size=(900, 768), reset_camera=False, order_transparent=True)
showm.initialize()

counter = itertools.count()


def timer_callback(_obj, _event):
    cnt = next(counter)
    t = cnt / 240
    for j in wheels:
        speed = -12.0 if names[j].startswith("right") else -8.0
        p.setJointMotorControl2(robot, j, p.VELOCITY_CONTROL, targetVelocity=speed, force=20)
    p.setJointMotorControl2(robot, head, p.VELOCITY_CONTROL, targetVelocity=3.0, force=5)
    p.setJointMotorControl2(robot, pole, p.POSITION_CONTROL, targetPosition=-0.3 * min(t, 0.5), force=50)
    for j in fingers:
        p.setJointMotorControl2(robot, j, p.POSITION_CONTROL, targetPosition=0.4 * np.sin(6 * t), force=5)

    p.stepSimulation()

    sync_actors()

    showm.render()

    if cnt == nb_steps - 1:
        showm.exit()


showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
