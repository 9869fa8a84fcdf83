"""Domino, FURY 2: ten dominoes stand in a row on a plate; the first is pushed near its top and the row topples.

This is the integration guide's "Domino Simulation" written for FURY 2.0 (pygfx). Every domino and the
plate is a whole actor built at the origin; after every step each domino's actor takes its body's
pose from pyBullet: ``actor.local.position`` is pyBullet's position and ``actor.local.rotation`` its
quaternion, both as pyBullet returns them (pygfx also orders quaternions x, y, z, w). A toppled domino
lies pitched by 90°, the gimbal lock the guide warns of for Euler angles; a quaternion has none.

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

client = p.connect(p.DIRECT)
p.setTimeStep(1 / 240)
p.setGravity(0, 0, -10)

nb_steps = 301


def box_actor(size, color):
    """A box at the origin with its edges along x, y, z; FURY 2's ``scales`` are full edge lengths."""
    return actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                     scales=np.array([size]), colors=np.array([color]))


# Base plate: static, its top face at z = 0. It never moves, so its actor is placed once.
base_size = np.array([20.0, 20.0, 0.2])
base_actor = box_actor(base_size, (1.0, 1.0, 1.0))
base_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(base_size / 2))
base = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=base_coll,
                         basePosition=[0, 0, -base_size[2] / 2], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(base, -1, lateralFriction=1.0, restitution=0.5)
base_actor.local.position = (0, 0, -base_size[2] / 2)

# Dominoes: a row along x, one whole actor each.
nb_dominoes = 10
domino_size = np.array([0.1, 1.0, 2.0])
domino_spacing = 0.99
domino_colors = np.random.default_rng(0).random((nb_dominoes, 3))
domino_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(domino_size / 2))
dominoes = []
domino_actors = []
for i in range(nb_dominoes):
    center = [-5.5 + i * domino_spacing, 0.4, domino_size[2] / 2]
    domino = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=domino_coll,
                               basePosition=center, baseOrientation=[0, 0, 0, 1])
    p.changeDynamics(domino, -1, lateralFriction=0.2, restitution=0.1)
    dominoes.append(domino)
    domino_actors.append(box_actor(domino_size, domino_colors[i]))


def sync_actor(body_actor, body):
    """Draw a whole actor where pyBullet has its body (a domino's centre of mass is its centre)."""
    pos, orn = p.getBasePositionAndOrientation(body)
    body_actor.local.position = pos
    body_actor.local.rotation = orn


# Every domino's actor starts where its body is.
for domino, domino_actor in zip(dominoes, domino_actors):
    sync_actor(domino_actor, domino)

scene = window.Scene()
scene.add(base_actor, *domino_actors)

window_size = (900, 768)
showm = window.ShowManager(scene=scene, size=window_size, title="FURY 2 + pyBullet: domino")


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


set_camera(showm.screens[0].camera, position=(10.46, -8.13, 6.18), focal_point=(0.0, 0.0, 0.79),
           view_up=(-0.27, 0.26, 0.9), view_angle=30.0, clipping_range=(0.5, 31.0), size=window_size)

counter = itertools.count()
apply_force = True
push_height = 1.7   # above the first domino's centre: near its top


def timer_callback():
    global apply_force
    cnt = next(counter)

    # Push the first domino once, near its top, before the first step.
    if apply_force:
        center = p.getBasePositionAndOrientation(dominoes[0])[0]
        push_at = [center[0], center[1], center[2] + push_height]
        p.applyExternalForce(dominoes[0], -1, forceObj=[100, 0, 0], posObj=push_at, flags=p.WORLD_FRAME)
        apply_force = False

    p.stepSimulation()

    # Draw what pyBullet has now, after the step.
    for domino, domino_actor in zip(dominoes, domino_actors):
        sync_actor(domino_actor, domino)

    showm.render()

    if cnt == nb_steps - 1:  # that was step number nb_steps
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
