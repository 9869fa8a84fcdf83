"""R2-D2, FURY 2, WRONG: only the links on moving joints are synced; the welded links stay where they were built.

A robot as users load it: ``p.loadURDF("r2d2.urdf")`` from ``pybullet_data``, with its fixed joints kept
(legs and wheel bases welded to the body, finger tips to the fingers, the box on the head), so six of
its 15 links never move relative to their parent. Each link is one actor built from the link's
collision shapes, as pyBullet holds them, in the link's centre-of-mass frame: boxes and the head's
sphere from ``getCollisionShapeData`` (dimensions, and the shape's frame relative to the centre of
mass), the cylinders and finger meshes (which pyBullet keeps as convex meshes) from
``getMeshData``'s vertices (already in that frame), closed by their convex hull. After every step each
actor's ``local.position`` and ``local.rotation`` (pyBullet's x, y, z, w quaternion as it is) are its
link's centre-of-mass pose: ``getBasePositionAndOrientation`` for the base,
``getLinkState(robot, j, computeForwardKinematics=1)[0:2]`` for a link.

The wheels turn on velocity motors (the right pair faster, so it arcs), the head swivels, the gripper
pole slides out and the fingers open and close; gravity -10, 1/240 s, 150 steps, on ``plane.urdf``.

MISTAKE: syncs the base and the links whose joint moves (getJointInfo's type is not JOINT_FIXED), as if a welded link followed its parent by itself: the legs, wheel bases, finger tips and the head's box stay where they were first placed
EXPECT: fail drawn never-moved
"""

import itertools

import numpy as np
import pybullet as p
import pybullet_data
from fury import actor, primitive, window
from scipy.spatial import ConvexHull

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
    """The link's collision shapes as one triangle mesh, in its centre-of-mass frame."""
    vertices, triangles = [], []
    mesh_vertices = p.getMeshData(robot, j)[1] if p.getMeshData(robot, j)[0] else []
    for shape in p.getCollisionShapeData(robot, j):
        kind, dims, local_pos, local_orn = shape[2], shape[3], shape[5], shape[6]
        if kind == p.GEOM_BOX:
            v, f = primitive.prim_box()
            v = v * np.asarray(dims)                      # a unit cube, scaled to the box's full extents
        elif kind == p.GEOM_SPHERE:
            v, f = primitive.prim_sphere(name="repulsion724")
            v = v * dims[0] / np.linalg.norm(v, axis=1).max()
        elif kind == p.GEOM_MESH and len(mesh_vertices):
            v = np.asarray(mesh_vertices, dtype=float)    # getMeshData: already in the centre-of-mass frame
            hull = ConvexHull(v)
            v, f = v[hull.vertices], np.searchsorted(hull.vertices, hull.simplices)
            local_pos, local_orn = (0, 0, 0), (0, 0, 0, 1)
        else:
            continue
        v = v @ quaternion_matrix(local_orn).T + local_pos
        triangles.append(f + sum(len(x) for x in vertices))
        vertices.append(v)
    return np.concatenate(vertices), np.concatenate(triangles)


colors = np.random.default_rng(2).uniform(0.3, 1.0, (len(links), 3))
link_actors = []
for k, j in enumerate(links):
    v, f = link_geometry(j)
    link_actors.append(actor.surface(v.astype(np.float32), f.astype(np.int32), colors=np.tile(colors[k], (len(v), 1)).astype(np.float32)))


def centre_of_mass_pose(j):
    if j == -1:
        return p.getBasePositionAndOrientation(robot)
    return p.getLinkState(robot, j, computeForwardKinematics=1)[0:2]


moving = [j for j in links if j == -1 or p.getJointInfo(robot, j)[2] != p.JOINT_FIXED]


def sync_actors(which=moving):
    for j, link_actor in zip(links, link_actors):
        if j not in which:
            continue
        pos, orn = centre_of_mass_pose(j)
        link_actor.local.position = pos
        link_actor.local.rotation = orn


sync_actors(links)   # every link placed once, at the start

scene = window.Scene()
scene.add(*link_actors)
window_size = (900, 768)
showm = window.ShowManager(scene=scene, size=window_size, title="FURY 2 + pyBullet: R2-D2")
camera = showm.screens[0].camera
camera.local.position = (2.2, -2.6, 1.6)
camera.world.reference_up = (0.0, 0.0, 1.0)
camera.look_at((0.1, 0.1, 0.35))

counter = itertools.count()


def timer_callback():
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
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
