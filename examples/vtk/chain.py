"""Chain, FURY 0.12: 20 links on spherical joints hang from a pivot that swings to and fro.

The integration guide's "Rendering Joints" section and its "Chain Simulation", written for FURY 0.12
(VTK). The 20 links are drawn by ONE cylinder actor; the tiny base box (the hinge) is a whole actor of
its own.

What is drawn is what pyBullet collides: each link's collision cylinder (radius 0.5 m, height 0.1 m)
lies along the link's z axis and is centred half a link BELOW its joint (``collisionFramePosition``
(0, 0, -0.05)). FURY 0.12 scales its unit cylinder uniformly by ``heights``, so the drawn radius is
``radius`` times the height: the actor is given ``radius=0.5 / 0.1``. The cylinder's vertices are
captured once in that link frame, offset included, and each frame they are recomputed from the link's
pose, read with ``p.getLinkState(rope, j, computeForwardKinematics=1)[4:6]``: the link frame's world
position and orientation as of the last step (without ``computeForwardKinematics`` pyBullet returns
the frame of the step before). ``utils.update_actor`` then tells VTK the points changed.

Physics as in the kit's ``chain`` scene: a 0.1 kg base pinned at (0, 0, 2) by a fixed constraint
whose pivot follows (0.9 sin(2 pi 0.6 t), 0, 2) with max force 500 N; 20 links of 0.5 kg, 0.1 m
apart; joint friction as a velocity motor (kp 0, kd 1, force 0.0005); gravity -10; 131 steps.

EXPECT: pass
"""

import itertools
import math

import numpy as np
import pybullet as p
from fury import actor, utils, window
from vtkmodules.vtkCommonMath import vtkMatrix4x4

client = p.connect(p.DIRECT)
dt = 1 / 240
p.setTimeStep(dt)
p.setGravity(0, 0, -10)

nb_steps = 131

# Link parameters (the base link is described separately).
n_links = 20
link_length = 0.1
link_radius = 0.5
link_mass = 0.5
link_offset = [0.0, 0.0, -link_length / 2]   # the collision cylinder, in the link frame
joint_friction = 0.0005
link_colors = np.random.default_rng(0).random((n_links, 3))

link_shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=link_radius, height=link_length,
                                    collisionFramePosition=link_offset, collisionFrameOrientation=[0, 0, 0, 1])

# Base: a 2 cm box.
base_half = 0.01
base_position = [0.0, 0.0, 2.0]
base_shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[base_half] * 3)

rope = p.createMultiBody(baseMass=0.1,
                         baseCollisionShapeIndex=base_shape,
                         baseVisualShapeIndex=-1,
                         basePosition=base_position,
                         baseOrientation=[0, 0, 0, 1],
                         linkMasses=[link_mass] * n_links,
                         linkCollisionShapeIndices=[link_shape] * n_links,
                         linkVisualShapeIndices=[-1] * n_links,
                         linkPositions=[[0.0, 0.0, -link_length]] * n_links,
                         linkOrientations=[[0, 0, 0, 1]] * n_links,
                         linkInertialFramePositions=[[0, 0, 0]] * n_links,
                         linkInertialFrameOrientations=[[0, 0, 0, 1]] * n_links,
                         linkParentIndices=list(range(n_links)),   # link j hangs from link j - 1 (0: the base)
                         linkJointTypes=[p.JOINT_SPHERICAL] * n_links,
                         linkJointAxis=[[1, 0, 0]] * n_links)

# Joint friction: a velocity motor with no position gain only resists joint motion.
for j in range(n_links):
    p.setJointMotorControlMultiDof(rope, j, p.POSITION_CONTROL, targetPosition=[0, 0, 0, 1],
                                   targetVelocity=[0, 0, 0], positionGain=0, velocityGain=1,
                                   force=[joint_friction] * 3)

# The pin holding the base; its pivot is moved before every step.
pivot_centre = (0.0, 0.0, 2.0)
pivot_amplitude = (0.9, 0.0, 0.0)
pivot_frequency = 0.6
root = p.createConstraint(rope, -1, -1, -1, p.JOINT_FIXED, [0, 0, 0], [0, 0, 0], base_position)

# Actors: the hinge box, and one cylinder actor for all the links (built along z at the origin).
base_actor = actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                       scales=np.array([[2 * base_half] * 3]), colors=np.array([[1.0, 0.0, 0.0]]))
rope_actor = actor.cylinder(centers=np.zeros((n_links, 3)), directions=np.tile([0.0, 0.0, 1.0], (n_links, 1)),
                            colors=link_colors, radius=link_radius / link_length, heights=link_length,
                            capped=True, resolution=16)

vertices = utils.vertices_from_actor(rope_actor)   # a writable view of VTK's points
sec = vertices.shape[0] // n_links                 # vertices a link

# Each link's cylinder in its link frame, captured once: the canonical cylinder moved by the offset.
link_local = [vertices[j * sec:(j + 1) * sec].astype(np.float64) + link_offset for j in range(n_links)]


def sync_base():
    pos, orn = p.getBasePositionAndOrientation(rope)   # the base's inertial frame is its link frame
    matrix = np.eye(4)
    matrix[:3, :3] = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
    matrix[:3, 3] = pos
    user = vtkMatrix4x4()
    user.DeepCopy(matrix.ravel())
    base_actor.SetUserMatrix(user)


def sync_joints():
    for j in range(n_links):
        pos, orn = p.getLinkState(rope, j, computeForwardKinematics=1)[4:6]
        rot_mat = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
        vertices[j * sec:(j + 1) * sec] = link_local[j] @ rot_mat.T + pos
    utils.update_actor(rope_actor)


sync_base()
sync_joints()

scene = window.Scene()
scene.add(base_actor, rope_actor)
scene.set_camera(position=(3.9, -4.93, 4.17), focal_point=(0.47, 0.0, 1.02), view_up=(-0.2, 0.2, 1.0))
showm = window.ShowManager(scene, size=(900, 768), reset_camera=False, order_transparent=True)
showm.initialize()

counter = itertools.count()


def timer_callback(_obj, _event):
    cnt = next(counter)

    # Move the pivot to where it is at the end of this step.
    s = math.sin(2 * math.pi * pivot_frequency * (cnt + 1) * dt)
    pivot = [c + a * s for c, a in zip(pivot_centre, pivot_amplitude)]
    p.changeConstraint(root, pivot, jointChildFrameOrientation=[0, 0, 0, 1], maxForce=500)

    p.stepSimulation()

    sync_base()
    sync_joints()

    showm.render()
    if cnt == nb_steps - 1:
        showm.exit()


showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
