"""A small right app (FURY 2): two tumbling balls as vertex ranges of ONE sphere actor, their normals
turned with them and both buffers announced range by range (tests/test_app_mode.py copies it wrong).

EXPECT: pass
"""
import itertools
import numpy as np
import pybullet as p
from fury import actor, window
from fury.lib import Buffer

p.connect(p.DIRECT)
p.setGravity(0, 0, -10)
starts = np.array([[-0.5, 0.0, 2.0], [0.5, 0.0, 2.5]])
balls = actor.sphere(centers=starts, colors=np.array([[1, 0, 0], [0, 0, 1]]), radii=0.2, impostor=False)
vertices = balls.geometry.positions.data
sec = len(vertices) // 2
local = [vertices[i * sec:(i + 1) * sec].astype(np.float64) - starts[i] for i in range(2)]
balls.geometry.normals = Buffer((np.concatenate(local) / 0.2).astype(np.float32))
normals = balls.geometry.normals.data
shape = p.createCollisionShape(p.GEOM_SPHERE, radius=0.2)
bodies = [p.createMultiBody(1, shape, basePosition=list(c)) for c in starts]
for b, spin in zip(bodies, ([1, 2, 3], [-3, 1, 2])):
    p.resetBaseVelocity(b, [0.3, 0, 0], spin)
scene = window.Scene()
scene.add(balls)
showm = window.ShowManager(scene=scene, size=(300, 300))
counter = itertools.count()

def timer_callback():
    cnt = next(counter)
    p.stepSimulation()
    for i, b in enumerate(bodies):
        pos, orn = p.getBasePositionAndOrientation(b)
        rot = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
        vertices[i * sec:(i + 1) * sec] = local[i] @ rot.T + pos
        normals[i * sec:(i + 1) * sec] = local[i] @ rot.T / 0.2
        balls.geometry.positions.update_range(i * sec, sec)
        balls.geometry.normals.update_range(i * sec, sec)
    showm.render()
    if cnt == 40:
        showm.cancel_callback("physics")

showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
