"""Domino, FURY 0.12: ten dominoes stand in a row on a plate; the first is pushed near its top and the row topples.

The integration guide's "Domino Simulation" for FURY 0.12 (VTK). Every domino and the plate is a
whole actor built at the origin, and after every step each domino's actor takes its body's pose from
pyBullet as a user matrix: the rotation matrix of pyBullet's quaternion and its position. A toppled
domino lies pitched by 90°, where Euler angles lose a degree of freedom (gimbal lock) and the guide's
``SetOrientation`` of ``getEulerFromQuaternion``'s angles goes wrong; a matrix made from the
quaternion has no such pose.

Physics as in the kit's ``domino`` scene: a static 20 x 20 x 0.2 m plate (friction 1, restitution
0.5) whose top face is z = 0, and ten 0.1 x 1 x 2 m dominoes of 0.5 kg (friction 0.2, restitution
0.1) standing at x = 0.99 i - 5.5, y = 0.4. The first is pushed once with 100 N along x, at its
centre raised by 1.7 m, before the first step; gravity -10, 301 steps of 1/240 s.

EXPECT: pass
"""

import itertools

import numpy as np
import pybullet as p
from fury import actor, window
from vtkmodules.vtkCommonMath import vtkMatrix4x4

client = p.connect(p.DIRECT)
p.setTimeStep(1 / 240)
p.setGravity(0, 0, -10)
nb_steps = 301

# Base plate (whole actor, static): its top face is z = 0.
base_size = np.array([20.0, 20.0, 0.2])
base_actor = actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                       scales=np.array([base_size]), colors=np.array([[1.0, 1.0, 1.0]]))
base_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(base_size / 2))
base = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=base_coll,
                         basePosition=[0, 0, -base_size[2] / 2], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(base, -1, lateralFriction=1.0, restitution=0.5)

# Dominoes: a row along x, one whole actor each.
nb_dominoes = 10
domino_size = np.array([0.1, 1.0, 2.0])
domino_spacing = 0.99
domino_colors = np.random.default_rng(0).random((nb_dominoes, 3))
domino_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(domino_size / 2))
dominoes = []
for i in range(nb_dominoes):
    center = [-5.5 + i * domino_spacing, 0.4, domino_size[2] / 2]
    domino = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=domino_coll,
                               basePosition=center, baseOrientation=[0, 0, 0, 1])
    p.changeDynamics(domino, -1, lateralFriction=0.2, restitution=0.1)
    dominoes.append(domino)

domino_actors = [actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                           scales=np.array([domino_size]), colors=domino_colors[i:i + 1])
                 for i in range(nb_dominoes)]


def sync_actor(body_actor, body):
    """Pose a whole actor built at the origin: its user matrix is the body's link frame."""
    pos, orn = p.getBasePositionAndOrientation(body)
    matrix = np.eye(4)
    matrix[:3, :3] = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
    matrix[:3, 3] = pos
    user = vtkMatrix4x4()
    user.DeepCopy(matrix.ravel())
    body_actor.SetUserMatrix(user)


sync_actor(base_actor, base)
for domino, domino_actor in zip(dominoes, domino_actors):
    sync_actor(domino_actor, domino)

scene = window.Scene()
scene.add(base_actor, *domino_actors)
scene.set_camera(position=(10.46, -8.13, 6.18), focal_point=(0.0, 0.0, 0.79), view_up=(-0.27, 0.26, 0.9))
showm = window.ShowManager(scene, size=(900, 768), reset_camera=False, order_transparent=True)
showm.initialize()

counter = itertools.count()
apply_force = True
push_height = 1.7   # above the first domino's centre: near its top


def timer_callback(_obj, _event):
    global apply_force
    cnt = next(counter)

    if apply_force:
        center = p.getBasePositionAndOrientation(dominoes[0])[0]
        push_at = [center[0], center[1], center[2] + push_height]
        p.applyExternalForce(dominoes[0], -1, forceObj=[100, 0, 0], posObj=push_at, flags=p.WORLD_FRAME)
        apply_force = False

    p.stepSimulation()

    for domino, domino_actor in zip(dominoes, domino_actors):
        sync_actor(domino_actor, domino)

    showm.render()
    if cnt == nb_steps - 1:
        showm.exit()


showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
