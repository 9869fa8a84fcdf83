"""Brick wall with one brick actor, FURY 2, WRONG: only the last brick's range is announced to the GPU.

The integration guide's "Brick Wall Simulation (Single Actor)" and its section "Rendering multiple
objects by a single actor", written for FURY 2.0 (pygfx). The ball and the base plate are whole
actors. The bricks are one ``actor.box`` of 100 boxes, 24 vertices each; FURY 2 keeps its vertices
in ``brick_actor.geometry.positions.data`` (float32, writable).

Rather than moving each range by the rotation between the previous and the current pose (the guide's
``getDifferenceQuaternion`` recipe, whose rounding adds up frame after frame), every brick's 24
vertices are captured ONCE, in the brick's own link frame, and each frame they are recomputed from
pyBullet's current pose: ``world = R(orn) @ local + pos``. The rewritten range is then announced
with ``positions.update_range(start, count)``; without it the GPU keeps drawing the old vertices.

Physics exactly as ``brick_wall.py`` (the kit's ``brick_wall_single`` scene), 131 steps.

MISTAKE: the positions.update_range(start, sec) call slipped out of the bricks' loop (one indentation level), so each frame announces only the last brick's range: every brick's vertices are right in positions.data, and the GPU keeps drawing 99 bricks where they were built
EXPECT: fail pictured stale-gpu
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

# Ball (whole actor).
ball_radius = 0.3
ball_actor = actor.sphere(centers=np.zeros((1, 3)), colors=np.array([[1.0, 0.0, 0.0]]), radii=ball_radius,
                          impostor=False)
ball_vertices = ball_actor.geometry.positions.data
ball_actor.geometry.normals = Buffer(
    (ball_vertices / np.linalg.norm(ball_vertices, axis=1, keepdims=True)).astype(np.float32))
ball_coll = p.createCollisionShape(p.GEOM_SPHERE, radius=ball_radius)
ball = p.createMultiBody(baseMass=3, baseCollisionShapeIndex=ball_coll,
                         basePosition=[2, 0, 1.5], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(ball, -1, lateralFriction=0.3, restitution=0.5)

# Base plate (whole actor, static).
base_size = np.array([5.0, 5.0, 0.2])
base_actor = actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                       scales=np.array([base_size]), colors=np.array([[1.0, 1.0, 1.0]]))
base_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(base_size / 2))
base = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=base_coll,
                         basePosition=[0, 0, -base_size[2] / 2], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(base, -1, lateralFriction=0.3, restitution=0.5)
base_actor.local.position = (0, 0, -base_size[2] / 2)

# Bricks: the guide's arrays, then one actor for all of them.
nb_rows, nb_columns = 10, 10
nb_bricks = nb_rows * nb_columns
brick_size = np.array([0.2, 0.4, 0.2])
brick_centers = np.zeros((nb_bricks, 3))
brick_orns = np.zeros((nb_bricks, 4))
brick_colors = np.random.default_rng(0).random((nb_bricks, 3))
brick_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(brick_size / 2))
bricks = np.zeros(nb_bricks, dtype=np.int64)  # body ids: int64, an int8 array would overflow
for k in range(nb_rows):
    for j in range(nb_columns):
        i = k * nb_columns + j
        brick_centers[i] = [-1.0, j * brick_size[1] - (nb_columns - 1) * brick_size[1] / 2, (k + 0.5) * brick_size[2]]
        brick_orns[i] = [0, 0, 0, 1]
        bricks[i] = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=brick_coll,
                                      basePosition=brick_centers[i].tolist(), baseOrientation=brick_orns[i].tolist())
        p.changeDynamics(int(bricks[i]), -1, lateralFriction=0.1, restitution=0.1)

brick_actor = actor.box(centers=brick_centers, directions=np.tile([1.0, 0.0, 0.0], (nb_bricks, 1)),
                        scales=np.tile(brick_size, (nb_bricks, 1)), colors=brick_colors)

vertices = brick_actor.geometry.positions.data   # (2400, 3) float32, what the GPU draws from
num_vertices = vertices.shape[0]
sec = num_vertices // nb_bricks                  # 24 vertices a brick

# Each brick's vertices in its own link frame, captured once: local = R0^T (v - c0).
brick_local = np.zeros((nb_bricks, sec, 3))
for i in range(nb_bricks):
    rot0 = np.reshape(p.getMatrixFromQuaternion(brick_orns[i].tolist()), (3, 3))
    brick_local[i] = (vertices[i * sec:(i + 1) * sec].astype(np.float64) - brick_centers[i]) @ rot0


def sync_brick(object_index, multibody):
    """Rewrite one brick's vertex range from its pose now; returns where it starts."""
    pos, orn = p.getBasePositionAndOrientation(int(multibody))
    rot_mat = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
    start = object_index * sec
    vertices[start:start + sec] = brick_local[object_index] @ rot_mat.T + pos
    return start


def sync_actor(body_actor, body):
    pos, orn = p.getBasePositionAndOrientation(body)
    body_actor.local.position = pos
    body_actor.local.rotation = orn


sync_actor(ball_actor, ball)

scene = window.Scene()
scene.add(ball_actor, base_actor, brick_actor)

window_size = (900, 768)
showm = window.ShowManager(scene=scene, size=window_size, title="FURY 2 + pyBullet: brick wall, one brick actor")


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
           view_up=(-0.27, 0.26, 0.9), view_angle=30.0, clipping_range=(0.5, 20.0), size=window_size)

counter = itertools.count()
apply_force = True


def timer_callback():
    global apply_force
    cnt = next(counter)

    if apply_force:
        ball_pos = p.getBasePositionAndOrientation(ball)[0]
        p.applyExternalForce(ball, -1, forceObj=[-10000, 0, 0], posObj=ball_pos, flags=p.WORLD_FRAME)
        apply_force = False

    p.stepSimulation()

    sync_actor(ball_actor, ball)
    for i, brick in enumerate(bricks):
        start = sync_brick(i, brick)
    brick_actor.geometry.positions.update_range(start, sec)  # meant inside the loop

    showm.render()

    if cnt == nb_steps - 1:
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
