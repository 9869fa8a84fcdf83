"""Wrecking ball, FURY 2: a heavy ball on a chain, its hinge pushed once, smashes a block of 125 bricks.

This is the integration guide's "Wrecking Ball Simulation" written for FURY 2.0 (pygfx), joining its
two ways of drawing many bodies. The 125 bricks are vertex ranges of ONE box actor (24 vertices a
brick), as in "Rendering multiple objects by a single actor"; the chain's 14 cylinder links are vertex
ranges of ONE cylinder actor (68 vertices a link), as in "Rendering Joints". The ball, the chain's last
link, is an actor of its own: a real sphere mesh with radial normals (FURY 2's default sphere is an
impostor), turned as a whole with ``local.rotation``. The tiny hinge box at the top of the chain and the
static plate are whole actors too.

Each range's vertices are captured once in its body's (or link's) own frame and recomputed from
pyBullet's pose after every step: ``world = R(orn) @ local + pos``, with a brick's pose from
``getBasePositionAndOrientation`` and a link's from ``getLinkState(rope, j, computeForwardKinematics=1)[4:6]``
(its link frame as of the last step). The chain actor holds 14 cylinders, so a link's range is its
vertex count divided by 14, not by the brick count. What is drawn is what pyBullet collides: each
cylinder (radius 0.1 m, height 0.1 m) along its link's z axis, half a link below its joint. The
rewritten ranges are announced with ``positions.update_range`` (bricks) and ``update_full`` (links).

Physics as in the kit's ``wrecking_ball`` scene, which corrects FURY's example: the link positions
are the real (0, 0, -0.1), where FURY's ``astype(int)`` truncated them to 0 and piled every link on
the hinge. A static 5 x 5 x 0.2 m plate (friction 0.3, restitution 0.5); a 5 x 5 x 5 block of
0.2 x 0.4 x 0.2 m bricks of 0.5 kg (friction 0.1, restitution 0.1), brick (i, j, k) centred at
(0.2 i - 1.8, 0.4 j - 0.9, 0.2 k + 0.1); a 0.1 kg hinge box (half extent 0.01 m) pinned at (0, 0, 2)
by a fixed constraint, with 15 spherical-joint links 0.1 m apart below it: 14 cylinders of 0.5 kg
and a 5 kg ball of radius 0.5 m; joint friction as a velocity motor (kp 0, kd 1, force 0.0005).
The hinge is pushed once with 500 N along -x before the first step; gravity -10, 131 steps.

EXPECT: pass
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
rng = np.random.default_rng(0)


def sphere_with_normals(radius, color):
    """A real sphere mesh (not FURY 2's default impostor) at the origin, lit by radial normals."""
    sphere = actor.sphere(centers=np.zeros((1, 3)), colors=np.array([color]), radii=radius, impostor=False)
    vertices = sphere.geometry.positions.data
    sphere.geometry.normals = Buffer((vertices / np.linalg.norm(vertices, axis=1, keepdims=True)).astype(np.float32))
    return sphere


def box_actor(size, color):
    """A box at the origin with its edges along x, y, z; FURY 2's ``scales`` are full edge lengths."""
    return actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                     scales=np.array([size]), colors=np.array([color]))


# Base plate: static, its top face at z = 0. It never moves, so its actor is placed once.
base_size = np.array([5.0, 5.0, 0.2])
base_actor = box_actor(base_size, (1.0, 1.0, 1.0))
base_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(base_size / 2))
base = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=base_coll,
                         basePosition=[0, 0, -base_size[2] / 2], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(base, -1, lateralFriction=0.3, restitution=0.5)
base_actor.local.position = (0, 0, -base_size[2] / 2)

# Bricks: a 5 x 5 x 5 block, brick (i, j, k) at wall_origin + (0.2 i, 0.4 j, 0.2 k + 0.1).
wall_length, wall_breadth, wall_height = 5, 5, 5
nb_bricks = wall_length * wall_breadth * wall_height
brick_size = np.array([0.2, 0.4, 0.2])
wall_origin = np.array([-1.8, -0.9, 0.0])
brick_centers = np.zeros((nb_bricks, 3))
brick_orns = np.zeros((nb_bricks, 4))
brick_colors = rng.random((nb_bricks, 3))
brick_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(brick_size / 2))
bricks = np.zeros(nb_bricks, dtype=np.int64)  # body ids: int64, an int8 array would overflow
index = 0
for i in range(wall_length):
    for k in range(wall_height):
        for j in range(wall_breadth):
            brick_centers[index] = wall_origin + [i * brick_size[0], j * brick_size[1], (k + 0.5) * brick_size[2]]
            brick_orns[index] = [0, 0, 0, 1]
            bricks[index] = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=brick_coll,
                                              basePosition=brick_centers[index].tolist(),
                                              baseOrientation=brick_orns[index].tolist())
            p.changeDynamics(int(bricks[index]), -1, lateralFriction=0.1, restitution=0.1)
            index += 1

# The chain: a hinge box, 14 cylinder links and the ball as its 15th link.
n_links = 15
n_cylinders = n_links - 1
link_length = 0.1
link_radius = 0.1
link_mass = 0.5
link_offset = [0.0, 0.0, -link_length / 2]   # each collision cylinder, in its link frame
ball_radius = 0.5
ball_mass = 5.0
joint_friction = 0.0005
link_colors = rng.random((n_cylinders, 3))

link_coll = p.createCollisionShape(p.GEOM_CYLINDER, radius=link_radius, height=link_length,
                                   collisionFramePosition=link_offset, collisionFrameOrientation=[0, 0, 0, 1])
ball_coll = p.createCollisionShape(p.GEOM_SPHERE, radius=ball_radius)
hinge_half = 0.01
hinge_position = [0.0, 0.0, 2.0]
hinge_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=[hinge_half] * 3)

rope = p.createMultiBody(baseMass=0.1,
                         baseCollisionShapeIndex=hinge_coll,
                         baseVisualShapeIndex=-1,
                         basePosition=hinge_position,
                         baseOrientation=[0, 0, 0, 1],
                         linkMasses=[link_mass] * n_cylinders + [ball_mass],
                         linkCollisionShapeIndices=[link_coll] * n_cylinders + [ball_coll],
                         linkVisualShapeIndices=[-1] * n_links,
                         linkPositions=[[0.0, 0.0, -link_length]] * n_links,   # floats: not astype(int)
                         linkOrientations=[[0, 0, 0, 1]] * n_links,
                         linkInertialFramePositions=[[0, 0, 0]] * n_links,
                         linkInertialFrameOrientations=[[0, 0, 0, 1]] * n_links,
                         linkParentIndices=list(range(n_links)),   # link j hangs from link j - 1 (0: the hinge)
                         linkJointTypes=[p.JOINT_SPHERICAL] * n_links,
                         linkJointAxis=[[1, 0, 0]] * n_links)

# Joint friction: a velocity motor with no position gain only resists joint motion.
for j in range(n_links):
    p.setJointMotorControlMultiDof(rope, j, p.POSITION_CONTROL, targetPosition=[0, 0, 0, 1],
                                   targetVelocity=[0, 0, 0], positionGain=0, velocityGain=1,
                                   force=[joint_friction] * 3)

# The pin holding the hinge where it was built.
p.createConstraint(rope, -1, -1, -1, p.JOINT_FIXED, [0, 0, 0], [0, 0, 0], hinge_position)

# Actors: one box actor for all bricks, one cylinder actor for the 14 links (built along z at the
# origin), and whole actors for the ball and the hinge.
brick_actor = actor.box(centers=brick_centers, directions=np.tile([1.0, 0.0, 0.0], (nb_bricks, 1)),
                        scales=np.tile(brick_size, (nb_bricks, 1)), colors=brick_colors)
chain_actor = actor.cylinder(centers=np.zeros((n_cylinders, 3)), directions=np.tile([0.0, 0.0, 1.0], (n_cylinders, 1)),
                             colors=link_colors, radii=link_radius, height=link_length, sectors=16, capped=True)
ball_actor = sphere_with_normals(ball_radius, (1.0, 0.0, 1.0))
hinge_actor = box_actor([2 * hinge_half] * 3, (1.0, 0.0, 0.0))

brick_vertices = brick_actor.geometry.positions.data   # (3000, 3) float32, what the GPU draws from
brick_sec = brick_vertices.shape[0] // nb_bricks        # 24 vertices a brick
chain_vertices = chain_actor.geometry.positions.data
link_sec = chain_vertices.shape[0] // n_cylinders       # 68 vertices a link: divided by the LINK count

# Each brick's vertices in its own frame, captured once: local = R0^T (v - c0).
brick_local = np.zeros((nb_bricks, brick_sec, 3))
for b in range(nb_bricks):
    rot0 = np.reshape(p.getMatrixFromQuaternion(brick_orns[b].tolist()), (3, 3))
    brick_local[b] = (brick_vertices[b * brick_sec:(b + 1) * brick_sec].astype(np.float64) - brick_centers[b]) @ rot0

# Each link's cylinder in its link frame, captured once: the canonical cylinder moved by the offset.
link_local = [chain_vertices[j * link_sec:(j + 1) * link_sec].astype(np.float64) + link_offset
              for j in range(n_cylinders)]


def sync_bricks():
    for b, brick in enumerate(bricks):
        pos, orn = p.getBasePositionAndOrientation(int(brick))
        rot_mat = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
        start = b * brick_sec
        brick_vertices[start:start + brick_sec] = brick_local[b] @ rot_mat.T + pos
        brick_actor.geometry.positions.update_range(start, brick_sec)


def sync_chain():
    # The hinge: the base's inertial frame is its link frame.
    pos, orn = p.getBasePositionAndOrientation(rope)
    hinge_actor.local.position = pos
    hinge_actor.local.rotation = orn
    for j in range(n_cylinders):
        pos, orn = p.getLinkState(rope, j, computeForwardKinematics=1)[4:6]
        rot_mat = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
        chain_vertices[j * link_sec:(j + 1) * link_sec] = link_local[j] @ rot_mat.T + pos
    chain_actor.geometry.positions.update_full()
    # The ball: the last link, its sphere centred on its link frame.
    pos, orn = p.getLinkState(rope, n_links - 1, computeForwardKinematics=1)[4:6]
    ball_actor.local.position = pos
    ball_actor.local.rotation = orn


sync_bricks()
sync_chain()

scene = window.Scene()
scene.add(base_actor, brick_actor, chain_actor, ball_actor, hinge_actor)

window_size = (900, 768)
showm = window.ShowManager(scene=scene, size=window_size, title="FURY 2 + pyBullet: wrecking ball")


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


set_camera(showm.screens[0].camera, position=(10.28, -7.1, 6.39), focal_point=(0.0, 0.0, 0.4),
           view_up=(-0.35, 0.26, 1.0), view_angle=30.0, clipping_range=(0.5, 19.0), size=window_size)

counter = itertools.count()
apply_force = True


def timer_callback():
    global apply_force
    cnt = next(counter)

    # Push the hinge once, at its centre, before the first step.
    if apply_force:
        hinge_pos = p.getBasePositionAndOrientation(rope)[0]
        p.applyExternalForce(rope, -1, forceObj=[-500, 0, 0], posObj=hinge_pos, flags=p.WORLD_FRAME)
        apply_force = False

    p.stepSimulation()

    # Draw what pyBullet has now, after the step.
    sync_bricks()
    sync_chain()

    showm.render()

    if cnt == nb_steps - 1:  # that was step number nb_steps
        showm.cancel_callback("physics")
        showm.close()


showm.register_callback(timer_callback, 1 / 240, True, "physics")
showm.start()
p.disconnect()
