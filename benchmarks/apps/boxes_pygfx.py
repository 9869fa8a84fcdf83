"""The app-mode benchmark's many-body app, FURY 2: ``BENCH_BODIES`` boxes (default 1,000) tumbling apart in
zero gravity, all drawn by one box actor (the guide's single-actor recipe), every range rewritten from its
body's pose each tick with one einsum and announced with one ``update_range``.

EXPECT: pass
"""
import itertools
import os

import numpy as np
import pybullet as p
from fury import actor, window

count = int(os.environ.get("BENCH_BODIES", "1000"))
ticks = int(os.environ.get("BENCH_TICKS", "60"))
p.connect(p.DIRECT)
p.setGravity(0, 0, 0)
rng = np.random.default_rng(0)
side = int(np.ceil(count ** (1 / 3)))
centers = np.array([(i % side, (i // side) % side, i // side ** 2) for i in range(count)], dtype=np.float64)
size = np.array([0.2, 0.4, 0.3])
shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(size / 2))
bodies = [p.createMultiBody(1, shape, basePosition=c.tolist()) for c in centers]
for body in bodies:
    p.resetBaseVelocity(body, rng.uniform(-0.2, 0.2, 3).tolist(), rng.uniform(-3, 3, 3).tolist())
boxes = actor.box(centers=centers, directions=np.tile([1.0, 0.0, 0.0], (count, 1)), scales=np.tile(size, (count, 1)),
                  colors=rng.random((count, 3)))
positions = boxes.geometry.positions
per_box = positions.data.shape[0] // count
local = positions.data.reshape(count, per_box, 3).astype(np.float64) - centers[:, None, :]
scene = window.Scene()
scene.add(boxes)
showm = window.ShowManager(scene=scene, size=(300, 300))
counter = itertools.count(1)


def timer_callback():
    p.stepSimulation()
    poses = [p.getBasePositionAndOrientation(b) for b in bodies]
    where = np.array([pose[0] for pose in poses])
    turns = np.array([p.getMatrixFromQuaternion(pose[1]) for pose in poses]).reshape(count, 3, 3)
    positions.data[:] = (np.einsum("bij,bvj->bvi", turns, local) + where[:, None, :]).reshape(-1, 3)
    positions.update_range(0, positions.data.shape[0])
    showm.render()
    if next(counter) == ticks:
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
