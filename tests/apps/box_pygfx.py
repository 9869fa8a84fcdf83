"""A small right app (FURY 2): one tumbling box, whole actor, posed every tick after the step. The kit's
tests copy it with one line changed to make wrong ones (tests/test_app_mode.py).

EXPECT: pass
"""
import itertools
import numpy as np
import pybullet as p
from fury import actor, window

p.connect(p.DIRECT)
p.setGravity(0, 0, -10)
box = actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0, 0]]), scales=np.array([[0.2, 0.4, 0.2]]), colors=np.array([[1, 0, 0]]))
shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.1, 0.2, 0.1])
body = p.createMultiBody(1, shape, basePosition=[0, 0, 2], baseOrientation=p.getQuaternionFromEuler([0.3, 0.2, 0.1]))
p.resetBaseVelocity(body, [0.5, 0, 0], [1, 2, 3])
scene = window.Scene()
scene.add(box)
showm = window.ShowManager(scene=scene, size=(300, 300))
# close enough that the box covers a few thousand pixels, so app mode's picture check judges it
camera = showm.screens[0].camera
camera.local.position = (0.05, -3, 1.9)
camera.world.reference_up = (0, 0, 1)
camera.look_at((0.05, 0, 1.9))
counter = itertools.count()

def timer_callback():
    cnt = next(counter)
    p.stepSimulation()
    pos, orn = p.getBasePositionAndOrientation(body)
    box.local.position = pos
    box.local.rotation = orn
    showm.render()
    if cnt == 50:
        showm.cancel_callback("physics")

showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
