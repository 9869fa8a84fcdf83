"""Ball collision, FURY 2: two balls pushed towards each other in zero gravity meet head-on.

The integration guide's "Ball Collision Simulation" written for FURY 2.0 (pygfx). Each ball is a
whole actor built at the origin; after every ``p.stepSimulation()`` it gets its body's position and
(x, y, z, w) quaternion through ``actor.local.position`` and ``actor.local.rotation``.

Physics as in the kit's ``ball_collision`` scene: balls of radius 0.5 m and 0.5 kg at x = +10 (red)
and x = -10 (blue), restitution 0.6 each, no gravity, each pushed once with 40 kN towards the other,
51 steps of 1/240 s. (40 kN on 0.5 kg for one step would be 333 m/s; pyBullet clamps a base's
velocity to 100 m/s per component, and that clamp sets the speed of the collision.)

EXPECT: pass
"""

import itertools

import numpy as np
import pybullet as p
from fury import actor, window
from fury.lib import Buffer

client = p.connect(p.DIRECT)
p.setTimeStep(1 / 240)
p.setGravity(0, 0, 0)

nb_steps = 51
ball_radius = 0.5
force = 40000


def sphere_with_normals(radius, color):
    """A real sphere mesh (``impostor=False``) at the origin, with radial unit normals to light it."""
    sphere = actor.sphere(centers=np.zeros((1, 3)), colors=np.array([color]), radii=radius, impostor=False)
    vertices = sphere.geometry.positions.data
    sphere.geometry.normals = Buffer((vertices / np.linalg.norm(vertices, axis=1, keepdims=True)).astype(np.float32))
    return sphere


red_ball_actor = sphere_with_normals(ball_radius, (1.0, 0.0, 0.0))
blue_ball_actor = sphere_with_normals(ball_radius, (0.0, 0.0, 1.0))

red_ball_coll = p.createCollisionShape(p.GEOM_SPHERE, radius=ball_radius)
red_ball = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=red_ball_coll,
                             basePosition=[10, 0, 0], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(red_ball, -1, restitution=0.6)

blue_ball_coll = p.createCollisionShape(p.GEOM_SPHERE, radius=ball_radius)
blue_ball = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=blue_ball_coll,
                              basePosition=[-10, 0, 0], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(blue_ball, -1, restitution=0.6)


def sync_actor(ball_actor, ball):
    pos, orn = p.getBasePositionAndOrientation(ball)
    ball_actor.local.position = pos
    ball_actor.local.rotation = orn


sync_actor(red_ball_actor, red_ball)
sync_actor(blue_ball_actor, blue_ball)

scene = window.Scene()
scene.add(red_ball_actor, blue_ball_actor)

window_size = (900, 768)
showm = window.ShowManager(scene=scene, size=window_size, title="FURY 2 + pyBullet: ball collision")


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


set_camera(showm.screens[0].camera, position=(0.31, -39.89, 1.03), focal_point=(0.0, 0.0, 0.0),
           view_up=(0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 45.0), size=window_size)

counter = itertools.count()
apply_force = True


def timer_callback():
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
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
