"""Ball collision, FURY 0.12, WRONG: each ball is moved but never turned.

The integration guide's "Ball Collision Simulation" for FURY 0.12 (VTK). Each ball is a whole sphere
actor built at the origin; after every ``p.stepSimulation()`` its user matrix is set to its body's
link frame: the rotation matrix of pyBullet's quaternion and its position (VTK turns the sphere's
stored normals with the actor's matrix).

Physics as in the kit's ``ball_collision`` scene: balls of radius 0.5 m and 0.5 kg at x = +10 (red)
and x = -10 (blue), restitution 0.6 each, no gravity, each pushed once with 40 kN towards the other,
51 steps of 1/240 s. (40 kN on 0.5 kg for one step would be 333 m/s; pyBullet clamps a base's
velocity to 100 m/s per component, and that clamp sets the speed of the collision.)

MISTAKE: moves each ball with SetPosition(*pos) alone and drops the guide's SetOrientation ("a ball looks the same turned"): the balls only slide in their own run, so only the kit's perturbed runs, which turn them, show the sphere's vertices (and its lighting) left unturned
EXPECT: fail perturbed translation-only
"""

import itertools

import numpy as np
import pybullet as p
from fury import actor, window

client = p.connect(p.DIRECT)
p.setTimeStep(1 / 240)
p.setGravity(0, 0, 0)

nb_steps = 51
ball_radius = 0.5
force = 40000


red_ball_actor = actor.sphere(centers=np.zeros((1, 3)), colors=np.array([[1.0, 0.0, 0.0]]), radii=ball_radius)
blue_ball_actor = actor.sphere(centers=np.zeros((1, 3)), colors=np.array([[0.0, 0.0, 1.0]]), radii=ball_radius)

red_ball_coll = p.createCollisionShape(p.GEOM_SPHERE, radius=ball_radius)
red_ball = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=red_ball_coll,
                             basePosition=[10, 0, 0], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(red_ball, -1, restitution=0.6)

blue_ball_coll = p.createCollisionShape(p.GEOM_SPHERE, radius=ball_radius)
blue_ball = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=blue_ball_coll,
                              basePosition=[-10, 0, 0], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(blue_ball, -1, restitution=0.6)


def sync_actor(ball_actor, ball):
    pos, _ = p.getBasePositionAndOrientation(ball)
    ball_actor.SetPosition(*pos)


sync_actor(red_ball_actor, red_ball)
sync_actor(blue_ball_actor, blue_ball)

scene = window.Scene()
scene.add(red_ball_actor, blue_ball_actor)
scene.set_camera(position=(0.31, -39.89, 1.03), focal_point=(0.0, 0.0, 0.0), view_up=(0.0, 0.0, 1.0))
showm = window.ShowManager(scene, size=(900, 768), reset_camera=False, order_transparent=True)
showm.initialize()

counter = itertools.count()
apply_force = True


def timer_callback(_obj, _event):
    global apply_force
    cnt = next(counter)

    if apply_force:
        # One push on each ball, at its centre, towards the other.
        red_pos = p.getBasePositionAndOrientation(red_ball)[0]
        p.applyExternalForce(red_ball, -1, forceObj=[-force, 0, 0], posObj=red_pos, flags=p.WORLD_FRAME)
        blue_pos = p.getBasePositionAndOrientation(blue_ball)[0]
        p.applyExternalForce(blue_ball, -1, forceObj=[force, 0, 0], posObj=blue_pos, flags=p.WORLD_FRAME)
        apply_force = False

    p.stepSimulation()

    sync_actor(red_ball_actor, red_ball)
    sync_actor(blue_ball_actor, blue_ball)

    showm.render()

    if cnt == nb_steps - 1:
        showm.exit()


showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
