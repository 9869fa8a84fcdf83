"""A small right app (FURY 0.12): one tumbling box, whole actor, posed every tick after the step. The kit's
tests copy it with one line changed to make wrong ones (tests/test_app_mode.py).

EXPECT: pass
"""
import itertools
import numpy as np
import pybullet as p
from fury import actor, window, utils
from scipy.spatial.transform import Rotation
from vtkmodules.vtkCommonMath import vtkMatrix4x4

p.connect(p.DIRECT)
p.setGravity(0, 0, -10)
ball_actor = actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0, 0]]), scales=np.array([[0.2, 0.4, 0.2]]), colors=np.array([[1, 0, 0]]))
shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.1, 0.2, 0.1])
ball = p.createMultiBody(1, shape, basePosition=[0, 0, 2], baseOrientation=p.getQuaternionFromEuler([0.3, 0.2, 0.1]))
p.resetBaseVelocity(ball, [0.5, 0, 0], [1, 2, 3])
scene = window.Scene()
scene.add(ball_actor)
showm = window.ShowManager(scene=scene, size=(300, 300))
showm.initialize()
# close enough that the box covers a few thousand pixels, so app mode's picture check judges it
scene.set_camera(position=(0.05, -3, 1.9), focal_point=(0.05, 0, 1.9), view_up=(0, 0, 1))  # after: it resets the camera
counter = itertools.count()

def timer_callback(_obj, _event):
    cnt = next(counter)
    p.stepSimulation()
    pos, orn = p.getBasePositionAndOrientation(ball)
    m = np.eye(4); m[:3, :3] = Rotation.from_quat(orn).as_matrix(); m[:3, 3] = pos
    u = vtkMatrix4x4(); u.DeepCopy(m.ravel()); ball_actor.SetUserMatrix(u)
    showm.render()
    if cnt == 50:
        showm.exit()

showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
