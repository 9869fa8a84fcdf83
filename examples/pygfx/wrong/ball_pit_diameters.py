"""Ball pit, FURY 2, WRONG: the balls are drawn twice their size (diameters given as radii).

``actor.sphere(centers, radii=...)`` in FURY 2.0 draws impostor spheres by default (``impostor=True``):
each sphere is six vertices at its centre, two triangles that a shader turns into a camera-facing quad
and shades as a sphere of the given radius. So one actor draws all the balls, and the sync moves each
ball's six vertices to its centre after every step and announces them with ``update_range``. A ball
turns, but an impostor sphere of one colour looks the same in every orientation: only the centre is
drawn, and that is what pyBullet's pose gives (a sphere's link frame is its centre).

Physics: a static floor and four walls (boxes), balls of radius 0.12-0.2 m and 0.3 kg dropped from
0.6-1.8 m with a little sideways speed, restitution 0.5; gravity -10, 1/240 s, 180 steps. The floor and
walls are drawn by one box actor that never moves.

MISTAKE: gives actor.sphere the balls' diameters (2 r) as its radii, so every ball is drawn twice the size of the sphere pyBullet simulates
EXPECT: fail placed scaled
"""

import itertools

import numpy as np
import pybullet as p
from fury import actor, window

client = p.connect(p.DIRECT)
p.setTimeStep(1 / 240)
p.setGravity(0, 0, -10)
nb_steps = 180
rng = np.random.default_rng(7)

# The pit: a floor 2 m x 2 m and four walls 0.4 m high, all static.
half_extents = [[1.0, 1.0, 0.05], [0.05, 1.0, 0.2], [0.05, 1.0, 0.2], [1.0, 0.05, 0.2], [1.0, 0.05, 0.2]]
centres = [[0, 0, -0.05], [-1.05, 0, 0.2], [1.05, 0, 0.2], [0, -1.05, 0.2], [0, 1.05, 0.2]]
for half, centre in zip(half_extents, centres):
    p.createMultiBody(0, p.createCollisionShape(p.GEOM_BOX, halfExtents=half), basePosition=centre)
pit_actor = actor.box(centers=np.array(centres), scales=2 * np.array(half_extents),
                      colors=np.tile([0.55, 0.5, 0.45], (len(centres), 1)))

n_balls = 12
radii = rng.uniform(0.12, 0.2, n_balls)
starts = np.column_stack([rng.uniform(-0.7, 0.7, n_balls), rng.uniform(-0.7, 0.7, n_balls),
                          rng.uniform(0.6, 1.8, n_balls)])
balls = []
for radius, start in zip(radii, starts):
    ball = p.createMultiBody(0.3, p.createCollisionShape(p.GEOM_SPHERE, radius=radius), basePosition=list(start))
    p.changeDynamics(ball, -1, restitution=0.5)
    p.resetBaseVelocity(ball, [*rng.uniform(-0.5, 0.5, 2), 0.0])
    balls.append(ball)

# FURY 2's default sphere: an impostor, six vertices a ball at its centre.
diameters = 2 * radii
ball_actor = actor.sphere(centers=starts, colors=rng.uniform(0.2, 1.0, (n_balls, 3)), radii=diameters)
positions = ball_actor.geometry.positions
per_ball = len(positions.data) // n_balls


def sync_balls():
    for i, ball in enumerate(balls):
        pos, _ = p.getBasePositionAndOrientation(ball)
        positions.data[i * per_ball:(i + 1) * per_ball] = pos
    positions.update_range(0, n_balls * per_ball)


sync_balls()

scene = window.Scene()
scene.add(pit_actor, ball_actor)
showm = window.ShowManager(scene=scene, size=(900, 768), title="FURY 2 + pyBullet: ball pit")
camera = showm.screens[0].camera
camera.local.position = (2.4, -3.2, 2.6)
camera.world.reference_up = (0.0, 0.0, 1.0)
camera.look_at((0.0, 0.0, 0.3))

counter = itertools.count()


def timer_callback():
    cnt = next(counter)
    p.stepSimulation()
    sync_balls()
    showm.render()
    if cnt == nb_steps - 1:
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
