"""A right app (FURY 2) with two pyBullet clients, one box in each, both drawn in one scene: each
client a world of its own (two DIRECT connections), stepped and synced every tick.

EXPECT: pass
"""
import itertools
import numpy as np
import pybullet as p
from fury import actor, window

clients = [p.connect(p.DIRECT), p.connect(p.DIRECT)]
scene = window.Scene()
pairs = []
for k, client in enumerate(clients):
    p.setGravity(0, 0, -10, physicsClientId=client)
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.5, 1.0, 0.5], physicsClientId=client)
    body = p.createMultiBody(1, shape, basePosition=[3.0 * k, 0, 2], physicsClientId=client,
                             baseOrientation=p.getQuaternionFromEuler([0.3, 0.2, 0.1 + k]))
    p.resetBaseVelocity(body, [0.5, 0, 0], [1, 2, 3], physicsClientId=client)
    box = actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0, 0]]), scales=np.array([[1.0, 2.0, 1.0]]),
                    colors=np.array([[1, 0, k]]))
    scene.add(box)
    pairs.append((client, body, box))
showm = window.ShowManager(scene=scene, size=(300, 300))
camera = showm.screens[0].camera
camera.local.position = (1.5, -14, 2)
camera.world.reference_up = (0, 0, 1)
camera.look_at((1.5, 0, 1.5))
counter = itertools.count()


def timer_callback():
    cnt = next(counter)
    for client, body, box in pairs:
        p.stepSimulation(physicsClientId=client)
        pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
        box.local.position = pos
        box.local.rotation = orn
    showm.render()
    if cnt == 50:
        showm.cancel_callback("physics")


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
