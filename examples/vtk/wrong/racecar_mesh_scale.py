"""Racecar, FURY 0.12, WRONG: the meshes are drawn without the scale the URDF gives them.

A wheeled robot as users load it: a chassis, steering hinges, four wheels, a laser and cameras, and two
differentials whose gears are meshes modelled in millimetres, which the URDF scales by 0.001 (and one
ring by 0.0005 x 0.0005 x 0.001). Each link is one actor built from the link's visual shapes as pyBullet
holds them (``getVisualShapeData``: the kind and dimensions, a mesh's file and scale, and the shape's
frame in the link frame), meshes read with trimesh and scaled, each moved once by its visual frame.
After every step each actor is placed at its link frame: ``getLinkState(car, j,
computeForwardKinematics=1)[4:6]`` for a link, and for the base ``getBasePositionAndOrientation`` with
its centre-of-mass offset undone (``getDynamicsInfo(car, -1)[3:5]``).

Velocity motors turn the wheels and the differentials' side gears, the steering hinges swing to and
fro; on ``plane.urdf``, gravity -10, 1/240 s, 150 steps.

MISTAKE: reads each mesh file and leaves out getVisualShapeData's scale (the URDF's <mesh scale="0.001 0.001 0.001">), so the differentials' gears, modelled in millimetres, are drawn a thousand times too large
EXPECT: fail placed scaled
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
car = p.loadURDF("racecar/racecar_differential.urdf", [0, 0, 0.1])
drawn = {shape[1] for shape in p.getVisualShapeData(car)}   # the camera frames have no visual shape
links = [j for j in range(-1, p.getNumJoints(car)) if j in drawn]
names = {j: p.getJointInfo(car, j)[12].decode() for j in range(p.getNumJoints(car))}
turning = [j for j in range(p.getNumJoints(car)) if p.getJointInfo(car, j)[2] == p.JOINT_REVOLUTE]
steering = [j for j in turning if "steering" in names[j]]
spinning = [j for j in turning if j not in steering]


def quaternion_matrix(q):
    return np.reshape(p.getMatrixFromQuaternion(q), (3, 3))


def link_geometry(j):
    """The link's visual shapes as one triangle mesh, in its link frame."""
    vertices, triangles = [], []
    for shape in p.getVisualShapeData(car):
        if shape[1] != j:
            continue
        kind, dims, path, local_pos, local_orn = shape[2], shape[3], shape[4], shape[5], shape[6]
        if kind == p.GEOM_MESH:
            mesh = trimesh.load(path.decode(), force="mesh")
        elif kind == p.GEOM_BOX:
            mesh = trimesh.creation.box(extents=dims)
        elif kind == p.GEOM_CYLINDER:
            mesh = trimesh.creation.cylinder(radius=dims[1], height=dims[0], sections=32)
        elif kind == p.GEOM_SPHERE:
            mesh = trimesh.creation.icosphere(subdivisions=3, radius=dims[0])
        else:
            continue
        v = np.asarray(mesh.vertices) @ quaternion_matrix(local_orn).T + local_pos
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
        com_pos, com_orn = p.getBasePositionAndOrientation(car)
        inertial_pos, inertial_orn = p.getDynamicsInfo(car, -1)[3:5]
        return p.multiplyTransforms(com_pos, com_orn, *p.invertTransform(inertial_pos, inertial_orn))
    return p.getLinkState(car, j, computeForwardKinematics=1)[4:6]


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
scene.set_camera(position=(1.1, -1.3, 0.8), focal_point=(-0.2, 0.0, 0.05), view_up=(0.0, 0.0, 1.0))
showm = window.ShowManager(scene, size=(900, 768), reset_camera=False, order_transparent=True)
showm.initialize()

counter = itertools.count()


def timer_callback(_obj, _event):
    cnt = next(counter)
    t = cnt / 240
    for j in spinning:
        p.setJointMotorControl2(car, j, p.VELOCITY_CONTROL, targetVelocity=-20.0, force=10)
    for j in steering:
        p.setJointMotorControl2(car, j, p.POSITION_CONTROL, targetPosition=0.4 * np.sin(4 * t), force=10)

    p.stepSimulation()

    sync_actors()

    showm.render()

    if cnt == nb_steps - 1:
        showm.exit()


showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
