"""Brick wall, FURY 0.12, WRONG: the actors are synced after every other step only.

The integration guide's "Brick Wall Simulation" for FURY 0.12 (VTK). Each actor is built at the
origin, as the guide asks, and takes its body's pose from pyBullet after every step as a user matrix:
the rotation matrix of pyBullet's quaternion and its position. (The guide's ``SetOrientation`` of
``getEulerFromQuaternion``'s angles turns bodies wrongly: VTK composes its angles Z, X, Y, pyBullet's
mean Z, Y, X; see ``wrong/brick_wall_euler_angles.py``.)

Physics as in the kit's ``brick_wall`` scene: a 3 kg ball of radius 0.3 m at (2, 0, 1.5), pushed
once with 10 kN towards a 10 x 10 wall of 0.2 x 0.4 x 0.2 m bricks (0.5 kg) on a static 5 x 5 x 0.2 m
plate, gravity -10, 131 steps of 1/240 s.

MISTAKE: syncs the actors only when the step count is even ('the window refreshes at 120 Hz, half the physics rate, so every other step is enough'): at the other ticks every moving body is drawn where it was a step before
EXPECT: fail attached skipped
"""

import itertools

import numpy as np
import pybullet as p
from fury import actor, window
from vtkmodules.vtkCommonMath import vtkMatrix4x4

client = p.connect(p.DIRECT)
p.setTimeStep(1 / 240)
p.setGravity(0, 0, -10)
nb_steps = 131

# Ball (whole actor).
ball_radius = 0.3
ball_actor = actor.sphere(centers=np.zeros((1, 3)), colors=np.array([[1.0, 0.0, 0.0]]), radii=ball_radius)
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

brick_actors = [actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                          scales=np.array([brick_size]), colors=brick_colors[i:i + 1]) for i in range(nb_bricks)]


def sync_actor(body_actor, body):
    """Pose a whole actor built at the origin: its user matrix is the body's link frame."""
    pos, orn = p.getBasePositionAndOrientation(body)
    matrix = np.eye(4)
    matrix[:3, :3] = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
    matrix[:3, 3] = pos
    user = vtkMatrix4x4()
    user.DeepCopy(matrix.ravel())
    body_actor.SetUserMatrix(user)


sync_actor(ball_actor, ball)
sync_actor(base_actor, base)
for brick, brick_actor in zip(bricks, brick_actors):
    sync_actor(brick_actor, int(brick))

scene = window.Scene()
scene.add(ball_actor, base_actor, *brick_actors)
scene.set_camera(position=(10.46, -8.13, 6.18), focal_point=(0.0, 0.0, 0.79), view_up=(-0.27, 0.26, 0.9))
showm = window.ShowManager(scene, size=(900, 768), reset_camera=False, order_transparent=True)
showm.initialize()

counter = itertools.count()
apply_force = True


def timer_callback(_obj, _event):
    global apply_force
    cnt = next(counter)

    if apply_force:
        ball_pos = p.getBasePositionAndOrientation(ball)[0]
        p.applyExternalForce(ball, -1, forceObj=[-10000, 0, 0], posObj=ball_pos, flags=p.WORLD_FRAME)
        apply_force = False

    p.stepSimulation()

    if cnt % 2 == 0:  # the window refreshes at 120 Hz: every other step is enough
        sync_actor(ball_actor, ball)
        for brick, brick_actor in zip(bricks, brick_actors):
            sync_actor(brick_actor, int(brick))

    showm.render()
    if cnt == nb_steps - 1:
        showm.exit()


showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
