"""Chain, FURY 2, WRONG: links read with getLinkState without forward kinematics.

The integration guide's "Rendering Joints" section and its "Chain Simulation", written for FURY 2.0
(pygfx). The 20 links are drawn by ONE cylinder actor, 68 vertices a link; the tiny base box (the
hinge) is a whole actor of its own.

What is drawn is what pyBullet collides: each link's collision cylinder (radius 0.5 m, height 0.1 m)
lies along the link's z axis and is centred half a link BELOW its joint (``collisionFramePosition``
(0, 0, -0.05)). The cylinder's vertices are captured once in that link frame, offset included, and
each frame they are recomputed from the link's pose, read with
``p.getLinkState(rope, j)[4:6]``: the link frame's world position and
orientation as of the last step (without ``computeForwardKinematics`` pyBullet returns the frame
of the step before). The rewritten vertices are announced with ``positions.update_full()``.

Physics as in the kit's ``chain`` scene: a 0.1 kg base pinned at (0, 0, 2) by a fixed constraint
whose pivot follows (0.9 sin(2 pi 0.6 t), 0, 2) with max force 500 N; 20 links of 0.5 kg, 0.1 m
apart; joint friction as a velocity motor (kp 0, kd 1, force 0.0005); gravity -10; 131 steps.

MISTAKE: reads p.getLinkState(rope, j)[4:6] without computeForwardKinematics=1, as the guide's sync_joints does, so each link is drawn where it was before the last step
EXPECT: fail attached previous-step
"""

import itertools
import math

import numpy as np
import pybullet as p
from fury import actor, window

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
                            colors=link_colors, radii=link_radius, height=link_length, sectors=16, capped=True)

vertices = rope_actor.geometry.positions.data
sec = vertices.shape[0] // n_links   # vertices a link

# Each link's cylinder in its link frame, captured once: the canonical cylinder moved by the offset.
link_local = [vertices[j * sec:(j + 1) * sec].astype(np.float64) + link_offset for j in range(n_links)]


def sync_base():
    pos, orn = p.getBasePositionAndOrientation(rope)   # the base's inertial frame is its link frame
    base_actor.local.position = pos
    base_actor.local.rotation = orn


def sync_joints():
    for j in range(n_links):
        pos, orn = p.getLinkState(rope, j)[4:6]
        rot_mat = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
        vertices[j * sec:(j + 1) * sec] = link_local[j] @ rot_mat.T + pos
    rope_actor.geometry.positions.update_full()


sync_base()
sync_joints()

scene = window.Scene()
scene.add(base_actor, rope_actor)

window_size = (900, 768)
showm = window.ShowManager(scene=scene, size=window_size, title="FURY 2 + pyBullet: chain")


def set_camera(camera, position, focal_point, view_up, view_angle, clipping_range, size):
    """Place the pygfx camera like a VTK camera (vertical view angle in degrees, near/far planes).
    pygfx spreads ``fov`` over the mean of width and height, hence the conversion."""
    aspect = size[0] / size[1]
    camera.fov = float(np.degrees(2 * np.arctan(np.tan(np.radians(view_angle) / 2) * (1 + aspect) / 2)))
    camera.aspect = aspect
    camera.depth_range = clipping_range
    camera.local.position = position
    camera.world.reference_up = view_up
    camera.look_at(focal_point)


set_camera(showm.screens[0].camera, position=(3.9, -4.93, 4.17), focal_point=(0.47, 0.0, 1.02),
           view_up=(-0.2, 0.2, 1.0), view_angle=30.0, clipping_range=(0.5, 9.0), size=window_size)

counter = itertools.count()


def timer_callback():
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
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
