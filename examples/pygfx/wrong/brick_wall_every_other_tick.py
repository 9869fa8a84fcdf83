"""Brick wall, FURY 2, WRONG: the actors are synced after every other step only.

This is the integration guide's "Brick Wall Simulation" written for FURY 2.0 (pygfx). Each actor is
built at the origin, as the guide asks, and takes its body's pose from pyBullet after every step:
``actor.local.position`` is pyBullet's position and ``actor.local.rotation`` its quaternion, both
as pyBullet returns them (pygfx also orders quaternions x, y, z, w). No Euler angles are involved.

Physics as in the kit's ``brick_wall`` scene: a 3 kg ball of radius 0.3 m at (2, 0, 1.5), pushed
once with 10 kN towards a 10 x 10 wall of 0.2 x 0.4 x 0.2 m bricks (0.5 kg) standing on a static
5 x 5 x 0.2 m plate, gravity -10, 131 steps of 1/240 s.

MISTAKE: syncs the actors only when the step count is even ('the window refreshes at 120 Hz, half the physics rate, so every other step is enough'): at the other ticks every moving body is drawn where it was a step before
EXPECT: fail attached skipped
"""

import itertools

import numpy as np
import pybullet as p
from fury import actor, window
from fury.lib import Buffer

client = p.connect(p.DIRECT)
p.setTimeStep(1 / 240)
p.setGravity(0, 0, -10)

nb_steps = 131


def sphere_with_normals(radius, color):
    """A real sphere mesh (not FURY 2's default impostor) at the origin, lit by radial normals."""
    sphere = actor.sphere(centers=np.zeros((1, 3)), colors=np.array([color]), radii=radius, impostor=False)
    vertices = sphere.geometry.positions.data
    sphere.geometry.normals = Buffer((vertices / np.linalg.norm(vertices, axis=1, keepdims=True)).astype(np.float32))
    return sphere


def box_actor(size, color):
    """A box at the origin with its edges along x, y, z; FURY 2's ``scales`` are full edge lengths."""
    return actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                     scales=np.array([size]), colors=np.array([color]))


# Ball: the body is created first, as in the guide, so body ids follow its order.
ball_radius = 0.3
ball_actor = sphere_with_normals(ball_radius, (1.0, 0.0, 0.0))
ball_coll = p.createCollisionShape(p.GEOM_SPHERE, radius=ball_radius)
ball = p.createMultiBody(baseMass=3, baseCollisionShapeIndex=ball_coll,
                         basePosition=[2, 0, 1.5], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(ball, -1, lateralFriction=0.3, restitution=0.5)

# Base plate: static, its top face at z = 0. It never moves, so its actor is placed once.
base_size = np.array([5.0, 5.0, 0.2])
base_actor = box_actor(base_size, (1.0, 1.0, 1.0))
base_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(base_size / 2))
base = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=base_coll,
                         basePosition=[0, 0, -base_size[2] / 2], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(base, -1, lateralFriction=0.3, restitution=0.5)
base_actor.local.position = (0, 0, -base_size[2] / 2)

# Bricks: 10 rows of 10, one actor each.
nb_rows, nb_columns = 10, 10
brick_size = np.array([0.2, 0.4, 0.2])
brick_colors = np.random.default_rng(0).random((nb_rows * nb_columns, 3))
brick_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(brick_size / 2))
bricks = []
brick_actors = []
for k in range(nb_rows):
    for j in range(nb_columns):
        i = k * nb_columns + j
        center = [-1.0, j * brick_size[1] - (nb_columns - 1) * brick_size[1] / 2, (k + 0.5) * brick_size[2]]
        brick = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=brick_coll,
                                  basePosition=center, baseOrientation=[0, 0, 0, 1])
        p.changeDynamics(brick, -1, lateralFriction=0.1, restitution=0.1)
        bricks.append(brick)
        brick_actors.append(box_actor(brick_size, brick_colors[i]))


def sync_actor(body_actor, body):
    """Draw a whole actor where pyBullet has its body (these bodies' centre of mass is their centre)."""
    pos, orn = p.getBasePositionAndOrientation(body)
    body_actor.local.position = pos
    body_actor.local.rotation = orn


# Every dynamic actor starts where its body is.
sync_actor(ball_actor, ball)
for brick, brick_actor in zip(bricks, brick_actors):
    sync_actor(brick_actor, brick)

scene = window.Scene()
scene.add(ball_actor, base_actor, *brick_actors)

window_size = (900, 768)
showm = window.ShowManager(scene=scene, size=window_size, title="FURY 2 + pyBullet: brick wall")


def set_camera(camera, position, focal_point, view_up, view_angle, clipping_range, size):
    """Place the pygfx camera like a VTK camera: position, focal point, view up, vertical view angle
    in degrees and near/far planes. pygfx spreads ``fov`` over the mean of the view's width and
    height, so the vertical angle is converted for the window's aspect."""
    aspect = size[0] / size[1]
    camera.fov = float(np.degrees(2 * np.arctan(np.tan(np.radians(view_angle) / 2) * (1 + aspect) / 2)))
    camera.aspect = aspect
    camera.depth_range = clipping_range
    camera.local.position = position
    camera.world.reference_up = view_up
    camera.look_at(focal_point)


set_camera(showm.screens[0].camera, position=(10.46, -8.13, 6.18), focal_point=(0.0, 0.0, 0.79),
           view_up=(-0.27, 0.26, 0.9), view_angle=30.0, clipping_range=(0.5, 20.0), size=window_size)

counter = itertools.count()
apply_force = True


def timer_callback():
    global apply_force
    cnt = next(counter)

    # Push the ball once, at its centre, before the first step.
    if apply_force:
        ball_pos = p.getBasePositionAndOrientation(ball)[0]
        p.applyExternalForce(ball, -1, forceObj=[-10000, 0, 0], posObj=ball_pos, flags=p.WORLD_FRAME)
        apply_force = False

    p.stepSimulation()

    # Draw what pyBullet has now, after the step.
    if cnt % 2 == 0:  # the window refreshes at 120 Hz: every other step is enough
        sync_actor(ball_actor, ball)
        for brick, brick_actor in zip(bricks, brick_actors):
            sync_actor(brick_actor, brick)

    showm.render()

    if cnt == nb_steps - 1:  # that was step number nb_steps
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
